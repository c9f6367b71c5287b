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
from geomlib.teaching.check.spectral import E_MISTAKES, ERROR_MISTAKES, LAM_MISTAKES, POSITION_MISTAKES


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


# --------------------------------------------------------------------------- the reconstructions and their errors


def study(V, F, ks, solve, weights="cotan", area="barycentric", first=0, extra=0, inner="M", zero_boundary=False,
          swap=False, centre=None, each=False, own=False, error="right", out="lists"):  # fmt: skip
    """A learner's reconstructions V_k for each k of ks and their errors, with the named changes."""
    M, C = laplacian(V, F, weights=weights, area=area)
    m = M.diagonal()
    if zero_boundary or own:  # the learner's own dense solve, not the one handed in
        C = C.toarray()
        if zero_boundary:
            edges = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
            once, count = np.unique(edges, axis=0, return_counts=True)
            C[np.unique(once[count == 1]), :] = 0.0  # the boundary vertices' rows
        E = la.eigh(-C, np.diag(m))[1] if zero_boundary else reduced(M, sp.csr_matrix(C), max(ks))[1]
    else:
        E = solve(C, M, max(ks))[1] if swap else solve(M, C, max(ks) + max(extra, 0))[1]
    mean = V.mean(axis=0)
    X = V - mean if centre else V
    W = {"M": m[:, None] * X, "plain": X, "left": X, "inverse": X / m[:, None]}[inner]
    V_ks = []
    for k in ks:
        Ek = (solve(M, C, k + extra)[1] if each else E)[:, first : k + extra]
        Y = m[:, None] * (Ek @ (Ek.T @ X)) if inner == "left" else Ek @ (Ek.T @ W)
        V_ks.append(Y + mean if centre == "back" else Y)
    gaps, d = [V - Y for Y in V_ks], np.linalg.norm(V.max(axis=0) - V.min(axis=0))
    norms = np.array([np.sqrt(np.sum(m[:, None] * g**2)) for g in gaps])
    err = {
        "right": norms / np.sqrt(m.sum()) / d,
        "not relative": norms,
        "no diagonal": norms / np.sqrt(m.sum()),
        "squared": norms**2 / m.sum() / d,
        "Euclidean": np.array([np.linalg.norm(g) for g in gaps]) / d,
        "centred": norms / np.sqrt(np.sum(m[:, None] * (V - mean) ** 2)),
        "shifted": norms / np.sqrt(m.sum()) / d + 0.01 * np.arange(len(ks)),
    }[error]
    if out == "arrays":
        return np.stack(V_ks), err
    return (V_ks, list(err)) if out == "lists" else V_ks


STUDY_CORRECT = {
    "one solve, lists": study,
    "arrays": lambda V, F, ks, solve: study(V, F, ks, solve, out="arrays"),
    "one solve per k": lambda V, F, ks, solve: study(V, F, ks, solve, each=True),
    "centred and the mean added back": lambda V, F, ks, solve: study(V, F, ks, solve, centre="back"),
    "its own solve by the reduction": lambda V, F, ks, solve: study(V, F, ks, solve, own=True),
}

STUDY_LEARNERS = {
    "the plain dot product E_k^T V": dict(inner="plain"),
    "V is divided by the vertex areas": dict(inner="inverse"),
    "M multiplies the result": dict(inner="left"),
    "the constant eigenvector e_0 (lam = 0) is left out": dict(first=1),
    "the mean is taken out twice": dict(centre="back", first=1),
    "the mean is not added back": dict(centre="away"),
    "one eigenvector too few": dict(extra=-1),
    "one eigenvector too many": dict(extra=1),
    "the uniform operator": dict(weights="uniform"),
    "the mixed (Voronoi) vertex areas": dict(area="mixed"),
    "the rows of the boundary vertices are zeroed": dict(zero_boundary=True),
    "(M, C) are swapped": dict(swap=True),
    "the errors are not relative": dict(error="not relative"),
    "not divided by the bounding-box diagonal": dict(error="no diagonal"),
    "the square root is missing": dict(error="squared"),
    "weighted equally (the Euclidean norm)": dict(error="Euclidean"),
    "right up to one factor": dict(error="centred"),
    "the errors differ from": dict(error="shifted"),
}
NOT_TYPICAL_STUDY = {"differs from the M-orthogonal projection", "the errors differ from"}


@pytest.mark.parametrize("name", STUDY_CORRECT)
def test_correct_studies_pass(name):
    result = check.spectral_reconstruction.evaluate(STUDY_CORRECT[name])
    assert result.passed, result.message


@pytest.mark.parametrize("name", [*STUDY_LEARNERS, "differs from the M-orthogonal projection"])
def test_each_study_mistake_is_named(name):
    if name in STUDY_LEARNERS:
        learner = lambda V, F, ks, solve: study(V, F, ks, solve, **STUDY_LEARNERS[name])  # noqa: E731
    else:
        learner = lambda V, F, ks, solve: ([1.01 * Y for Y in study(V, F, ks, solve)[0]], study(V, F, ks, solve)[1])  # noqa: E731
    result = check.spectral_reconstruction.evaluate(learner)
    assert not result.passed and name in result.message, result.message
    assert result.partial == (name not in NOT_TYPICAL_STUDY), result.message


def test_the_eigenpairs_come_from_the_solve_handed_in_however_often_it_is_called():
    calls = []

    def counting(V, F, ks, solve):
        def counted(M, C, k):
            calls.append(k)
            return solve(M, C, k)

        return study(V, F, ks, counted, each=True)

    assert check.spectral_reconstruction.evaluate(counting).passed
    assert sorted(set(calls)) == [1, 3, 4, 8, 12]  # ks = [1, 4, 12] and [3, 8], once per k


def test_a_study_of_the_wrong_shape_earns_nothing():
    for learner in (
        lambda V, F, ks, solve: study(V, F, ks, solve, out="positions"),  # the V_k alone
        lambda V, F, ks, solve: (study(V, F, ks, solve)[0][:1], study(V, F, ks, solve)[1][:1]),  # the first k only
        lambda V, F, ks, solve: (study(V, F, ks, solve)[0], np.zeros((len(ks), 3))),  # errors per coordinate
    ):
        result = check.spectral_reconstruction.evaluate(learner)
        assert not result.passed and not result.partial, result.message


@pytest.mark.parametrize(
    "catalogue, learners",
    [(LAM_MISTAKES + E_MISTAKES, EIGEN_LEARNERS), (POSITION_MISTAKES + ERROR_MISTAKES, STUDY_LEARNERS)],
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
        assert check.spectral_reconstruction.evaluate(study, seed=seed).passed
