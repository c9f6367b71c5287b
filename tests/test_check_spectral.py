"""The checks of notebook 04's exercises name each typical mistake and pass every correct variant.

The catalogue is written fresh with numpy and scipy (scipy.linalg.eigh on dense matrices,
scipy.sparse.linalg.eigsh in shift-invert mode), as learners write it; geomlib's own routines
stand only as the reference that must pass the check's body.
"""

import numpy as np
import pytest
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as sla
from diagnoses import assert_diagnosed

from geomlib import check, laplacian, spectral_reconstruction
from geomlib.lessons.spectral import eigenpairs
from geomlib.teaching.check import CheckFailed

REREAD_EIGEN = "Reread section 2 · The discrete eigenproblem"
REREAD = "Reread section 4 · Reconstruction from the first k eigenvectors"


@pytest.fixture(autouse=True)
def lenient(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")


# --------------------------------------------------------------------------
# the generalised eigenproblem: learners' solvers


def dense(M, C, k):
    return la.eigh(-C.toarray(), M.toarray(), subset_by_index=[0, k - 1])


def sparse(M, C, k):
    lam, E = sla.eigsh(-C, k, M, sigma=-1e-8, which="LM")  # shift-invert just below 0
    order = np.argsort(lam)
    return lam[order], E[:, order]


def signs_flipped(M, C, k):
    lam, E = dense(M, C, k)
    return lam, E * np.where(np.arange(k) % 2, -1.0, 1.0)


def eigenspaces_rotated(M, C, k):
    """Any M-orthonormal basis of a repeated eigenvalue's eigenspace is right: rotate each one."""
    lam, E = dense(M, C, k)
    R, i = np.eye(k), 0
    while i < k:
        j = i
        while j + 1 < k and abs(lam[j + 1] - lam[i]) < 1e-8 * abs(lam[-1]):
            j += 1
        R[i : j + 1, i : j + 1] = np.linalg.qr(np.random.default_rng(i).normal(size=(j - i + 1,) * 2))[0]
        i = j + 1
    return lam, E @ R


def symmetric_form(M, C, k):
    """Q = -M^-1/2 C M^-1/2, then E = M^-1/2 Y (section 2's form), rounded constants and all."""
    d = 1.0 / np.sqrt(M.diagonal())
    lam, Y = la.eigh(-(d[:, None] * C.toarray() * d[None, :]), subset_by_index=[0, k - 1])
    return np.round(lam, 12), d[:, None] * Y


def lists(M, C, k):
    lam, E = dense(M, C, k)
    return list(lam), E.tolist()


CORRECT = [dense, sparse, signs_flipped, eigenspaces_rotated, symmetric_form, lists]


@pytest.mark.parametrize("solver", CORRECT, ids=[f.__name__ for f in CORRECT])
def test_correct_solvers_pass(solver):
    result = check.eigenpairs(solver)
    assert result.passed, result.message
    assert "with k = 4" in result.message and "open" in result.message


def test_geomlib_eigenpairs_meets_the_check_body():
    # the check's body without the ground rules (which refuse geomlib's own routine)
    assert len(check.eigenpairs.__wrapped__(eigenpairs)) == 3


def without_M(M, C, k):
    return la.eigh(-C.toarray(), subset_by_index=[0, k - 1])


def sign_of_C(M, C, k):
    lam, E = la.eigh(C.toarray(), M.toarray())  # C e = lam M e: lam <= 0; the k nearest 0 are the last
    return lam[-k:], E[:, -k:]


def sign_of_C_smallest(M, C, k):
    lam, E = la.eigh(C.toarray(), M.toarray())
    return lam[:k], E[:, :k]


def largest(M, C, k):
    lam, E = sla.eigsh(-C, k, M)  # which="LM" without a shift: the largest
    return lam, E


def null_mode_dropped(M, C, k):
    lam, E = dense(M, C, k + 1)
    return lam[1:], E[:, 1:]


def euclidean_normalised(M, C, k):
    lam, E = dense(M, C, k)
    return lam, E / np.linalg.norm(E, axis=0)


def scaled(M, C, k):
    lam, E = dense(M, C, k)
    return lam, 2.0 * E


def not_transformed_back(M, C, k):
    d = 1.0 / np.sqrt(M.diagonal())
    return la.eigh(-(d[:, None] * C.toarray() * d[None, :]), subset_by_index=[0, k - 1])


def non_symmetric_solver(M, C, k):
    lam, E = la.eig(-(sp.diags(1.0 / M.diagonal()) @ C).toarray())  # M^-1 C: E^T E-normalised columns
    order = np.argsort(lam.real)[:k]
    return lam[order], E[:, order]


def descending(M, C, k):
    lam, E = dense(M, C, k)
    return lam[::-1], E[:, ::-1]


def swapped(M, C, k):
    lam, E = dense(M, C, k)
    return E, lam


def transposed(M, C, k):
    lam, E = dense(M, C, k)
    return lam, E.T


def one_more(M, C, k):
    return dense(M, C, k + 1)


def columns_mixed_up(M, C, k):
    lam, E = dense(M, C, k)
    return lam, E[:, ::-1]


def only_E(M, C, k):
    return dense(M, C, k)[1]


WRONG = [
    (without_M, "M is left out"),
    (sign_of_C, "the sign of C is flipped: the eigenvalues are <= 0"),
    (sign_of_C_smallest, "the k of largest magnitude"),
    (largest, "the k largest, not the k smallest"),
    (null_mode_dropped, "the null mode is lost"),
    (euclidean_normalised, "normalised in the plain dot product (E^T E = I)"),
    (non_symmetric_solver, "normalised in the plain dot product (E^T E = I)"),
    (scaled, "not M-normalised"),
    (not_transformed_back, "not transformed back"),
    (descending, "not in ascending order"),
    (swapped, "(E, lam)"),
    (transposed, "E is transposed"),
    (one_more, "eigenpairs were returned where k = 6"),
]


@pytest.mark.parametrize("solver, phrase", WRONG, ids=[f.__name__ for f, _ in WRONG])
def test_wrong_solver_is_named_and_earns_partial_credit(solver, phrase):
    result = check.eigenpairs(solver)
    assert_diagnosed(result, phrase, REREAD_EIGEN)
    assert result.partial and check.eigenpairs.partial_credit(solver).passed


@pytest.mark.parametrize("solver", [columns_mixed_up, only_E], ids=["columns_mixed_up", "only_E"])
def test_catch_alls_earn_no_partial_credit(solver):
    result = check.eigenpairs(solver)
    assert not result.passed and not result.partial, result.message


def test_the_eigenpairs_stub_is_not_written_yet():
    def stub(M, C, k):
        raise NotImplementedError

    assert_diagnosed(check.eigenpairs(stub), "not written yet")


def test_the_reveal_shows_eigenbasis_and_the_rules_name_the_solvers():
    assert check.eigenpairs.own[0] == "lessons.spectral.eigenbasis"
    for name in ("eigenbasis", "spectral_basis", "SpectralBasis", "spectral_reconstruction", "smallest_eigenpairs"):
        assert f"`{name}`" in check.eigenpairs.rules


# --------------------------------------------------------------------------
# the reconstruction: learners' pipelines, built on a learner's solver


def learner(solver=dense, inner="M", columns=lambda k: slice(0, k), extra=0, out=lambda X, c: X, **options):
    """A learner's reconstruction with one chosen mistake: the inner product, the columns kept, the output,
    the vertex areas (``area``) or the boundary rows (``zero_boundary``)."""

    def fn(V, F, k):
        M, C = laplacian(V, F, area=options.get("area", "barycentric"))
        if options.get("zero_boundary"):
            C = C.tolil()
            E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
            edges, count = np.unique(E, axis=0, return_counts=True)
            C[np.unique(edges[count == 1]), :] = 0.0  # the boundary vertices, in numpy (ground rules)
            C = C.tocsr()
        _, E = solver(M, C, k + extra)
        W = {"M": M @ V, "plain": V, "C": C @ V, "M^-1": V / M.diagonal()[:, None]}[inner]
        Ek = E[:, columns(k)]
        c = Ek.T @ W
        return out(Ek @ c, c)

    return fn


RIGHT = [learner(), learner(sparse), learner(signs_flipped), learner(symmetric_form)]


@pytest.mark.parametrize("fn", RIGHT, ids=["eigh", "eigsh", "signs", "symmetric form"])
def test_correct_reconstructions_pass_at_every_k_below_n(fn):
    result = check.spectral_reconstruction(fn)
    assert result.passed, result.message
    assert "k = 12" in result.message and "open: a boundary" in result.message and "k = 42" not in result.message


def test_geomlib_reconstruction_meets_the_check_body():
    assert len(check.spectral_reconstruction.__wrapped__(spectral_reconstruction)) == 3


def test_geomlib_eigenpairs_may_feed_the_reconstruction():
    """The notebook's fallback: a learner's projection on geomlib's solver is within the rules."""
    assert check.spectral_reconstruction(learner(eigenpairs)).passed


WRONG_RECONSTRUCTIONS = [
    (dict(inner="plain"), "plain dot product"),
    (dict(inner="C"), "C (or M^-1 C) is used where M belongs"),
    (dict(inner="M^-1"), "divided by the vertex areas"),
    (dict(columns=lambda k: slice(1, k)), "constant eigenvector e_0 (the mean"),
    (dict(columns=lambda k: slice(1, k), inner="plain"), "dropped and the plain inner product"),
    (dict(columns=lambda k: slice(0, k - 1)), "k is off by one"),
    (dict(columns=lambda k: slice(1, k + 1), extra=1), "k is off by one"),
    (dict(area="mixed"), "mixed (Voronoi) vertex areas"),
    (dict(zero_boundary=True), "rows of the boundary vertices are zeroed"),
    (dict(out=lambda X, c: X.T), "transposed"),
    (dict(out=lambda X, c: c), "coefficients"),
]


@pytest.mark.parametrize("mistake, phrase", WRONG_RECONSTRUCTIONS, ids=[p for _, p in WRONG_RECONSTRUCTIONS])
def test_wrong_reconstruction_is_named(mistake, phrase):
    result = check.spectral_reconstruction(learner(**mistake))
    assert_diagnosed(result, phrase, REREAD)
    assert result.partial


def test_zeroed_boundary_rows_pass_on_a_closed_mesh_and_fail_on_the_open_one():
    result = check.spectral_reconstruction(learner(zero_boundary=True))
    assert "49-vertex jittered saddle (open" in result.message


def test_zeroed_boundary_rows_with_a_sparse_solver_still_fail():
    def sparse_asymmetric(M, C, k):
        lam, E = sla.eigs(-C, k, M, sigma=-1e-8)  # C is no longer symmetric
        order = np.argsort(lam.real)
        return lam[order].real, E[:, order].real

    result = check.spectral_reconstruction(learner(sparse_asymmetric, zero_boundary=True))
    assert not result.passed and "open" in result.message, result.message


def test_wrong_shape_is_a_catch_all():
    result = check.spectral_reconstruction(learner(out=lambda X, c: X[:, 0]))
    assert_diagnosed(result, "expected (")
    assert not result.partial


def test_reconstruction_stub_is_not_written_yet():
    def stub(V, F, k):
        raise NotImplementedError("Your turn")

    assert_diagnosed(check.spectral_reconstruction(stub), "not written yet")


def test_exception_is_named():
    assert_diagnosed(check.spectral_reconstruction(lambda V, F, k: np.linalg.inv(laplacian(V, F)[0]) @ V), "raised")


def test_strict_mode_raises_for_a_written_wrong_function(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "1")
    with pytest.raises(CheckFailed, match="plain dot product"):
        check.spectral_reconstruction(learner(inner="plain"))
    with pytest.raises(CheckFailed, match="M is left out"):
        check.eigenpairs(without_M)
