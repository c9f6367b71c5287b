"""Tests of geomlib.lessons.laplace: closed forms, matrix laws, bad triangles, libigl cross-checks."""

import warnings

import numpy as np
import pytest
import scipy.sparse as sp
import trimesh
from meshdata import COURSE, COURSE_MESHES, SHIPPED, SHIPPED_MESHES, load_quietly, needs_course

from geomlib import MeshError, MeshWarning, laplacian, surfaces, vertex_areas
from geomlib.lessons.laplace import (
    barycentric_areas,
    cotangent_matrix,
    edge_lengths,
    face_geometry,
    intrinsic_cotangent_matrix,
    mixed_areas,  # noqa: E402
    uniform_adjacency,
    uniform_laplacian,
    voronoi_pieces,
)

AREAS = ("barycentric", "mixed")


def icosphere(subdivisions=3, scale=(1.0, 1.0, 1.0)):
    m = trimesh.creation.icosphere(subdivisions=subdivisions)
    return np.asarray(m.vertices) * np.asarray(scale), np.asarray(m.faces, dtype=np.int64)


def random_rotation(seed):
    Q, R = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    Q = Q * np.sign(np.diag(R))
    if np.linalg.det(Q) < 0:
        Q[:, 0] *= -1
    return Q


def dense(A):
    return np.asarray(A.todense())


# ---------------------------------------------------------------- closed forms


def test_right_triangle_cotan_entries():
    # angles: 90 deg at vertex 0, 45 deg at vertices 1 and 2
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    F = np.array([[0, 1, 2]])
    M, C = laplacian(V, F)
    expected = np.array([[-1.0, 0.5, 0.5], [0.5, -0.5, 0.0], [0.5, 0.0, -0.5]])
    np.testing.assert_allclose(dense(C), expected, atol=1e-15)
    np.testing.assert_allclose(M.diagonal(), [1 / 6, 1 / 6, 1 / 6], atol=1e-15)
    # right triangle is not obtuse: Voronoi areas 1/4 at the right angle, 1/8 at the others
    M, _ = laplacian(V, F, area="mixed")
    np.testing.assert_allclose(M.diagonal(), [1 / 4, 1 / 8, 1 / 8], atol=1e-15)


def test_obtuse_triangle_mixed_area():
    # angle of 120 degrees at vertex 0: A/2 there, A/4 at the others
    V = np.array([[0.0, 0, 0], [1, 0, 0], [np.cos(2 * np.pi / 3), np.sin(2 * np.pi / 3), 0]])
    F = np.array([[0, 1, 2]])
    A = 0.5 * np.sin(2 * np.pi / 3)
    np.testing.assert_allclose(vertex_areas(V, F, "mixed"), [A / 2, A / 4, A / 4], atol=1e-15)
    np.testing.assert_allclose(vertex_areas(V, F, "barycentric"), [A / 3] * 3, atol=1e-15)
    C = dense(cotangent_matrix(V, F))
    # cot(120) = -1/sqrt(3) on the edge opposite vertex 0; cot(30) = sqrt(3) elsewhere
    assert C[1, 2] == pytest.approx(-0.5 / np.sqrt(3), abs=1e-15)
    assert C[0, 1] == pytest.approx(0.5 * np.sqrt(3), abs=1e-15)


def test_uniform_is_graph_laplacian():
    V, F = icosphere(2)
    M, C = laplacian(V, F, weights="uniform")
    A = dense(C) - np.diag(C.diagonal())
    assert set(np.unique(A)) == {0.0, 1.0}
    valence = A.sum(axis=1)
    np.testing.assert_array_equal(M.diagonal(), valence)
    np.testing.assert_array_equal(-C.diagonal(), valence)
    assert set(valence) == {5.0, 6.0}


def test_output_formats():
    V, F = icosphere(1)
    for weights in ("cotan", "uniform"):
        M, C = laplacian(V, F, weights=weights)
        assert sp.issparse(M) and sp.issparse(C)
        assert C.format == "csr" and M.format in ("dia", "csr")
        assert M.dtype == C.dtype == np.float64
        assert dense(M - sp.diags(M.diagonal())).any() == False  # noqa: E712 (diagonal)


