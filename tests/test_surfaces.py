"""Tests of geomlib.teaching.shapes.surfaces: exact truth, exact placement, closed and oriented meshes."""

import numpy as np
import pytest
from partials import central_partials

from geomlib import MeshError
from geomlib.teaching.shapes import surfaces as S

# ---------------------------------------------------------------------------
# independent helpers (written here, not imported from the module under test)
# ---------------------------------------------------------------------------


def edge_counts(F):
    """(undirected edge -> number of faces), (directed edge -> number of faces)."""
    E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    _, directed = np.unique(E, axis=0, return_counts=True)
    _, undirected = np.unique(np.sort(E, axis=1), axis=0, return_counts=True)
    return undirected, directed


def signed_volume(V, F):
    return np.einsum("ij,ij->i", V[F[:, 0]], np.cross(V[F[:, 1]], V[F[:, 2]])).sum() / 6.0


def face_areas(V, F):
    return 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)


def mean_edge(V, F):
    E = np.unique(np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1), axis=0)
    return np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1).mean()


def fundamental_truth(p, u, v, outward, h=1e-4):
    """Normal, H, K from the first and second fundamental forms of a
    parametrisation p(u, v) -> (n, 3), with derivatives by central differences.

    ``outward(u, v)`` gives a vector on the outward side; H > 0 where the
    surface bends away from the chosen normal (sphere: outward normal, H = 1/r).
    """
    pu, pv, puu, puv, pvv = central_partials(p, u, v, h)
    n = np.cross(pu, pv)
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    n *= np.sign(np.einsum("ij,ij->i", n, outward(u, v)))[:, None]
    E, Fm, G = (np.einsum("ij,ij->i", a, b) for a, b in ((pu, pu), (pu, pv), (pv, pv)))
    # second fundamental form with the sign that makes a sphere positive
    L, M, N = (-np.einsum("ij,ij->i", a, n) for a in (puu, puv, pvv))
    det = E * G - Fm * Fm
    K = (L * N - M * M) / det
    H = (E * N - 2 * Fm * M + G * L) / (2 * det)
    return n, H, K


def ellipsoid_p(a, b, c):
    return lambda u, v: np.stack([a * np.cos(u) * np.sin(v), b * np.sin(u) * np.sin(v), c * np.cos(v)], 1)


def torus_p(R, r):
    return lambda u, v: np.stack([(R + r * np.cos(v)) * np.cos(u), (R + r * np.cos(v)) * np.sin(u), r * np.sin(v)], 1)


# ---------------------------------------------------------------------------
# fixtures: one small mesh of each kind, plain and jittered
# ---------------------------------------------------------------------------

CLOSED = {
    "icosphere": lambda **kw: S.sphere(1.7, subdivisions=3, **kw),
    "uv_sphere": lambda **kw: S.uv_sphere(0.8, n=12, **kw),
    "ellipsoid": lambda **kw: S.ellipsoid(1.0, 0.7, 0.5, subdivisions=3, **kw),
    "uv_ellipsoid": lambda **kw: S.uv_ellipsoid(1.2, 0.5, 0.9, n=14, **kw),
    "torus": lambda **kw: S.torus(1.0, 0.35, n=40, **kw),
}
OPEN = {
    "plane": lambda **kw: S.plane(n=12, size=3.0, **kw),
    "plane_alternate": lambda **kw: S.plane(n=12, diagonals="alternate", **kw),
    "saddle": lambda **kw: S.saddle(n=24, **kw),
}
ALL = {**CLOSED, **OPEN}


