"""Laws of explicit and implicit Laplacian smoothing (geomlib.lessons.smoothing)."""

import warnings

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as sla
import trimesh
from meshdata import COURSE

from geomlib import MeshError, MeshWarning, explicit_smoothing, explicit_step_limit, implicit_smoothing, laplacian
from geomlib.lessons.filters import mode_factor
from geomlib.lessons.smoothing import (
    ExplicitSmoother,
    ImplicitSmoother,
    explicit_step,
    fixed_point,
    highest_frequency_mode,
    implicit_step,
    taubin_smoothing,
    volume_rescaled,
)
from geomlib.mesh.geometry import volume_and_centroid
from geomlib.mesh.topology import boundary_vertices


def _boundary_mask(F, n):
    mask = np.zeros(n, dtype=bool)
    mask[boundary_vertices(F, n)] = True
    return mask


def icosphere(subdivisions=2, radius=1.0, centre=(0.0, 0.0, 0.0)):
    m = trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius)
    return np.asarray(m.vertices, float) + np.asarray(centre), np.asarray(m.faces, np.int64)


def grid(n=12, jitter=0.0, seed=0):
    """Regular triangulated grid of [0, 1]^2 in the plane z = 0, interior vertices jittered in-plane."""
    x, y = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n), indexing="ij")
    V = np.column_stack([x.ravel(), y.ravel(), np.zeros(n * n)])
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    F = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    if jitter:
        rng = np.random.default_rng(seed)
        inner = ~_boundary_mask(F, len(V))
        V[inner, :2] += jitter / n * rng.uniform(-1, 1, (inner.sum(), 2))
    return V, F


def tilt(V):
    """Put the grid on the plane z = 0.3 x - 0.5 y + 2 (a rigid-free affine map)."""
    W = V.copy()
    W[:, 2] = 0.3 * V[:, 0] - 0.5 * V[:, 1] + 2.0
    return W


def plane_distance(V):
    return np.abs(V[:, 2] - (0.3 * V[:, 0] - 0.5 * V[:, 1] + 2.0)).max()


# ---------------------------------------------------------------------------
# a plane stays planar


@pytest.mark.parametrize("weights", ["cotan", "uniform"])
@pytest.mark.parametrize("boundary", ["fixed", "free"])
def test_plane_stays_planar(weights, boundary):
    V, F = grid(12, jitter=0.6)
    V = tilt(V)
    limit = explicit_step_limit(V, F, weights, boundary_condition=boundary)
    P = explicit_smoothing(V, F, 0.9 * limit, 20, weights, boundary_condition=boundary)
    assert plane_distance(P) < 1e-12
    assert np.abs(P - V).max() > 1e-3  # it did move (in the plane)
    Q = implicit_smoothing(V, F, 50 * limit, 5, weights, boundary_condition=boundary)
    assert plane_distance(Q) < 1e-12


# ---------------------------------------------------------------------------
# the fixed point P*


def test_fixed_point_of_a_flat_mesh_is_itself_with_cotan_weights():
    """Linear precision: on a flat (tilted, irregular) grid every coordinate is cotan-harmonic."""
    V, F = grid(12, jitter=0.3)  # no triangle folds over
    V = tilt(V)
    assert np.abs(fixed_point(V, F) - V).max() < 1e-12


def test_fixed_point_of_a_bumpy_open_mesh_is_its_membrane():
    V, F = grid(12)
    inner = ~_boundary_mask(F, len(V))
    W = V.copy()
    W[inner, 2] = np.random.default_rng(3).normal(0, 0.05, inner.sum())  # bumps inside, flat boundary
    P = fixed_point(W, F)
    assert np.abs(P[~inner] - W[~inner]).max() == 0  # the boundary stays
    assert np.abs(P[:, 2]).max() < 1e-12  # zero boundary heights: a flat membrane
    M, C = laplacian(W, F)
    assert np.abs((C @ P)[inner]).max() < 1e-12  # harmonic inside, with W's own weights


def test_fixed_point_of_a_closed_mesh_is_the_area_weighted_centroid():
    V, F = icosphere(2, radius=2.0, centre=(1.0, -2.0, 0.5))
    V = V * [1.0, 0.7, 0.4]
    m = laplacian(V, F)[0].diagonal()
    P = fixed_point(V, F)
    assert P.shape == V.shape and np.ptp(P, axis=0).max() == 0
    assert np.allclose(P[0], m @ V / m.sum(), rtol=0, atol=1e-14)
    # explicit smoothing converges to it
    Q = explicit_smoothing(V, F, 0.9 * explicit_step_limit(V, F), 3000)
    assert np.abs(Q - P).max() < 1e-6


def test_fixed_boundary_stays_and_free_boundary_moves():
    V, F = grid(10, jitter=0.5)
    b = _boundary_mask(F, len(V))
    P = implicit_smoothing(V, F, 0.01, 3, boundary_condition="fixed")
    assert np.array_equal(P[b], V[b])
    Q = implicit_smoothing(V, F, 0.01, 3, boundary_condition="free")
    assert np.abs(Q[b] - V[b]).max() > 1e-4


