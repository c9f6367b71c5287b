"""Tests of geomlib.lessons.curvature: closed forms, Gauss-Bonnet, laws, boundary rules, bad input, libigl."""

import warnings

import numpy as np
import pytest
from meshdata import COURSE, COURSE_MESHES, SHIPPED, load_quietly, needs_course

from geomlib import (
    MeshError,
    MeshWarning,
    discrete_principal_curvatures,
    gaussian_curvature,
    laplacian,
    mean_curvature,
    principal_curvatures,
    surfaces,
)
from geomlib.lessons.curvature import BOUNDARY_RULES, angle_sums, boundary_mask


def euler_characteristic(V, F):
    E = np.unique(np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1), axis=0)
    return len(np.unique(F)) - len(E) + len(F)


def random_rotation(seed):
    Q, R = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    Q = Q * np.sign(np.diag(R))
    if np.linalg.det(Q) < 0:
        Q[:, 0] *= -1
    return Q


# ---------------------------------------------------------------- closed forms


@pytest.mark.parametrize("jitter", [0.0, 0.35])
@pytest.mark.parametrize("diagonals", ["right", "alternate"])
def test_flat_grid_has_zero_curvature_inside(jitter, diagonals):
    s = surfaces.plane(n=16, jitter=jitter, seed=4, diagonals=diagonals)
    interior = ~boundary_mask(s.V, s.F)
    for area in ("barycentric", "mixed"):
        H = mean_curvature(s.V, s.F, area=area)
        K = gaussian_curvature(s.V, s.F, area=area)
        assert np.abs(H[interior]).max() < 1e-12
        assert np.abs(K[interior]).max() < 1e-12
        assert np.isnan(K[~interior]).all()
    if jitter == 0.0 and diagonals == "right":
        # the uniform operator is exact only on the regular (valence 6) grid
        assert np.abs(mean_curvature(s.V, s.F, weights="uniform")[interior]).max() < 1e-12


def test_uniform_mean_curvature_is_not_zero_on_a_jittered_plane():
    s = surfaces.plane(n=16, jitter=0.35, seed=4)
    interior = ~boundary_mask(s.V, s.F)
    assert np.median(mean_curvature(s.V, s.F, weights="uniform")[interior]) > 1e-3


@pytest.mark.parametrize("r", [0.5, 3.0])
def test_sphere_converges_to_one_over_r(r):
    # regular icospheres: the median error of every estimate and the maximum
    # error of the mixed-area ones shrink about fourfold per halving of the edges
    errors = {}
    for k in (2, 3, 4, 5):
        s = surfaces.sphere(r=r, subdivisions=k)
        e = {}
        for area in ("barycentric", "mixed"):
            H = mean_curvature(s.V, s.F, area=area, signed=True)
            K = gaussian_curvature(s.V, s.F, area=area)
            assert (H > 0).all() and (K > 0).all()
            e["H", area] = np.abs(H * r - 1)
            e["K", area] = np.abs(K * r * r - 1)
        errors[k] = e
    for k in (3, 4, 5):
        for key in errors[k]:
            assert np.median(errors[k][key]) < 0.5 * np.median(errors[k - 1][key]) + 1e-12
        assert errors[k]["H", "mixed"].max() < 0.5 * errors[k - 1]["H", "mixed"].max()
        assert errors[k]["K", "mixed"].max() < 0.5 * errors[k - 1]["K", "mixed"].max()
    assert max(np.median(v) for v in errors[5].values()) < 1e-3
    assert errors[5]["K", "mixed"].max() < 1e-3


def test_sphere_mean_curvature_signs_and_uniform_units():
    s = surfaces.sphere(r=2.0, subdivisions=3)
    H = mean_curvature(s.V, s.F, signed=True)
    assert (H > 0).all()
    np.testing.assert_allclose(mean_curvature(s.V, s.F), np.abs(H), rtol=1e-2)
    # flipping the orientation flips the signed value only
    Hf = mean_curvature(s.V, s.F[:, ::-1], signed=True)
    np.testing.assert_allclose(Hf, -H, rtol=1e-12)
    np.testing.assert_allclose(mean_curvature(s.V, s.F[:, ::-1]), mean_curvature(s.V, s.F), rtol=1e-12)