def implicit_residual(m):
    """Value of the surface's implicit equation at the vertices (0 on the surface)."""
    V, p = m.V, m.params
    if m.name == "sphere":
        return np.linalg.norm(V, axis=1) / p["r"] - 1.0
    if m.name == "ellipsoid":
        return (V[:, 0] / p["a"]) ** 2 + (V[:, 1] / p["b"]) ** 2 + (V[:, 2] / p["c"]) ** 2 - 1.0
    if m.name == "torus":
        return ((np.hypot(V[:, 0], V[:, 1]) - p["R"]) ** 2 + V[:, 2] ** 2 - p["r"] ** 2) / p["r"] ** 2
    if m.name == "plane":
        return V[:, 2]
    x, y = V[:, 0], V[:, 1]
    return V[:, 2] - (p["amplitude"] * 6.75 * x * (1 - x * x) * y * (1 - y * y) + p["monkey"] * (x**3 - 3 * x * y * y))


@pytest.fixture(params=[0.0, 0.3], ids=["regular", "jittered"])
def jitter(request):
    return request.param


# ---------------------------------------------------------------------------
# placement, normals, topology
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("kind", ALL)
def test_vertices_on_exact_surface(kind, jitter):
    m = ALL[kind](jitter=jitter, seed=3)
    assert np.abs(implicit_residual(m)).max() < 1e-12


@pytest.mark.parametrize("kind", ALL)
def test_types_shapes_and_unit_normals(kind, jitter):
    m = ALL[kind](jitter=jitter, seed=3)
    n = m.V.shape[0]
    assert m.V.dtype == np.float64 and m.V.shape == (n, 3)
    assert m.F.dtype == np.int64 and m.F.shape[1] == 3
    assert m.F.min() == 0 and m.F.max() == n - 1
    for a in (m.H, m.K, m.k1, m.k2):
        assert a.shape == (n,) and a.dtype == np.float64 and np.isfinite(a).all()
    assert np.abs(np.linalg.norm(m.N, axis=1) - 1).max() < 1e-14
    assert np.all(m.k1 >= m.k2)
    np.testing.assert_allclose((m.k1 + m.k2) / 2, m.H, atol=1e-12)
    np.testing.assert_allclose(m.k1 * m.k2, m.K, atol=1e-10)
    # every vertex is used by some face (no isolated points)
    assert np.unique(m.F).size == n


@pytest.mark.parametrize("kind", ALL)
def test_no_zero_area_or_inverted_faces(kind, jitter):
    m = ALL[kind](jitter=jitter, seed=3)
    A = face_areas(m.V, m.F)
    assert A.min() > 1e-3 * A.mean()
    # face normals agree with the exact normal at the face's vertices
    FN = np.cross(m.V[m.F[:, 1]] - m.V[m.F[:, 0]], m.V[m.F[:, 2]] - m.V[m.F[:, 0]])
    assert np.all(np.einsum("ij,ij->i", FN, m.N[m.F].mean(axis=1)) > 0)


@pytest.mark.parametrize("kind", CLOSED)
def test_closed_meshes_are_closed_and_consistently_oriented(kind, jitter):
    m = CLOSED[kind](jitter=jitter, seed=3)
    undirected, directed = edge_counts(m.F)
    assert m.closed
    assert np.all(undirected == 2)  # every edge used by exactly two faces
    assert np.all(directed == 1)  # ... in opposite directions
    # no duplicate vertex positions on seams or poles
    assert np.unique(np.round(m.V, 12), axis=0).shape[0] == m.V.shape[0]
    nV, nE, nF = m.V.shape[0], undirected.size, m.F.shape[0]
    assert nV - nE + nF == (0 if m.name == "torus" else 2)


