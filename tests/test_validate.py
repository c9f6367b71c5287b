"""Tests for geomlib.mesh.validate: as_mesh at the door, check_mesh and MeshReport."""

import numpy as np
import pytest
import trimesh
from meshdata import COURSE, needs_course

from geomlib import MeshError, MeshReport, check_mesh, load_mesh
from geomlib.mesh.validate import as_faces, as_mesh, repeated_vertex_faces


def icosahedron():
    m = trimesh.creation.icosahedron()
    return np.asarray(m.vertices), np.asarray(m.faces, dtype=np.int64)


def tetrahedron():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    return V, F


def torus(nu=10, nv=6):
    m = trimesh.creation.torus(major_radius=1.0, minor_radius=0.3, major_sections=nu, minor_sections=nv)
    return np.asarray(m.vertices), np.asarray(m.faces, dtype=np.int64)


# ---------------------------------------------------------------- as_mesh


def test_as_mesh_coerces_and_keeps_good_arrays():
    V, F = icosahedron()
    V2, F2 = as_mesh(V, F)
    assert V2 is V and F2 is F  # already float64 / int64, C-contiguous: no copy
    V3, F3 = as_mesh(V.tolist(), F.astype(np.int32))
    assert V3.dtype == np.float64 and F3.dtype == np.int64
    assert V3.flags.c_contiguous and F3.flags.c_contiguous
    V4, F4 = as_mesh(np.asfortranarray(V), F.astype(np.float64))  # integral floats are fine
    assert np.array_equal(F4, F) and V4.flags.c_contiguous
    Vi, _ = as_mesh(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]]), [[0, 1, 2]])
    assert Vi.dtype == np.float64


def test_as_mesh_bad_shapes():
    with pytest.raises(MeshError, match=r"V must have shape \(n, 3\), got shape \(3, 2\)"):
        as_mesh(np.zeros((3, 2)), [[0, 1, 2]])
    with pytest.raises(MeshError, match=r"F must have shape \(m, 3\) \(triangles\), got shape \(1, 4\)"):
        as_mesh(np.zeros((4, 3)), [[0, 1, 2, 3]])
    with pytest.raises(MeshError, match=r"V has no vertices"):
        as_mesh(np.zeros((0, 3)), [[0, 1, 2]])
    with pytest.raises(MeshError, match=r"F has no faces"):
        as_mesh(np.zeros((3, 3)), np.zeros((0, 3), int))
    V, F = as_mesh(np.zeros((3, 3)), np.zeros((0, 3), int), allow_empty=True)
    assert F.shape == (0, 3)


def test_as_mesh_bad_dtypes():
    with pytest.raises(MeshError, match=r"V has dtype <U1; vertex positions must be real numbers"):
        as_mesh(np.array([["a", "b", "c"]]), [[0, 0, 0]])
    with pytest.raises(MeshError, match=r"non-integral or non-finite values in faces 1; face indices must be integers"):
        as_mesh(np.zeros((4, 3)), [[0, 1, 2], [0, 1.5, 3]])
    with pytest.raises(MeshError, match=r"non-integral or non-finite values in faces 0"):
        as_mesh(np.zeros((4, 3)), [[0, 1, np.nan]])
    with pytest.raises(MeshError, match="boolean array"):
        as_faces(np.ones((2, 3), bool))
    with pytest.raises(MeshError, match=r"F has dtype complex128"):
        as_faces(np.ones((2, 3), complex))


def test_as_mesh_nan_and_inf_name_the_vertices():
    V, F = icosahedron()
    V = V.copy()
    V[3, 1] = np.nan
    V[7, 2] = np.inf
    with pytest.raises(MeshError, match=r"2 vertices have NaN or infinite coordinates: vertices 3, 7$"):
        as_mesh(V, F)


