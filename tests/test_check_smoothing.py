"""The exercise checks of notebooks 05 and 06: each accepts the reference
solution and its legitimate variants (an iterative solver at its default
tolerance, dense matrices, any way of holding a boundary), names every typical
wrong implementation of the catalogue (written here with numpy and scipy) by its
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
from geomlib.mesh.topology import boundary_vertices
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
    # the uniform step (neighbour averaging) written for the cotangent C it was handed
    "divided by |C_ii|": (lambda P, M, C, tau: P + tau * (C @ P) / -C.diagonal()[:, None], "divides C P by |C_ii|"),
    "neighbour average": (
        lambda P, M, C, tau: P + tau * (neighbours(C) @ P / neighbours(C).sum(axis=1).A - P),
        "the uniform step (every neighbour weighs 1",
    ),
    "C P over the valence": (
        lambda P, M, C, tau: P + tau * (C @ P) / neighbours(C).sum(axis=1).A,
        "the uniform step (every neighbour weighs 1",
    ),
}


def neighbours(C):
    """The adjacency of C's graph, every weight 1 (what a uniform step averages over)."""
    A = sp.csr_matrix(C, copy=True)
    A.setdiag(0)
    A.eliminate_zeros()
    A.data[:] = 1.0
    return A


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


def step(P, M, C, tau):
    return P + tau * (C @ P) / areas(M)


def implicit(P, M, C, tau):
    return solve(M - tau * C, M @ P)


def test_references_pass_quickly():
    for name, fn in (
        ("explicit_step", step),
        ("explicit_step_limit", on_matrices(reference_limit)),
        ("implicit_step", implicit),
        ("smoothing_loop", masked_rows),
    ):
        start = time.perf_counter()
        result = getattr(check, name)(fn)
        assert result.passed, result.message
        assert "ellipsoid" in result.message
        assert time.perf_counter() - start < 1.0


@pytest.mark.parametrize(
    "name, fn",
    [
        ("explicit_step", explicit_step),
        ("explicit_step_limit", reference_limit_of_mesh),
        ("implicit_step", implicit_step),
    ],
)
def test_geomlibs_own_routine_is_refused(name, fn):
    assert_diagnosed(getattr(check, name)(fn), "earns no points")


def by_columns(solver, **options):
    """An implicit step solved column by column with an iterative ``solver`` of scipy at its defaults."""

    def fn(P, M, C, tau):
        A, R = sp.csr_matrix(M - tau * C), M @ P
        return np.column_stack([solver(A, R[:, j], **options)[0] for j in range(R.shape[1])])

    return fn


IMPLICIT_VARIANTS = {
    "cg, default tolerance": by_columns(sla.cg),
    "minres, default tolerance": by_columns(sla.minres),
    "bicgstab, default tolerance": by_columns(sla.bicgstab),
    "dense solve": lambda P, M, C, tau: np.linalg.solve((M - tau * C).toarray(), M @ P),
    "splu": lambda P, M, C, tau: sla.splu(sp.csc_matrix(M - tau * C)).solve(M @ P),
}


@pytest.mark.parametrize("name", IMPLICIT_VARIANTS)
def test_a_right_implicit_step_passes_whatever_its_solver(name):
    result = check.implicit_step(IMPLICIT_VARIANTS[name])
    assert result.passed, result.message


def test_a_mistake_solved_by_cg_is_still_named():
    def rhs_p_by_cg(P, M, C, tau):
        A = sp.csr_matrix(M - tau * C)
        return np.column_stack([sla.cg(A, P[:, j])[0] for j in range(3)])

    assert_diagnosed(check.implicit_step(rhs_p_by_cg), "right-hand side is P instead of M P")


def test_the_equivalent_implicit_form_passes():
    def with_delta(P, M, C, tau):  # (I - tau M^-1 C) P' = P is the same system divided by M
        return solve(sp.identity(len(P)) - tau * sp.diags(1 / M.diagonal()) @ C, P)

    assert check.implicit_step(with_delta).passed


@pytest.mark.parametrize("name", STEP_MISTAKES)
def test_explicit_step_mistakes(name):
    fn, phrase = STEP_MISTAKES[name]
    assert_diagnosed(check.explicit_step(fn), phrase, "Reread section 1 · The heat flow, one explicit step at a time")