# ---------------------------------------------------------------------------
# a sphere stays a sphere, centred where it was


@pytest.mark.parametrize("keep_volume", [False, True])
def test_sphere_stays_sphere_centred(keep_volume):
    centre = np.array([1.0, -2.0, 0.5])
    V, F = icosphere(3, radius=2.0, centre=centre)
    vol0, c0 = volume_and_centroid(V, F)
    P = implicit_smoothing(V, F, 0.05, 5, keep_volume=keep_volume)
    r = np.linalg.norm(P - centre, axis=1)
    assert r.std() / r.mean() < 1e-3  # still a sphere (the icosphere's own unevenness)
    _, c = volume_and_centroid(P, F)
    assert np.abs(c - centre).max() < 1e-12
    vol, _ = volume_and_centroid(P, F)
    if keep_volume:
        assert abs(vol / vol0 - 1) < 1e-12
        assert np.abs(c - c0).max() < 1e-12
        assert abs(r.mean() / 2.0 - 1) < 1e-3
    else:
        assert vol < 0.8 * vol0  # heat flow shrinks the sphere


def test_keep_volume_explicit_smoother_api():
    V, F = icosphere(2)
    vol0, _ = volume_and_centroid(V, F)
    P = ImplicitSmoother(V, F).smooth(0.2, 4, keep_volume=True)
    assert abs(volume_and_centroid(P, F)[0] / vol0 - 1) < 1e-12


def test_keep_volume_on_open_mesh_is_an_error():
    V, F = grid(6)
    with pytest.raises(MeshError, match="closed mesh"):
        implicit_smoothing(V, F, 0.01, 1, keep_volume=True)


# ---------------------------------------------------------------------------
# explicit uniform step 1 = neighbour averaging


@pytest.mark.parametrize("mesh", ["sphere", "grid"])
def test_uniform_step_one_is_neighbour_average(mesh):
    V, F = icosphere(2) if mesh == "sphere" else grid(8, jitter=0.5)
    if mesh == "sphere":
        V = V + 0.02 * np.random.default_rng(1).standard_normal(V.shape)
    P = explicit_smoothing(V, F, 1.0, 1, "uniform", boundary_condition="free")
    E = np.unique(np.sort(F[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1), axis=0)
    total = np.zeros_like(V)
    np.add.at(total, E[:, 0], V[E[:, 1]])
    np.add.at(total, E[:, 1], V[E[:, 0]])
    count = np.bincount(E.ravel(), minlength=len(V))[:, None]
    np.testing.assert_allclose(P, total / count, rtol=0, atol=1e-14)


def test_uniform_limit_is_at_least_one():
    for V, F in (icosphere(1), icosphere(3), grid(9, jitter=0.3)):
        assert explicit_step_limit(V, F, "uniform") >= 1.0


# ---------------------------------------------------------------------------
# implicit with step -> 0 changes nothing; explicit limit laws


@pytest.mark.parametrize("weights", ["cotan", "uniform"])
def test_implicit_tiny_step_changes_nothing(weights):
    V, F = icosphere(2)
    V = V + 0.05 * np.random.default_rng(2).standard_normal(V.shape)
    assert np.array_equal(implicit_smoothing(V, F, 0.0, 3, weights), V)
    d = np.abs(implicit_smoothing(V, F, 1e-12, 3, weights) - V).max()
    assert d < 1e-9
    # and the change is linear in the step for small steps
    d2 = np.abs(implicit_smoothing(V, F, 2e-12, 3, weights) - V).max()
    assert abs(d2 / d - 2) < 1e-3


@pytest.mark.parametrize("weights", ["cotan", "uniform"])
@pytest.mark.parametrize("subdivisions", [2, 4])  # dense (162) and Lanczos (2562) paths
def test_explicit_just_above_limit_grows_just_below_decays(weights, subdivisions):
    V, F = icosphere(subdivisions)
    V = V + 0.01 * np.random.default_rng(8).standard_normal(V.shape)  # no symmetric clusters
    lam, e = highest_frequency_mode(V, F, weights)
    limit = explicit_step_limit(V, F, weights)
    assert abs(limit * lam / 2 - 1) < 1e-7
    M, C = laplacian(V, F, weights)
    m = M.diagonal()
    np.testing.assert_allclose(C @ e, -lam * m * e, atol=1e-6 * lam * np.abs(m * e).max())
    # the operator is built from the input positions, so follow the top-mode component
    # of the input itself (a perturbation would change a cotan operator)
    c0 = np.abs(e @ (m[:, None] * V)).max()
    j = int(np.argmax(np.abs(e @ (m[:, None] * V))))
    assert c0 > 1e-6

    def amplitude_history(fraction):
        amps = []
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshWarning)
            explicit_smoothing(
                V, F, fraction * limit, 60, weights, callback=lambda k, P: amps.append(e @ (m * P[:, j]))
            )
        return np.abs(np.array(amps))

    above, below = amplitude_history(1.02), amplitude_history(0.98)
    assert above[-1] > 5 * c0 and below[-1] < 0.2 * c0
    np.testing.assert_allclose(above[1:] / above[:-1], 1.04, rtol=1e-4)
    np.testing.assert_allclose(below[1:] / below[:-1], 0.96, rtol=1e-4)