def test_principal_curvatures_identities_and_sphere():
    s = surfaces.ellipsoid(1.0, 0.7, 0.5, subdivisions=4)
    H = mean_curvature(s.V, s.F, area="mixed", signed=True)
    K = gaussian_curvature(s.V, s.F, area="mixed")
    k1, k2 = principal_curvatures(H, K)
    assert (k1 >= k2).all()
    np.testing.assert_allclose(0.5 * (k1 + k2), H, rtol=1e-14)
    ok = H * H >= K
    np.testing.assert_allclose((k1 * k2)[ok], K[ok], rtol=1e-10)
    assert np.median(np.abs(k1 - s.k1) / s.k1) < 0.05
    assert np.median(np.abs(k2 - s.k2) / s.k2) < 0.05
    k1, k2 = principal_curvatures(np.full(3, 2.0), np.array([4.0, 4.1, 3.0]))
    np.testing.assert_allclose(k1, [2.0, 2.0, 3.0])
    np.testing.assert_allclose(k2, [2.0, 2.0, 1.0])


def kappas(V, F, area="mixed"):
    """discrete_principal_curvatures of the cotangent pair of ``area`` and the boundary-NaN deficit."""
    M, C = laplacian(V, F, area=area)
    return discrete_principal_curvatures(V, F, M, C, gaussian_curvature(V, F, integrated=True))


@pytest.mark.parametrize("r", [0.5, 3.0])
def test_discrete_principal_curvatures_of_a_sphere_are_one_over_r(r):
    s = surfaces.sphere(r, subdivisions=4)
    k1, k2 = kappas(s.V, s.F)
    assert np.abs(k1 * r - 1).max() < 0.02 and np.abs(k2 * r - 1).max() < 0.02
    coarse = surfaces.sphere(r, subdivisions=2)  # twice the edge length: the error is larger
    assert np.abs(kappas(coarse.V, coarse.F)[0] * r - 1).max() > np.abs(k1 * r - 1).max()


@pytest.mark.parametrize("jitter", [0.0, 0.3])
def test_discrete_principal_curvatures_of_a_plane_are_zero_inside_and_nan_on_the_boundary(jitter):
    p = surfaces.plane(n=9, size=2.0, jitter=jitter, seed=4)
    k1, k2 = kappas(p.V, p.F)
    boundary = boundary_mask(p.V, p.F)
    assert np.isnan(k1[boundary]).all() and np.isnan(k2[boundary]).all()
    # H and K are 0 to rounding (1e-14); the square root of H^2 - K lifts that to about 1e-7 on edges of 0.25
    assert np.abs(k1[~boundary]).max() < 1e-6 and np.abs(k2[~boundary]).max() < 1e-6
    # the rule holds whatever the deficit holds at the boundary (here the interior formula, pi there)
    M, C = laplacian(p.V, p.F, area="mixed")
    deficit = 2 * np.pi - angle_sums(p.V, p.F)
    assert np.isnan(discrete_principal_curvatures(p.V, p.F, M, C, deficit)[0][boundary]).all()


@pytest.mark.parametrize("jitter", [0.0, 0.3])
def test_discrete_principal_curvatures_are_ordered_and_give_back_h_and_k(jitter):
    e = surfaces.ellipsoid(1.0, 0.7, 0.5, subdivisions=3, jitter=jitter, seed=2)
    M, C = laplacian(e.V, e.F, area="mixed")
    deficit = gaussian_curvature(e.V, e.F, integrated=True)
    k1, k2 = discrete_principal_curvatures(e.V, e.F, M, C, deficit)
    H = mean_curvature(e.V, e.F, area="mixed", signed=True)
    K = deficit / M.diagonal()
    assert (k1 >= k2).all()
    np.testing.assert_allclose(k1 + k2, 2 * H, rtol=1e-12)
    real = H * H >= K  # where the root exists, k1 k2 = K exactly; elsewhere the clamp gives k1 = k2 = H
    assert real.any() and (~real).any()
    np.testing.assert_allclose((k1 * k2)[real], K[real], rtol=1e-9)
    assert np.array_equal(k1[~real], H[~real]) and np.array_equal(k2[~real], H[~real])
    within = 0.05 if jitter == 0 else 0.1  # the jittered mesh converges only weakly (notebook 03)
    assert np.median(np.abs(k1 - e.k1) / e.k1) < within and np.median(np.abs(k2 - e.k2) / e.k2) < within


