"""Reading and writing triangle meshes: OBJ, OFF, PLY, STL.

Convention: :func:`load_mesh` returns ``V`` as (n, 3) float64 and ``F`` as
(m, 3) int64 with 0-based indices, and the vertices are exactly the file's
vertices in the file's order: nothing is merged, dropped, split or reordered.
(General-purpose loaders often merge duplicate positions, drop unreferenced
vertices or split vertices along texture seams; the workbook's results are
per-vertex arrays that must line up with the file.)

Format notes
------------
OBJ (read by this module's own parser, vectorised over lines)
    Files as real tools write them: a UTF-8 byte-order mark, CRLF or CR line
    ends, ``v x y z`` with an optional ``w`` or vertex colour ``r g b`` after
    the coordinates (ignored); faces ``f v``, ``f v/vt``, ``f v//vn``,
    ``f v/vt/vn`` with 1-based or negative (relative: -1 is the latest vertex
    defined above the face) indices. Only the vertex index of each corner is
    used: ``vn`` and ``vt`` lines are skipped, so normals and texture
    coordinates never split a vertex. A polygon with k > 3 corners
    ``(p0, p1, ..., pk-1)`` is triangulated as the fan
    ``(p0, p1, p2), (p0, p2, p3), ..., (p0, pk-2, pk-1)``, which keeps the
    polygon's orientation (exact for convex planar polygons). Comments (``#``,
    also after a statement), blank lines, groups, objects, materials and
    smoothing groups (``g o usemtl mtllib s``), points ``p`` and the free-form
    geometry statements are ignored; line elements ``l`` are ignored and
    counted in the load warning; a line continued with a trailing backslash
    is joined to the next. Any other line is an error naming its line number.
OFF (own parser)
    Optional ``OFF``/``COFF``/``NOFF``/``CNOFF`` header (counts on the same or
    the next line), ``#`` comments, vertex lines (extra numbers after x y z
    such as colours ignored), face lines ``k i0 ... ik-1`` with 0-based
    indices (extra numbers after them ignored), polygons fan-triangulated as
    for OBJ. Binary OFF is not supported.
PLY (read with trimesh, ``process=False, maintain_order=True``)
    Vertex order and count as in the file. Triangles keep the file's order;
    larger polygons are triangulated by trimesh, which lists them after the
    file's triangles when a file mixes both (quads split as (0, 1, 2),
    (2, 3, 0)). Errors name the face rows of the returned F, no line numbers.
STL (read with trimesh, ``process=False``)
    STL has no shared vertices: each facet stores its own three corners. The
    corners are kept as they are, three vertices per facet in file order
    (facet f is ``(3f, 3f+1, 3f+2)``); nothing is merged. :func:`check_mesh`
    therefore reports m components and every edge on the boundary. Merge
    coincident vertices yourself (e.g. ``trimesh.Trimesh(V, F).merge_vertices()``)
    if you want a connected surface.

Errors
------
Bad files raise :class:`~geomlib.MeshError` whose message starts with the
path and names the problem: missing or unreadable file, unknown extension,
empty file, vertices without faces, a malformed line (its line number),
NaN/infinite coordinates (the vertices), face indices out of range (the
faces, their lines for OBJ/OFF, the bad index and the vertex count), faces
repeating a vertex (the faces and lines). Properties that do not stop a
computation (zero-area faces, non-manifold parts, several components,
unreferenced vertices, ...) are summarised in one :class:`~geomlib.MeshWarning`
(see :func:`geomlib.mesh.report.check_mesh`); the mesh is returned unaltered.
Nothing else reaches the screen: what trimesh logs while it reads a PLY or
STL file for geomlib (tracebacks of what it recovers from) is dropped.
"""

from __future__ import annotations

import contextlib
import logging
import os
import re
import threading
import warnings
from pathlib import Path

import numpy as np

from .errors import MeshError, MeshWarning, count_text, format_indices
from .report import check_mesh
from .validate import as_mesh, as_vertices, repeated_vertex_faces

__all__ = ["load_mesh", "save_mesh", "parse_obj", "SUPPORTED_EXTENSIONS"]

SUPPORTED_EXTENSIONS = (".obj", ".off", ".ply", ".stl")

