"""Checks of the exercises of notebook 06 (one implicit step).

Convention of the workbook: Delta = M^-1 C (C symmetric negative semidefinite,
M diagonal); one implicit (backward Euler) step solves (M - tau C) P' = M P.
"""

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from ...lessons.laplace import laplacian
from .catalogue import positions
from .explicit import step_cases
from .result import Mistake, call, close, exercise

__all__ = ["implicit_step"]

_REREAD = "section 1 · Backward Euler, derived"


#: How close an answer must come to the solution, as a fraction of the largest coordinate. An
#: iterative solver at its default tolerance lands within it (scipy's cg about 4e-6 on these cases,
#: minres 7e-5); every mistake the check names lies at least 0.067 away (I - tau C on the ellipsoid).
AGREE = 1e-3


# NaN from a solve comes from its matrix: infinities in it (a dense 1 / M) or a singular one (C alone)
_NAN_HINT = (
    "the system's matrix holds infinities (a dense 1 / M divides by its zeros off the diagonal) or is singular "
    "(C alone: its rows sum to zero); solve (M - tau C) P' = M P, positive definite for every tau >= 0"
)


def _solve(A, B):
    return sla.spsolve(sp.csc_matrix(A), B)


@exercise(
    "implicit_step",
    reread=_REREAD,
    forbid=(
        "lessons.smoothing.implicit_step",
        "lessons.smoothing.implicit_smoothing",
        "lessons.smoothing.ImplicitSmoother",
    ),
)
def implicit_step(fn):
    """Check ``fn(P, M, C, tau) -> P'`` solving (M - tau C) P' = M P."""
    checked = []
    rng = np.random.default_rng(6)
    for label, V, F in step_cases():
        M, C = laplacian(V, F)
        I = sp.identity(len(V), format="csc")
        # tau lam_max about 3: far from both 0 (where every scheme agrees) and the explicit limit 2
        tau = 3.0 / np.abs(C.diagonal() / M.diagonal()).max()
        for P in (V, V + 0.05 * rng.standard_normal(V.shape)):
            out = positions(call(fn, P.copy(), M.copy(), C.copy(), tau), len(V), nan_hint=_NAN_HINT)
            right = _solve(M - tau * C, M @ P)
            atol = AGREE * np.abs(right).max()

            def agree(X, out=out, atol=atol):
                return close(out, X, rtol=0, atol=atol)

            if agree(right):
                continue
            if agree(P + tau * (C @ P) / M.diagonal()[:, None]):
                raise Mistake(
                    "this is one explicit step P + tau M^-1 C P, not an implicit one",
                    "evaluate the Laplacian at the new positions: solve (M - tau C) P' = M P",
                )
            if agree(_solve(M + tau * C, M @ P)):
                raise Mistake(
                    "the sign in the matrix is flipped: (M + tau C) instead of (M - tau C)",
                    "C is negative semidefinite; M - tau C is the positive definite one",
                )
            if agree(_solve(M - tau * C, P)):
                raise Mistake(
                    "the right-hand side is P instead of M P",
                    "multiplying (P' - P) / tau = M^-1 C P' by tau M gives M P on the right",
                )
            if agree(_solve(I - tau * C, P)) or agree(_solve(I - tau * C, M @ P)):
                raise Mistake(
                    "the matrix is (I - tau C): M is missing",
                    "the system is (M - tau C) P' = M P (or I - tau M^-1 C with P on the right)",
                )
            if agree(right - P):
                raise Mistake(
                    "the function returns the displacement P' - P, not the new positions",
                    "return the solution P' of the system itself",
                )
            raise Mistake(
                f"the new positions differ from the solution of (M - tau C) P' = M P on {label} "
                f"(largest difference {np.abs(out - right).max():.3g})",
                "scipy.sparse.linalg.spsolve((M - tau * C).tocsc(), M @ P)",
                typical=False,
            )
        checked.append(label)
    return checked