def test_discrete_principal_curvatures_scale_as_one_over_length_and_flip_with_the_orientation():
    e = surfaces.ellipsoid(1.0, 0.7, 0.5, subdivisions=2)
    k1, k2 = kappas(e.V, e.F)
    s1, s2 = kappas(2.5 * e.V, e.F)
    np.testing.assert_allclose(s1, k1 / 2.5, rtol=1e-12)
    np.testing.assert_allclose(s2, k2 / 2.5, rtol=1e-12)
    f1, f2 = kappas(e.V, e.F[:, ::-1])  # inward normals: H changes sign, K does not: (-k2, -k1)
    np.testing.assert_allclose(f1, -k2, rtol=1e-12)
    np.testing.assert_allclose(f2, -k1, rtol=1e-12)


def test_discrete_principal_curvatures_of_a_saddle_have_opposite_signs():
    s = surfaces.saddle(n=20)
    k1, k2 = kappas(s.V, s.F)
    inside = ~boundary_mask(s.V, s.F) & (s.K < -0.05 * np.abs(s.K).max())
    assert inside.any() and (k1[inside] > 0).all() and (k2[inside] < 0).all()


def test_discrete_principal_curvatures_are_nan_at_a_vertex_of_no_area_without_a_warning():
    import scipy.sparse as sp

    s = surfaces.sphere(1.0, subdivisions=1)
    M, C = laplacian(s.V, s.F)
    V = np.vstack([s.V, [[5.0, 5.0, 5.0]]])  # in no triangle: M_ii = 0
    M, C = sp.block_diag([M, sp.csr_matrix((1, 1))]), sp.block_diag([C, sp.csr_matrix((1, 1))])
    deficit = np.append(gaussian_curvature(s.V, s.F, integrated=True), 0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        k1, k2 = discrete_principal_curvatures(V, s.F, M, C, deficit)
    assert np.isnan(k1[-1]) and np.isnan(k2[-1]) and np.isfinite(k1[:-1]).all()


def test_discrete_principal_curvatures_refuse_bad_input():
    s = surfaces.sphere(1.0, subdivisions=1)
    M, C = laplacian(s.V, s.F)
    deficit = gaussian_curvature(s.V, s.F, integrated=True)
    with pytest.raises(MeshError, match=r"M has shape \(41, 41\), expected \(42, 42\)"):
        discrete_principal_curvatures(s.V, s.F, M.tocsr()[:41, :41], C, deficit)
    with pytest.raises(MeshError, match=r"C has shape None"):
        discrete_principal_curvatures(s.V, s.F, M, "C", deficit)
    with pytest.raises(MeshError, match=r"deficit has shape \(41,\), expected \(42,\)"):
        discrete_principal_curvatures(s.V, s.F, M, C, deficit[:41])
    with pytest.raises(MeshError, match=r"negative vertex areas at vertices 0"):
        discrete_principal_curvatures(s.V, s.F, -M, C, deficit)
    with pytest.raises(MeshError):
        discrete_principal_curvatures(s.V[:, :2], s.F, M, C, deficit)


# ---------------------------------------------------------------- Gauss-Bonnet

CLOSED = {
    "sphere": lambda: surfaces.sphere(1.0, 3, jitter=0.3, seed=1),
    "ellipsoid": lambda: surfaces.ellipsoid(1.0, 0.6, 0.3, 3, jitter=0.3, seed=2),
    "torus": lambda: surfaces.torus(1.0, 0.3, n=40, jitter=0.3, seed=3),
}
OPEN = {
    "plane": lambda: surfaces.plane(n=10, jitter=0.3, seed=1),
    "saddle": lambda: surfaces.saddle(n=20, jitter=0.3, seed=5),
}


@pytest.mark.parametrize("name", sorted(CLOSED))
def test_gauss_bonnet_closed(name):
    s = CLOSED[name]()
    chi = euler_characteristic(s.V, s.F)
    assert chi == (0 if name == "torus" else 2)
    total = gaussian_curvature(s.V, s.F, integrated=True).sum()
    assert abs(total - 2 * np.pi * chi) < 1e-9
    for area in ("barycentric", "mixed"):
        K = gaussian_curvature(s.V, s.F, area=area)
        from geomlib import vertex_areas

        assert abs((K * vertex_areas(s.V, s.F, area)).sum() - 2 * np.pi * chi) < 1e-9


@pytest.mark.parametrize("name", sorted(OPEN))
def test_gauss_bonnet_open_with_turning_angle(name):
    s = OPEN[name]()
    chi = euler_characteristic(s.V, s.F)
    assert chi == 1
    total = gaussian_curvature(s.V, s.F, boundary="turning", integrated=True).sum()
    assert abs(total - 2 * np.pi * chi) < 1e-9
    # the square's boundary turns by pi/2 at each corner and not at all along its sides
    if name == "plane":
        turning = gaussian_curvature(s.V, s.F, boundary="turning", integrated=True)
        assert np.sort(turning)[-4:] == pytest.approx([np.pi / 2] * 4, abs=1e-12)
        assert np.abs(np.sort(turning)[:-4]).max() < 1e-12


def test_boundary_rules():
    s = surfaces.plane(n=6)
    b = boundary_mask(s.V, s.F)
    assert b.sum() == 24
    K = {rule: gaussian_curvature(s.V, s.F, boundary=rule) for rule in BOUNDARY_RULES}
    for rule in BOUNDARY_RULES:
        np.testing.assert_allclose(K[rule][~b], 0.0, atol=1e-12)
    assert np.isnan(K["nan"][b]).all()
    assert (K["zero"][b] == 0).all()
    # a straight stretch of boundary does not turn; the naive deficit is pi there
    deficit = gaussian_curvature(s.V, s.F, boundary="deficit", integrated=True)
    turning = gaussian_curvature(s.V, s.F, boundary="turning", integrated=True)
    np.testing.assert_allclose(deficit[b] - turning[b], np.pi, atol=1e-12)
    H = mean_curvature(s.V, s.F, boundary="nan")
    assert np.isnan(H[b]).all() and np.abs(H[~b]).max() < 1e-12
    assert (mean_curvature(s.V, s.F, boundary="zero")[b] == 0).all()
    # the formula at boundary vertices is large on a flat plane: not a curvature
    assert mean_curvature(s.V, s.F)[b].min() > 1.0
    with pytest.raises(MeshError, match="boundary"):
        gaussian_curvature(s.V, s.F, boundary="mask")
    with pytest.raises(MeshError, match="boundary"):
        mean_curvature(s.V, s.F, boundary="turning")


# ---------------------------------------------------------------- laws


@pytest.mark.parametrize("s", [0.02, 7.0])
def test_scaling_laws(s):
    m = surfaces.ellipsoid(1.0, 0.7, 0.5, subdivisions=3, jitter=0.3, seed=1)
    for area in ("barycentric", "mixed"):
        H1 = mean_curvature(m.V, m.F, area=area, signed=True)
        K1 = gaussian_curvature(m.V, m.F, area=area)
        np.testing.assert_allclose(mean_curvature(s * m.V, m.F, area=area, signed=True), H1 / s, rtol=1e-10)
        np.testing.assert_allclose(gaussian_curvature(s * m.V, m.F, area=area), K1 / s**2, rtol=1e-10)
    # the uniform "curvature" has units of length: it scales with s, not 1/s
    Hu = mean_curvature(m.V, m.F, weights="uniform")
    np.testing.assert_allclose(mean_curvature(s * m.V, m.F, weights="uniform"), s * Hu, rtol=1e-10)


@pytest.mark.parametrize("seed", [0, 1])
def test_rigid_motion_invariance(seed):
    m = surfaces.saddle(n=16, jitter=0.3, seed=seed)
    W = m.V @ random_rotation(seed).T + np.array([1.0, -2.0, 3.0])
    for kwargs in ({}, {"signed": True}, {"weights": "uniform"}, {"area": "mixed", "signed": True}):
        a = mean_curvature(m.V, m.F, **kwargs)
        b = mean_curvature(W, m.F, **kwargs)
        np.testing.assert_allclose(b, a, rtol=1e-9, atol=1e-12)
    for rule in BOUNDARY_RULES:
        np.testing.assert_allclose(
            gaussian_curvature(W, m.F, boundary=rule), gaussian_curvature(m.V, m.F, boundary=rule), rtol=1e-9, atol=1e-9
        )


def test_angle_sums_add_to_pi_per_triangle():
    m = surfaces.torus(1.0, 0.3, n=20, jitter=0.3, seed=0)
    assert angle_sums(m.V, m.F).sum() == pytest.approx(np.pi * len(m.F), rel=1e-14)


@pytest.mark.parametrize("area", ["barycentric", "mixed"])
def test_one_pass_over_blocks_equals_the_separate_formulas(monkeypatch, area):
    """Angles and areas measured together, 7 faces per block, are the per-face formulas summed at the vertices."""
    import geomlib.lessons.laplace as laplace
    from geomlib.lessons.curvature import angle_and_area_sums, corner_angles
    from geomlib.mesh.geometry import face_blocks

    m = surfaces.torus(1.0, 0.3, n=20, jitter=0.3, seed=1)
    V, F = m.V, m.F
    theta = corner_angles(V, F)
    expected = np.zeros(len(V))
    np.add.at(expected, F, theta)
    A = laplace.vertex_areas(V, F, area)
    monkeypatch.setattr(laplace, "face_blocks", lambda F: face_blocks(F, 7))
    theta_sum, A_blocks = angle_and_area_sums(V, F, area)
    assert len(F) > 10 * 7 and len(F) % 7  # many blocks, and a last one that is shorter
    np.testing.assert_allclose(theta_sum, expected, rtol=1e-14)
    np.testing.assert_allclose(A_blocks, A, rtol=1e-13)
    assert angle_and_area_sums(V, F)[1] is None
    np.testing.assert_allclose(gaussian_curvature(V, F, area), (2 * np.pi - expected) / A, rtol=1e-10, atol=1e-12)


def test_zero_area_face_in_a_later_block_is_named_by_its_index(monkeypatch):
    import geomlib.lessons.laplace as laplace
    from geomlib.mesh.geometry import face_blocks

    m = surfaces.sphere(1.0, 1)
    a, b, c = m.F[0]
    V = np.vstack([m.V, 0.5 * (m.V[a] + m.V[b])])
    w = len(V) - 1
    F = np.vstack([m.F[1:], [[a, w, c], [w, b, c], [b, w, a]]])  # the sliver (b, w, a) is the last face
    monkeypatch.setattr(laplace, "face_blocks", lambda F: face_blocks(F, 5))
    with pytest.warns(MeshWarning, match=f"zero-area triangle.*faces {len(F) - 1}$"):
        K = gaussian_curvature(V, F)
    assert np.isfinite(K).all()


def test_a_vertex_seen_only_at_zero_angles_is_not_unreferenced():
    # vertex 1 is in the zero-area triangle (0, 1, 3) only, at a corner of angle 0: its angle sum is 0,
    # but it is in a triangle, so the deficit is 2 pi there (not NaN); vertex 4 is in no triangle
    from geomlib.lessons.curvature import angle_deficit

    V = np.array([[0.0, 0, 0], [8, 0, 0], [0, 3, 0], [4, 0, 0], [9, 9, 9]])
    F = np.array([[0, 3, 2], [0, 1, 3]])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        deficit = angle_deficit(V, F)
    unreferenced = [str(x.message) for x in caught if "in no triangle;" in str(x.message)]
    assert len(unreferenced) == 1 and unreferenced[0].endswith("vertices 4")
    assert deficit[1] == 2 * np.pi and np.isnan(deficit[4]) and np.isfinite(deficit[:4]).all()


# ---------------------------------------------------------------- bad input


def test_isolated_vertex_gives_nan_with_a_warning():
    m = surfaces.sphere(1.0, 2)
    V = np.vstack([m.V, [[5.0, 5.0, 5.0]]])
    with pytest.warns(MeshWarning, match=f"vertices {len(m.V)}"):
        H = mean_curvature(V, m.F)
    assert np.isnan(H[-1]) and np.isfinite(H[:-1]).all()
    with pytest.warns(MeshWarning, match=f"vertices {len(m.V)}"):
        K = gaussian_curvature(V, m.F)
    assert np.isnan(K[-1]) and np.isfinite(K[:-1]).all()


def test_zero_area_faces_keep_gauss_bonnet_and_stay_finite():
    # split face (a, b, c) of a closed sphere at the midpoint w of (a, b) and
    # close the mesh with the zero-area sliver (b, w, a)
    m = surfaces.sphere(1.0, 1)
    a, b, c = m.F[0]
    V = np.vstack([m.V, 0.5 * (m.V[a] + m.V[b])])
    w = len(V) - 1
    F = np.vstack([m.F[1:], [[a, w, c], [w, b, c], [b, w, a]]])
    assert euler_characteristic(V, F) == 2
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        K = gaussian_curvature(V, F, integrated=True)
        Kp = gaussian_curvature(V, F)
        H = mean_curvature(V, F)
    assert any("zero-area" in str(x.message) and f"faces {len(F) - 1}" in str(x.message) for x in caught)
    assert np.isfinite(K).all() and np.isfinite(Kp).all() and np.isfinite(H).all()
    assert abs(K.sum() - 4 * np.pi) < 1e-9
    # the sliver counts as flat: w sees angles pi (sliver) + the two halves of face 0
    assert K[w] == pytest.approx(0.0, abs=1e-12)


def test_non_manifold_vertex_keeps_the_total():
    # two octahedra sharing one vertex (a pinch): chi = 2 + 2 - 1 = 3
    o = surfaces.sphere(1.0, 0)
    V1, F1 = o.V, o.F
    top = int(np.argmax(V1[:, 2]))
    V2 = V1 * [1, 1, -1] + [0, 0, 2 * V1[top, 2]]  # mirror image through the plane z = z_top
    F2 = F1[:, ::-1] + len(V1)
    V = np.vstack([V1, V2])
    F = np.vstack([F1, F2])
    top2 = top + len(V1)
    np.testing.assert_allclose(V[top2], V[top])
    F[F == top2] = top
    assert euler_characteristic(V, F) == 3
    with pytest.warns(MeshWarning, match=f"vertices {top2}"):
        K = gaussian_curvature(V, F, integrated=True)
    assert np.isnan(K[top2])
    assert abs(np.nansum(K) - 2 * np.pi * 3) < 1e-9
    # an icosahedron vertex has a deficit of 2 pi - 5 pi / 3 = pi / 3; the pinch
    # carries both cones' deficits minus 2 pi
    assert K[top] == pytest.approx(2 * (np.pi / 3) - 2 * np.pi, abs=1e-12)


def test_bow_tie_boundary_vertex_and_non_manifold_edge():
    # two triangles touching at one vertex (a bow-tie): every vertex is on the boundary
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]])
    F = np.array([[0, 1, 2], [0, 3, 4]])
    with pytest.warns(MeshWarning, match="every vertex"):
        K = gaussian_curvature(V, F)
    assert np.isnan(K).all()
    with pytest.warns(MeshWarning, match="every vertex"):
        assert np.isnan(mean_curvature(V, F, boundary="nan")).all()
    assert np.isfinite(mean_curvature(V, F)).all()
    with pytest.warns(MeshWarning, match="every vertex"):
        turning = gaussian_curvature(V, F, boundary="turning", integrated=True)
    # chi = 5 - 6 + 2 = 1; vertex 0 has four boundary edges: 2 pi - 2 pi - pi/2 - pi/2
    assert turning[0] == pytest.approx(-np.pi, abs=1e-12)
    assert turning.sum() == pytest.approx(2 * np.pi * 1, abs=1e-12)
    # three triangles on one edge
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, -1, 0], [0.5, 0, 1]])
    F = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        gaussian_curvature(V, F)
    messages = " ".join(str(x.message) for x in caught)
    assert "1 edge(s) belong to three or more triangles" in messages and "(0, 1)" in messages