@pytest.mark.parametrize("kind", OPEN)
def test_open_meshes_have_one_boundary_loop_on_the_square(kind, jitter):
    m = OPEN[kind](jitter=jitter, seed=3)
    undirected, directed = edge_counts(m.F)
    assert not m.closed
    assert np.all(directed == 1) and set(np.unique(undirected)) == {1, 2}
    nE = undirected.size
    assert m.V.shape[0] - nE + m.F.shape[0] == 1  # a disc
    half = m.params["size"] / 2
    # the square's outline is kept exactly: boundary vertices stay on the sides
    E = np.unique(
        np.sort(np.concatenate([m.F[:, [0, 1]], m.F[:, [1, 2]], m.F[:, [2, 0]]]), axis=1), axis=0, return_counts=True
    )
    bnd = np.unique(E[0][E[1] == 1])
    on_side = np.isclose(np.abs(m.V[bnd, 0]), half, atol=1e-15) | np.isclose(np.abs(m.V[bnd, 1]), half, atol=1e-15)
    assert on_side.all()
    assert np.abs(m.V[:, :2]).max() <= half + 1e-15


@pytest.mark.parametrize("kind", ["icosphere", "ellipsoid", "uv_sphere", "uv_ellipsoid"])
def test_normals_point_outward(kind, jitter):
    m = CLOSED[kind](jitter=jitter, seed=3)
    assert np.all(np.einsum("ij,ij->i", m.N, m.V) > 0)
    assert signed_volume(m.V, m.F) > 0


def test_torus_and_height_field_normals():
    t = S.torus(1.0, 0.35, n=40)
    centre = t.V.copy()
    centre[:, 2] = 0
    centre[:, :2] *= (1.0 / np.linalg.norm(centre[:, :2], axis=1))[:, None]
    assert np.all(np.einsum("ij,ij->i", t.N, t.V - centre) > 0)  # away from the tube's centre line
    s = S.saddle(n=24)
    assert np.all(s.N[:, 2] > 0)  # upward
    assert np.all(np.cross(s.V[s.F[:, 1]] - s.V[s.F[:, 0]], s.V[s.F[:, 2]] - s.V[s.F[:, 0]])[:, 2] > 0)


# ---------------------------------------------------------------------------
# the truth against closed forms and independent derivations
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("make", [lambda: S.sphere(1.7, subdivisions=3, jitter=0.2), lambda: S.uv_sphere(1.7, n=10)])
def test_sphere_truth(make):
    m = make()
    r = 1.7
    np.testing.assert_allclose(m.H, 1 / r, rtol=1e-15)
    np.testing.assert_allclose(m.K, 1 / r**2, rtol=1e-15)
    np.testing.assert_allclose(m.k1, 1 / r, rtol=1e-7)
    np.testing.assert_allclose(m.k2, 1 / r, rtol=1e-7)
    np.testing.assert_allclose(m.N, m.V / r, atol=1e-15)


def test_ellipsoid_truth_closed_forms(jitter):
    a, b, c = 1.0, 0.7, 0.5
    m = S.ellipsoid(a, b, c, subdivisions=3, jitter=jitter, seed=1)
    x, y, z = m.V.T
    q = x**2 / a**4 + y**2 / b**4 + z**2 / c**4
    np.testing.assert_allclose(m.K, 1 / (a * b * c) ** 2 / q**2, rtol=1e-12)
    # H from the implicit surface's gradient and Hessian, computed here directly:
    # H = (|g|^2 tr(Hess) - g^T Hess g) / (2 |g|^3) with f = x^2/a^2 + ... - 1
    g = np.stack([2 * x / a**2, 2 * y / b**2, 2 * z / c**2], 1)
    Hess = np.diag([2 / a**2, 2 / b**2, 2 / c**2])
    gn = np.linalg.norm(g, axis=1)
    H = (gn**2 * np.trace(Hess) - np.einsum("ij,jk,ik->i", g, Hess, g)) / (2 * gn**3)
    np.testing.assert_allclose(m.H, H, rtol=1e-12)
    np.testing.assert_allclose(m.N, g / gn[:, None], atol=1e-14)