def test_as_mesh_indices_out_of_range():
    V, F = tetrahedron()
    F = F.copy()
    F[2, 1] = 4
    F[3, 0] = -1
    with pytest.raises(MeshError) as err:
        as_mesh(V, F)
    msg = str(err.value)
    assert "face indices out of range (valid: 0..3 for 4 vertices)" in msg
    assert "face 2 has index 4" in msg and "face 3 has index -1" in msg
    assert msg.endswith("faces 2, 3")


def test_as_mesh_repeated_vertex_names_the_faces():
    V, F = tetrahedron()
    F = np.vstack([F, [[1, 1, 2], [3, 0, 3]]])
    with pytest.raises(
        MeshError, match=r"2 faces repeat a vertex.*face 4 = \[1, 1, 2\], face 5 = \[3, 0, 3\]; faces 4, 5"
    ):
        as_mesh(V, F)


def test_as_mesh_where_prefix():
    with pytest.raises(MeshError, match=r"^mine\.obj: V has no vertices"):
        as_mesh(np.zeros((0, 3)), [[0, 1, 2]], where="mine.obj")


def test_as_mesh_many_offenders_are_abbreviated():
    V = np.full((30, 3), np.nan)
    with pytest.raises(MeshError, match=r"vertices 0, 1, 2, 3, 4, 5, 6, 7, 8, 9 \(and 20 more\)"):
        as_mesh(V, [[0, 1, 2]])


# ---------------------------------------------------------------- check_mesh


def test_clean_closed_meshes():
    for (V, F), chi, genus in ((icosahedron(), 2, 0), (tetrahedron(), 2, 0), (torus(), 0, 1)):
        r = check_mesh(V, F)
        assert isinstance(r, MeshReport)
        assert r.ok and r.problems == [] and "No problems found." in str(r)
        assert r.euler_characteristic == chi and r.genus == genus
        assert r.is_closed and r.is_manifold and r.is_oriented and r.n_components == 1


def test_open_disk_is_not_a_problem():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]], float)
    F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]])
    r = check_mesh(V, F)
    assert r.ok and not r.is_closed
    assert r.euler_characteristic == 1 and r.genus == 0
    assert r.boundary_loop_lengths == [4]
    assert np.array_equal(r.boundary_loops[0], [1, 2, 3, 4])
    assert len(r.boundary_edges) == 4
    assert "Note: open surface, 4 boundary edges in 1 loop" in str(r)
    assert "Note: open surface" in r._repr_html_()


def test_zero_area_face():
    V = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]], float)
    F = np.array([[0, 1, 3], [0, 2, 1]])  # face 1 is collinear
    r = check_mesh(V, F)
    assert np.array_equal(r.zero_area_faces, [1])
    assert any("1 zero-area face (1)" in p and "still work" in p for p in r.problems)


def test_zero_area_is_scale_free():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1e-9, 0]], float)
    for s in (1e-6, 1.0, 1e6):
        assert len(check_mesh(s * V, [[0, 1, 2]]).zero_area_faces) == 0
    V[2, 1] = 1e-14
    for s in (1e-6, 1.0, 1e6):
        assert np.array_equal(check_mesh(s * V, [[0, 1, 2]]).zero_area_faces, [0])


def test_non_manifold_edge():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1]], float)
    F = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])  # edge (0, 1) has three faces
    r = check_mesh(V, F)
    assert np.array_equal(r.non_manifold_edges, [[0, 1]])
    assert not r.is_manifold and r.genus is None
    assert any("1 non-manifold edge used by more than two faces ((0, 1))" in p for p in r.problems)


def test_non_manifold_vertex_two_cones():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [-1, 0, 0], [0, -1, 0], [0, 0, -1]], float)
    tet = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    F = np.concatenate([tet, np.where(tet == 0, 0, tet + 3)])
    r = check_mesh(V, F)
    assert np.array_equal(r.non_manifold_vertices, [0])
    assert len(r.non_manifold_edges) == 0 and r.is_closed and r.is_oriented
    assert r.euler_characteristic == 3  # 7 - 12 + 8: two spheres (2 + 2) glued at a point (-1)
    assert r.genus is None
    assert any("1 non-manifold vertex" in p and "(0)" in p for p in r.problems)