def test_bad_arguments_raise():
    m = surfaces.sphere(1.0, 1)
    with pytest.raises(MeshError, match="area"):
        gaussian_curvature(m.V, m.F, area="voronoi")
    with pytest.raises(MeshError, match="weights"):
        mean_curvature(m.V, m.F, weights="cot")
    with pytest.raises(MeshError):
        mean_curvature(m.V[:, :2], m.F)


# ---------------------------------------------------------------- libigl

igl = pytest.importorskip("igl")


def _against_libigl(V, F):
    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    ours = gaussian_curvature(V, F, boundary="deficit", integrated=True)
    ref = igl.gaussian_curvature(V, F)
    used = np.bincount(F.ravel(), minlength=len(V)) > 0
    np.testing.assert_allclose(ours[used], ref[used], atol=1e-11)


@pytest.mark.parametrize("name", sorted(CLOSED) + sorted(OPEN))
def test_libigl_gaussian_curvature_generated(name):
    s = {**CLOSED, **OPEN}[name]()
    _against_libigl(s.V, s.F)


@pytest.mark.parametrize("name", sorted(p.name for p in SHIPPED.glob("*.obj")))
def test_libigl_gaussian_curvature_shipped(name):
    _against_libigl(*load_quietly(SHIPPED / name))


@needs_course
@pytest.mark.parametrize("name", COURSE_MESHES)
def test_libigl_gaussian_curvature_course(name):
    V, F = load_quietly(COURSE / name)
    _against_libigl(V, F)
    # Gauss-Bonnet with the turning angle on every course mesh, open or closed
    total = gaussian_curvature(V, F, boundary="turning", integrated=True)
    assert abs(np.nansum(total) - 2 * np.pi * euler_characteristic(V, F)) < 1e-9