def test_top_mode_rate_exact():
    V, F = icosphere(2)
    V = V + 0.01 * np.random.default_rng(9).standard_normal(V.shape)
    lam, e = highest_frequency_mode(V, F)
    limit = explicit_step_limit(V, F)
    m = laplacian(V, F)[0].diagonal()
    amps = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshWarning)
        explicit_smoothing(V, F, 1.01 * limit, 10, callback=lambda k, P: amps.append(e @ (m[:, None] * P)))
    start = e @ (m[:, None] * V)
    ratio = np.array(amps) / np.vstack([start, amps[:-1]])
    np.testing.assert_allclose(ratio, 1 - 1.01 * limit * lam, rtol=1e-9)


def test_step_limit_scaling_law():
    V, F = icosphere(3)
    for s in (1e-3, 1.0, 250.0):
        assert explicit_step_limit(s * V, F, "cotan") == pytest.approx(s**2 * explicit_step_limit(V, F), rel=1e-8)
        assert explicit_step_limit(s * V, F, "uniform") == pytest.approx(
            explicit_step_limit(V, F, "uniform"), rel=1e-12
        )


def test_step_limit_fixed_boundary_at_least_free():
    V, F = grid(10, jitter=0.5)
    for w in ("cotan", "uniform"):
        assert explicit_step_limit(V, F, w, boundary_condition="fixed") >= explicit_step_limit(
            V, F, w, boundary_condition="free"
        )


def test_step_fraction_equals_step():
    V, F = icosphere(2)
    V = V + 0.02 * np.random.default_rng(3).standard_normal(V.shape)
    limit = explicit_step_limit(V, F)
    np.testing.assert_array_equal(
        explicit_smoothing(V, F, step_fraction=0.5, iterations=4), explicit_smoothing(V, F, 0.5 * limit, 4)
    )


def test_lanczos_limit_agrees_with_eigsh():
    V, F = icosphere(4)
    V = V * np.array([1.0, 2.0, 3.0])  # an ellipsoid: no symmetric clusters
    for w in ("cotan", "uniform"):
        M, C = laplacian(V, F, w)
        lam = sla.eigsh(
            -C,
            k=1,
            M=M.tocsc(),
            which="LA",
            tol=1e-12,
            v0=np.random.default_rng(0).standard_normal(len(V)),
            return_eigenvectors=False,
        )[0]
        assert explicit_step_limit(V, F, w) == pytest.approx(2 / lam, rel=1e-6)


# ---------------------------------------------------------------------------
# implicit equals a direct sparse solve


@pytest.mark.parametrize("weights", ["cotan", "uniform"])
def test_implicit_equals_direct_solve_closed(weights):
    V, F = icosphere(3)
    V = V + 0.02 * np.random.default_rng(4).standard_normal(V.shape)
    step = 0.01 if weights == "cotan" else 3.0
    M, C = laplacian(V, F, weights)
    A = (M - step * C).tocsc()
    P = V.copy()
    for _ in range(3):
        P = sla.spsolve(A, M @ P)
    np.testing.assert_allclose(implicit_smoothing(V, F, step, 3, weights), P, rtol=0, atol=1e-10)
    np.testing.assert_allclose(implicit_smoothing(V, F, step, 3, weights, solver="cg"), P, rtol=0, atol=1e-8)


def test_implicit_equals_direct_solve_fixed_boundary():
    V, F = grid(12, jitter=0.6)
    V[:, 2] = 0.05 * np.random.default_rng(5).standard_normal(len(V))
    b = _boundary_mask(F, len(V))
    step = 0.002
    M, C = laplacian(V, F)
    # the full system with identity rows at the boundary (not symmetric, solved directly)
    A = (M - step * C).tolil()
    rhs = M @ V
    for i in np.flatnonzero(b):
        A.rows[i], A.data[i] = [i], [1.0]
    rhs[b] = V[b]
    P = sla.spsolve(A.tocsc(), rhs)
    np.testing.assert_allclose(implicit_smoothing(V, F, step, 1), P, rtol=0, atol=1e-10)


def test_implicit_huge_step_stays_bounded():
    V, F = icosphere(3)
    V = V + 0.02 * np.random.default_rng(6).standard_normal(V.shape)
    limit = explicit_step_limit(V, F)
    P = implicit_smoothing(V, F, 1e4 * limit, 3)
    assert np.isfinite(P).all()
    assert np.abs(P).max() <= np.abs(V).max()


def test_smoother_cache_reuses_factorisation():
    V, F = icosphere(2)
    S = ImplicitSmoother(V, F)
    assert S.factor(0.1) is S.factor(0.1)
    np.testing.assert_allclose(S.smooth(0.1, 2), implicit_smoothing(V, F, 0.1, 2), atol=1e-14)


# ---------------------------------------------------------------------------
# rebuilt operator (curvature flow) and divergence: stated stops, never NaN