def test_flat_mesh_reproduces_linear_functions():
    # cotan C is exact on linear functions at interior vertices of any flat mesh
    s = surfaces.plane(n=12, jitter=0.3, seed=1)
    _, C = laplacian(s.V, s.F)
    interior = np.ones(len(s.V), bool)
    interior[np.unique(np.concatenate([np.flatnonzero(np.isclose(abs(s.V[:, k]), 1.0)) for k in (0, 1)]))] = False
    f = 0.3 * s.V[:, 0] - 1.7 * s.V[:, 1] + 2.0
    assert np.abs((C @ f)[interior]).max() < 1e-12


def test_sphere_laplacian_of_position():
    # Delta x = -2 H n, H = 1/r on a sphere of radius r. With vertices on the
    # sphere, <x_j - x_i, n_i> = -|x_j - x_i|^2 / (2 r), so the normal part of
    # C x is -1/r times the Voronoi area: exact with mixed areas on this
    # non-obtuse mesh; barycentric areas are 15% off at the valence-5 vertices.
    r = 2.5
    V, F = icosphere(4)
    V = r * V
    n = V / np.linalg.norm(V, axis=1, keepdims=True)
    for area, tol in (("mixed", 1e-12), ("barycentric", 0.16)):
        M, C = laplacian(V, F, area=area)
        DV = (C @ V) / M.diagonal()[:, None]
        H = -0.5 * np.einsum("ij,ij->i", DV, n)
        assert np.abs(H * r - 1).max() < tol
        assert np.median(np.abs(H * r - 1)) < 0.001


# ---------------------------------------------------------------- laws


MESHES = {
    "ellipsoid": lambda: icosphere(2, (1.0, 0.7, 0.5)),
    "jittered_ellipsoid": lambda: (lambda s: (s.V, s.F))(surfaces.ellipsoid(1.0, 0.6, 0.4, 2, jitter=0.4, seed=3)),
    "saddle_open": lambda: (lambda s: (s.V, s.F))(surfaces.saddle(n=12, jitter=0.3, seed=2)),
    "torus": lambda: (lambda s: (s.V, s.F))(surfaces.torus(1.0, 0.35, n=24)),
}


@pytest.mark.parametrize("name", sorted(MESHES))
@pytest.mark.parametrize("weights,area", [("cotan", "barycentric"), ("cotan", "mixed"), ("uniform", "barycentric")])
def test_symmetric_zero_rows_negative_semidefinite(name, weights, area):
    V, F = MESHES[name]()
    M, C = laplacian(V, F, weights=weights, area=area)
    D = dense(C)
    scale = np.abs(D).max()
    np.testing.assert_allclose(D, D.T, atol=1e-14 * scale)
    assert np.abs(D.sum(axis=1)).max() < 1e-13 * scale
    lam = np.linalg.eigvalsh(D)
    assert lam.max() < 1e-12 * scale
    # exactly one zero eigenvalue per connected component
    assert np.sum(np.abs(lam) < 1e-9 * scale) == 1
    assert (M.diagonal() > 0).all()
    assert np.isfinite(D).all() and np.isfinite(M.diagonal()).all()


@pytest.mark.parametrize("area", AREAS)
def test_areas_sum_to_surface_area(area):
    V, F = MESHES["jittered_ellipsoid"]()
    total = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1).sum()
    assert vertex_areas(V, F, area).sum() == pytest.approx(total, rel=1e-13)


@pytest.mark.parametrize("s", [0.01, 3.0, 250.0])
@pytest.mark.parametrize("area", AREAS)
def test_scaling(s, area):
    V, F = MESHES["jittered_ellipsoid"]()
    M1, C1 = laplacian(V, F, area=area)
    Ms, Cs = laplacian(s * V, F, area=area)
    np.testing.assert_allclose(Ms.diagonal(), s * s * M1.diagonal(), rtol=1e-12)
    assert abs(Cs - C1).max() < 1e-12 * abs(C1).max()
    Mu, Cu = laplacian(s * V, F, weights="uniform")
    Mu1, Cu1 = laplacian(V, F, weights="uniform")
    assert abs(Cu - Cu1).max() == 0
    np.testing.assert_array_equal(Mu.diagonal(), Mu1.diagonal())


@pytest.mark.parametrize("seed", [0, 1])
def test_rigid_motion_invariance(seed):
    V, F = MESHES["saddle_open"]()
    Q = random_rotation(seed)
    W = V @ Q.T + np.array([3.0, -1.0, 0.5]) * (seed + 1)
    for area in AREAS:
        M1, C1 = laplacian(V, F, area=area)
        M2, C2 = laplacian(W, F, area=area)
        assert abs(C2 - C1).max() < 1e-12 * abs(C1).max()
        np.testing.assert_allclose(M2.diagonal(), M1.diagonal(), rtol=1e-11)


