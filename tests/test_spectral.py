"""Tests for geomlib.lessons.spectral: C e = -lam M e, E^T M E = I, reconstruction, cache."""

import re
import sys
import warnings

import numpy as np
import pytest
from meshdata import COURSE

import geomlib
import geomlib.numerics.eigen as eigen
import geomlib.numerics.eigenbasis_store as basis_cache
from geomlib import (
    MeshError,
    MeshWarning,
    clear_spectral_cache,
    eigenbasis,
    laplacian,
    spectral_basis,
    spectral_cache_dir,
    spectral_reconstruction,
)
from geomlib.lessons.spectral import spectral_reconstructions
from geomlib.teaching.shapes.surfaces import ellipsoid, icosphere, sphere


@pytest.fixture(autouse=True)
def private_cache(tmp_path, monkeypatch):
    """Every test gets an empty cache folder of its own and an empty memory cache."""
    monkeypatch.setenv("GEOMLIB_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(basis_cache, "CACHE_DIR", None)
    basis_cache.clear(memory=True)
    yield
    basis_cache.forget()


@pytest.fixture(scope="module")
def egg():
    """An irregular ellipsoid (no repeated eigenvalues), 642 vertices."""
    S = ellipsoid(1.0, 0.7, 0.5, subdivisions=3, jitter=0.2, seed=1)
    return S.V, S.F


@pytest.fixture(scope="module")
def egg_fine():
    """The same shape with 2562 vertices (sparse solver by default)."""
    S = ellipsoid(1.0, 0.7, 0.5, subdivisions=4, jitter=0.2, seed=1)
    return S.V, S.F


def _mass(V, F, weights="cotan"):
    M, C = laplacian(V, F, weights=weights)
    return M.diagonal(), C


def _rel_error(V, Vk, m):
    return np.sqrt(np.sum(m[:, None] * (V - Vk) ** 2) / np.sum(m[:, None] * (V - V.mean(0)) ** 2))


# --------------------------------------------------------------------------
# identities


@pytest.mark.parametrize("method", ["dense", "sparse"])
def test_m_orthonormal_and_residual(egg, method):
    V, F = egg
    lam, E = eigenbasis(V, F, 40, method=method)
    m, C = _mass(V, F)
    assert E.shape == (len(V), 40) and lam.shape == (40,)
    assert np.abs(E.T @ (m[:, None] * E) - np.eye(40)).max() < 1e-8
    # C E + M E diag(lam) = 0, relative to the size of C E
    R = C @ E + (m[:, None] * E) * lam[None, :]
    assert np.abs(R).max() < 1e-9 * np.abs(C).max()
    assert np.all(np.diff(lam) >= 0) and lam[0] == 0.0 and lam[1] > 0
    # the eigenvectors are M-orthonormal, NOT orthonormal
    assert np.abs(E.T @ E - np.eye(40)).max() > 1e-2


def test_first_eigenvector_is_the_constant(egg):
    V, F = egg
    lam, E = eigenbasis(V, F, 5)
    m, _ = _mass(V, F)
    assert lam[0] == 0.0
    np.testing.assert_allclose(E[:, 0], 1.0 / np.sqrt(m.sum()), rtol=1e-12)


@pytest.mark.parametrize("method", ["sparse", "arpack"])
def test_dense_and_sparse_agree(egg, method):
    V, F = egg
    ld, Ed = eigenbasis(V, F, 30, method="dense")
    ls, Es = eigenbasis(V, F, 30, method=method)
    np.testing.assert_allclose(ls, ld, rtol=1e-9, atol=1e-9)
    # simple eigenvalues here, and the sign convention fixes each vector
    m, _ = _mass(V, F)
    G = Ed.T @ (m[:, None] * Es)
    np.testing.assert_allclose(np.diag(G), 1.0, atol=1e-7)


def test_smallest_eigenpairs_of_a_known_spectrum():
    """A path graph's Laplacian: eigenvalues 2 - 2 cos(pi j / n), j = 0 .. n-1, every one simple."""
    import scipy.sparse as sp

    n = 900
    S = sp.diags([-np.ones(n - 1), np.r_[1.0, 2 * np.ones(n - 2), 1.0], -np.ones(n - 1)], [-1, 0, 1]).tocsr()
    exact = 2 - 2 * np.cos(np.pi * np.arange(n) / n)
    constant = np.full((n, 1), 1 / np.sqrt(n))  # its null space, known: the sparse solve squares the inverse
    for method, null in (("dense", None), ("sparse", None), ("sparse", constant)):
        lam, Y = eigen.smallest_eigenpairs(S, 12, 1e-6, method, null=null)
        np.testing.assert_allclose(lam, exact[:12], atol=1e-12)
        assert np.abs(Y.T @ Y - np.eye(12)).max() < 1e-10
        assert np.abs(S @ Y - Y * lam).max() < 1e-10
    top, y = eigen.largest_eigenpair(S)
    assert abs(top - exact[-1]) <= 1e-8 * exact[-1] and top <= exact[-1] + 1e-12
    assert np.abs(S @ y - top * y).max() < 1e-3
    top = eigen.largest_eigenvalue(S)  # a cluster (the top gaps shrink like 1/n^2): within it, from below
    assert exact[-2] < top <= exact[-1] + 1e-12
    diagonal = sp.diags(np.linspace(1.0, 3.0, n)).tocsr()  # well separated: to 1e-8
    assert abs(eigen.largest_eigenvalue(diagonal) - 3.0) <= 1e-8 * 3.0


def test_unit_sphere_eigenvalues_are_l_l_plus_1():
    """Spherical harmonics: lam = l (l + 1), multiplicity 2 l + 1, the first 25 within 1%."""
    S = sphere(1.0, subdivisions=4)  # 2562 vertices
    lam, E = eigenbasis(S.V, S.F, 25)
    l = np.repeat(np.arange(5), 2 * np.arange(5) + 1)
    exact = l * (l + 1.0)
    assert lam[0] == 0.0
    rel = np.abs(lam[1:] / exact[1:] - 1.0)
    assert rel.max() < 0.01
    # multiplicities: group the eigenvalues by their nearest l(l + 1)
    nearest = np.rint((-1 + np.sqrt(1 + 4 * lam)) / 2).astype(int)
    assert np.bincount(nearest).tolist() == [1, 3, 5, 7, 9]
    # refining the mesh brings them closer (second order in the edge length)
    C3 = sphere(1.0, subdivisions=3)
    coarse, _ = eigenbasis(C3.V, C3.F, 25)
    assert np.abs(coarse[1:] / exact[1:] - 1.0).max() > 2.5 * rel.max()


def test_the_l1_eigenvectors_are_the_coordinates():
    S = sphere(1.0, subdivisions=3)
    lam, E = eigenbasis(S.V, S.F, 4)
    m, _ = _mass(S.V, S.F)
    # x, y, z lie in the span of e_1, e_2, e_3 (to discretisation error)
    P = E[:, 1:4] @ (E[:, 1:4].T @ (m[:, None] * S.V))
    assert np.abs(P - S.V).max() < 2e-3


# --------------------------------------------------------------------------
# laws


def test_scaling_and_rigid_motion(egg):
    V, F = egg
    lam, E = eigenbasis(V, F, 12)
    s = 2.5
    lam_s, E_s = eigenbasis(s * V, F, 12)
    np.testing.assert_allclose(lam_s, lam / s**2, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(E_s, E / s, rtol=1e-7, atol=1e-9)
    rng = np.random.default_rng(3)
    Q, _ = np.linalg.qr(rng.standard_normal((3, 3)))
    lam_r, _ = eigenbasis(V @ Q.T + [1.0, -2.0, 0.5], F, 12)
    np.testing.assert_allclose(lam_r, lam, rtol=1e-9, atol=1e-12)


def test_uniform_weights_use_the_valence(egg):
    V, F = egg
    lam, E = eigenbasis(V, F, 8, weights="uniform")
    M, C = laplacian(V, F, weights="uniform")
    m = M.diagonal()
    assert np.abs(E.T @ (m[:, None] * E) - np.eye(8)).max() < 1e-8
    assert np.abs(C @ E + (m[:, None] * E) * lam).max() < 1e-9 * np.abs(C).max()
    # the graph Laplacian ignores the geometry: same for any vertex positions
    lam2, _ = eigenbasis(V * [3.0, 1.0, 0.2], F, 8, weights="uniform")
    np.testing.assert_allclose(lam2, lam, atol=1e-10)


# --------------------------------------------------------------------------
# reconstruction


def test_reconstruction_error_decreases_with_k(egg_fine):
    V, F = egg_fine
    m, _ = _mass(V, F)
    errors = [_rel_error(V, spectral_reconstruction(V, F, k), m) for k in (1, 2, 4, 10, 25, 60, 120)]
    assert errors[0] == pytest.approx(1.0)  # k = 1 keeps only the (area-weighted) centroid
    assert np.all(np.diff(errors) < 0)
    assert errors[-1] < 0.01


def test_reconstruction_with_one_vector_is_the_area_centroid(egg):
    V, F = egg
    m, _ = _mass(V, F)
    V1 = spectral_reconstruction(V, F, 1, cache=False)
    np.testing.assert_allclose(V1, np.broadcast_to(m @ V / m.sum(), V.shape), atol=1e-12)


def test_k_equal_n_reproduces_the_mesh():
    P, F = icosphere(1)  # 42 vertices
    V = P * [1.0, 0.8, 0.6]
    lam, E = eigenbasis(V, F, len(V))
    m, _ = _mass(V, F)
    assert np.abs(E.T @ (m[:, None] * E) - np.eye(len(V))).max() < 1e-10
    np.testing.assert_allclose(spectral_reconstruction(V, F, len(V), cache=False), V, atol=1e-12)
    assert _rel_error(V, spectral_reconstruction(V, F, len(V) - 5, cache=False), m) > 1e-6


def test_projection_is_m_orthogonal_not_euclidean(egg):
    """The M projection minimises the M-norm error; the plain dot product does not."""
    V, F = egg
    m, _ = _mass(V, F)
    basis = spectral_basis(V, F, 15, cache=False)
    right = basis.reconstruct(V)
    wrong = basis.E @ (basis.E.T @ V)
    assert _rel_error(V, right, m) < _rel_error(V, wrong, m)
    # the residual of the M projection is M-orthogonal to the basis
    assert np.abs(basis.E.T @ (m[:, None] * (V - right))).max() < 1e-10


def test_residual_norms_follow_parseval(egg):
    V, F = egg
    m, _ = _mass(V, F)
    basis = spectral_basis(V, F, 30, cache=False)
    norms = basis.residual_norms(V)
    for k in (1, 7, 30):
        direct = np.sqrt(np.sum(m[:, None] * (V - basis.reconstruct(V, k)) ** 2))
        assert norms[k - 1] == pytest.approx(direct, rel=1e-7, abs=1e-10)


def test_reconstructions_from_one_solve_are_the_projections_and_their_errors_parsevals(egg):
    """spectral_reconstructions: one solve of max(ks) pairs, V_k in the order of ks, the error measured directly."""
    V, F = egg
    m, _ = _mass(V, F)
    asked = []

    def solve(M, C, k):
        asked.append(k)
        return geomlib.lessons.spectral.eigenpairs(M, C, k)

    ks = [12, 1, 30, 7]
    V_ks, err = spectral_reconstructions(V, F, ks, solve)
    assert asked == [30] and V_ks.shape == (4, len(V), 3) and err.shape == (4,)
    basis = spectral_basis(V, F, 30, cache=False)
    scale = np.sqrt(m.sum()) * geomlib.bounding_box_diagonal(V)
    for V_k, e, k in zip(V_ks, err, ks):
        np.testing.assert_allclose(V_k, basis.reconstruct(V, k), atol=1e-12 * np.abs(V).max())
        assert e == pytest.approx(basis.residual_norms(V)[k - 1] / scale, rel=1e-7)
    # k = 1 keeps the area-weighted centroid: the error is the RMS distance to it
    centroid = m @ V / m.sum()
    assert err[1] == pytest.approx(np.sqrt(m @ np.sum((V - centroid) ** 2, axis=1)) / scale)


def test_reconstruction_errors_are_scale_free_and_vanish_at_k_equal_n():
    P, F = icosphere(1)
    V = P * [1.0, 0.8, 0.6]
    V_ks, err = spectral_reconstructions(V, F, [3, len(V)])
    np.testing.assert_allclose(V_ks[1], V, atol=1e-12)
    assert err[1] < 1e-12 and 0 < err[0] < 1
    moved = spectral_reconstructions(7.0 * V + [1.0, -2.0, 3.0], F, [3, len(V)])[1]  # err: no unit, no origin
    np.testing.assert_allclose(moved, err, rtol=1e-9, atol=1e-12)
    with pytest.raises(MeshError, match="ks is empty"):
        spectral_reconstructions(V, F, [])
    with pytest.raises(MeshError, match="at most n = 42"):
        spectral_reconstructions(V, F, [5, 43])


# --------------------------------------------------------------------------
# components and boundaries


def test_several_components_give_several_zero_eigenvalues():
    P, F = icosphere(2)
    V = np.vstack([P, 0.5 * P + [3.0, 0.0, 0.0], 0.3 * P - [3.0, 0.0, 0.0]])
    FF = np.vstack([F, F + len(P), F + 2 * len(P)])
    with pytest.warns(MeshWarning, match="3 connected components"):
        lam, E = eigenbasis(V, FF, 16)
    m, C = _mass(V, FF)
    assert lam[:3].tolist() == [0.0, 0.0, 0.0] and lam[3] > 1.0
    # indicator functions, the largest component first
    n = len(P)
    assert np.allclose(E[:n, 0], 1 / np.sqrt(m[:n].sum())) and np.allclose(E[n:, 0], 0)
    assert np.allclose(E[n : 2 * n, 1], 1 / np.sqrt(m[n : 2 * n].sum())) and np.allclose(E[:n, 1], 0)
    assert np.abs(E.T @ (m[:, None] * E) - np.eye(16)).max() < 1e-8
    assert np.abs(C @ E + (m[:, None] * E) * lam).max() < 1e-9 * np.abs(C).max()
    # each component's own spectrum: the unit sphere has 2 three times, the
    # sphere of radius 0.5 has 2 / 0.25 = 8 three times
    assert np.sum(np.abs(lam / 2.0 - 1.0) < 0.01) == 3
    assert np.sum(np.abs(lam / 8.0 - 1.0) < 0.01) == 3


def _square(n, L):
    """Flat n x n grid of squares on [0, L]^2, each split into two triangles (open, a boundary)."""
    x = np.linspace(0.0, L, n + 1)
    X, Y = np.meshgrid(x, x, indexing="ij")
    V = np.column_stack([X.ravel(), Y.ravel(), np.zeros(X.size)])
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a = (i * (n + 1) + j).ravel()
    b, c, d = a + n + 1, a + n + 2, a + 1
    F = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])]).astype(np.int64)
    return V, F