def test_ellipsoid_truth_against_fundamental_forms():
    a, b, c = 1.0, 0.7, 0.5
    m = S.uv_ellipsoid(a, b, c, n=16, jitter=0.3, seed=2)
    keep = (m.uv[:, 1] > 0.05) & (m.uv[:, 1] < np.pi - 0.05)  # the chart is singular at the poles
    u, v = m.uv[keep].T
    n, H, K = fundamental_truth(ellipsoid_p(a, b, c), u, v, lambda u, v: ellipsoid_p(a, b, c)(u, v))
    np.testing.assert_allclose(m.V[keep], ellipsoid_p(a, b, c)(u, v), atol=1e-15)
    np.testing.assert_allclose(m.H[keep], H, rtol=1e-6)
    np.testing.assert_allclose(m.K[keep], K, rtol=1e-6)
    np.testing.assert_allclose(m.N[keep], n, atol=1e-7)


def test_ellipsoid_parameters_reproduce_the_vertices():
    a, b, c = 1.3, 0.6, 0.9
    m = S.ellipsoid(a, b, c, subdivisions=2, jitter=0.25, seed=5)
    np.testing.assert_allclose(ellipsoid_p(a, b, c)(*m.uv.T), m.V, atol=1e-14)


def test_torus_truth(jitter):
    R, r = 1.0, 0.35
    m = S.torus(R, r, n=40, jitter=jitter, seed=4)
    u, v = m.uv.T
    np.testing.assert_allclose(torus_p(R, r)(u, v), m.V, atol=1e-15)
    np.testing.assert_allclose(m.K, np.cos(v) / (r * (R + r * np.cos(v))), rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(m.k1, 1 / r, rtol=1e-12)
    np.testing.assert_allclose(m.k2, np.cos(v) / (R + r * np.cos(v)), atol=1e-12)
    centre = lambda u, v: np.stack([R * np.cos(u), R * np.sin(u), 0 * u], 1)  # noqa: E731
    n, H, K = fundamental_truth(torus_p(R, r), u, v, lambda u, v: torus_p(R, r)(u, v) - centre(u, v))
    np.testing.assert_allclose(m.H, H, atol=1e-6)
    np.testing.assert_allclose(m.K, K, atol=1e-6)
    np.testing.assert_allclose(m.N, n, atol=1e-7)


def test_saddle_truth(jitter):
    A, B = 0.2, 0.1
    m = S.saddle(n=24, amplitude=A, monkey=B, jitter=jitter, seed=6)
    x, y = m.uv.T
    h = lambda x, y: np.stack([x, y, A * 6.75 * x * (1 - x * x) * y * (1 - y * y) + B * (x**3 - 3 * x * y * y)], 1)  # noqa: E731
    up = lambda x, y: np.tile([0.0, 0.0, 1.0], (x.size, 1))  # noqa: E731
    n, H, K = fundamental_truth(h, x, y, up)
    np.testing.assert_allclose(m.H, H, atol=2e-6)
    np.testing.assert_allclose(m.K, K, atol=2e-6)
    np.testing.assert_allclose(m.N, n, atol=1e-7)
    # the surface is saddle-rich: both signs of K, and K < 0 at the origin
    assert (m.K < -0.5).sum() > 0.1 * m.K.size and (m.K > 0.5).sum() > 0.1 * m.K.size
    o = np.argmin(np.hypot(x, y))
    assert m.K[o] < 0
    if jitter == 0:  # a vertex sits at the origin: a saddle point with H = 0
        assert np.hypot(x[o], y[o]) == 0 and abs(m.H[o]) < 1e-15


def test_saddle_closed_form_at_the_origin_and_sign_on_a_bump():
    # at the origin h_x = h_y = h_xx = h_yy = 0 and h_xy = (27/4) A: H = 0, K = -h_xy^2
    A = 0.2
    m = S.saddle(n=20, amplitude=A, monkey=0.1)
    o = np.flatnonzero((m.V[:, 0] == 0) & (m.V[:, 1] == 0))[0]
    assert abs(m.H[o]) < 1e-15
    np.testing.assert_allclose(m.K[o], -((6.75 * A) ** 2), rtol=1e-14)
    np.testing.assert_allclose([m.k1[o], m.k2[o]], [6.75 * A, -6.75 * A], rtol=1e-14)
    np.testing.assert_allclose(m.N[o], [0, 0, 1], atol=1e-15)
    # the highest vertex sits on a bump that bends down, away from the upward normal
    top = np.argmax(m.V[:, 2])
    assert 0 < abs(m.V[top, 0]) < 1 and 0 < abs(m.V[top, 1]) < 1
    assert m.H[top] > 0 and m.K[top] > 0 and m.k2[top] > 0


def monge_closed_form(hx, hy, hxx, hxy, hyy):
    """Upward normal, H (workbook sign), K of z = h(x, y) from its derivatives."""
    W2 = 1 + hx * hx + hy * hy
    N = np.stack([-hx, -hy, np.ones_like(hx)], 1) / np.sqrt(W2)[:, None]
    K = (hxx * hyy - hxy * hxy) / W2**2
    H = -((1 + hy * hy) * hxx - 2 * hx * hy * hxy + (1 + hx * hx) * hyy) / (2 * W2**1.5)
    return N, H, K


def test_saddle_truth_against_monge_closed_form():
    A, B = 0.2, 0.1
    m = S.saddle(n=16, amplitude=A, monkey=B, jitter=0.3, seed=2)
    x, y = m.uv.T
    a = 6.75 * A
    px, dpx, ddpx = x * (1 - x * x), 1 - 3 * x * x, -6 * x
    py, dpy, ddpy = y * (1 - y * y), 1 - 3 * y * y, -6 * y
    hx = a * dpx * py + B * (3 * x * x - 3 * y * y)
    hy = a * px * dpy - 6 * B * x * y
    hxx = a * ddpx * py + 6 * B * x
    hxy = a * dpx * dpy - 6 * B * y
    hyy = a * px * ddpy - 6 * B * x
    N, H, K = monge_closed_form(hx, hy, hxx, hxy, hyy)
    np.testing.assert_allclose(m.N, N, atol=1e-14)
    np.testing.assert_allclose(m.H, H, atol=1e-13)
    np.testing.assert_allclose(m.K, K, atol=1e-13)


def test_plane_truth():
    m = S.plane(n=10, jitter=0.4, seed=1)
    assert np.all(m.H == 0) and np.all(m.K == 0) and np.all(m.V[:, 2] == 0)
    np.testing.assert_array_equal(m.N, np.tile([0.0, 0.0, 1.0], (m.V.shape[0], 1)))
    assert np.isclose(face_areas(m.V, m.F).sum(), m.area, rtol=1e-13)


# ---------------------------------------------------------------------------
# volumes, areas and refinement
# ---------------------------------------------------------------------------


def test_sphere_volume_converges_under_refinement():
    errors, edges = [], []
    for k in range(1, 6):
        m = S.sphere(1.0, subdivisions=k)
        errors.append(m.volume - signed_volume(m.V, m.F))
        edges.append(mean_edge(m.V, m.F))
    errors, edges = np.array(errors), np.array(edges)
    assert np.all(errors > 0)  # inscribed polyhedron
    np.testing.assert_allclose(edges[1:] / edges[:-1], 0.5, atol=0.03)  # edge length halves per step
    np.testing.assert_allclose(errors[1:] / errors[:-1], 0.25, atol=0.03)  # second order
    assert errors[-1] / m.volume < 1e-3


@pytest.mark.parametrize(
    "make, start, refine",
    [
        (lambda k: S.ellipsoid(1.0, 0.7, 0.5, subdivisions=k), 2, lambda k: k + 1),
        (lambda k: S.ellipsoid(1.0, 0.7, 0.5, subdivisions=k, jitter=0.3, seed=0), 2, lambda k: k + 1),
        (lambda n: S.uv_ellipsoid(1.0, 0.7, 0.5, n=n), 8, lambda n: 2 * n),
        (lambda n: S.torus(1.0, 0.4, n=n, m=n // 2), 12, lambda n: 2 * n),
        (lambda n: S.uv_sphere(2.0, n=n), 8, lambda n: 2 * n),
    ],
    ids=["ellipsoid", "ellipsoid_jittered", "uv_ellipsoid", "torus", "uv_sphere"],
)
def test_volume_and_area_converge(make, start, refine):
    res = start
    vol_err, area_err = [], []
    for _ in range(3):
        m = make(res)
        vol = signed_volume(m.V, m.F)
        assert vol > 0
        vol_err.append(abs(m.volume - vol) / m.volume)
        area_err.append(abs(m.area - face_areas(m.V, m.F).sum()) / m.area)
        res = refine(res)
    assert vol_err[0] > vol_err[1] > vol_err[2]
    assert area_err[0] > area_err[1] > area_err[2]
    assert vol_err[2] < 0.4 * vol_err[1]  # at least close to second order (ratio 1/4)
    assert area_err[2] < 0.4 * area_err[1]


def test_ellipsoid_exact_area_by_quadrature():
    a, b, c = 1.0, 0.7, 0.5
    x, w = np.polynomial.legendre.leggauss(200)
    u = np.pi * (x + 1)  # [0, 2 pi]
    v = np.pi / 2 * (x + 1)  # [0, pi]
    U, Vv = np.meshgrid(u, v, indexing="ij")
    pu = np.stack([-a * np.sin(U) * np.sin(Vv), b * np.cos(U) * np.sin(Vv), 0 * U], -1)
    pv = np.stack([a * np.cos(U) * np.cos(Vv), b * np.sin(U) * np.cos(Vv), -c * np.sin(Vv)], -1)
    dA = np.linalg.norm(np.cross(pu, pv), axis=-1)
    area = np.pi * (np.pi / 2) * np.einsum("i,j,ij->", w, w, dA)
    assert abs(S.ellipsoid(a, b, c, subdivisions=0).area - area) < 1e-10
    assert abs(S.ellipsoid(0.5, 1.0, 0.7, subdivisions=0).area - area) < 1e-10  # order of the axes


def test_resolution_counts():
    for k in range(4):
        m = S.ellipsoid(subdivisions=k)
        assert m.V.shape[0] == 10 * 4**k + 2 and m.F.shape[0] == 20 * 4**k
    m = S.uv_sphere(n=6)
    assert m.V.shape[0] == 2 * 6 * 5 + 2 and m.F.shape[0] == 4 * 6 * 5
    m = S.torus(n=10, m=6)
    assert m.V.shape[0] == 60 and m.F.shape[0] == 120
    assert S.torus(1.0, 0.4, n=20).params["m"] == 8
    m = S.plane(n=7)
    assert m.V.shape[0] == 64 and m.F.shape[0] == 98
    # the coarsest meshes are valid too
    assert S.uv_sphere(n=2).F.shape[0] == 8 and S.sphere(subdivisions=0).V.shape[0] == 12


# ---------------------------------------------------------------------------
# jitter: on the surface, reproducible, seeded
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("kind", ALL)
def test_jitter_is_reproducible_and_seeded(kind):
    m1 = ALL[kind](jitter=0.3, seed=11)
    m2 = ALL[kind](jitter=0.3, seed=11)
    m3 = ALL[kind](jitter=0.3, seed=12)
    m0 = ALL[kind]()
    np.testing.assert_array_equal(m1.V, m2.V)
    np.testing.assert_array_equal(m1.H, m2.H)
    assert not np.array_equal(m1.V, m3.V)
    assert not np.array_equal(m1.V, m0.V)
    np.testing.assert_array_equal(m1.F, m0.F)  # same connectivity, vertices moved
    assert np.abs(implicit_residual(m1)).max() < 1e-12
    # jitter moved most vertices by a fraction of an edge, not more
    d = np.linalg.norm(m1.V - m0.V, axis=1)
    assert np.mean(d > 0) > 0.7 and d.max() < 0.6 * mean_edge(m0.V, m0.F) * 2


def test_jitter_makes_triangles_irregular():
    def angles(m):
        P = m.V[m.F]
        out = []
        for i in range(3):
            e1 = P[:, (i + 1) % 3] - P[:, i]
            e2 = P[:, (i + 2) % 3] - P[:, i]
            out.append(
                np.arccos(np.einsum("ij,ij->i", e1, e2) / np.linalg.norm(e1, axis=1) / np.linalg.norm(e2, axis=1))
            )
        return np.degrees(np.concatenate(out))

    regular = angles(S.plane(n=16))
    irregular = angles(S.plane(n=16, jitter=0.35, seed=0))
    assert regular.max() < 90 + 1e-9
    assert (irregular > 90 + 1e-6).mean() > 0.1  # a share of obtuse angles


# ---------------------------------------------------------------------------
# attach_truth and argument checks
# ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    "m, params",
    [
        (S.ellipsoid(1.0, 0.7, 0.5, subdivisions=3, jitter=0.2, seed=1), dict(a=1.0, b=0.7, c=0.5)),
        (S.sphere(2.0, subdivisions=2), dict(r=2.0)),
        (S.torus(1.0, 0.4, n=24, jitter=0.2), dict(R=1.0, r=0.4)),
        (S.saddle(n=16, jitter=0.2), dict(amplitude=0.2, monkey=0.1)),
        (S.plane(n=4), dict()),
    ],
)
def test_attach_truth_reproduces_the_truth(m, params):
    t = S.attach_truth(m.name, np.round(m.V, 9), m.F, **params)  # as read back from a file
    for name, tol in (("H", 1e-7), ("K", 1e-7), ("k1", 1e-6), ("k2", 1e-6), ("N", 1e-8)):
        np.testing.assert_allclose(getattr(t, name), getattr(m, name), atol=tol, err_msg=name)
    assert t.closed == m.closed


def test_attach_truth_rejects_points_off_the_surface():
    m = S.sphere(1.0, subdivisions=1)
    V = m.V.copy()
    V[5] *= 1.01
    with pytest.raises(MeshError, match="5"):
        S.attach_truth("sphere", V, m.F, r=1.0)
    with pytest.raises(MeshError, match="unknown surface"):
        S.attach_truth("cone", m.V, m.F)
    with pytest.raises(MeshError, match="unknown"):
        S.attach_truth("sphere", m.V, m.F, radius=1.0)


@pytest.mark.parametrize(
    "call",
    [
        lambda: S.sphere(r=0),
        lambda: S.sphere(r=-1),
        lambda: S.sphere(r=float("nan")),
        lambda: S.sphere(subdivisions=-1),
        lambda: S.sphere(subdivisions=2.5),
        lambda: S.sphere(subdivisions=10),
        lambda: S.plane(n=5000),
        lambda: S.ellipsoid(1, 0, 1),
        lambda: S.ellipsoid(1, 1, "x"),
        lambda: S.uv_sphere(n=1),
        lambda: S.uv_ellipsoid(n=1),
        lambda: S.torus(R=1, r=1),
        lambda: S.torus(R=1, r=0.4, n=2),
        lambda: S.torus(R=1, r=0.4, m=2),
        lambda: S.plane(n=0),
        lambda: S.plane(size=-2),
        lambda: S.plane(diagonals="left"),
        lambda: S.saddle(n=1),
        lambda: S.saddle(amplitude=float("inf")),
        lambda: S.sphere(jitter=0.5),
        lambda: S.sphere(jitter=-0.1),
        lambda: S.torus(jitter=0.2, seed=1.5),
    ],
)
def test_bad_arguments_raise_mesherror(call):
    with pytest.raises(MeshError):
        call()


def test_analytic_mesh_is_frozen():
    m = S.sphere(subdivisions=1)
    with pytest.raises(AttributeError):
        m.V = None
    assert "sphere" in repr(m) and "42 vertices" in repr(m)
    assert m.n_vertices == 42 and m.n_faces == 80


def test_principal_curvatures_agree_with_symbolic_principal_curvatures():
    from geomlib import symbolic

    m = S.ellipsoid(1.0, 0.7, 0.5, subdivisions=2, jitter=0.2, seed=0)
    k1, k2 = symbolic.ellipsoid(1.0, 0.7, 0.5).lambdify("principal_curvatures")(*m.uv.T)
    np.testing.assert_allclose(m.k1, k1, atol=1e-7)
    np.testing.assert_allclose(m.k2, k2, atol=1e-7)
    t = S.torus(1.0, 0.4, n=16)
    k1, k2 = symbolic.torus(1.0, 0.4).lambdify("principal_curvatures")(*t.uv.T)
    np.testing.assert_allclose(t.k1, k1, atol=1e-7)
    np.testing.assert_allclose(t.k2, k2, atol=1e-7)


def test_truth_is_computed_on_first_access_and_kept():
    m = S.torus(1.0, 0.4, n=8)
    assert "_values" not in m.__dict__
    H = m.H
    assert "_values" in m.__dict__ and m.H is H


@pytest.mark.parametrize(
    "make", [lambda: S.ellipsoid(1.0, 0.7, 0.5, subdivisions=2), lambda: S.uv_ellipsoid(1.0, 0.7, 0.5, n=6)]
)
def test_ellipsoid_truth_at_the_poles(make):
    # the parametrisation is singular at v = 0, pi; the truth there is still exact:
    # normal +-z, principal curvatures c / a^2 and c / b^2
    m = make()
    poles = np.flatnonzero(np.abs(m.V[:, 2]) == 0.5)
    assert poles.size == 2
    np.testing.assert_allclose(m.N[poles], [[0, 0, np.sign(z)] for z in m.V[poles, 2]], atol=1e-15)
    np.testing.assert_allclose(m.k1[poles], 0.5 / 0.7**2, rtol=1e-7)
    np.testing.assert_allclose(m.k2[poles], 0.5 / 1.0**2, rtol=1e-7)
    np.testing.assert_allclose(m.K[poles], 0.5**2 / (0.7**2 * 1.0**2), rtol=1e-13)


def test_the_saddle_height_has_nine_saddles_eight_on_the_boundary():
    # without the monkey term: grad z = 0 and det Hess z < 0 exactly at x, y in {-1, 0, 1}
    # (the origin, the four edge midpoints and the four corners); the four bumps and dips are
    # at x, y = +-1/sqrt(3), where det Hess z > 0
    import sympy as sp

    x, y = sp.symbols("x y", real=True)
    z = sp.Rational(27, 4) * x * (1 - x**2) * y * (1 - y**2)
    grad = [sp.diff(z, x), sp.diff(z, y)]
    critical = sp.solve(grad, [x, y], dict=True)
    hessian = sp.hessian(z, (x, y)).det()
    saddles = sorted((p[x], p[y]) for p in critical if hessian.subs(p) < 0)
    extrema = [p for p in critical if hessian.subs(p) > 0]
    assert saddles == sorted((a, b) for a in (-1, 0, 1) for b in (-1, 0, 1))
    assert len([s for s in saddles if 1 in map(abs, s)]) == 8 and len(extrema) == 4
    assert all(abs(p[x]) == abs(p[y]) == 1 / sp.sqrt(3) for p in extrema)
    # the function the meshes use is this polynomial
    u = np.linspace(-1, 1, 7)
    np.testing.assert_allclose(
        S.saddle_height(u[:, None], u[None, :], amplitude=1.0, monkey=0.0),
        sp.lambdify((x, y), z)(u[:, None], u[None, :]),
        rtol=1e-14,
        atol=1e-15,
    )