# ---------------------------------------------------------------- bad triangles and input


def _mesh_with_bad_triangles():
    """A flat fan plus a zero-area triangle (collinear), a near-collinear needle,
    a triangle with two coincident vertices and an isolated vertex."""
    V = np.array(
        [
            [0.0, 0, 0],
            [1, 0, 0],
            [0, 1, 0],
            [-1, 0, 0],
            [0, -1, 0],  # 0-4: a fan
            [2.0, 0, 0],
            [3.0, 0, 0],  # 5, 6: collinear with 1
            [1.0, 1e-9, 0],  # 7: needle apex
            [0.0, 1.0, 0],  # 8: coincides with 2
            [9.0, 9.0, 9.0],  # 9: isolated
        ]
    )
    F = np.array(
        [
            [0, 1, 2],
            [0, 2, 3],
            [0, 3, 4],
            [0, 4, 1],
            [1, 5, 6],  # zero area (collinear)
            [3, 1, 7],  # needle: height 1e-9 over a base of length 2
            [0, 2, 8],  # zero area (2 and 8 coincide)
        ]
    )
    return V, F


@pytest.mark.parametrize("weights,area", [("cotan", "barycentric"), ("cotan", "mixed"), ("uniform", "barycentric")])
def test_bad_triangles_give_finite_matrices(weights, area):
    V, F = _mesh_with_bad_triangles()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        M, C = laplacian(V, F, weights=weights, area=area)
    D = dense(C)
    assert np.isfinite(D).all() and np.isfinite(M.diagonal()).all()
    np.testing.assert_allclose(D, D.T, atol=0)
    assert np.abs(D.sum(axis=1)).max() < 1e-12 * np.abs(D).max()
    assert np.linalg.eigvalsh(D).max() < 1e-12 * np.abs(D).max()
    # isolated vertex: zero row and zero area
    assert not D[9].any() and M.diagonal()[9] == 0
    if weights == "cotan":
        messages = [str(w.message) for w in caught if issubclass(w.category, MeshWarning)]
        assert any("zero-area" in m and "faces 4, 6" in m for m in messages)
        # the zero-area faces add nothing: vertices 5, 6 and 8 are in no other face
        assert M.diagonal()[[5, 6, 8]].tolist() == [0.0, 0.0, 0.0]
        assert not D[[5, 6, 8]].any()
        # the needle keeps its exact, large but finite cotangent
        # the needle (3, 1, 7) keeps its exact cotangent: the angle at 3 is atan(1e-9 / 2)
        assert D[1, 7] == pytest.approx(0.5 * 2.0 / 1e-9, rel=1e-6)


def test_needle_triangle_cotangent_is_exact():
    h = 1e-9
    V = np.array([[-1.0, 0, 0], [1, 0, 0], [0, h, 0]])
    C = dense(cotangent_matrix(V, [[0, 1, 2]]))
    # angle at the apex is pi - 2 atan(h): cot = (h^2 - 1) / (2 h)
    assert C[0, 1] == pytest.approx(0.5 * (h * h - 1) / (2 * h), rel=1e-9)
    assert C[0, 2] == pytest.approx(0.5 / h, rel=1e-9)


def test_bad_options_raise():
    V, F = icosphere(0)
    with pytest.raises(MeshError, match="weights"):
        laplacian(V, F, weights="cotangent")
    with pytest.raises(MeshError, match="area"):
        laplacian(V, F, area="voronoi")
    with pytest.raises(MeshError):
        laplacian(V, F[:, :2])
    with pytest.raises(MeshError):
        laplacian(V, F + len(V))
    bad = V.copy()
    bad[3, 1] = np.nan
    with pytest.raises(MeshError, match="3"):
        laplacian(bad, F)


def test_non_manifold_edge_sums_its_triangles():
    # three triangles on the edge (0, 1)
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, -1, 0], [0.5, 0, 1]])
    F = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    C = dense(cotangent_matrix(V, F))
    expected = sum(float(dense(cotangent_matrix(V, [f]))[0, 1]) for f in F)
    assert C[0, 1] == pytest.approx(expected, rel=1e-14)
    assert np.linalg.eigvalsh(C).max() < 1e-14


# ---------------------------------------------------------------- libigl cross-checks

igl = pytest.importorskip("igl")