@pytest.mark.parametrize("name", LIMIT_MISTAKES)
def test_explicit_step_limit_mistakes(name):
    wrong, phrase = LIMIT_MISTAKES[name]
    assert_diagnosed(
        check.explicit_step_limit(on_matrices(wrong)), phrase, "Reread section 2 · Why the step has a limit"
    )


@pytest.mark.parametrize("name", IMPLICIT_MISTAKES)
def test_implicit_step_mistakes(name):
    fn, phrase = IMPLICIT_MISTAKES[name]
    assert_diagnosed(check.implicit_step(fn), phrase, "Reread section 1 · Backward Euler, derived")


@pytest.mark.parametrize("name", ["explicit_step", "explicit_step_limit", "implicit_step", "smoothing_loop"])
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


# --------------------------------------------------------------------------
# the smoothing loop with the boundary held (notebook 05, section 4)


def held(F, n):
    mask = np.zeros(n, dtype=bool)
    mask[boundary_vertices(F, n)] = True
    return mask


def masked_rows(V, F, tau, iterations):
    M, C = laplacian(V, F)
    moving, P = ~held(F, len(V)), V.copy()
    for _ in range(iterations):
        P = P + tau * moving[:, None] * (C @ P) / areas(M)
    return P


def reset_positions(V, F, tau, iterations):
    M, C = laplacian(V, F)
    B, P = held(F, len(V)), V.copy()
    for _ in range(iterations):
        P = P + tau * (C @ P) / areas(M)
        P[B] = V[B]
    return P


def reduced_system(V, F, tau, iterations):
    M, C = laplacian(V, F)
    B = held(F, len(V))
    C = C.tocsr()
    C_II, C_IB, m_I = C[~B][:, ~B], C[~B][:, B], M.diagonal()[~B][:, None]
    P = V.copy()
    for _ in range(iterations):
        P[~B] = P[~B] + tau * (C_II @ P[~B] + C_IB @ V[B]) / m_I
    return P


def dense_matrix_power(V, F, tau, iterations):
    M, C = laplacian(V, F)
    S = C.toarray() / M.diagonal()[:, None]
    S[held(F, len(V))] = 0.0
    return np.linalg.matrix_power(np.eye(len(V)) + tau * S, iterations) @ V


def every_vertex(V, F, tau, iterations):
    M, C = laplacian(V, F)
    P = V.copy()
    for _ in range(iterations):
        P = P + tau * (C @ P) / areas(M)
    return P


def rebuilt_each_step(V, F, tau, iterations):
    moving, P = ~held(F, len(V)), V.copy()
    for _ in range(iterations):
        M, C = laplacian(P, F)
        P = P + tau * moving[:, None] * (C @ P) / areas(M)
    return P


def rebuilt_and_free(V, F, tau, iterations):
    P = V.copy()
    for _ in range(iterations):
        M, C = laplacian(P, F)
        P = P + tau * (C @ P) / areas(M)
    return P


def uniform_weights(V, F, tau, iterations):
    M, C = laplacian(V, F, weights="uniform")
    moving, P = ~held(F, len(V)), V.copy()
    for _ in range(iterations):
        P = P + tau * moving[:, None] * (C @ P) / areas(M)
    return P


def half_held(V, F, tau, iterations):
    P, Q = masked_rows(V, F, tau, iterations), every_vertex(V, F, tau, iterations)
    B = held(F, len(V))
    P[B] = (P[B] + Q[B]) / 2
    return P


LOOP_VARIANTS = {
    "rows masked": masked_rows,
    "positions reset": reset_positions,
    "reduced system": reduced_system,
    "dense matrix power": dense_matrix_power,
}