def test_open_mesh_with_boundary():
    """Natural (Neumann) boundary: the flat square's eigenvalues pi^2 (a^2 + b^2) / L^2."""
    L = 2.0
    V, F = _square(40, L)
    lam, E = eigenbasis(V, F, 10)
    m, C = _mass(V, F)
    assert lam[0] == 0.0 and lam[1] > 0.0
    np.testing.assert_allclose(E[:, 0], 1 / np.sqrt(m.sum()), rtol=1e-12)
    assert np.abs(E.T @ (m[:, None] * E) - np.eye(10)).max() < 1e-8
    assert np.abs(C @ E + (m[:, None] * E) * lam).max() < 1e-9 * np.abs(C).max()
    ab = sorted(a * a + b * b for a in range(5) for b in range(5))[:10]
    np.testing.assert_allclose(lam[1:], np.pi**2 * np.array(ab[1:]) / L**2, rtol=0.01)


# --------------------------------------------------------------------------
# bad input


@pytest.mark.parametrize("k", [0, -3])
def test_k_below_one(egg, k):
    with pytest.raises(MeshError, match="at least 1"):
        eigenbasis(*egg, k)


def test_k_above_vertex_count(egg):
    V, F = egg
    with pytest.raises(MeshError, match=f"only {len(V)} vertices"):
        eigenbasis(V, F, len(V) + 1)
    with pytest.raises(MeshError, match=f"only {len(V)} vertices"):
        spectral_reconstruction(V, F, len(V) + 1)