# statements of the OBJ format that carry nothing for a triangle mesh
_OBJ_IGNORED = {
    b"vn",
    b"vt",
    b"vp",
    b"o",
    b"g",
    b"s",
    b"usemtl",
    b"mtllib",
    b"l",
    b"p",
    b"mg",
    b"cstype",
    b"deg",
    b"bmat",
    b"step",
    b"curv",
    b"curv2",
    b"surf",
    b"parm",
    b"trim",
    b"hole",
    b"scrv",
    b"sp",
    b"end",
    b"con",
    b"bevel",
    b"c_interp",
    b"d_interp",
    b"lod",
    b"maplib",
    b"usemap",
    b"shadow_obj",
    b"trace_obj",
    b"ctech",
    b"stech",
}


_HUGE = 2**62  # larger indices cannot be a vertex of any file (and would overflow int64)


def _show(line, limit=60):
    text = line.decode("utf-8", "replace").strip()
    return repr(text if len(text) <= limit else text[:limit] + "...")


# --------------------------------------------------------------------------
# OBJ: one reader, vectorised over lines
#
# 1. _obj_lines: bytes -> one statement per line, with the file's line numbers
#    kept (byte-order mark and CR line ends removed; comments, continuation
#    backslashes and leading blanks resolved in Python, only on the few lines
#    that have them).
# 2. _obj_statements: the keyword of every line (vectorised on its first bytes).
# 3. _obj_numbers: the numbers of all v lines, then of all f lines, each with one
#    np.fromstring call; when that fails, _obj_bad_line names the first bad line.


_BOM = b"\xef\xbb\xbf"


def _line_bounds(data):
    """Start and end (the index of its newline) of every line of ``data`` (which ends with a newline)."""
    ends = np.flatnonzero(np.frombuffer(data, np.uint8) == 10)
    starts = np.empty_like(ends)
    starts[:1] = 0
    starts[1:] = ends[:-1] + 1
    return starts, ends


def _obj_lines(data):
    """The file as newline-terminated statements, line k of the result being line k + 1 of the file."""
    if data.startswith(_BOM):  # written by many Windows programs
        data = data[len(_BOM) :]
    if b"\r" in data:  # CRLF (Windows) or CR (classic Mac OS) line ends
        data = data.replace(b"\r\n", b"\n").replace(b"\r", b"\n")
    if not data.endswith(b"\n"):
        data += b"\n"
    arr = np.frombuffer(data, np.uint8)
    starts, ends = _line_bounds(data)
    special = np.isin(arr[starts], (32, 9))  # leading blanks
    special[np.searchsorted(ends, np.flatnonzero(arr == ord("#")))] = True  # a comment ...
    special &= arr[starts] != ord("#")  # ... after a statement
    special |= (ends > starts) & (arr[np.maximum(ends - 1, 0)] == ord("\\"))  # a continuation
    if not special.any():
        return data
    text = {k: data[starts[k] : ends[k]].split(b"#", 1)[0].strip() for k in np.flatnonzero(special).tolist()}
    # a trailing backslash (outside a comment) continues the statement on the next line: the
    # joined statement keeps the number of its first line, and the continued line becomes blank
    for k in sorted(text):
        while text[k].endswith(b"\\") and k + 1 < len(starts):
            following = text.get(k + 1, data[starts[k + 1] : ends[k + 1]])
            text[k] = text[k][:-1] + b" " + following.split(b"#", 1)[0].strip()
            text[k + 1] = b""
        text[k] = text[k].rstrip(b"\\")
    pieces, pos = [], 0
    for k in sorted(text):
        pieces += [data[pos : starts[k]], text[k]]
        pos = ends[k]
    return b"".join(pieces) + data[pos:]


def _obj_statements(data, starts, ends, where):
    """Boolean masks of the v, f and l lines; MeshError on the first unknown statement."""
    arr = np.frombuffer(data, np.uint8)
    last = len(arr) - 1
    c0, c1, c2 = (arr[np.minimum(starts + k, last)] for k in range(3))
    ws1 = (c1 == 32) | (c1 == 9)
    ws2 = (c2 == 32) | (c2 == 9)
    is_v, is_f, is_l = ((c0 == ord(c)) & ws1 for c in "vfl")
    known = (
        is_v
        | is_f
        | is_l
        | (starts == ends)
        | (c0 == ord("#"))
        | ((c0 == ord("v")) & np.isin(c1, np.frombuffer(b"ntp", np.uint8)) & ws2)
        | (np.isin(c0, np.frombuffer(b"ogsp", np.uint8)) & (ws1 | (starts + 1 == ends)))
    )
    for k in np.flatnonzero(~known).tolist():  # longer keywords (usemtl, mtllib, ...) or an error
        words = data[starts[k] : ends[k]].split()
        if words and words[0] not in _OBJ_IGNORED:
            raise MeshError(
                f"{where}: line {k + 1}: not an OBJ statement (expected v, f, vn, vt, o, g, s, "
                f"usemtl, mtllib or a # comment): {_show(data[starts[k] : ends[k]])}"
            )
    return is_v, is_f, is_l


