"""Seeded Gaussian noise: statistics, reproducibility, the input left alone."""

import numpy as np
import pytest
import trimesh

import geomlib
from geomlib import MeshError, add_noise, surfaces
from geomlib.lessons.metrics import bounding_box_diagonal
from geomlib.mesh.geometry import vertex_normals


@pytest.fixture(scope="module")
def sphere_10k():
    mesh = trimesh.creation.icosphere(subdivisions=5, radius=2.0)  # 10242 vertices
    return np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)


@pytest.mark.parametrize("sigma", [0.001, 0.01, 0.05])
def test_isotropic_noise_has_the_requested_standard_deviation(sphere_10k, sigma):
    V, F = sphere_10k
    assert len(V) >= 10_000
    D = add_noise(V, F, sigma, seed=7) - V
    target = sigma * bounding_box_diagonal(V)
    # each coordinate is N(0, target^2): sample sd within 5 %, mean near 0
    for axis in range(3):
        assert abs(D[:, axis].std() / target - 1) < 0.05
    assert np.abs(D.mean(axis=0)).max() < 5 * target / np.sqrt(len(V))
    # coordinates are independent: the correlation matrix is close to I
    R = np.corrcoef(D.T)
    assert np.abs(R - np.eye(3)).max() < 0.05


def test_normal_noise_moves_along_the_normal_only(sphere_10k):
    V, F = sphere_10k
    sigma = 0.01
    D = add_noise(V, F, sigma, seed=3, direction="normal") - V
    N = vertex_normals(V, F)
    along = np.einsum("ij,ij->i", D, N)
    tangential = D - along[:, None] * N
    assert np.abs(tangential).max() < 1e-12 * bounding_box_diagonal(V)
    assert abs(along.std() / (sigma * bounding_box_diagonal(V)) - 1) < 0.05


def test_noise_is_relative_to_the_bounding_box_diagonal(sphere_10k):
    # scaling the mesh scales the noise with it: the same seed gives s * D
    V, F = sphere_10k
    D1 = add_noise(V, F, 0.01, seed=11) - V
    D2 = add_noise(3.5 * V, F, 0.01, seed=11) - 3.5 * V
    np.testing.assert_allclose(D2, 3.5 * D1, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("direction", ["isotropic", "normal"])
def test_same_seed_same_noise_and_input_untouched(sphere_10k, direction):
    V, F = sphere_10k
    V0, F0 = V.copy(), F.copy()
    A = add_noise(V, F, 0.02, seed=42, direction=direction)
    B = add_noise(V, F, 0.02, seed=42, direction=direction)
    C = add_noise(V, F, 0.02, seed=43, direction=direction)
    assert np.array_equal(A, B)
    assert not np.allclose(A, C)
    assert np.array_equal(V, V0) and np.array_equal(F, F0)
    assert A is not V and not np.shares_memory(A, V)


def test_zero_sigma_returns_an_equal_copy(sphere_10k):
    V, F = sphere_10k
    W = add_noise(V, F, 0.0, seed=0)
    assert np.array_equal(W, V) and not np.shares_memory(W, V)


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(sigma=-0.1, seed=0), "sigma"),
        (dict(sigma=float("nan"), seed=0), "sigma"),
        (dict(sigma="a lot", seed=0), "sigma"),
        (dict(sigma=0.1, seed=None), "seed"),
        (dict(sigma=0.1, seed=0, direction="tangent"), "direction"),
    ],
)
def test_bad_arguments_raise_mesh_error(kwargs, words):
    V = np.eye(3)
    F = np.array([[0, 1, 2]])
    with pytest.raises(MeshError, match=words):
        add_noise(V, F, **kwargs)


def test_bad_mesh_raises_mesh_error_naming_the_faces():
    V = np.eye(3)
    with pytest.raises(MeshError, match="faces 1"):
        add_noise(V, np.array([[0, 1, 2], [0, 1, 5]]), 0.1, seed=0)
    with pytest.raises(MeshError, match="vertices 1"):
        add_noise(np.array([[0, 0, 0], [np.nan, 0, 0], [0, 1, 0.0]]), np.array([[0, 1, 2]]), 0.1, seed=0)


def test_normal_noise_moves_along_the_geometry_vertex_normals():
    from geomlib.mesh.geometry import vertex_normals

    V, F = _sphere()
    W = add_noise(V, F, 0.01, seed=4, direction="normal")
    D = W - V
    N = vertex_normals(V, F)
    np.testing.assert_allclose(np.linalg.norm(np.cross(D, N), axis=1), 0, atol=1e-15)


def _sphere():
    from geomlib.teaching.shapes.surfaces import icosphere as ico

    return ico(2)


def test_the_sweep_is_implicit_smoothing_measured_after_every_count():
    import geomlib

    V, F = geomlib.load_mesh(geomlib.data_path("sphere.obj"))
    W = add_noise(V, F, 0.05, 7)
    taus, N = [3e-4, 3e-3, 3e-2], 12
    tau, k, E = geomlib.denoising_sweep(W, F, V, taus, N)
    assert E.shape == (3, N + 1)
    assert np.allclose(E[:, 0], geomlib.vertex_rms(W, V), rtol=1e-12)  # 0 iterations: the noisy mesh
    for i, t in enumerate(taus):
        for count in (1, 5, N):
            P = geomlib.implicit_smoothing(W, F, t, count)
            assert np.isclose(E[i, count], geomlib.vertex_rms(P, V), rtol=1e-9)
    assert E[taus.index(tau), k] == E.min() and k == int(np.argmin(E[taus.index(tau)]))
    assert E.min() < E[0, 0]  # smoothing a noisy sphere helps at some setting


def test_the_sweep_refuses_an_open_mesh_and_bad_steps():
    import geomlib

    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    F = np.array([[0, 1, 2]])
    with pytest.raises(MeshError, match="closed"):
        geomlib.denoising_sweep(V, F, V, [1e-3], 2)
    S, G = geomlib.load_mesh(geomlib.data_path("sphere.obj"))
    for taus in ([], [0.0], [float("nan")]):
        with pytest.raises(MeshError, match="taus"):
            geomlib.denoising_sweep(S, G, S, taus, 2)
    with pytest.raises(MeshError, match="iterations"):
        geomlib.denoising_sweep(S, G, S, [1e-3], 1.5)


def test_the_spread_is_the_mean_and_sample_std_of_single_draws():
    S = surfaces.sphere(1.0, subdivisions=2)
    E = [geomlib.denoising_experiment(S.V, S.F, 0.02, 1e-3, 3, s)[0] for s in (1, 2, 5)]
    E_mean, E_std = geomlib.denoising_spread(S.V, S.F, 0.02, 1e-3, 3, (1, 2, 5))
    assert E_mean == pytest.approx(sum(E) / 3, rel=1e-12)
    assert E_std == pytest.approx(np.sqrt(sum((e - E_mean) ** 2 for e in E) / 2), rel=1e-12)  # ddof = 1
    assert geomlib.denoising_spread(S.V, S.F, 0.02, 1e-3, 3, (4, 4))[1] == 0.0  # one pattern twice: no spread
    for seeds, said in (((3,), "at least 2 draws"), ((1, 2.5), r"seeds\[1\] must be an integer")):
        with pytest.raises(geomlib.MeshError, match=said):
            geomlib.denoising_spread(S.V, S.F, 0.02, 1e-3, 3, seeds)