def test_rebuilt_operator_collapse_is_a_clear_error():
    V, F = icosphere(2)
    with pytest.raises(MeshError, match="implicit smoothing stopped") as info:
        implicit_smoothing(V, F, 1.0, 20, rebuild=True)
    assert np.isfinite(info.value.V).all()
    with pytest.warns(MeshWarning, match="stopped and returned"):
        P = implicit_smoothing(V, F, 1.0, 20, rebuild=True, on_failure="stop")
    assert np.isfinite(P).all()


def test_rebuilt_operator_small_step_is_curvature_flow():
    # sphere under mean curvature flow: r(t)^2 = r0^2 - 4 t; implicit Euler lags a little
    V, F = icosphere(3)
    P = implicit_smoothing(V, F, 0.005, 10, rebuild=True)
    r = np.linalg.norm(P, axis=1)
    assert r.std() / r.mean() < 1e-3
    assert abs(r.mean() - np.sqrt(1 - 4 * 0.05)) < 0.01


def test_explicit_divergence_stops_cleanly():
    V, F = icosphere(2)
    V = V + 1e-3 * np.random.default_rng(7).standard_normal(V.shape)
    limit = explicit_step_limit(V, F)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshWarning)
        with pytest.raises(MeshError, match="diverged"):
            explicit_smoothing(V, F, 3 * limit, 500)
    with pytest.warns(MeshWarning) as record:
        P = explicit_smoothing(V, F, 3 * limit, 500, on_failure="stop")
    assert np.isfinite(P).all()
    assert any("diverged" in str(w.message) for w in record)


# ---------------------------------------------------------------------------
# bad input


@pytest.mark.parametrize("step", [-0.1, float("nan"), float("inf"), "0.1", None, True])
def test_bad_step(step):
    V, F = icosphere(1)
    with pytest.raises(MeshError, match="tau"):
        implicit_smoothing(V, F, step, 1)
    with pytest.raises(MeshError, match="tau"):
        explicit_smoothing(V, F, step, 1) if step is not None else explicit_smoothing(V, F, None, 1)


@pytest.mark.parametrize("iterations", [-1, 1.5, "3", True])
def test_bad_iterations(iterations):
    V, F = icosphere(1)
    with pytest.raises(MeshError, match="iterations"):
        implicit_smoothing(V, F, 0.1, iterations)
    with pytest.raises(MeshError, match="iterations"):
        explicit_smoothing(V, F, 0.001, iterations)


def test_bad_options():
    V, F = icosphere(1)
    with pytest.raises(MeshError, match="weights"):
        implicit_smoothing(V, F, 0.1, 1, weights="mean")
    with pytest.raises(MeshError, match="boundary"):
        explicit_smoothing(V, F, 0.001, 1, boundary_condition="clamped")
    with pytest.raises(MeshError, match="exactly one"):
        explicit_smoothing(V, F, 0.001, 1, step_fraction=0.5)
    with pytest.raises(MeshError, match="step_fraction"):
        explicit_smoothing(V, F, step_fraction=-0.5)


def test_step_past_limit_warns_once_naming_the_limit():
    V, F = icosphere(2)
    limit = explicit_step_limit(V, F)
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        P = explicit_smoothing(V, F, 1.05 * limit, 30)
    msgs = [str(w.message) for w in record if issubclass(w.category, MeshWarning)]
    assert len(msgs) == 1
    assert f"{limit:.6g}" in msgs[0]
    assert np.isfinite(P).all()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        explicit_smoothing(V, F, 0.999 * limit, 3)  # no warning below the limit


def distorted_plane():
    """A 7 x 7 grid with every vertex (boundary too) moved in-plane: 24 negative cotangent weights."""
    V, F = grid(7)
    V[:, :2] += 0.35 / 6 * np.random.default_rng(183).uniform(-1, 1, (49, 2))
    return V, F


def test_a_step_past_the_limit_warns_where_negative_weights_beat_the_short_bound():
    # Gershgorin's short form max 2|C_ii|/M_ii bounds lam_max only when no weight is negative;
    # here it lies below lam_max, so a step between the two limits must still be caught at once
    V, F = distorted_plane()
    M, C = laplacian(V, F)
    m, c = M.diagonal(), C.diagonal()
    assert int((C.data < 0).sum() - (c < 0).sum()) // 2 == 24
    lam_max = 2 / explicit_step_limit(V, F, boundary_condition="free")
    short, true = (2 * np.abs(c) / m).max(), (abs(C).sum(axis=1).A1 / m).max()
    assert short < lam_max / 1.1 and lam_max < true  # 3188 < 3538 < 4618
    tau = 1.008 * 2 / lam_max
    assert tau * short < 2  # the short bound alone would call this step safe
    seen = []
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        explicit_smoothing(V, F, tau, 200, boundary_condition="free", callback=lambda k, P: seen.append(len(record)))
    assert seen[0] == 1 and "exceeds the stability limit" in str(record[0].message)  # before iteration 1
    assert [issubclass(w.category, MeshWarning) for w in record] == [True]