def test_non_manifold_vertex_bow_tie_and_general_path():
    # two open fans at vertex 0 (oriented), then the same with one face flipped
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [-1, 0, 0], [-1, -1, 0]], float)
    F = np.array([[0, 1, 2], [0, 3, 4]])
    assert np.array_equal(check_mesh(V, F).non_manifold_vertices, [0])
    assert check_mesh(V, F).n_components == 1
    F2 = np.array([[0, 1, 2], [0, 4, 3]])
    assert np.array_equal(check_mesh(V, F2).non_manifold_vertices, [0])


def test_non_manifold_vertex_with_inconsistent_orientation():
    # two cones at vertex 0, and one face of the first flipped: the general (unoriented) path
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [-1, 0, 0], [0, -1, 0], [0, 0, -1]], float)
    tet = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    F = np.concatenate([tet, np.where(tet == 0, 0, tet + 3)])
    F[3] = F[3, ::-1]
    r = check_mesh(V, F)
    assert np.array_equal(r.non_manifold_vertices, [0])
    assert len(r.inconsistent_edges) == 3


def test_inconsistent_orientation():
    V, F = icosahedron()
    F = F.copy()
    F[5] = F[5, ::-1]
    r = check_mesh(V, F)
    flipped = {tuple(sorted(e)) for e in [(F[5, 0], F[5, 1]), (F[5, 1], F[5, 2]), (F[5, 2], F[5, 0])]}
    assert {tuple(e) for e in r.inconsistent_edges.tolist()} == flipped
    assert not r.is_oriented and r.genus is None
    assert len(r.non_manifold_vertices) == 0
    assert any(
        "inconsistent orientation" in p and "unsigned H, K and the Laplacians still work" in p for p in r.problems
    )


def test_components_unreferenced_and_duplicates():
    V, F = tetrahedron()
    V2 = np.vstack([V, V + 5, [[9, 9, 9]]])  # vertex 8 unused
    F2 = np.vstack([F, F + 4, F[[1]]])  # two components, face 8 duplicates face 1
    F2[8] = F2[8, [1, 2, 0]]  # same triangle, rotated
    r = check_mesh(V2, F2)
    assert r.n_components == 2 and np.array_equal(r.component_sizes, [5, 4])
    assert np.array_equal(r.unreferenced_vertices, [8])
    assert np.array_equal(r.duplicate_faces, [8])
    assert r.euler_characteristic == 8 - 12 + 9  # vertex 8 not counted
    text = " ".join(r.problems)
    assert "2 connected components" in text
    assert "1 unreferenced vertex (8)" in text
    assert "1 duplicate face (8)" in text


def test_check_mesh_does_not_alter_input():
    V, F = icosahedron()
    V0, F0 = V.copy(), F.copy()
    check_mesh(V, F)
    assert np.array_equal(V, V0) and np.array_equal(F, F0)


def test_check_mesh_validates_at_the_door():
    V, F = tetrahedron()
    with pytest.raises(MeshError, match="face 0 has index 7"):
        check_mesh(V, np.array([[0, 1, 7]]))


def test_report_text_and_html():
    V, F = tetrahedron()
    V2 = np.vstack([V, [[2, 2, 2]]])
    r = check_mesh(V2, F)
    text = str(r)
    assert "vertices" in text and "Euler characteristic V - E + F  2" in text
    assert "unreferenced vertices" in text and "Problems (and what still works):" in text
    html = r._repr_html_()
    assert html.startswith("<div>") and "<table>" in html and "unreferenced vertices" in html
    assert "MeshReport(n_vertices=5, n_faces=4" in repr(r)
    assert r.summary().startswith("1 unreferenced vertex (4)")