def _against_libigl(V, F):
    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    Mb, C = laplacian(V, F, area="barycentric")
    Mv, _ = laplacian(V, F, area="mixed")
    scale = abs(C).max()
    assert abs(C - igl.cotmatrix(V, F)).max() < 1e-12 * scale
    Mb_ref = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_BARYCENTRIC).diagonal()
    Mv_ref = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI).diagonal()
    area = Mb_ref.max()
    assert np.abs(Mb.diagonal() - Mb_ref).max() < 1e-12 * area
    assert np.abs(Mv.diagonal() - Mv_ref).max() < 1e-12 * area


@pytest.mark.parametrize("name", sorted(MESHES))
def test_libigl_generated(name):
    _against_libigl(*MESHES[name]())


@pytest.mark.parametrize("name", SHIPPED_MESHES)
def test_libigl_shipped_meshes(name):
    _against_libigl(*load_quietly(SHIPPED / name))


@needs_course
@pytest.mark.parametrize("name", COURSE_MESHES)
def test_libigl_course_meshes(name):
    _against_libigl(*load_quietly(COURSE / name))


# ---------------------------------------------------------------- the teaching functions one by one


def test_face_geometry_of_a_3_4_5_triangle():
    V = np.array([[0.0, 0, 0], [4, 0, 0], [0, 3, 0]])
    l2, dblA, cot, degenerate = face_geometry(V, [[0, 1, 2]])
    assert l2.tolist() == [[25.0, 9.0, 16.0]]  # opposite corners 0, 1, 2
    assert dblA.tolist() == [12.0] and not degenerate[0]
    np.testing.assert_allclose(cot, [[0.0, 4 / 3, 3 / 4]], atol=1e-15)  # right angle at 0; cot = adjacent / opposite


def test_each_teaching_function_equals_the_dispatcher():
    V, F = icosphere(2, scale=(1.0, 0.8, 0.6))
    M, C = laplacian(V, F)
    assert abs(cotangent_matrix(V, F) - C).max() == 0
    assert np.array_equal(barycentric_areas(V, F), M.diagonal())
    assert np.array_equal(mixed_areas(V, F), laplacian(V, F, area="mixed")[0].diagonal())
    Mu, Cu = uniform_laplacian(V, F)
    assert abs(Cu - laplacian(V, F, weights="uniform")[1]).max() == 0
    A = uniform_adjacency(len(V), F)
    assert A.nnz == 2 * (3 * len(F) // 2) and (A.data == 1).all()
    np.testing.assert_array_equal(np.asarray(A.sum(axis=1)).ravel(), Mu.diagonal())


def test_uniform_laplacian_of_a_tetrahedron_is_exact():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    M, C = uniform_laplacian(V, F)
    np.testing.assert_array_equal(dense(C), np.ones((4, 4)) - 4 * np.eye(4))
    np.testing.assert_array_equal(M.diagonal(), [3, 3, 3, 3])


def test_mixed_area_obtuse_cases_exact():
    # one triangle obtuse at corner 2 (angle 120 degrees): A/4, A/4, A/2
    V = np.array([[-1.0, 0, 0], [1, 0, 0], [0, 1 / np.sqrt(3), 0]])
    A = 1 / np.sqrt(3)
    np.testing.assert_allclose(mixed_areas(V, [[0, 1, 2]]), [A / 4, A / 4, A / 2], rtol=1e-14)
    # an equilateral triangle is all Voronoi: A/3 each
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, np.sqrt(3) / 2, 0]])
    np.testing.assert_allclose(mixed_areas(V, [[0, 1, 2]]), np.full(3, np.sqrt(3) / 12), rtol=1e-14)


def test_right_triangle_voronoi_meets_the_hypotenuse_midpoint():
    # right angle at corner 0 (not obtuse): Voronoi parts 1/8 sum |e|^2 cot, summing to A
    V = np.array([[0.0, 0, 0], [4, 0, 0], [0, 3, 0]])
    a = mixed_areas(V, [[0, 1, 2]])
    np.testing.assert_allclose(a, [3.0, (16 * 0.75 + 25 * 0) / 8, (9 * 4 / 3 + 25 * 0) / 8], rtol=1e-14)
    assert a.sum() == pytest.approx(6.0, rel=1e-14)


def test_teaching_functions_against_libigl_one_by_one():
    igl = pytest.importorskip("igl")
    V, F = icosphere(3, scale=(1.0, 0.7, 0.4))
    scale = np.abs(igl.cotmatrix(V, F)).max()
    assert abs(cotangent_matrix(V, F) - igl.cotmatrix(V, F)).max() < 1e-12 * scale
    np.testing.assert_allclose(
        barycentric_areas(V, F), igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_BARYCENTRIC).diagonal(), rtol=1e-12
    )
    np.testing.assert_allclose(
        mixed_areas(V, F), igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI).diagonal(), rtol=1e-12
    )