def test_explicit_smoother_gives_explicit_smoothing_for_every_step_from_one_operator():
    V, F = grid(9, jitter=0.2)
    smoother = ExplicitSmoother(V, F)
    limit = explicit_step_limit(V, F)
    for step, iterations in ((0.3 * limit, 5), (0.9 * limit, 12), (0.0, 3), (0.5 * limit, 0)):
        np.testing.assert_array_equal(smoother.smooth(step, iterations), explicit_smoothing(V, F, step, iterations))
    np.testing.assert_array_equal(
        smoother.smooth(step_fraction=0.7, iterations=4), explicit_smoothing(V, F, step_fraction=0.7, iterations=4)
    )
    assert np.abs(smoother.smooth(0.9 * limit, 12) - V).max() > 0  # it moved, from V every time
    np.testing.assert_array_equal(
        smoother.smooth(0.9 * limit, 12)[_boundary_mask(F, len(V))], V[_boundary_mask(F, len(V))]
    )


def test_explicit_warnings_name_the_readers_line_through_either_door():
    V, F = icosphere(1)
    limit = explicit_step_limit(V, F)
    smoother = ExplicitSmoother(V, F)
    for run in (
        lambda: explicit_smoothing(V, F, 1.5 * limit, 3),
        lambda: smoother.smooth(1.5 * limit, 3),
        lambda: explicit_smoothing(V, F, 3 * limit, 500, on_failure="stop"),
        lambda: smoother.smooth(3 * limit, 500, on_failure="stop"),
    ):
        with warnings.catch_warnings(record=True) as record:
            warnings.simplefilter("always")
            run()
        assert record and {w.filename for w in record} == {__file__}, [(w.filename, str(w.message)) for w in record]


def test_progress_bar_options_do_not_change_results(capsys):
    V, F = icosphere(2)
    a = implicit_smoothing(V, F, 0.01, 3, progress=True)
    b = implicit_smoothing(V, F, 0.01, 3, progress=False)
    np.testing.assert_array_equal(a, b)
    c = explicit_smoothing(V, F, 1e-4, 3, progress=True)
    np.testing.assert_array_equal(c, explicit_smoothing(V, F, 1e-4, 3, progress=None))


# ---------------------------------------------------------------------------
# the course meshes (skipped when the course folder is absent)


@pytest.mark.skipif(not (COURSE / "smoothing" / "plane_ns.obj").exists(), reason="course meshes absent")
def test_course_noisy_plane():
    from geomlib import load_mesh

    V, F = load_mesh(COURSE / "smoothing" / "plane_ns.obj")
    limit = explicit_step_limit(V, F)
    assert 0 < limit < 1e-3  # bbox diagonal 0.27: a tiny length^2 step
    M, C = laplacian(V, F, "uniform")

    def roughness(P):  # mean length of the uniform Laplacian (umbrella) vector
        return np.linalg.norm((C @ P) / M.diagonal()[:, None], axis=1).mean()

    P = implicit_smoothing(V, F, 100 * limit, 5)
    Q = explicit_smoothing(V, F, step_fraction=0.9, iterations=50)
    assert roughness(P) < 0.5 * roughness(V)
    assert roughness(Q) < 0.5 * roughness(V)


def test_cholesky_factorisation_solves_exactly():
    V, F = icosphere(5)  # 10242 vertices
    V = V + 0.01 * np.random.default_rng(10).standard_normal(V.shape)
    M, C = laplacian(V, F)
    step = 0.001
    P = sla.spsolve((M - step * C).tocsc(), M @ V)
    np.testing.assert_allclose(implicit_smoothing(V, F, step, 1), P, rtol=0, atol=1e-10)


def test_the_formulas_are_one_step_of_the_smoothers():
    V, F = icosphere(2)
    V = V + 0.02 * np.random.default_rng(3).standard_normal(V.shape)
    M, C = laplacian(V, F)
    tau = 0.5 * explicit_step_limit(V, F)
    np.testing.assert_allclose(explicit_step(V, M, C, tau), V + tau * sp.diags(1 / M.diagonal()) @ (C @ V), atol=1e-14)
    np.testing.assert_allclose(explicit_step(V, M, C, tau), explicit_smoothing(V, F, tau, 1), atol=1e-13)
    P = implicit_step(V, M, C, 10 * tau)
    np.testing.assert_allclose((M - 10 * tau * C) @ P, M @ V, atol=1e-12)
    np.testing.assert_allclose(P, implicit_smoothing(V, F, 10 * tau, 1), atol=1e-12)


def _wrong_steps(monkeypatch):
    """Replace the shown steps by ones that also move every vertex by 1 along x: a wrong step to catch."""
    import geomlib.lessons.smoothing as smoothing

    right_explicit, right_implicit = smoothing.explicit_step, smoothing.implicit_step
    monkeypatch.setattr(smoothing, "explicit_step", lambda P, M, C, tau: right_explicit(P, M, C, tau) + [1.0, 0, 0])
    monkeypatch.setattr(
        smoothing, "implicit_step", lambda P, M, C, tau, solve=None: right_implicit(P, M, C, tau, solve) + [1.0, 0, 0]
    )


