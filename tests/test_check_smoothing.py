"""The exercise checks of notebooks 05 and 06: each accepts the reference
solution, names every typical wrong implementation of the catalogue by its
mistake, and reports an unwritten stub as "not written yet"."""

import time

import numpy as np
import pytest
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as sla
from diagnoses import assert_diagnosed

from geomlib import check, laplacian
from geomlib import explicit_step_limit as reference_limit_of_mesh
from geomlib.lessons.smoothing import explicit_step, implicit_step
from geomlib.teaching.check import CheckFailed


@pytest.fixture(autouse=True)
def lenient(monkeypatch):
    """Checks return their verdict instead of raising (the notebooks' reader mode)."""
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")


def areas(M):
    return M.diagonal()[:, None]


def reference_limit(M, C):
    return 2 / scipy.linalg.eigh(-C.toarray(), M.toarray(), eigvals_only=True)[-1]


def solve(A, B):
    return sla.spsolve(sp.csc_matrix(A), B)


STEP_MISTAKES = {
    "sign": (lambda P, M, C, tau: P - tau * (C @ P) / areas(M), "sign is flipped"),
    "C for M^-1 C": (lambda P, M, C, tau: P + tau * (C @ P), "C was used where M^-1 C belongs"),
    "displacement": (lambda P, M, C, tau: tau * (C @ P) / areas(M), "returns the displacement"),
    "times M": (lambda P, M, C, tau: P + tau * areas(M) * (C @ P), "multiplied by M instead of divided"),
    "no tau": (lambda P, M, C, tau: P + (C @ P) / areas(M), "the step tau is missing"),
    "C M^-1": (lambda P, M, C, tau: P + tau * (C @ (P / areas(M))), "C M^-1 P"),
    "one coordinate": (lambda P, M, C, tau: (P + tau * (C @ P) / areas(M))[:, 0], "expected ("),
    "something else": (lambda P, M, C, tau: P + 0.5 * tau * (C @ P) / areas(M), "differ from P + tau M^-1 C P"),
}


@pytest.mark.parametrize("name", STEP_MISTAKES)
def test_a_step_mistake_the_check_names_earns_partial_credit(name):
    wrong, _ = STEP_MISTAKES[name]
    earned = check.explicit_step.partial_credit(wrong).passed
    assert earned == (name not in ("one coordinate", "something else")), check.explicit_step(wrong).message


def on_matrices(wrong):
    """A learner's fn(V, F) that builds (M, C) and then makes the mistake ``wrong(M, C)``."""
    return lambda V, F: wrong(*laplacian(V, F))


LIMIT_MISTAKES = {
    "1/lam_max": (lambda M, C: reference_limit(M, C) / 2, "1 / lam_max, half the true one"),
    "eigenvalues of C": (lambda M, C: 2 / np.linalg.eigvalsh(-C.toarray())[-1], "from C instead of M^-1 C"),
    "smallest non-zero": (
        lambda M, C: 2 / scipy.linalg.eigh(-C.toarray(), M.toarray(), eigvals_only=True)[1],
        "smallest non-zero eigenvalue",
    ),
    "smallest, zero": (
        lambda M, C: 2 / abs(scipy.linalg.eigh(-C.toarray(), M.toarray(), eigvals_only=True)[0]),
        "smallest eigenvalue (0, the constant mode)",
    ),
    "sign": (lambda M, C: -reference_limit(M, C), "negative limit"),
    "lam_max itself": (lambda M, C: 2 / reference_limit(M, C), "returns lam_max"),
    "a vector": (lambda M, C: np.full(3, reference_limit(M, C)), "not one number"),
}

IMPLICIT_MISTAKES = {
    "M + tau C": (lambda P, M, C, tau: solve(M + tau * C, M @ P), "(M + tau C) instead of (M - tau C)"),
    "rhs P": (lambda P, M, C, tau: solve(M - tau * C, P), "right-hand side is P instead of M P"),
    "I - tau C": (lambda P, M, C, tau: solve(sp.identity(len(P)) - tau * C, P), "(I - tau C): M is missing"),
    "explicit": (lambda P, M, C, tau: P + tau * (C @ P) / areas(M), "one explicit step"),
    "displacement": (lambda P, M, C, tau: solve(M - tau * C, M @ P) - P, "returns the displacement"),
    "transposed": (lambda P, M, C, tau: solve(M - tau * C, M @ P).T, "expected ("),
}


def test_references_pass_quickly():
    for name, fn in (
        ("explicit_step", explicit_step),
        ("explicit_step_limit", reference_limit_of_mesh),
        ("explicit_step_limit", on_matrices(reference_limit)),
        ("implicit_step", implicit_step),
    ):
        start = time.perf_counter()
        result = getattr(check, name)(fn)
        assert result.passed, result.message
        assert "tetrahedron" in result.message and "ellipsoid" in result.message
        assert time.perf_counter() - start < 1.0


def test_the_equivalent_implicit_form_passes():
    def with_delta(P, M, C, tau):  # (I - tau M^-1 C) P' = P is the same system divided by M
        return solve(sp.identity(len(P)) - tau * sp.diags(1 / M.diagonal()) @ C, P)

    assert check.implicit_step(with_delta).passed


@pytest.mark.parametrize("name", STEP_MISTAKES)
def test_explicit_step_mistakes(name):
    fn, phrase = STEP_MISTAKES[name]
    assert_diagnosed(check.explicit_step(fn), phrase, "Reread section 2 · Discretised in space and time")


@pytest.mark.parametrize("name", LIMIT_MISTAKES)
def test_explicit_step_limit_mistakes(name):
    wrong, phrase = LIMIT_MISTAKES[name]
    assert_diagnosed(
        check.explicit_step_limit(on_matrices(wrong)), phrase, "Reread section 3 · Why the step has a limit"
    )


@pytest.mark.parametrize("name", IMPLICIT_MISTAKES)
def test_implicit_step_mistakes(name):
    fn, phrase = IMPLICIT_MISTAKES[name]
    assert_diagnosed(check.implicit_step(fn), phrase, "Reread section 1 · Backward Euler, derived")


@pytest.mark.parametrize("name", ["explicit_step", "explicit_step_limit", "implicit_step"])
def test_stubs_are_not_written_yet(name, monkeypatch):
    def stub(*args):
        raise NotImplementedError("Your turn")

    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "1")  # a stub never raises, even under the tests
    assert_diagnosed(getattr(check, name)(stub), "not written yet")


def test_a_wrong_answer_raises_under_the_strict_tests(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "1")
    with pytest.raises(CheckFailed, match="sign is flipped"):
        check.explicit_step(STEP_MISTAKES["sign"][0])


def test_a_crashing_function_is_named():
    assert_diagnosed(check.implicit_step(lambda P, M, C, tau: P @ M), "raised ValueError")