LOOP_MISTAKES = {
    "the boundary moves": (every_vertex, "the boundary moves: every vertex was updated"),
    "operator rebuilt": (rebuilt_each_step, "M and C are rebuilt from the moving mesh at every step"),
    "rebuilt and free": (rebuilt_and_free, "smoothing asked for); the boundary moves: every vertex"),
    "N - 1 steps": (lambda V, F, tau, n: masked_rows(V, F, tau, n - 1), "3 steps for iterations = 4 (one too few)"),
    "N + 1 steps": (lambda V, F, tau, n: masked_rows(V, F, tau, n + 1), "5 steps for iterations = 4 (one too many)"),
    "uniform weights": (uniform_weights, "smooths with the uniform operator"),
    "sign": (lambda V, F, tau, n: masked_rows(V, F, -tau, n), "sign of the step is flipped"),
    "no areas": (lambda V, F, tau, n: no_areas(V, F, tau, n), "not divided by the vertex areas"),
    "boundary half held": (half_held, "the boundary vertices moved (the furthest by"),
    "something else": (lambda V, F, tau, n: masked_rows(V, F, 0.7 * tau, n), "differ from the loop"),
    "the input": (lambda V, F, tau, n: V.copy(), "returns the input positions unchanged"),
}


def no_areas(V, F, tau, iterations):
    M, C = laplacian(V, F)
    moving, P = ~held(F, len(V)), V.copy()
    for _ in range(iterations):
        P = P + tau * moving[:, None] * (C @ P)
    return P


@pytest.mark.parametrize("name", LOOP_VARIANTS)
def test_any_way_of_holding_the_boundary_passes(name):
    result = check.smoothing_loop(LOOP_VARIANTS[name])
    assert result.passed, result.message
    assert "open noisy grid" in result.message and "closed ellipsoid" in result.message


@pytest.mark.parametrize("name", LOOP_MISTAKES)
def test_smoothing_loop_mistakes(name):
    fn, phrase = LOOP_MISTAKES[name]
    result = check.smoothing_loop(fn)
    assert_diagnosed(result, phrase, "Reread section 3 · The smoothing loop, boundary held")
    assert check.smoothing_loop.partial_credit(fn).passed == (name != "something else"), result.message


def test_the_loop_may_not_hand_the_work_to_geomlibs_smoothers():
    from geomlib import ExplicitSmoother, ImplicitSmoother, implicit_smoothing
    from geomlib.lessons.operator import LaplaceOperator

    for fn, named in (
        (lambda V, F, tau, n: ExplicitSmoother(V, F).smooth(tau, n), "ExplicitSmoother"),
        (lambda V, F, tau, n: implicit_smoothing(V, F, tau, n), "implicit_smoothing"),
        (lambda V, F, tau, n: ImplicitSmoother(V, F).smooth(tau, n), "ImplicitSmoother"),
        (lambda V, F, tau, n: LaplaceOperator(V, F).M_step @ V, "LaplaceOperator"),
    ):
        assert_diagnosed(check.smoothing_loop(fn), f"`{named}`", "earns no points")


def zeroed_boundary_areas(V, F, tau, iterations):
    M, C = laplacian(V, F)
    moving, P = ~held(F, len(V)), V.copy()
    m = M.diagonal().copy()
    m[~moving] = 0.0  # "no area, no motion": 0 * (C P / 0) is NaN on the boundary rows
    for _ in range(iterations):
        P = P + tau * moving[:, None] * (C @ P) / m[:, None]
    return P


NAN_MISTAKES = {
    # each exercise's NaN gets the hint of its own likely cause, not another exercise's
    "explicit step, dense 1 / M": (
        check.explicit_step,
        lambda P, M, C, tau: P + tau * (1 / M.toarray()) @ (C @ P),
        "not by a dense 1 / M",
    ),
    "loop, boundary areas zeroed": (check.smoothing_loop, zeroed_boundary_areas, "areas zeroed on the boundary rows"),
    "implicit step, dense 1 / M": (
        check.implicit_step,
        lambda P, M, C, tau: solve(np.eye(len(P)) - tau * (1 / M.toarray()) @ C.toarray(), P),
        "the system's matrix holds infinities",
    ),
}


@pytest.mark.parametrize("name", NAN_MISTAKES)
@pytest.mark.filterwarnings("ignore::RuntimeWarning", "ignore::scipy.sparse.linalg.MatrixRankWarning")
def test_nan_positions_are_told_their_own_cause(name):
    run_check, fn, phrase = NAN_MISTAKES[name]
    assert_diagnosed(run_check(fn), "NaN or infinite positions", phrase)