@pytest.mark.parametrize("boundary_condition", ["fixed", "free"])
def test_the_engines_advance_by_the_shown_steps(monkeypatch, boundary_condition):
    V, F = grid(8, jitter=0.4)
    V[:, 2] = 0.05 * np.random.default_rng(11).standard_normal(len(V))
    options = dict(boundary_condition=boundary_condition)
    tau = 0.5 * explicit_step_limit(V, F, **options)
    runs = {
        "explicit_smoothing": lambda: explicit_smoothing(V, F, tau, 3, **options),
        "ExplicitSmoother": lambda: ExplicitSmoother(V, F, **options).smooth(tau, 3),
        "implicit_smoothing": lambda: implicit_smoothing(V, F, 10 * tau, 3, **options),
        "implicit_smoothing cg": lambda: implicit_smoothing(V, F, 10 * tau, 3, solver="cg", **options),
        "implicit_smoothing rebuilt": lambda: implicit_smoothing(V, F, 10 * tau, 3, rebuild=True, **options),
        "ImplicitSmoother": lambda: ImplicitSmoother(V, F, **options).smooth(10 * tau, 3),
    }
    right = {name: run() for name, run in runs.items()}
    _wrong_steps(monkeypatch)
    for name, run in runs.items():
        np.testing.assert_allclose(run()[:, 0] - right[name][:, 0], 3.0, atol=1e-9, err_msg=name)


def test_the_sweep_advances_by_the_shown_steps(monkeypatch):
    from geomlib.teaching.experiments.sweep import smoothing_sweep

    V, F = icosphere(1)

    def sweep():
        return smoothing_sweep(
            V,
            F,
            [0.01, 0.02],
            seed=1,
            explicit_fractions=[0.5],
            implicit_steps=[0.3],
            iterations=[1, 2],
            progress=False,
        )

    right = sweep().values["rms"]
    _wrong_steps(monkeypatch)
    wrong = sweep().values["rms"]
    assert np.isfinite(right).all() and np.isfinite(wrong).all()
    assert (wrong > right + 0.1).all()  # every scheme moved by 1 per step, about 0.5 of the diagonal


def test_the_operator_is_built_once_per_mesh_and_options():
    from geomlib.lessons.operator import laplace_operator

    V, F = icosphere(2)
    L = laplace_operator(V, F)
    assert laplace_operator(V.copy(), F.copy()) is L
    assert ExplicitSmoother(V, F).L is L and ImplicitSmoother(V, F).L is L
    assert laplace_operator(V, F, "uniform") is not L
    assert laplace_operator(V + 1e-9, F) is not L  # the key is the mesh's bytes
    U = laplace_operator(V, F, "uniform")  # combinatorial: one for every position of the vertices
    assert laplace_operator(V + 0.1, F, "uniform") is U and laplace_operator(V[:-1], F[:5], "uniform") is not U


def test_not_positive_definite_is_a_clear_error():
    from geomlib.numerics.factor import factorise

    with pytest.raises(np.linalg.LinAlgError, match="not positive definite"):
        factorise(sp.csr_matrix(np.array([[1.0, 2.0], [2.0, 1.0]])))


def test_an_equal_matrix_gets_the_kept_factorisation_and_a_changed_one_a_new_one():
    from geomlib.numerics import factor

    V, F = icosphere(2)
    M, C = laplacian(V, F)
    A = (M - 0.1 * C).tocsr()
    kept = factor.factorise(A)
    b = np.random.default_rng(3).standard_normal((len(V), 3))
    np.testing.assert_allclose(A @ kept.solve(b), b, atol=1e-10)
    assert factor.factorise(A.copy()) is kept and factor.factorise(A.tocoo()) is kept  # by content, any format
    B = A.copy()
    B.data[0] *= 1.0 + 1e-12
    changed = factor.factorise(B)
    assert changed is not kept
    np.testing.assert_allclose(B @ changed.solve(b), b, atol=1e-10)
    for s in range(factor.CACHE_SIZE):  # others push the first one out
        factor.factorise((M - (1.0 + s) * C).tocsr())
    assert factor.factorise(A) is not kept


def test_a_rebuilt_run_starts_with_the_fixed_operators_step():
    V, F = icosphere(2)
    V = V + 0.01 * np.random.default_rng(4).standard_normal(V.shape)
    np.testing.assert_array_equal(implicit_smoothing(V, F, 0.05, 1, rebuild=True), implicit_smoothing(V, F, 0.05, 1))


@pytest.mark.parametrize(
    "call",
    [
        lambda V, F: explicit_smoothing(V, F, 1e-4, 2),
        lambda V, F: explicit_step_limit(V, F),
        lambda V, F: implicit_smoothing(V, F, 1e-3, 2),
        lambda V, F: implicit_smoothing(V, F, 1e-3, 2, rebuild=True),
        lambda V, F: ImplicitSmoother(V, F),
    ],
)
def test_unused_vertices_are_named_never_nan(call):
    V, F = icosphere(1)
    V2 = np.vstack([V, [[3.0, 0.0, 0.0]], V[:2] + 5.0])  # vertices 42, 43, 44 used by no face
    with pytest.raises(
        MeshError,
        match=r"3 vertices are used by no face \(42, 43, 44\).*"
        r"remove_unreferenced_vertices\(V, F\)",
    ):
        call(V2, F)