def test_boundary_detection_ignores_orientation_flips():
    # flipping faces unbalances the boundary probes at their vertices; the exact
    # check that follows must still find no boundary on a closed mesh
    m = surfaces.ellipsoid(1.0, 0.7, 0.5, 3, jitter=0.3, seed=4)
    F = m.F.copy()
    F[::7] = F[::7, ::-1]
    assert not boundary_mask(m.V, F).any()
    np.testing.assert_allclose(gaussian_curvature(m.V, F), gaussian_curvature(m.V, m.F), rtol=1e-12)
    # and an open mesh keeps exactly its boundary
    s = surfaces.saddle(n=9)
    Fs = s.F.copy()
    Fs[1::3] = Fs[1::3, ::-1]
    np.testing.assert_array_equal(boundary_mask(s.V, Fs), boundary_mask(s.V, s.F))
    assert boundary_mask(s.V, s.F).sum() == 4 * 9


# ---------------------------------------------------------------- the teaching functions one by one


def test_corner_angles_and_angle_deficit_against_libigl():
    from geomlib.lessons.curvature import angle_deficit, corner_angles

    V, F = surfaces.ellipsoid(1.0, 0.7, 0.5, 3).V, surfaces.ellipsoid(1.0, 0.7, 0.5, 3).F
    np.testing.assert_allclose(corner_angles(V, F), igl.internal_angles(V, F), atol=1e-13)
    np.testing.assert_allclose(angle_deficit(V, F), igl.gaussian_curvature(V, F), atol=1e-12)