def test_laplacian_measures_the_faces_once(monkeypatch):
    import geomlib.lessons.laplace as laplace

    calls = []
    measure = laplace.FaceGeometry.of
    monkeypatch.setattr(laplace.FaceGeometry, "of", lambda V, F: calls.append(1) or measure(V, F))
    V, F = surfaces.sphere(1.0, subdivisions=2).V, surfaces.sphere(1.0, subdivisions=2).F
    for area in ("barycentric", "mixed"):
        calls.clear()
        M, C = laplacian(V, F, area=area)
        assert len(calls) == 1
        np.testing.assert_array_equal(C.toarray(), cotangent_matrix(V, F).toarray())
        np.testing.assert_array_equal(M.diagonal(), vertex_areas(V, F, area))


def test_voronoi_pieces_fill_each_triangle_and_are_the_mixed_areas_without_an_obtuse_angle():
    # the three circumcentric pieces of a triangle sum to its area, obtuse or not (signed areas)
    V = np.array([[0.0, 0, 0], [4, 0, 0], [1, 1, 0], [2, -1.5, 0.3]])
    F = np.array([[0, 1, 2], [0, 3, 1]])
    pieces = voronoi_pieces(V, F)
    assert np.allclose(pieces.sum(axis=1), face_geometry(V, F)[1] / 2)
    assert pieces[0, 0] < 0  # at vertex 0 of the obtuse triangle: its other two angles differ by more than 90 degrees
    s = surfaces.sphere(1.0, subdivisions=1)  # the icosphere has no obtuse triangle
    summed = np.bincount(s.F.ravel(), voronoi_pieces(s.V, s.F).ravel(), minlength=len(s.V))
    assert np.allclose(summed, mixed_areas(s.V, s.F))


def test_intrinsic_cotangent_matrix_of_a_3_4_5_triangle_is_exact():
    # corner 0 opposite the hypotenuse 5 (the right angle), corners 1 and 2 opposite 3 and 4; area 6
    C = dense(intrinsic_cotangent_matrix([[5.0, 3.0, 4.0]], [[0, 1, 2]]))
    # cot of the right angle is 0; cot theta_1 = 4/3 (opposite 3), cot theta_2 = 3/4 (opposite 4)
    assert C[1, 2] == pytest.approx(0.0, abs=1e-15)
    assert C[0, 2] == pytest.approx(0.5 * 4 / 3, rel=1e-15) and C[0, 1] == pytest.approx(0.5 * 3 / 4, rel=1e-15)
    np.testing.assert_allclose(C.sum(axis=1), 0.0, atol=1e-15)


def test_intrinsic_cotangent_matrix_needs_only_the_lengths():
    V, F = icosphere(2, scale=(1.0, 0.7, 0.4))
    l = edge_lengths(V, F)
    Q = random_rotation(5)
    # Heron's areas (no positions) give the matrix the positions give, and a rigid motion changes nothing
    np.testing.assert_allclose(dense(intrinsic_cotangent_matrix(l, F)), dense(cotangent_matrix(V, F)), atol=1e-12)
    np.testing.assert_allclose(edge_lengths(V @ Q.T + 3.0, F), l, rtol=1e-12)


def test_intrinsic_cotangent_matrix_against_libigl():
    igl = pytest.importorskip("igl")
    e = surfaces.ellipsoid(1.0, 0.7, 0.5, subdivisions=2, jitter=0.3, seed=1)
    V, F = e.V, e.F
    l = edge_lengths(V, F)
    ref = igl.cotmatrix_intrinsic(l, F)
    assert abs(intrinsic_cotangent_matrix(l, F) - ref).max() < 1e-12 * abs(ref).max()


def test_intrinsic_cotangent_matrix_drops_a_flat_triangle_with_a_warning():
    with pytest.warns(MeshWarning, match="zero-area"):
        C = dense(intrinsic_cotangent_matrix([[2.0, 1.0, 1.0], [1.0, 1.0, 1.0]], [[0, 1, 2], [1, 3, 2]], n=5))
    assert C.shape == (5, 5) and np.isfinite(C).all()
    assert C[0].tolist() == [0.0] * 5 and C[4].tolist() == [0.0] * 5  # vertex 0 is only in the flat face