@pytest.mark.parametrize("k", [2.5, "10", True, None])
def test_k_not_an_integer(egg, k):
    with pytest.raises(MeshError, match="integer"):
        eigenbasis(*egg, k)


def test_isolated_vertex_is_named(egg):
    V, F = egg
    V2 = np.vstack([V, [[5.0, 5.0, 5.0]]])
    with pytest.raises(
        MeshError,
        match=rf"1 vertices are used by no face \({len(V)}\).*"
        r"geomlib.mesh.repair.remove_unreferenced_vertices\(V, F\)",
    ):
        eigenbasis(V2, F, 5)
    with pytest.raises(MeshError, match="remove_unreferenced_vertices"):
        spectral_reconstruction(V2, F, 5)


def test_bad_method(egg):
    with pytest.raises(MeshError, match="method"):
        eigenbasis(*egg, 5, method="lobster")


def test_sparse_agrees_with_arpack_at_2562_vertices(egg_fine):
    V, F = egg_fine
    lb, Eb = eigenbasis(V, F, 60, method="sparse")
    la_, Ea = eigenbasis(V, F, 60, method="arpack")
    np.testing.assert_allclose(lb, la_, rtol=1e-10, atol=1e-12)


def test_k_beyond_basis_in_reconstruct(egg):
    basis = spectral_basis(*egg, 5, cache=False)
    with pytest.raises(MeshError, match="1..5"):
        basis.reconstruct(egg[0], 6)


