"""The checks of notebook 04's exercises: every correct variant passes, every entry of a catalogue is
named when a learner's code makes it, the shortcuts the ground rules exclude are refused.

The learners' code is written fresh with numpy and scipy: the reduction to the symmetric
Q = -M^-1/2 C M^-1/2 solved densely (numpy or scipy) or by shift-invert Lanczos (eigsh on Q).
"""

import numpy as np
import pytest
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from geomlib import check, laplacian
from geomlib.teaching.check.spectral import E_MISTAKES, LAM_MISTAKES, RECONSTRUCTION_MISTAKES


@pytest.fixture(autouse=True)
def lenient(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")


# --------------------------------------------------------------------------- the eigenpairs


def reduced(
    M, C, k, sign=1.0, exponent=-0.5, back=-0.5, solver="numpy", first=0, normalise="M", order="sorted", out="pair"
):
    """A learner's reduction with the named changes: Q = -sign D C D, D = M^exponent; E = M^back Z."""
    m = M.diagonal()
    D = sp.diags(m**exponent)
    Q = -sign * (D @ C @ D)
    if solver == "numpy":
        lam, Z = np.linalg.eigh(Q.toarray())
    elif solver == "scipy":
        lam, Z = la.eigh(Q.toarray())
    elif solver == "eig":
        lam, Z = np.linalg.eig(Q.toarray())
        lam, Z = lam.real, Z.real
    else:  # shift-invert Lanczos, sorted afterwards
        lam, Z = sla.eigsh(Q.tocsc(), k + first, sigma=-1e-3 * 4 * np.pi / m.sum())
        if order == "sorted":
            lam, Z = lam[np.argsort(lam)], Z[:, np.argsort(lam)]
    if order == "largest":
        lam, Z = lam[::-1][:k][::-1], Z[:, ::-1][:, :k][:, ::-1]
    lam, Z = lam[first : first + k], Z[:, first : first + k]
    E = sp.diags(m**back) @ Z
    if normalise == "M":
        E = E / np.sqrt(np.einsum("ij,i,ij->j", E, m, E))
    elif normalise == "plain":
        E = E / np.linalg.norm(E, axis=0)
    elif normalise == "twice":
        E = 2 * E / np.sqrt(np.einsum("ij,i,ij->j", E, m, E))
    if out == "lists":
        return list(lam), E.tolist()
    return (E, lam) if out == "swapped" else (E.T, lam)[::-1] if out == "transposed" else (lam, E)


def signs_flipped(M, C, k):
    lam, E = reduced(M, C, k)
    return lam, E * np.where(np.arange(k) % 2, -1.0, 1.0)


CORRECT = {
    "numpy": reduced,
    "scipy": lambda M, C, k: reduced(M, C, k, solver="scipy"),
    "eigsh on Q": lambda M, C, k: reduced(M, C, k, solver="eigsh"),
    "lists": lambda M, C, k: reduced(M, C, k, out="lists"),
    "signs flipped": signs_flipped,
}


@pytest.mark.parametrize("name", CORRECT)
def test_correct_solvers_pass(name):
    result = check.eigenpairs.evaluate(CORRECT[name])
    assert result.passed, result.message


EIGEN_LEARNERS = {
    "the sign of C is flipped: the eigenvalues are <= 0": lambda M, C, k: reduced(M, C, k, sign=-1.0, order="largest"),
    "the first k of M^-1/2 C M^-1/2 are its most negative": lambda M, C, k: reduced(M, C, k, sign=-1.0),
    "the k largest, not the k smallest": lambda M, C, k: reduced(M, C, k, order="largest"),
    "the null mode is lost": lambda M, C, k: reduced(M, C, k, first=1),
    "M is left out": lambda M, C, k: reduced(M, C, k, exponent=0.0, back=0.0),
    "M^-1 stands on both sides": lambda M, C, k: reduced(M, C, k, exponent=-1.0, back=-1.0),
    "the eigenvalues are not sorted": lambda M, C, k: reduced(M, C, k, solver="eig"),
    "differ from the k smallest": lambda M, C, k: (1.1 * reduced(M, C, k)[0], reduced(M, C, k)[1]),
    "not transformed back": lambda M, C, k: reduced(M, C, k, back=0.0, normalise="none"),
    "uses M^-1 instead of M^-1/2": lambda M, C, k: reduced(M, C, k, back=-1.0, normalise="none"),
    "the columns of E are not eigenvectors": lambda M, C, k: (reduced(M, C, k)[0], reduced(M, C, k)[1][:, ::-1]),
    "normalised in the plain dot product": lambda M, C, k: reduced(M, C, k, normalise="plain"),
    "E^T M E is diagonal but not I": lambda M, C, k: reduced(M, C, k, normalise="twice"),
}
NOT_TYPICAL = {"differ from the k smallest", "the columns of E are not eigenvectors"}


@pytest.mark.parametrize("name", EIGEN_LEARNERS)
def test_each_eigenpairs_mistake_is_named(name):
    result = check.eigenpairs.evaluate(EIGEN_LEARNERS[name])
    assert not result.passed and name in result.message, result.message
    assert result.partial == (name not in NOT_TYPICAL), result.message


@pytest.mark.parametrize("out", ["swapped", "transposed"])
def test_a_wrong_shape_earns_nothing(out):
    result = check.eigenpairs.evaluate(lambda M, C, k: reduced(M, C, k, out=out))
    assert not result.passed and not result.partial, result.message


def test_a_generalised_solver_is_refused_however_it_is_imported():
    from scipy.linalg import eigh as imported

    learners = {
        "scipy.linalg.eigh": lambda M, C, k: imported(-C.toarray(), M.toarray(), subset_by_index=[0, k - 1]),
        "scipy.sparse.linalg.eigsh": lambda M, C, k: sla.eigsh(-C, k, M, sigma=-1e-3),
    }
    for name, learner in learners.items():
        result = check.eigenpairs.evaluate(learner)
        assert not result.partial and f"calls {name} with a second matrix" in result.message, result.message


# --------------------------------------------------------------------------- the reconstruction


def projection(
    V,
    F,
    k,
    weights="cotan",
    area="barycentric",
    first=0,
    extra=0,
    inner="M",
    zero_boundary=False,
    out="positions",
    swap=False,
):
    """A learner's V_k with the named changes (dense basis of the reduction)."""
    M, C = laplacian(V, F, weights=weights, area=area)
    if swap:
        M, C = C, M
    m = M.diagonal()
    C = C.toarray()
    if zero_boundary:
        edges = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
        once, count = np.unique(edges, axis=0, return_counts=True)
        C[np.unique(once[count == 1]), :] = 0.0  # the boundary vertices' rows
        E = la.eigh(-C, np.diag(m))[1]
    else:
        d = 1 / np.sqrt(m)
        E = d[:, None] * np.linalg.eigh(-(d[:, None] * C * d[None, :]))[1]
    E = E[:, first : k + extra]
    W = {"M": m[:, None] * V, "plain": V, "left": V, "inverse": V / m[:, None], "C": C @ V}[inner]
    c = E.T @ W
    if out == "coefficients":
        return c
    return m[:, None] * (E @ (E.T @ V)) if inner == "left" else E @ c


def eig_rows(V, F, k):
    """np.linalg.eig of -C alone, its eigenvector matrix sorted by rows: M left out, rows for columns."""
    w, U = np.linalg.eig(-laplacian(V, F)[1].toarray())
    basis = U.real[np.argsort(w.real)][:, :k]
    return basis @ (basis.T @ V)


RECONSTRUCTION_LEARNERS = {
    "the plain dot product E_k^T V": lambda V, F, k: projection(V, F, k, inner="plain"),
    "V is divided by the vertex areas": lambda V, F, k: projection(V, F, k, inner="inverse"),
    "M multiplies the result": lambda V, F, k: projection(V, F, k, inner="left"),
    "C stands where M belongs": lambda V, F, k: projection(V, F, k, inner="C"),
    "dropped and the plain inner product is used": lambda V, F, k: projection(V, F, k, first=1, inner="plain"),
    "the constant eigenvector e_0 (lam = 0) is left out": lambda V, F, k: projection(V, F, k, first=1),
    "one eigenvector too few": lambda V, F, k: projection(V, F, k, extra=-1),
    "one eigenvector too many": lambda V, F, k: projection(V, F, k, extra=1),
    "the uniform operator": lambda V, F, k: projection(V, F, k, weights="uniform"),
    "the mixed (Voronoi) vertex areas": lambda V, F, k: projection(V, F, k, area="mixed"),
    "the rows of the boundary vertices are zeroed": lambda V, F, k: projection(V, F, k, zero_boundary=True),
    "(M, C) are swapped": lambda V, F, k: projection(V, F, k, swap=True),
    "the rows of the eigenvector matrix are sorted": eig_rows,
    "differs from the M-orthogonal projection": lambda V, F, k: 1.01 * projection(V, F, k),
}


def test_the_reconstruction_passes():
    assert check.spectral_reconstruction.evaluate(projection).passed


@pytest.mark.parametrize("name", RECONSTRUCTION_LEARNERS)
def test_each_reconstruction_mistake_is_named(name):
    result = check.spectral_reconstruction.evaluate(RECONSTRUCTION_LEARNERS[name])
    assert not result.passed and name in result.message, result.message
    assert result.partial == (name != "differs from the M-orthogonal projection"), result.message


def test_the_coefficients_returned_are_named_but_earn_nothing():
    result = check.spectral_reconstruction.evaluate(lambda V, F, k: projection(V, F, k, out="coefficients"))
    assert not result.passed and not result.partial and "coefficients" in result.message, result.message


@pytest.mark.parametrize(
    "catalogue, learners",
    [(LAM_MISTAKES + E_MISTAKES, EIGEN_LEARNERS), (RECONSTRUCTION_MISTAKES, RECONSTRUCTION_LEARNERS)],
)
def test_every_entry_of_a_catalogue_has_a_learner_here(catalogue, learners):
    for entry in catalogue:
        if "repeated eigenvalue" in entry.diagnosis or "M-orthogonal projection on" in entry.diagnosis:
            continue  # catch-alls of a repeated eigenspace, and of a projection (tested above)
        assert any(name in entry.diagnosis for name in learners), entry.diagnosis


@pytest.mark.parametrize("name", ["eigenpairs", "spectral_reconstruction"])
def test_a_stub_is_not_written_yet(name):
    def stub(*args):
        raise NotImplementedError

    result = getattr(check, name).evaluate(stub)
    assert not result.passed and not result.written and "not written yet" in result.message


def test_the_checks_pass_whatever_the_seed():
    for seed in (0, 1, 2):
        assert check.eigenpairs.evaluate(reduced, seed=seed).passed
        assert check.spectral_reconstruction.evaluate(projection, seed=seed).passed