def test_unused_vertices_in_the_step_formulas():
    V, F = icosphere(1)
    V2 = np.vstack([V, [[3.0, 0.0, 0.0]]])
    M, C = laplacian(V2, F)
    for step in (explicit_step, implicit_step):
        with pytest.raises(MeshError, match="zero at 1 of 43 vertices"):
            step(V2, M, C, 1e-3)


def test_several_components_smooth_independently():
    V, F = icosphere(2)
    V2 = np.vstack([V, V + [5.0, 0.0, 0.0]])
    F2 = np.vstack([F, F + len(V)])
    P = implicit_smoothing(V2, F2, 0.01, 3)
    np.testing.assert_allclose(P[: len(V)], implicit_smoothing(V, F, 0.01, 3), atol=1e-12)
    np.testing.assert_allclose(P[len(V) :], implicit_smoothing(V, F, 0.01, 3) + [5.0, 0.0, 0.0], atol=1e-12)


def test_smoother_history_matches_fresh_runs():
    V, F = icosphere(3)
    V = V + 0.02 * np.random.default_rng(11).standard_normal(V.shape)
    S = ImplicitSmoother(V, F)
    five = S.smooth(0.05, 5)
    three = S.smooth(0.05, 3)  # from the stored iterates
    seven = S.smooth(0.05, 7)  # continues from the fifth
    np.testing.assert_allclose(three, implicit_smoothing(V, F, 0.05, 3), atol=1e-14)
    np.testing.assert_allclose(seven, implicit_smoothing(V, F, 0.05, 7), atol=1e-14)
    three[:] = 0.0  # a returned array is the caller's
    np.testing.assert_allclose(S.smooth(0.05, 3), implicit_smoothing(V, F, 0.05, 3), atol=1e-14)
    vol0 = volume_and_centroid(V, F)[0]
    assert abs(volume_and_centroid(S.smooth(0.05, 4, keep_volume=True), F)[0] / vol0 - 1) < 1e-12
    assert not np.allclose(five, S.smooth(0.05, 5, keep_volume=True))


def test_progress_bar_appears_for_long_runs(monkeypatch, capsys):
    import geomlib.numerics.progress as progress

    V, F = icosphere(2)
    monkeypatch.setattr(progress, "SECONDS", 0.0)  # every run counts as long
    implicit_smoothing(V, F, 0.01, 3)
    assert "implicit smoothing" in capsys.readouterr().err
    monkeypatch.setattr(progress, "SECONDS", 1e9)  # no run does
    explicit_smoothing(V, F, 1e-4, 3)
    assert capsys.readouterr().err == ""


def test_prepare_factorises_and_keeps_iterates():
    V, F = icosphere(2)
    V = V + 0.02 * np.random.default_rng(12).standard_normal(V.shape)
    steps = [0.01, 0.1, 1.0]
    S = ImplicitSmoother(V, F, cache_size=1, history_size=1).prepare(steps, iterations=3)
    assert len(S._factors) == 3 and len(S._history) == 3
    for s in steps:
        np.testing.assert_allclose(S.smooth(s, 3), implicit_smoothing(V, F, s, 3), atol=1e-14)
        np.testing.assert_allclose(S.smooth(s, 4), implicit_smoothing(V, F, s, 4), atol=1e-14)


def test_prepare_shows_progress_when_long(monkeypatch, capsys):
    from geomlib.numerics import progress

    V, F = icosphere(2)
    monkeypatch.setattr(progress, "SECONDS", 0.0)
    ImplicitSmoother(V, F).prepare([0.01, 0.1, 1.0], iterations=2)
    assert "factorising the step values" in capsys.readouterr().err


def test_design_contract_calls_keep_working():
    V, F = icosphere(2)
    tau = 0.3 * explicit_step_limit(V, F)
    P = explicit_smoothing(V, F, tau, 3, weights="uniform")  # explicit_smoothing(V, F, step, iterations, weights=...)
    np.testing.assert_array_equal(explicit_smoothing(V, F, step=tau, iterations=3, weights="uniform"), P)
    Q = implicit_smoothing(V, F, tau, 3, "cotan")
    np.testing.assert_array_equal(implicit_smoothing(V, F, step=tau, iterations=3, weights="cotan"), Q)
    with pytest.raises(MeshError, match="once"):
        explicit_smoothing(V, F, tau, 3, step=tau)


def test_an_unknown_option_names_the_option_the_value_and_the_choices():
    V, F = icosphere(1)
    with pytest.raises(MeshError, match=r"boundary_condition must be one of 'fixed', 'free', not 'clamped'"):
        implicit_smoothing(V, F, 0.1, 1, boundary_condition="clamped")
    with pytest.raises(MeshError, match=r"solver must be one of 'cholesky', 'cg', not 'lu'"):
        implicit_smoothing(V, F, 0.1, 1, solver="lu")