def test_corner_angles_of_a_3_4_5_triangle_and_a_collinear_one():
    from geomlib.lessons.curvature import corner_angles

    V = np.array([[0.0, 0, 0], [4, 0, 0], [0, 3, 0], [8, 0, 0]])
    theta = corner_angles(V, [[0, 1, 2]])
    np.testing.assert_allclose(theta, [[np.pi / 2, np.arctan2(3, 4), np.arctan2(4, 3)]], atol=1e-15)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshWarning)
        flat = corner_angles(V, [[0, 1, 3]])  # zero area: pi opposite the longest edge (0, 3)
    assert flat.tolist() == [[0.0, np.pi, 0.0]]


def test_principal_curvatures_of_a_cylinder_point():
    # cylinder of radius 2: H = 1/4, K = 0, so kappa_1 = 1/2 and kappa_2 = 0
    k1, k2 = principal_curvatures(np.array([0.25]), np.array([0.0]))
    assert k1.tolist() == [0.5] and k2.tolist() == [0.0]


def test_zero_below_rounding_zeroes_rounding_noise_of_a_flat_grid_and_keeps_curvature():
    from geomlib.mesh.geometry import mean_edge_length, zero_below_rounding

    flat = surfaces.plane(n=9, size=0.3, jitter=0.3, seed=1)
    ell = mean_edge_length(flat.V, flat.F)
    K = gaussian_curvature(flat.V, flat.F)
    H = mean_curvature(flat.V, flat.F, weights="uniform", signed=True, boundary="nan")
    K0, H0 = zero_below_rounding(K, 1 / ell**2), zero_below_rounding(H, ell)
    inside = np.isfinite(K)
    assert inside.any() and np.isnan(K0[~inside]).all()  # NaN is kept
    assert (K0[inside] == 0).all() and not np.signbit(K0[inside]).any()  # +0.0: no "K < 0", no "-0"
    assert (H0[np.isfinite(H0)] == 0).all() and not np.signbit(H0[np.isfinite(H0)]).any()
    ball = surfaces.sphere(1e-3, subdivisions=2)  # tiny but curved: nothing is rounding
    Kb = gaussian_curvature(ball.V, ball.F)
    assert np.array_equal(zero_below_rounding(Kb, 1 / mean_edge_length(ball.V, ball.F) ** 2), Kb)
    assert zero_below_rounding([-5e-10, 2e-9], 1.0).tolist() == [0.0, 2e-9]