def _select(data, starts, ends, idx, keyword):
    """The lines ``idx`` (each with its newline) concatenated, their keyword blanked.

    The keyword's letter occurs nowhere else in a valid v or f line, so a
    byte replacement removes it.
    """
    if len(idx) == 0:
        return b""
    breaks = np.flatnonzero(np.diff(idx) != 1)
    if len(breaks) < 64:  # a few runs of consecutive lines (all v, then all f): plain slices
        first, last = np.r_[idx[0], idx[breaks + 1]], np.r_[idx[breaks], idx[-1]]
        buf = b"".join(data[a : b + 1] for a, b in zip(starts[first].tolist(), ends[last].tolist()))
    else:  # interleaved lines (v and vn alternating): a mask of the bytes to keep
        arr = np.frombuffer(data, np.uint8)
        keep = np.zeros(len(arr) + 1, np.int8)
        keep[starts[idx]] = 1
        keep[ends[idx] + 1] -= 1
        buf = arr[np.cumsum(keep[:-1], dtype=np.int8).view(bool)].tobytes()
    return buf.replace(keyword, b" ")


def _tokens_per_line(buf):
    """Whitespace-separated tokens on each newline-terminated line of ``buf``."""
    s = np.frombuffer(buf, np.uint8)
    ws = s <= 32
    tok = np.flatnonzero(~ws[1:] & ws[:-1]) + 1
    if len(s) and not ws[0]:
        tok = np.r_[0, tok]
    return np.diff(np.searchsorted(tok, np.flatnonzero(s == 10)), prepend=0)


