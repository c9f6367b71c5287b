"""Tests for geomlib.mesh.io: exact vertex order, OBJ syntax, round trips, and bad files.

Every bad-input case checks the message: the problem, and where (path, line,
vertex or face indices).
"""

import logging
import re
import struct
import subprocess
import sys
import threading
import warnings
from pathlib import Path

import numpy as np
import pytest
import trimesh
from meshdata import COURSE, needs_course

from geomlib import MeshError, MeshReport, MeshWarning, load_mesh, save_mesh


def write(tmp_path, name, text):
    p = tmp_path / name
    p.write_bytes(text.encode() if isinstance(text, str) else text)
    return p


def load_quiet(path):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a clean file must load without any warning
        return load_mesh(path)


def icosphere():
    m = trimesh.creation.icosphere(subdivisions=2)
    return np.asarray(m.vertices), np.asarray(m.faces, dtype=np.int64)


SQUARE_V = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"


# ---------------------------------------------------------------- OBJ syntax


@pytest.mark.parametrize(
    "faces",
    [
        "f 1 2 3\nf 1 3 4\n",
        "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
        "f 1//1 2//2 3//3\nf 1//1 3//3 4//4\n",
        "f 1/1/1 2/2/2 3/3/3\nf 1/1/1 3/3/3 4/4/4\n",
        "f -4 -3 -2\nf -4 -2 -1\n",
        "f 1 2 3 4\n",  # quad: fan (1 2 3), (1 3 4)
        "f 1/4/2 2/3/1 3/2/4 4/1/3\n",
    ],
)
def test_obj_face_syntax(tmp_path, faces):
    text = (
        "# a unit square\nmtllib square.mtl\no square\n"
        + SQUARE_V
        + "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\n"
        + "g top\nusemtl paper\ns off\n"
        + faces
    )
    V, F = load_quiet(write(tmp_path, "sq.obj", text))
    assert V.dtype == np.float64 and F.dtype == np.int64
    assert np.array_equal(V, [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    assert np.array_equal(F, [[0, 1, 2], [0, 2, 3]])


def test_obj_polygon_fan_and_mixed_sizes(tmp_path):
    ring = "".join(f"v {np.cos(t):.6f} {np.sin(t):.6f} 0\n" for t in np.arange(6) * np.pi / 3)
    V, F = load_quiet(write(tmp_path, "hex.obj", ring + "v 0 0 1\nf 1 2 3 4 5 6\nf 7 2 1\n"))
    assert np.array_equal(F, [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5], [6, 1, 0]])


def test_obj_relative_indices_refer_to_vertices_above(tmp_path):
    text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 1 1 0\nf -3 -1 -2\n"
    V, F = load_mesh(write(tmp_path, "rel.obj", text), report=True)[:2]
    assert np.array_equal(F, [[0, 1, 2], [1, 3, 2]])


def test_obj_vertex_extras_crlf_continuation_and_blanks(tmp_path):
    text = "v 0 0 0 1.0\r\nv 1 0 0 0.5 0.5 0.5\r\n  v 0 1 0\r\n\r\nf 1 2 \\\r\n 3  # a comment\r\n"
    V, F = load_quiet(write(tmp_path, "odd.obj", text))
    assert np.array_equal(V, [[0, 0, 0], [1, 0, 0], [0, 1, 0]])
    assert np.array_equal(F, [[0, 1, 2]])


def test_obj_inline_comments(tmp_path):
    V, F = load_quiet(write(tmp_path, "c.obj", SQUARE_V + "f 1 2 3 # first\nf 1 3 4#second\n"))
    assert np.array_equal(F, [[0, 1, 2], [0, 2, 3]])


def test_obj_backslash_in_a_comment_is_not_a_continuation(tmp_path):
    text = "# made in C:\\meshes\\\n" + SQUARE_V + "f 1 2 3\nf 1 3 4\n"
    V, F = load_quiet(write(tmp_path, "bs.obj", text))
    assert len(V) == 4 and np.array_equal(F, [[0, 1, 2], [0, 2, 3]])


def test_obj_without_final_newline_and_tabs(tmp_path):
    V, F = load_quiet(write(tmp_path, "t.obj", "v\t0 0 0\nv 1\t0 0\nv 0 1 0\nf\t1 2 3"))
    assert len(V) == 3 and np.array_equal(F, [[0, 1, 2]])


def test_interleaved_normals_and_texture_corners_keep_every_vertex(tmp_path):
    V, F = icosphere()
    rng = np.random.default_rng(0)
    V = V + 1e-3 * rng.standard_normal(V.shape)
    lines = ["# made for a test", "o ball"]
    for p in V:
        lines.append("v %.17g %.17g %.17g" % tuple(p))
        lines.append("vn 0 0 1")
        lines.append("vt 0.5 0.5")
    for f in F + 1:
        lines.append("f %d/1/1 %d/1/1 %d/1/1" % tuple(f))
    V2, F2 = load_quiet(write(tmp_path, "ball.obj", "\n".join(lines) + "\n"))
    assert np.array_equal(V2, V) and np.array_equal(F2, F)


def test_windows_scanner_file_loads_as_written(tmp_path):
    # byte-order mark, CRLF, vertex colours, groups, objects, materials, smoothing groups, comments
    V, F = icosphere()
    colours = np.random.default_rng(1).uniform(0, 1, size=V.shape)
    lines = ["# exported by a scanner", "mtllib scan.mtl", "o scan", "g body"]
    lines += ["v %.17g %.17g %.17g %.3f %.3f %.3f" % (*p, *c) for p, c in zip(V, colours)]
    lines += ["usemtl skin", "s 1"] + ["f %d %d %d" % tuple(f) for f in F + 1]
    data = ("\ufeff" + "\r\n".join(lines) + "\r\n").encode("utf-8")
    V2, F2 = load_quiet(write(tmp_path, "scan.obj", data))
    assert np.array_equal(V2, V) and np.array_equal(F2, F)


def test_bom_alone_and_classic_mac_line_ends(tmp_path):
    V, F = load_quiet(
        write(tmp_path, "mac.obj", b"\xef\xbb\xbf" + (SQUARE_V + "f 1 2 3\nf 1 3 4").replace("\n", "\r").encode())
    )
    assert np.array_equal(V, [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]) and np.array_equal(F, [[0, 1, 2], [0, 2, 3]])


def test_line_elements_are_ignored_with_a_count(tmp_path):
    text = SQUARE_V + "l 1 2\nl 2 3 4\nf 1 2 3\nf 1 3 4\n"
    with pytest.warns(MeshWarning, match=r"l\.obj: 2 line elements \('l' statements\) ignored") as rec:
        V, F = load_mesh(write(tmp_path, "l.obj", text))
    assert len(rec) == 1 and len(V) == 4 and np.array_equal(F, [[0, 1, 2], [0, 2, 3]])


def test_awkward_scan_with_holes_loads_with_its_unused_vertices(tmp_path):
    from awkward_meshes import scan_with_holes

    path = scan_with_holes(tmp_path)
    V, F, report = load_mesh(path, report=True)
    written = path.read_bytes().decode("utf-8-sig").splitlines()
    assert len(V) == sum(line.startswith("v ") for line in written)
    assert len(F) == sum(line.startswith("f ") for line in written)
    first = [float(x) for x in written[4].split()[1:4]]
    assert V[0].tolist() == pytest.approx(first, abs=1e-9)
    assert len(report.unreferenced_vertices) == 12 and report.n_boundary_loops == 3


def test_unreferenced_vertex_is_kept_with_a_warning(tmp_path):
    path = write(tmp_path, "extra.obj", SQUARE_V + "v 5 5 5\nf 1 2 3\nf 1 3 4\n")
    with pytest.warns(MeshWarning, match=r"extra\.obj: 1 unreferenced vertex \(4\)") as rec:
        V, F = load_mesh(path)
    assert len(rec) == 1  # one warning summarising everything
    assert len(V) == 5 and np.array_equal(V[4], [5, 5, 5])


def test_one_warning_for_several_problems(tmp_path):
    text = SQUARE_V + "v 5 5 5\nv 2 0 0\nf 1 2 3\nf 1 3 4\nf 1 3 4\nf 1 2 6\n"
    with pytest.warns(MeshWarning) as rec:
        load_mesh(write(tmp_path, "many.obj", text))
    assert len(rec) == 1
    msg = str(rec[0].message)
    assert "1 zero-area face (3)" in msg and "1 unreferenced vertex (4)" in msg and "1 duplicate face (2)" in msg


def test_report_true_returns_the_report_without_warning(tmp_path):
    path = write(tmp_path, "extra.obj", SQUARE_V + "v 5 5 5\nf 1 2 3\nf 1 3 4\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        V, F, rep = load_mesh(path, report=True)
    assert isinstance(rep, MeshReport) and np.array_equal(rep.unreferenced_vertices, [4])


# ---------------------------------------------------------------- round trips


@pytest.mark.parametrize("ext", [".obj", ".off", ".ply"])
def test_round_trip_is_exact(tmp_path, ext):
    V, F = icosphere()
    rng = np.random.default_rng(1)
    V = V * np.pi + rng.standard_normal(V.shape) * 1e-7  # digits that %.6f would lose
    F = F[rng.permutation(len(F))]
    path = tmp_path / f"ball{ext}"
    save_mesh(path, V, F)
    V2, F2 = load_quiet(path)
    assert V2.dtype == np.float64 and F2.dtype == np.int64
    assert np.array_equal(V2, V) and np.array_equal(F2, F)


def test_round_trip_keeps_unreferenced_and_order(tmp_path):
    V, F = icosphere()
    V = np.vstack([[[7.0, 7.0, 7.0]], V])  # vertex 0 unused, the rest shifted by one
    F = F + 1
    for ext in (".obj", ".off", ".ply"):
        save_mesh(tmp_path / f"u{ext}", V, F)
        V2, F2, rep = load_mesh(tmp_path / f"u{ext}", report=True)
        assert np.array_equal(V2, V) and np.array_equal(F2, F)
        assert np.array_equal(rep.unreferenced_vertices, [0])


def test_stl_keeps_three_vertices_per_facet(tmp_path):
    V, F = icosphere()
    path = tmp_path / "ball.stl"
    save_mesh(path, V, F)
    V2, F2, rep = load_mesh(path, report=True)
    assert len(V2) == 3 * len(F) and np.array_equal(F2, np.arange(3 * len(F)).reshape(-1, 3))
    assert np.array_equal(V2, V[F].reshape(-1, 3).astype(np.float32).astype(np.float64))
    assert rep.n_components == len(F) and len(rep.boundary_edges) == 3 * len(F)
    with pytest.warns(MeshWarning, match=f"{len(F)} connected components"):
        load_mesh(path)


def test_save_mesh_refuses_bad_input(tmp_path):
    V, F = icosphere()
    with pytest.raises(MeshError, match=r"x\.xyz: unknown mesh format '\.xyz'; supported: \.obj, \.off, \.ply, \.stl"):
        save_mesh(tmp_path / "x.xyz", V, F)
    with pytest.raises(MeshError, match="face 0 has index 9999"):
        save_mesh(tmp_path / "x.obj", V, np.array([[0, 1, 9999]]))
    assert not (tmp_path / "x.obj").exists()
    with pytest.raises(MeshError, match="cannot write the file"):
        save_mesh(tmp_path / "no_such_dir" / "x.obj", V, F)


def test_upper_case_extension(tmp_path):
    V, F = icosphere()
    save_mesh(tmp_path / "BALL.OBJ", V, F)
    assert np.array_equal(load_quiet(tmp_path / "BALL.OBJ")[0], V)


# ---------------------------------------------------------------- bad files: OBJ


def expect(path, pattern):
    with pytest.raises(MeshError) as err:
        load_mesh(path)
    msg = str(err.value)
    assert msg.startswith(str(path)), msg
    assert re.search(pattern, msg), msg
    return msg


def test_missing_file(tmp_path):
    expect(tmp_path / "nothing.obj", r"nothing\.obj: no such file$")


def test_directory(tmp_path):
    (tmp_path / "dir.obj").mkdir()
    expect(tmp_path / "dir.obj", r": is a directory, not a mesh file$")


def test_unreadable_file(tmp_path, monkeypatch):
    path = write(tmp_path, "locked.obj", SQUARE_V + "f 1 2 3\n")

    def refuse(self):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(Path, "read_bytes", refuse)
    expect(path, r"locked\.obj: cannot read the file: Permission denied$")


def test_unknown_extension(tmp_path):
    expect(
        write(tmp_path, "mesh.xyz", SQUARE_V), r": unknown mesh format '\.xyz'; supported: \.obj, \.off, \.ply, \.stl$"
    )
    expect(write(tmp_path, "mesh", SQUARE_V), r": unknown mesh format '\(no extension\)'")


@pytest.mark.parametrize("ext", [".obj", ".off", ".ply", ".stl"])
def test_empty_file(tmp_path, ext):
    expect(write(tmp_path, "e" + ext, ""), r": the file is empty$")
    expect(write(tmp_path, "w" + ext, " \n\n\t\n"), r": the file is empty$")


def test_only_comments(tmp_path):
    expect(write(tmp_path, "c.obj", "# nothing here\no empty\n"), r": the file holds no vertices and no faces$")


def test_vertices_but_no_faces(tmp_path):
    expect(write(tmp_path, "pts.obj", SQUARE_V), r": the file has 4 vertices but no faces \(a point cloud")


def test_faces_but_no_vertices(tmp_path):
    expect(write(tmp_path, "nov.obj", "f 1 2 3\n"), r": the file has 1 faces but no vertices$")


def test_nan_and_inf_coordinates(tmp_path):
    text = "v 0 0 0\nv nan 0 0\nv 0 1 0\nv 0 0 inf\nf 1 2 3\nf 1 3 4\n"
    expect(
        write(tmp_path, "nan.obj", text),
        r": 2 vertices have NaN or infinite coordinates: vertices 1, 3 \(0-based; lines 2, 4\)$",
    )


def test_face_index_out_of_range(tmp_path):
    text = "# header\n" + SQUARE_V + "f 1 2 3\nf 1 3 5\nf 9 1 2\n"
    msg = expect(write(tmp_path, "range.obj", text), r": face indices out of range, the file has 4 vertices")
    assert "(valid: 1..4, or -1..-4 counting back)" in msg
    assert "line 7 (face 1): index 5; line 8 (face 2): index 9" in msg
    assert msg.endswith("2 faces on lines 7, 8")


def test_negative_index_out_of_range(tmp_path):
    text = "v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n"  # only 2 vertices above the face
    expect(
        write(tmp_path, "neg.obj", text),
        r"out of range, the file has 3 vertices .*: line 3 \(face 0\): index -3; 1 face on line 3$",
    )


def test_index_zero(tmp_path):
    expect(
        write(tmp_path, "zero.obj", SQUARE_V + "f 1 2 3\nf 0 1 2\n"),
        r": line 6: vertex index 0 is invalid \(OBJ indices start at 1\)$",
    )


def test_face_repeating_a_vertex(tmp_path):
    expect(
        write(tmp_path, "rep.obj", SQUARE_V + "f 1 2 3\nf 3 4 3\n"),
        r": 1 face repeats a vertex \(no triangle; 0-based vertex indices\): line 6: face 1 = \[2, 3, 2\]$",
    )
    # a pentagon listing a corner twice in a row (its fan has a degenerate triangle), and a bad triangle
    msg = expect(
        write(tmp_path, "rep2.obj", SQUARE_V + "f 1 2 3 3 4\nf 4 4 1\n"),
        r": 2 faces repeat a vertex .*: line 5: face 1 = \[0, 2, 2\]; line 6: face 3 = \[3, 3, 0\]",
    )
    assert msg.endswith("faces 1, 3 on lines 5, 6")


def test_malformed_vertex_line(tmp_path):
    expect(
        write(tmp_path, "badv.obj", "v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n"),
        r": line 2: vertex coordinates are not numbers: 'v 1 zero 0'$",
    )
    expect(
        write(tmp_path, "shortv.obj", "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n"),
        r": line 2: a vertex needs x y z \(optionally w or r g b\), found 2 numbers: 'v 1 0'$",
    )


def test_malformed_face_line(tmp_path):
    expect(
        write(tmp_path, "badf.obj", SQUARE_V + "f 1 2 3\nf 1 2 x\n"),
        r": line 6: face corners must be integers \(v, v/vt, v//vn or v/vt/vn\): 'f 1 2 x'$",
    )
    expect(write(tmp_path, "floatf.obj", SQUARE_V + "f 1 2 3.5\n"), r": line 5: face corners must be integers")


def test_face_index_too_large(tmp_path):
    expect(
        write(tmp_path, "big.obj", SQUARE_V + "f 1 2 123456789012345678901234567890\n"),
        r": line 5: face index too large: 'f 1 2 123456789012345678901234567890'$",
    )


def test_face_with_two_vertices(tmp_path):
    expect(
        write(tmp_path, "two.obj", SQUARE_V + "f 1 2 3\nf 1 2\n"),
        r": line 6: a face needs at least 3 vertex indices, found 2$",
    )


def test_unknown_statement(tmp_path):
    expect(
        write(tmp_path, "junk.obj", SQUARE_V + "hello world\nf 1 2 3\n"),
        r": line 5: not an OBJ statement \(expected v, f, vn, vt, o, g, s, usemtl, mtllib or a # comment\): 'hello world'$",
    )


def test_binary_garbage_named_obj(tmp_path):
    expect(write(tmp_path, "bin.obj", bytes(range(1, 256)) * 4), r": line 1: not an OBJ statement")


# ---------------------------------------------------------------- bad files: OFF, PLY, STL


def test_off_reader_polygons_comments_and_colours(tmp_path):
    text = (
        "OFF\n# a square and a triangle\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0 0.5 0.5 0.5\n0 0 1\n"
        "4 0 1 2 3 255 0 0\n3 0 4 1\n"
    )
    V, F, rep = load_mesh(write(tmp_path, "sq.off", text), report=True)
    assert len(V) == 5 and np.array_equal(F, [[0, 1, 2], [0, 2, 3], [0, 4, 1]])
    V2, F2, _ = load_mesh(write(tmp_path, "sq2.off", "OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"), report=True)
    assert np.array_equal(F2, [[0, 1, 2]])


def test_off_bad_header(tmp_path):
    expect(
        write(tmp_path, "h.off", "OFF\nthree 1 0\n0 0 0\n"),
        r": line 2: expected the counts 'nv nf ne' of the OFF header, found 'three 1 0'$",
    )


def test_off_truncated(tmp_path):
    expect(
        write(tmp_path, "t.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n"),
        r": the header \(line 2\) announces 4 vertices and 2 faces, but the file ends after 4 vertex lines and 1 face line$",
    )


def test_off_malformed_lines(tmp_path):
    expect(
        write(tmp_path, "v.off", "OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n"),
        r": line 4: a vertex needs 3 numbers x y z, found '1 0'$",
    )
    expect(
        write(tmp_path, "f.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n"),
        r": line 6: a face is 'k i0 ... ik-1' with k integer indices, found '4 0 1 2'$",
    )


def test_off_index_out_of_range(tmp_path):
    msg = expect(
        write(tmp_path, "r.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 3\n"),
        r": face indices out of range, the file has 3 vertices \(valid: 0..2\): line 7 \(face 1\): index 3",
    )
    assert msg.endswith("1 face on line 7")


def test_off_vertices_but_no_faces_and_nan(tmp_path):
    expect(write(tmp_path, "p.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n"), r": the file has 3 vertices but no faces")
    expect(
        write(tmp_path, "n.off", "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n"),
        r": 1 vertex has NaN or infinite coordinates: vertices 1 \(0-based; lines 4\)$",
    )


def test_off_binary_refused(tmp_path):
    expect(write(tmp_path, "b.off", b"OFF BINARY\n\x00\x01\x02"), r": line 1: binary OFF is not supported")


def test_ply_and_stl_garbage(tmp_path):
    expect(
        write(tmp_path, "g.ply", b"this is not a ply file\n"),
        r": not a PLY file: it does not start with the line 'ply'$",
    )
    expect(write(tmp_path, "h.ply", b"ply\nformat ascii 1.0\nelement vertex x\n"), r": cannot read as PLY: ")
    expect(write(tmp_path, "g.stl", b"solid x\nfacet what\n"), r": cannot read as STL: ")


# ---------------------------------------------------------------- library logging off the reader's screen

# an ASCII STL whose facet normals do not parse (trimesh logs a traceback and goes on)
STL_BAD_NORMALS = (
    "solid x\nfacet normal a b c\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex {}\nendloop\nendfacet\nendsolid x\n"
)
# a binary STL whose header announces 5 facets and holds one
STL_TRUNCATED = (
    b"binary".ljust(80) + struct.pack("<I", 5) + struct.pack("<12fH", *[0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0], 0)
)


def _heard(caplog):
    """Log records a reader could see: trimesh's at any level, and any library's warning or worse.

    (trimesh's text decoding asks charset_normalizer, which logs at DEBUG level: shown
    only to a reader who turned DEBUG logging on.)
    """
    return [
        f"{r.name}: {r.getMessage()}"
        for r in caplog.records
        if r.name.split(".")[0] == "trimesh" or r.levelno >= logging.WARNING
    ]


@pytest.mark.parametrize(
    "name, data, problem",
    [
        ("normals.stl", STL_BAD_NORMALS.format("0 nan 0"), r": 1 vertex has NaN or infinite coordinates: vertices 2"),
        ("short.stl", STL_TRUNCATED, r": cannot read as STL: no mesh found in the file$"),
    ],
)
def test_malformed_stl_shows_the_mesh_error_and_nothing_else(tmp_path, caplog, capfd, name, data, problem):
    path = write(tmp_path, name, data)
    caplog.set_level(logging.DEBUG)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(MeshError, match=problem):
            load_mesh(path)
    assert _heard(caplog) == []
    assert caught == []
    assert capfd.readouterr() == ("", "")


def test_stl_with_unreadable_normals_loads_without_a_word(tmp_path, caplog, capfd):
    """geomlib does not use an STL's normals: trimesh's complaint about them is no news for the reader."""
    caplog.set_level(logging.DEBUG)
    V, F = load_quiet(write(tmp_path, "normals.stl", STL_BAD_NORMALS.format("0 1 0")))
    assert np.array_equal(V, [[0, 0, 0], [1, 0, 0], [0, 1, 0]]) and np.array_equal(F, [[0, 1, 2]])
    assert _heard(caplog) == []
    assert capfd.readouterr() == ("", "")


def test_malformed_stl_prints_nothing_on_a_plain_python_stderr(tmp_path):
    """Without pytest's log handlers, Python prints unhandled log records on stderr: none may come."""
    path = write(tmp_path, "normals.stl", STL_BAD_NORMALS.format("0 nan 0"))
    code = "import sys, geomlib\ntry:\n    geomlib.load_mesh(sys.argv[1])\nexcept geomlib.MeshError as e:\n    print(e)"
    done = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True, text=True, cwd=tmp_path)
    assert done.stderr == ""
    assert done.stdout.strip() == f"{path}: 1 vertex has NaN or infinite coordinates: vertices 2 (0-based)"


def test_trimesh_logs_as_configured_outside_geomlib_calls(tmp_path, caplog):
    """Only geomlib's own calls are quiet: after them, and in another thread, trimesh logs as before."""
    caplog.set_level(logging.WARNING)
    path = write(tmp_path, "normals.stl", STL_BAD_NORMALS.format("0 1 0"))
    load_quiet(path)
    logger = logging.getLogger("trimesh.util")
    assert logger.filters == []
    logger.warning("after the load")
    assert [r.getMessage() for r in caplog.records] == ["after the load"]

    caplog.clear()
    other = threading.Thread(target=trimesh.load, args=(str(path),), kwargs={"process": False})
    other.start()
    other.join()
    assert [r.getMessage() for r in caplog.records] == ["failed to extract face_normals"]


def test_ply_out_of_range_and_nan(tmp_path):
    head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    head += "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
    expect(
        write(tmp_path, "r.ply", head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n"),
        r"face indices out of range \(valid: 0..2 for 3 vertices\): face 0 has index 5",
    )
    expect(
        write(tmp_path, "n.ply", head + "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n"),
        r"1 vertex has NaN or infinite coordinates: vertices 1 \(0-based\)$",
    )


def test_ply_vertices_but_no_faces(tmp_path):
    head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
    expect(write(tmp_path, "pts.ply", head + "0 0 0\n1 0 0\n0 1 0\n"), r": the file has 3 vertices but no faces")


# ---------------------------------------------------------------- course meshes


def provenance_counts():
    """(file, V, F) rows of the table in the course meshes' PROVENANCE.md."""
    rows = []
    for line in (COURSE / "PROVENANCE.md").read_text().splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) > 8 and cells[0].startswith("`") and cells[6].isdigit():
            rows.append((cells[0].strip("`"), int(cells[6]), int(cells[7])))
    return rows


@needs_course
def test_every_course_mesh_loads_with_its_counts():
    rows = provenance_counts()
    assert len(rows) >= 17
    for name, nv, nf in rows:
        V, F, rep = load_mesh(COURSE / name, report=True)
        assert (len(V), len(F)) == (nv, nf), name
        assert len(rep.unreferenced_vertices) == 0


@needs_course
def test_armadillo_vertices_in_file_order():
    path = COURSE / "decompose" / "armadillo.obj"
    V, F = load_quiet(path)
    assert V.shape == (361, 3) and F.shape == (718, 3)
    text = path.read_text().splitlines()
    ref = np.array([[float(x) for x in l.split()[1:4]] for l in text if l.startswith("v ")])
    refF = np.array([[int(c.split("/")[0]) - 1 for c in l.split()[1:]] for l in text if l.startswith("f ")])
    assert np.array_equal(V, ref) and np.array_equal(F, refF)