def test_volume_rescaled_gives_back_the_volume_and_centroid_of_the_reference():
    V, F = icosphere(2, centre=(2.0, 1.0, -3.0))
    P = 0.7 * V @ np.diag([1.0, 0.9, 1.1]) + np.array([0.3, -1.0, 2.0])
    vol0, c0 = volume_and_centroid(V, F)
    vol, c = volume_and_centroid(volume_rescaled(P, F, V), F)
    assert abs(vol / vol0 - 1) < 1e-12 and np.allclose(c, c0, atol=1e-12)
    with pytest.raises(MeshError, match="enclosed volume became"):
        volume_rescaled(np.zeros_like(V), F, V)


# ---------------------------------------------------------------- Taubin's filter (Taubin 1995)


def test_one_taubin_pair_multiplies_an_eigenvector_by_the_pair_s_factor_exactly():
    from scipy.linalg import eigh

    V, F = icosphere(1)  # closed, valences 5 and 6: the uniform operator depends on F alone
    M, C = laplacian(V, F, "uniform")
    lam, E = eigh(-C.toarray(), M.toarray())  # C e = -lam M e
    pick = [3, 12, 40]  # a low, a middle and a high mode as the three coordinates
    tau_shrink, tau_inflate = 0.33, -0.34
    for pairs in (1, 3):
        P = taubin_smoothing(E[:, pick], F, tau_shrink, tau_inflate, pairs)
        factor = ((1 - tau_shrink * lam[pick]) * (1 - tau_inflate * lam[pick])) ** pairs
        np.testing.assert_allclose(P, E[:, pick] * factor, atol=1e-12)
        np.testing.assert_allclose(factor[0] ** (1 / pairs), mode_factor(lam[3], tau_shrink, "taubin", tau_inflate))


def test_taubin_holds_the_boundary_and_keeps_the_valence_weighted_centroid():
    V, F = grid(9, jitter=0.3)
    V[:, 2] = 0.1 * np.random.default_rng(2).standard_normal(len(V))
    P = taubin_smoothing(V, F, 0.5, -0.53, 7)
    held = _boundary_mask(F, len(V))
    assert np.array_equal(P[held], V[held]) and not np.allclose(P[~held], V[~held])
    W, G = icosphere(2, centre=(1.0, -2.0, 0.5))
    W = W + 0.02 * np.random.default_rng(3).standard_normal(W.shape)
    m = laplacian(W, G, "uniform")[0].diagonal()  # the valences: 1^T C = 0, so sum_i m_i p_i is kept
    Q = taubin_smoothing(W, G, 0.5, -0.53, 20)
    np.testing.assert_allclose(m @ Q / m.sum(), m @ W / m.sum(), atol=1e-12)
    assert not np.allclose(Q.mean(axis=0), W.mean(axis=0), atol=1e-9, rtol=0)  # the plain mean moves: valences differ


def test_taubin_steps_are_explicit_steps_and_match_trimesh():
    V, F = icosphere(2)
    W = V + 0.01 * np.random.default_rng(4).standard_normal(V.shape)
    M, C = laplacian(W, F, "uniform")
    seen = []
    P = taubin_smoothing(W, F, 0.5, -0.5, 3, callback=lambda k, P: seen.append(k))
    Q = W
    for _ in range(3):
        Q = explicit_step(explicit_step(Q, M, C, 0.5), M, C, -0.5)
    mesh = trimesh.smoothing.filter_taubin(trimesh.Trimesh(W.copy(), F, process=False), lamb=0.5, nu=0.5, iterations=6)
    np.testing.assert_allclose(P, Q, atol=1e-13)
    np.testing.assert_allclose(P, mesh.vertices, atol=1e-12)
    assert seen == [1, 2, 3] and np.array_equal(taubin_smoothing(W, F, 0.5, -0.5, 0), W)


def test_taubin_past_its_limit_diverges_clearly():
    V, F = icosphere(1)
    W = V + 0.01 * np.random.default_rng(5).standard_normal(V.shape)
    with pytest.raises(MeshError, match="diverged at pair") as caught:
        taubin_smoothing(W, F, 1.9, -1.9, 200)  # |1 - 1.9^2 lam^2| > 1 for the top modes
    assert np.isfinite(caught.value.V).all()
    with pytest.warns(MeshWarning, match="diverged"):
        assert np.isfinite(taubin_smoothing(W, F, 1.9, -1.9, 200, on_failure="stop")).all()


@pytest.mark.parametrize(
    "args, match",
    [
        ((0.0, -0.5, 1), "tau_shrink > 0 > tau_inflate"),
        ((0.5, 0.5, 1), "tau_shrink > 0 > tau_inflate"),
        ((-0.5, 0.53, 1), "tau_shrink > 0 > tau_inflate"),
        ((0.5, -0.53, -1), "pairs"),
        ((0.5, -0.53, 1.5), "pairs"),
        ((0.5, float("nan"), 1), "tau_inflate"),
    ],
)
def test_taubin_refuses_bad_input(args, match):
    V, F = icosphere(1)
    with pytest.raises(MeshError, match=match):
        taubin_smoothing(V, F, *args)
    with pytest.raises(MeshError, match="weights"):
        taubin_smoothing(V, F, 0.5, -0.53, 1, weights="umbrella")
    with pytest.raises(MeshError):
        taubin_smoothing(V[:, :2], F, 0.5, -0.53, 1)