def _numbers(buf, dtype):
    """All numbers of ``buf`` with one C call; None when a token is not a number."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            return np.fromstring(buf, sep=" ", dtype=dtype)
        except (ValueError, DeprecationWarning):
            return None


def _obj_bad_line(data, starts, ends, idx, where):
    """Raise the MeshError naming the first malformed v or f line among ``idx`` (the error path only)."""
    for k in idx.tolist():
        raw = data[starts[k] : ends[k]]
        words = raw.split()
        if words[0] == b"v":
            if len(words) - 1 not in (3, 4, 6, 7):
                raise MeshError(
                    f"{where}: line {k + 1}: a vertex needs x y z (optionally w or r g b), "
                    f"found {len(words) - 1} numbers: {_show(raw)}"
                )
            try:
                [float(w) for w in words[1:]]
            except ValueError:
                raise MeshError(f"{where}: line {k + 1}: vertex coordinates are not numbers: {_show(raw)}") from None
        else:
            try:
                corners = [int(c.split(b"/")[0]) for c in words[1:]]
            except ValueError:
                raise MeshError(
                    f"{where}: line {k + 1}: face corners must be integers (v, v/vt, v//vn or v/vt/vn): {_show(raw)}"
                ) from None
            if any(abs(c) > _HUGE for c in corners):
                raise MeshError(f"{where}: line {k + 1}: face index too large: {_show(raw)}")
    raise MeshError(f"{where}: cannot read the numbers of the v and f lines")  # not reached for valid bytes


def parse_obj(data, where):
    """(V, F, notes) from the bytes of an OBJ file; ``notes`` lists what was ignored."""
    data = _obj_lines(data)
    starts, ends = _line_bounds(data)
    is_v, is_f, is_l = _obj_statements(data, starts, ends, where)
    v_idx, f_idx = np.flatnonzero(is_v), np.flatnonzero(is_f)

    vbuf = _select(data, starts, ends, v_idx, b"v")
    counts = _tokens_per_line(vbuf)
    vals = _numbers(vbuf, np.float64)
    if vals is None or len(vals) != counts.sum() or not np.isin(counts, (3, 4, 6, 7)).all():
        _obj_bad_line(data, starts, ends, v_idx, where)
    V = vals.reshape(-1, 3) if (counts == 3).all() else vals[(np.cumsum(counts) - counts)[:, None] + np.arange(3)]

    fbuf = _select(data, starts, ends, f_idx, b"f")
    if b"/" in fbuf:  # v/vt/vn corners: only the vertex index is used
        fbuf = re.sub(rb"/\S*", b"", fbuf)
    sizes = _tokens_per_line(fbuf)
    idx = _numbers(fbuf, np.int64)
    if idx is None or len(idx) != sizes.sum() or (len(idx) and (idx.max() > _HUGE or idx.min() < -_HUGE)):
        _obj_bad_line(data, starts, ends, f_idx, where)  # (np.fromstring saturates huge integers)

    _no_mesh_check(where, len(V), len(sizes))
    V = _check_vertices(V, where, lines_of=v_idx + 1)
    vbefore = np.searchsorted(v_idx, f_idx) if len(idx) and idx.min() < 0 else None  # v lines above each face
    F = _build_faces(where, len(V), idx, sizes, f_idx + 1, one_based=True, vbefore=vbefore)
    notes = [f"{count_text(np.flatnonzero(is_l), 'line element')} ('l' statements) ignored"] if is_l.any() else []
    return V, F, notes


# --------------------------------------------------------------------------
# polygons -> triangles, with file-level checks


def _build_faces(where, n, idx, sizes, lines, one_based, vbefore=None):
    """Resolve file indices, check them with line numbers, fan-triangulate.

    ``idx`` holds the corner indices as written; ``sizes`` the corners per
    polygon; ``lines`` the line number of each polygon. Faces are named by
    their 0-based row in the returned F (a polygon by its first triangle).
    """
    if len(sizes) == 0:
        return np.zeros((0, 3), np.int64)
    small = np.flatnonzero(sizes < 3)
    if len(small):
        p = small[0]
        more = (
            f" (and {count_text(small[1:], 'more such face')} on lines {format_indices(lines[small[1:]])})"
            if len(small) > 1
            else ""
        )
        raise MeshError(f"{where}: line {lines[p]}: a face needs at least 3 vertex indices, found {sizes[p]}{more}")
    ntri = sizes - 2
    first_tri = np.cumsum(ntri) - ntri  # row in F of each polygon's first triangle
    poly = np.repeat(np.arange(len(sizes)), sizes)
    if one_based:
        zero = np.flatnonzero(idx == 0)
        if len(zero):
            others = np.unique(lines[poly[zero]])[1:]
            more = f"; also on lines {format_indices(others)}" if len(others) else ""
            raise MeshError(
                f"{where}: line {lines[poly[zero[0]]]}: vertex index 0 is invalid (OBJ indices start at 1){more}"
            )
        res = idx - 1
        neg = idx < 0
        if neg.any():
            res = np.where(neg, vbefore[poly] + idx, res)
    else:
        res = idx
    bad = (res < 0) | (res >= n)
    if bad.any():
        corners = np.flatnonzero(bad)
        bad_polys = np.unique(poly[corners])
        detail = "; ".join(f"line {lines[poly[c]]} (face {first_tri[poly[c]]}): index {idx[c]}" for c in corners[:5])
        if len(corners) > 5:
            detail += f" (and {len(corners) - 5} more)"
        valid = f"1..{n}, or -1..-{n} counting back" if one_based else f"0..{n - 1}"
        raise MeshError(
            f"{where}: face indices out of range, the file has {count_text(range(n), 'vertex', 'vertices')} "
            f"(valid: {valid}): {detail}; {count_text(bad_polys, 'face')} on "
            f"line{'s' if len(bad_polys) > 1 else ''} {format_indices(lines[bad_polys])}"
        )
    if (sizes == 3).all():
        F = res.reshape(-1, 3)
        tri_poly = None
    else:
        tri_poly = np.repeat(np.arange(len(sizes)), ntri)
        j = np.arange(int(ntri.sum())) - first_tri[tri_poly] + 1
        o = (np.cumsum(sizes) - sizes)[tri_poly]
        F = np.stack([res[o], res[o + j], res[o + j + 1]], axis=1)
    rows = repeated_vertex_faces(F)
    if len(rows):
        plines = lines[rows if tri_poly is None else tri_poly[rows]]
        detail = "; ".join(f"line {L}: face {r} = {F[r].tolist()}" for r, L in zip(rows[:5], plines[:5]))
        tail = f"; faces {format_indices(rows)} on lines {format_indices(np.unique(plines))}" if len(rows) > 1 else ""
        raise MeshError(
            f"{where}: {count_text(rows, 'face repeats', 'faces repeat')} a vertex (no triangle; 0-based vertex "
            f"indices): {detail}{tail}"
        )
    return np.ascontiguousarray(F, dtype=np.int64)


def _no_mesh_check(where, nv, nf):
    if nv == 0 and nf == 0:
        raise MeshError(f"{where}: the file holds no vertices and no faces")
    if nv == 0:
        raise MeshError(f"{where}: the file has {nf} faces but no vertices")
    if nf == 0:
        raise MeshError(
            f"{where}: the file has {nv} vertices but no faces (a point cloud or polyline is not a triangle mesh)"
        )


def _check_vertices(V, where, lines_of=None):
    if not np.isfinite(V).all():
        bad = np.flatnonzero(~np.isfinite(V).all(axis=1))
        at = f"; lines {format_indices(lines_of[bad])}" if lines_of is not None else ""
        raise MeshError(
            f"{where}: {count_text(bad, 'vertex has', 'vertices have')} NaN or infinite coordinates: "
            f"vertices {format_indices(bad)} (0-based{at})"
        )
    return as_vertices(V, where=where)


# --------------------------------------------------------------------------
# OFF


def _read_off(data, where):
    content = []  # (line number, words) of lines with content
    for lineno, raw in enumerate(data.split(b"\n"), start=1):
        hash_pos = raw.find(b"#")
        if hash_pos >= 0:
            raw = raw[:hash_pos]
        words = raw.split()
        if words:
            content.append((lineno, words))
    if not content:
        raise MeshError(f"{where}: the file holds no vertices and no faces")
    pos = 0
    lineno, words = content[0]
    head = words[0].upper()
    if head.endswith(b"OFF"):
        if len(words) > 1 and words[1].upper() == b"BINARY":
            raise MeshError(f"{where}: line {lineno}: binary OFF is not supported; save it as ASCII OFF, OBJ or PLY")
        words = words[1:]
        if not words:
            pos = 1
            if len(content) < 2:
                raise MeshError(f"{where}: line {lineno}: OFF header without the counts line 'nv nf ne'")
            lineno, words = content[1]
    try:
        nv, nf = int(words[0]), int(words[1])
        if nv < 0 or nf < 0:
            raise ValueError
    except (ValueError, IndexError):
        raise MeshError(
            f"{where}: line {lineno}: expected the counts 'nv nf ne' of the OFF header, found {_show(b' '.join(words))}"
        ) from None
    pos += 1
    vlines = content[pos : pos + nv]
    flines = content[pos + nv : pos + nv + nf]
    if len(vlines) < nv or len(flines) < nf:
        raise MeshError(
            f"{where}: the header (line {lineno}) announces {nv} vertices and {nf} faces, but the file ends "
            f"after {count_text(vlines, 'vertex line')} and {count_text(flines, 'face line')}"
        )
    _no_mesh_check(where, nv, nf)
    V = np.empty((nv, 3))
    for k, (ln, w) in enumerate(vlines):
        try:
            if len(w) < 3:
                raise ValueError
            V[k] = [float(x) for x in w[:3]]
        except ValueError:
            raise MeshError(
                f"{where}: line {ln}: a vertex needs 3 numbers x y z, found {_show(b' '.join(w))}"
            ) from None
    idx, sizes, lines = [], [], []
    for ln, w in flines:
        try:
            k = int(w[0])
            if k < 0 or len(w) < 1 + k:
                raise ValueError
            face = [int(x) for x in w[1 : 1 + k]]
            if any(abs(c) > _HUGE for c in face):
                raise ValueError
            idx.extend(face)
        except ValueError:
            raise MeshError(
                f"{where}: line {ln}: a face is 'k i0 ... ik-1' with k integer indices, found {_show(b' '.join(w))}"
            ) from None
        sizes.append(k)
        lines.append(ln)
    vline_numbers = np.asarray([ln for ln, _ in vlines])
    V = _check_vertices(V, where, lines_of=vline_numbers)
    F = _build_faces(
        where, nv, np.asarray(idx, np.int64), np.asarray(sizes, np.int64), np.asarray(lines, np.int64), one_based=False
    )
    return V, F


# --------------------------------------------------------------------------
# PLY and STL through trimesh


class _OtherThreads(logging.Filter):
    """Passes the log records of every thread but the one that made it."""

    def __init__(self):
        super().__init__()
        self.thread = threading.get_ident()

    def filter(self, record):
        return record.thread != self.thread


@contextlib.contextmanager
def _trimesh_quiet():
    """Keep trimesh's log records and warnings off the reader's screen while geomlib calls it.

    trimesh logs what it recovers from, with tracebacks ("failed to extract
    face_normals" for an STL whose normals do not parse: geomlib does not use
    them), and Python prints such records on stderr when nothing else handles
    them. Around geomlib's own calls the result or the MeshError is the one
    message. Only records from this thread are dropped, only while the call
    runs: trimesh used directly, or from another thread, logs as configured.
    """
    import trimesh  # noqa: F401  (its modules' loggers exist once it is imported)

    loggers = [
        logger
        for name, logger in list(logging.Logger.manager.loggerDict.items())
        if (name == "trimesh" or name.startswith("trimesh.")) and isinstance(logger, logging.Logger)
    ]
    only_others = _OtherThreads()
    for logger in loggers:
        logger.addFilter(only_others)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            yield
    finally:
        for logger in loggers:
            logger.removeFilter(only_others)


def _read_trimesh(path, where, ext, data):
    import trimesh

    if ext == ".ply" and not data.lstrip().startswith(b"ply"):
        raise MeshError(f"{where}: not a PLY file: it does not start with the line 'ply'")

    try:
        with _trimesh_quiet():
            loaded = trimesh.load(str(path), file_type=ext[1:], process=False, maintain_order=True)
    except Exception as exc:  # any parser failure becomes a MeshError naming the file
        raise MeshError(f"{where}: cannot read as {ext[1:].upper()}: {type(exc).__name__}: {exc}") from None
    if isinstance(loaded, trimesh.Scene):
        geoms = list(loaded.geometry.values())
        if not geoms:
            raise MeshError(f"{where}: cannot read as {ext[1:].upper()}: no mesh found in the file")
        if len(geoms) != 1:
            raise MeshError(f"{where}: the file holds {len(geoms)} objects; save one mesh per file")
        loaded = geoms[0]
    V = np.asarray(getattr(loaded, "vertices", np.zeros((0, 3))), dtype=np.float64)
    F = np.asarray(getattr(loaded, "faces", np.zeros((0, 3))))
    if F.size == 0:
        F = np.zeros((0, 3), np.int64)
    _no_mesh_check(where, len(V), len(F))
    V = _check_vertices(V, where)
    _, F = as_mesh(V, F, where=where)
    return V, F


# --------------------------------------------------------------------------
# public


def load_mesh(path, report=False):
    """Read a triangle mesh from an OBJ, OFF, PLY or STL file, exactly as stored.

    Returns the file's vertices in the file's order (nothing merged, dropped
    or reordered) and its faces, polygons fan-triangulated; see the module
    docstring for each format.

    Parameters
    ----------
    path : str or os.PathLike
        File name; the format is chosen by the extension (case-insensitive).
    report : bool
        False (default): if :func:`~geomlib.check_mesh` finds problems (zero-area
        faces, non-manifold edges or vertices, inconsistent orientation,
        several components, unreferenced vertices, duplicate faces), emit ONE
        :class:`~geomlib.MeshWarning` summarising them. True: emit nothing and
        return the :class:`~geomlib.MeshReport` as a third value.

    Returns
    -------
    V : (n, 3) float64
        Vertex positions in the file's units.
    F : (m, 3) int64
        Triangles, 0-based, in the file's order and orientation (polygons
        fan-triangulated in place; for PLY files mixing triangles and larger
        polygons, see the module notes).
    report : MeshReport
        Only when ``report=True``.

    Raises
    ------
    MeshError
        Missing or unreadable file, unknown extension, empty file, vertices
        without faces, malformed line (line number), NaN or infinite
        coordinates (vertex indices), face indices out of range (faces, lines,
        the index and the vertex count), faces repeating a vertex.
    """
    where = os.fspath(path)
    p = Path(where)
    ext = p.suffix.lower()
    if not p.exists():
        raise MeshError(f"{where}: no such file")
    if p.is_dir():
        raise MeshError(f"{where}: is a directory, not a mesh file")
    if ext not in SUPPORTED_EXTENSIONS:
        raise MeshError(
            f"{where}: unknown mesh format {ext or '(no extension)'!r}; supported: {', '.join(SUPPORTED_EXTENSIONS)}"
        )
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise MeshError(f"{where}: cannot read the file: {exc.strerror or exc}") from None
    if not data or data.isspace():  # isspace stops at the first other byte
        raise MeshError(f"{where}: the file is empty")
    notes = []
    if ext == ".obj":
        V, F, notes = parse_obj(data, where)
    elif ext == ".off":
        V, F = _read_off(data, where)
    else:
        V, F = _read_trimesh(p, where, ext, data)
    rep = check_mesh(V, F)
    if report:
        return V, F, rep
    if not rep.ok or notes:
        warnings.warn(MeshWarning(f"{where}: {'; '.join(rep.problems + notes)}"), stacklevel=2)
    return V, F


def _write_obj(path, V, F):
    n, m = len(V), len(F)
    head = f"# {n} vertices, {m} triangles; 1-based indices, counter-clockwise seen from outside\n"
    # %.17g gives every float64 back exactly when read again
    vtext = ("v %.17g %.17g %.17g\n" * n) % tuple(V.ravel().tolist())
    ftext = ("f %d %d %d\n" * m) % tuple((F + 1).ravel().tolist())
    with open(path, "w", encoding="ascii", newline="\n") as fh:
        fh.write(head)
        fh.write(vtext)
        fh.write(ftext)


def _write_off(path, V, F):
    n, m = len(V), len(F)
    vtext = ("%.17g %.17g %.17g\n" * n) % tuple(V.ravel().tolist())
    ftext = ("3 %d %d %d\n" * m) % tuple(F.ravel().tolist())
    with open(path, "w", encoding="ascii", newline="\n") as fh:
        fh.write(f"OFF\n{n} {m} 0\n")
        fh.write(vtext)
        fh.write(ftext)


def _write_ply(path, V, F):
    n, m = len(V), len(F)
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {n}\nproperty double x\nproperty double y\nproperty double z\n"
        f"element face {m}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    faces = np.empty(m, dtype=[("k", "u1"), ("idx", "<i4", (3,))])
    faces["k"] = 3
    if m and F.max() > np.iinfo(np.int32).max:
        raise MeshError(f"{path}: PLY stores indices as int32; {n} vertices are too many")
    faces["idx"] = F
    with open(path, "wb") as fh:
        fh.write(header.encode("ascii"))
        fh.write(np.ascontiguousarray(V, dtype="<f8").tobytes())
        fh.write(faces.tobytes())


def save_mesh(path, V, F):
    """Write a triangle mesh; the format is chosen by the extension.

    * ``.obj``, ``.off``: written by this module with ``%.17g``, so every
      float64 coordinate reads back bit for bit; OBJ indices 1-based, OFF
      0-based.
    * ``.ply``: binary little-endian PLY written by this module, vertices as
      ``double``, faces as ``uchar``-counted ``int`` lists: exact round trip.
    * ``.stl``: binary STL through trimesh; STL stores float32 corners per
      facet, so coordinates are rounded to float32 and a reload gives three
      vertices per facet (see :func:`load_mesh`).

    Vertex order and faces are written as given (no merging, no reordering).

    Parameters
    ----------
    path : str or os.PathLike
    V : (n, 3) float64
    F : (m, 3) int64

    Raises
    ------
    MeshError
        Invalid ``V``/``F`` (see :func:`geomlib.mesh.validate.as_mesh`) or an
        unknown extension.
    """
    where = os.fspath(path)
    ext = Path(where).suffix.lower()
    if ext not in SUPPORTED_EXTENSIONS:
        raise MeshError(
            f"{where}: unknown mesh format {ext or '(no extension)'!r}; supported: {', '.join(SUPPORTED_EXTENSIONS)}"
        )
    V, F = as_mesh(V, F)
    try:
        if ext == ".obj":
            _write_obj(where, V, F)
        elif ext == ".off":
            _write_off(where, V, F)
        elif ext == ".ply":
            _write_ply(where, V, F)
        else:
            import trimesh

            with _trimesh_quiet():
                stl = trimesh.exchange.stl.export_stl(
                    trimesh.Trimesh(vertices=V, faces=F, process=False, validate=False)
                )
            with open(where, "wb") as fh:
                fh.write(stl)
    except OSError as exc:
        raise MeshError(f"{where}: cannot write the file: {exc.strerror or exc}") from None