# --------------------------------------------------------------------------
# the cache


def test_cache_round_trip_and_slices(egg_fine, tmp_path):
    V, F = egg_fine
    b = spectral_basis(V, F, 30)
    assert b.source == "solved"
    files = list(spectral_cache_dir().glob("*.npz"))
    assert len(files) == 1 and files[0].name.endswith("-k30.npz")
    # memory: same numbers, no solve
    b2 = spectral_basis(V, F, 30)
    assert b2.source == "memory" and np.shares_memory(b2.E, b.E)
    # disk, as after a kernel restart; a basis with more pairs serves fewer
    basis_cache.forget()
    b3 = spectral_basis(V, F, 12)
    assert b3.source == "disk"
    np.testing.assert_array_equal(b3.E, b.E[:, :12])
    lam, E = eigenbasis(V, F, 12)  # the solve itself: no cache behind it
    assert not list(spectral_cache_dir().glob("*-k12.npz"))
    np.testing.assert_allclose(lam, b.lam[:12], rtol=1e-9, atol=1e-12)


def test_cache_invalidated_by_mesh_and_operator(egg):
    V, F = egg
    spectral_basis(V, F, 10)
    basis_cache.forget()
    assert spectral_basis(V, F, 10, area="mixed").source == "solved"
    assert spectral_basis(V, F, 10, weights="uniform").source == "solved"
    V2 = V.copy()
    V2[3, 0] += 1e-9
    assert spectral_basis(V2, F, 10).source == "solved"
    F2 = F[::-1].copy()  # the same triangles in another order: another key
    assert spectral_basis(V, F2, 10).source == "solved"
    assert len(list(spectral_cache_dir().glob("*.npz"))) == 5
    # more pairs than stored: solved again, and the larger file replaces the smaller
    basis_cache.forget()
    assert spectral_basis(V, F, 20).source == "solved"
    assert len(list(spectral_cache_dir().glob("*.npz"))) == 5