@needs_course
def test_camel_has_exactly_one_non_manifold_vertex():
    V, F, r = load_mesh(COURSE / "camel.obj", report=True)
    assert np.array_equal(r.non_manifold_vertices, [946])
    assert r.is_closed and r.euler_characteristic == 1 and len(r.non_manifold_edges) == 0


@needs_course
@pytest.mark.parametrize(
    "name, loops", [("cow_manifold2.obj", [16]), ("cow_small_manifold2.obj", [6]), ("curvatures/lilium_s.obj", [70])]
)
def test_course_boundary_loops(name, loops):
    r = load_mesh(COURSE / name, report=True)[2]
    assert r.boundary_loop_lengths == loops and r.ok and r.genus == 0


def test_is_zero_area_is_scale_free_and_zero_area_faces_uses_it():
    from geomlib.mesh.geometry import zero_area_faces
    from geomlib.mesh.validate import is_zero_area

    assert is_zero_area(np.array([0.0, 1e-13, 1e-11]), np.ones(3)).tolist() == [True, True, False]
    V = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [1, 1e-14, 0]])
    F = np.array([[0, 1, 3], [0, 1, 2], [0, 2, 4]])
    assert zero_area_faces(V, F).tolist() == [1, 2]
    assert zero_area_faces(1e6 * V, F).tolist() == [1, 2]


def test_check_mesh_lives_in_report_and_validate_does_not_import_topology():
    import geomlib.mesh.report
    import geomlib.mesh.validate

    assert geomlib.check_mesh is geomlib.mesh.report.check_mesh
    assert "topology" not in open(geomlib.mesh.validate.__file__).read()


def test_faces_repeating_a_vertex_are_found_in_one_place():
    V, F = tetrahedron()
    G = np.vstack([F, [[1, 1, 2], [3, 0, 3]]])
    np.testing.assert_array_equal(repeated_vertex_faces(G), [4, 5])
    assert len(repeated_vertex_faces(F)) == 0
    # a drawing may accept them; every computation refuses them
    assert as_faces(G, len(V), allow_repeated=True) is not None
    with pytest.raises(MeshError, match="2 faces repeat a vertex"):
        as_faces(G, len(V))


# ---------------------------------------------------------------- scalar arguments


def test_real_number_takes_finite_reals_in_range_and_names_the_rest():
    from geomlib.mesh.validate import real_number

    assert real_number("tau", np.float32(0.5), 0) == 0.5 and real_number("tau", 0, 0) == 0.0
    assert real_number("jitter", 0.25, 0, below=0.5) == 0.25
    for value, said in [
        (True, "tau must be a real number, not bool True"),
        ("0.1", "tau must be a real number, not str '0.1'"),
        (float("nan"), "tau must be finite, not nan"),
        (-1e-9, "tau must be >= 0 (why), not -1e-09"),
    ]:
        with pytest.raises(MeshError) as err:
            real_number("tau", value, 0, why=" (why)" if value == -1e-9 else "")
        assert str(err.value) == said
    with pytest.raises(MeshError, match=r"r must be > 0, not 0"):
        real_number("r", 0, 0, strict=True)
    with pytest.raises(MeshError, match=r"jitter must be below 0.5, not 0.5"):
        real_number("jitter", 0.5, 0, below=0.5)


def test_whole_number_takes_integers_in_range_and_names_the_rest():
    from geomlib.mesh.validate import whole_number

    assert whole_number("k", np.int64(3), 1, 5) == 3 and type(whole_number("k", np.int64(3), 1)) is int
    with pytest.raises(MeshError, match=r"iterations must be an integer \(a whole number\), not float 2.0"):
        whole_number("iterations", 2.0)
    with pytest.raises(MeshError, match=r"iterations must be an integer \(a whole number\), not bool True"):
        whole_number("iterations", True)
    with pytest.raises(MeshError, match=r"k must be at least 1, not 0"):
        whole_number("k", 0, 1)
    with pytest.raises(MeshError, match=r"k = 6 is more than 5 \(five\)"):
        whole_number("k", 6, 1, 5, why=" (five)")