def test_cache_false_touches_nothing(egg):
    V, F = egg
    spectral_basis(V, F, 10, cache=False)
    assert not spectral_cache_dir().exists()
    assert not basis_cache._MEMORY


def test_cache_folder_choice(egg, tmp_path, monkeypatch):
    V, F = egg
    spectral_basis(V, F, 6, cache_dir=tmp_path / "mine")
    assert len(list((tmp_path / "mine" / "spectral").glob("*.npz"))) == 1
    monkeypatch.setattr(basis_cache, "CACHE_DIR", str(tmp_path / "attr"))
    assert spectral_cache_dir() == tmp_path / "attr" / "spectral"
    monkeypatch.setattr(basis_cache, "CACHE_DIR", None)
    monkeypatch.delenv("GEOMLIB_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    if not sys.platform.startswith(("win", "darwin")):
        assert spectral_cache_dir() == tmp_path / "xdg" / "geomlib" / "spectral"
    assert clear_spectral_cache(tmp_path / "mine") == 1


def test_corrupt_cache_file_is_solved_again(egg):
    V, F = egg
    b = spectral_basis(V, F, 8)
    (path,) = spectral_cache_dir().glob("*.npz")
    path.write_bytes(b"not a numpy file")
    basis_cache.forget()
    with pytest.warns(MeshWarning, match="damaged"):
        b2 = spectral_basis(V, F, 8)
    assert b2.source == "solved"
    np.testing.assert_allclose(b2.lam, b.lam)
    basis_cache.forget()
    assert spectral_basis(V, F, 8).source == "disk"  # the damaged file was replaced


def test_truncated_cache_file_is_solved_again(egg):
    """As a full disk or a sync tool leaves it: the first half of a valid file."""
    V, F = egg
    b = spectral_basis(V, F, 8)
    (path,) = spectral_cache_dir().glob("*.npz")
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    basis_cache.forget()
    with pytest.warns(MeshWarning, match=f"{path.name} is damaged"):
        lam = spectral_basis(V, F, 8).lam
    np.testing.assert_allclose(lam, b.lam, rtol=1e-12, atol=1e-12)


def test_file_where_the_cache_folder_should_be(egg, tmp_path):
    V, F = egg
    blocker = tmp_path / "blocked"
    blocker.write_text("a file, not a folder")
    with pytest.warns(MeshWarning, match="could not write the eigenbasis cache"):
        lam = spectral_basis(V, F, 6, cache_dir=blocker).lam
    assert blocker.read_text() == "a file, not a folder"
    spectral_folder = tmp_path / "inner"
    spectral_folder.mkdir()
    (spectral_folder / "spectral").write_text("a file")
    basis_cache.forget()
    with pytest.warns(MeshWarning, match="is a file, not a folder"):
        lam2 = spectral_basis(V, F, 6, cache_dir=spectral_folder).lam
    np.testing.assert_array_equal(lam, lam2)


def test_unwritable_cache_folder(egg, tmp_path, monkeypatch):
    """A read-only folder (simulated: the tests may run as root, who may write anywhere)."""
    V, F = egg

    def refuse(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(basis_cache.np, "savez", refuse)
    with pytest.warns(MeshWarning, match="Permission denied"):
        lam = spectral_basis(V, F, 6, cache_dir=tmp_path / "ro").lam
    assert lam[0] == 0.0 and lam.shape == (6,)
    assert not list((tmp_path / "ro").rglob("*.npz"))


def test_public_names():
    for name in (
        "eigenbasis",
        "spectral_reconstruction",
        "spectral_basis",
        "SpectralBasis",
        "spectral_cache_dir",
        "clear_spectral_cache",
    ):
        assert name in geomlib.__all__ and callable(getattr(geomlib, name))


# --------------------------------------------------------------------------
# the course's armadillo (read from ../shared/meshes when present)


@pytest.mark.skipif(not (COURSE / "decompose" / "armadillo.obj").exists(), reason="course meshes not present")
def test_course_armadillo():
    V, F = geomlib.load_mesh(COURSE / "decompose" / "armadillo.obj")
    assert len(V) == 361
    with warnings.catch_warnings():
        warnings.simplefilter("error", MeshWarning)  # one component, no degenerate faces
        ld, Ed = eigenbasis(V, F, 60, method="dense")
    ls, Es = eigenbasis(V, F, 60, method="sparse")
    np.testing.assert_allclose(ls, ld, rtol=1e-8, atol=1e-8)
    m, C = _mass(V, F)
    assert np.abs(Es.T @ (m[:, None] * Es) - np.eye(60)).max() < 1e-8
    errors = [_rel_error(V, spectral_reconstruction(V, F, k), m) for k in (5, 15, 60, 200, 361)]
    assert np.all(np.diff(errors) < 0)
    assert errors[-1] < 1e-10


def test_blas_thread_setting_is_restored(egg):
    from threadpoolctl import threadpool_info

    before = [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"]
    with eigen.one_blas_thread():
        assert all(i["num_threads"] == 1 for i in threadpool_info() if i["user_api"] == "blas")
    eigenbasis(*egg, 5)
    assert [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"] == before


def test_long_solves_show_their_stages(egg_fine, monkeypatch, capsys):
    import geomlib.numerics.progress as progress

    V, F = egg_fine
    monkeypatch.setattr(progress, "SECONDS", -1.0)  # every solve counts as long
    eigenbasis(V, F, 20, method="sparse")
    err = capsys.readouterr().err
    assert "20 eigenpairs (about" in err and "factorising" in err
    monkeypatch.setattr(progress, "SECONDS", 1e9)  # none does
    eigenbasis(V, F, 20, method="sparse")
    assert capsys.readouterr().err == ""


# --------------------------------------------------------------------------
# the code shown is the code that runs


def test_eigenbasis_is_the_solve_and_the_cache_calls_it(egg_fine, monkeypatch):
    """spectral_basis and spectral_reconstruction get their basis from eigenbasis, once per mesh."""
    import inspect

    import geomlib.lessons.spectral as spectral

    assert "cache" not in inspect.signature(eigenbasis).parameters
    V, F = egg_fine
    calls = []

    def counted(*args, **kwargs):
        calls.append(args[2])
        return eigenbasis(*args, **kwargs)

    monkeypatch.setattr(spectral, "eigenbasis", counted)
    b = spectral_basis(V, F, 20)
    spectral_reconstruction(V, F, 12)  # from memory
    basis_cache.forget()
    spectral_reconstruction(V, F, 15)  # from disk
    assert calls == [20] and b.source == "solved"


def test_a_wrong_solve_shows_in_the_reconstruction(egg_fine, monkeypatch):
    """Replace the eigensolver eigenbasis calls by one that skips the smallest eigenpair (the
    constant): the reconstruction through the cache entry loses the centroid."""
    import geomlib.lessons.spectral as spectral

    V, F = egg_fine[0] + [2.0, -1.0, 0.5], egg_fine[1]  # the centroid away from the origin
    m, _ = _mass(V, F)
    right = _rel_error(V, spectral_reconstruction(V, F, 30, cache=False), m)

    def skipping(S, k, *args, **kwargs):
        lam, Y = eigen.smallest_eigenpairs(S, k + 1, *args)
        return lam[1:], Y[:, 1:]

    monkeypatch.setattr(spectral, "smallest_eigenpairs", skipping)
    V_wrong = spectral_reconstruction(V, F, 30, cache=False)
    assert right < 0.05 and _rel_error(V, V_wrong, m) > 10 * right
    np.testing.assert_allclose(m @ V_wrong, 0.0, atol=1e-12)  # no constant: the centroid went to 0


def test_lanczos_resolves_repeated_eigenvalues():
    """A diagonal matrix with a 6-fold smallest non-zero eigenvalue: every copy is found."""
    import scipy.sparse as sp

    d = np.r_[0.0, np.full(6, 1.0), np.linspace(2.0, 50.0, 2000)]
    lam, Y = eigen.smallest_eigenpairs(sp.diags(d).tocsr(), 12, 1e-4, "sparse")
    np.testing.assert_allclose(lam, d[:12], atol=1e-12)
    assert np.abs(Y.T @ Y - np.eye(12)).max() < 1e-12


# --------------------------------------------------------------------------
# eigenpairs(M, C, k): the solve for a given pair (notebook 04's exercise and its fallback)


def test_eigenpairs_of_the_pair_is_eigenbasis(egg):
    from geomlib.lessons.spectral import eigenpairs

    V, F = egg
    M, C = laplacian(V, F)
    lam, E = eigenpairs(M, C, 12)
    lam_b, E_b = eigenbasis(V, F, 12)
    np.testing.assert_allclose(lam, lam_b, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(E, E_b, atol=1e-8)  # same signs: the entry of largest magnitude is positive
    # dense arrays are taken as well
    np.testing.assert_allclose(eigenpairs(M.toarray(), C.toarray(), 12)[0], lam, rtol=1e-10, atol=1e-12)


def test_eigenpairs_finds_the_components_from_C():
    from geomlib.lessons.spectral import eigenpairs

    P, F = icosphere(1)
    V = np.vstack([0.5 * P, P + [3.0, 0.0, 0.0]])  # the larger piece second
    FF = np.vstack([F, F + len(P)])
    M, C = laplacian(V, FF)
    with pytest.warns(MeshWarning, match="2 connected components"):
        lam, E = eigenpairs(M, C, 5)
    m = M.diagonal()
    assert lam[:2].tolist() == [0.0, 0.0] and lam[2] > 1.0
    np.testing.assert_allclose(E[len(P) :, 0], 1 / np.sqrt(m[len(P) :].sum()))  # largest area first
    np.testing.assert_allclose(E[: len(P), 0], 0.0)


@pytest.mark.parametrize(
    "M, C, k, phrase",
    [
        (np.eye(3), np.zeros((4, 4)), 1, "square and of one size"),
        (np.ones((3, 3)), np.zeros((3, 3)), 1, "M must be diagonal"),
        (np.diag([1.0, 0.0, 1.0]), np.zeros((3, 3)), 1, "M_ii is zero at 1 of 3 vertices"),
        (np.eye(3), np.zeros((3, 3)), 4, "at most n = 3"),
    ],
)
def test_eigenpairs_names_bad_input(M, C, k, phrase):
    from geomlib.lessons.spectral import eigenpairs

    with pytest.raises(MeshError, match=re.escape(phrase)):
        eigenpairs(M, C, k)
