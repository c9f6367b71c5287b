"""Checks of the exercises of notebook 05 (one explicit step and its stability limit).

Convention of the workbook: Delta = M^-1 C (C symmetric negative semidefinite,
M diagonal), lam >= 0 the eigenvalues of -M^-1 C, one explicit step
P' = P + tau M^-1 C P, stable for tau < 2 / lam_max.
"""

import numpy as np
import scipy.linalg

from ...lessons.laplace import laplacian
from .. import surfaces
from .result import Mistake, call, close, exercise

__all__ = ["explicit_step", "explicit_step_limit"]

_REREAD_STEP = "section 2 · Discretised in space and time"
_REREAD_LIMIT = "section 3 · Why the step has a limit"

# a tetrahedron with unequal faces (so M is not a multiple of I) and a small
# ellipsoid scaled by 3 (so the eigenvalues of C and of M^-1 C differ by far)
_TET_V = np.array([[0.0, 0, 0], [1.3, 0, 0], [0.2, 0.9, 0], [0.1, 0.3, 0.7]])
_TET_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def step_cases():
    """The small meshes every smoothing check runs on: (label, V, F) triples."""
    ell = surfaces.ellipsoid(1.0, 0.7, 0.5, subdivisions=1)
    return (
        ("an irregular tetrahedron", _TET_V, _TET_F),
        ("an ellipsoid scaled by 3 (42 vertices)", 3.0 * ell.V, ell.F),
    )


def positions(out, n, what="the function"):
    """Check that ``out`` is an (n, 3) array of positions; return it as float."""
    P = np.asarray(out.toarray() if hasattr(out, "toarray") else out)
    if P.shape != (n, 3):
        raise Mistake(
            f"{what} returned shape {P.shape}, expected ({n}, 3): one new position per vertex",
            "return the (n, 3) array of new positions, like P",
            typical=False,
        )
    if not np.isfinite(P.astype(float)).all():
        raise Mistake(
            f"{what} returned NaN or infinite positions",
            "divide by the vertex areas M_ii, which are positive on these meshes",
            typical=False,
        )
    return P.astype(float)


@exercise(
    "explicit_step",
    reread=_REREAD_STEP,
    forbid=(
        "lessons.smoothing.explicit_step",
        "lessons.smoothing.explicit_smoothing",
        "lessons.smoothing.ExplicitSmoother",
    ),
)
def explicit_step(fn):
    """Check ``fn(P, M, C, tau) -> P'`` = P + tau M^-1 C P (forward Euler on dP/dt = Delta P)."""
    checked = []
    rng = np.random.default_rng(5)
    for label, V, F in step_cases():
        M, C = laplacian(V, F)
        m = M.diagonal()[:, None]
        tau = 0.3 / np.abs(C.diagonal() / M.diagonal()).max()
        for P in (V, V + 0.05 * rng.standard_normal(V.shape)):
            out = positions(call(fn, P.copy(), M.copy(), C.copy(), tau), len(V))
            move = tau * (C @ P) / m
            if close(out, P + move):
                continue
            if close(out, P - move):
                raise Mistake(
                    "the sign is flipped: the step runs the heat flow backwards",
                    "P' = P + tau M^-1 C P; C is negative semidefinite, so this pulls vertices "
                    "towards their neighbours",
                )
            if close(out, move):
                raise Mistake(
                    "the function returns the displacement tau M^-1 C P, not the new positions",
                    "add it to P: return P + tau M^-1 C P",
                )
            if close(out, P + tau * (C @ P)):
                raise Mistake(
                    "C was used where M^-1 C belongs (the vertex areas are missing)",
                    "divide each row of C P by its vertex area M_ii: Delta = M^-1 C",
                )
            if close(out, P + tau * m * (C @ P)):
                raise Mistake(
                    "C P was multiplied by M instead of divided by it", "Delta = M^-1 C: divide row i of C P by M_ii"
                )
            if close(out, P + (C @ P) / m):
                raise Mistake("the step tau is missing", "scale the Laplacian by tau: P + tau M^-1 C P")
            if close(out, P + tau * (C @ (P / m))):
                raise Mistake(
                    "the areas divide P before C is applied (C M^-1 P), not after (M^-1 C P)",
                    "first C @ P, then divide row i by M_ii",
                )
            raise Mistake(
                f"the new positions differ from P + tau M^-1 C P on {label} "
                f"(largest difference {np.abs(out - P - move).max():.3g})",
                "one step is one sparse product: P + tau * (C @ P) / M.diagonal()[:, None]",
                typical=False,
            )
        checked.append(label)
    return checked


def _lam(A, M):
    """Eigenvalues of A e = lam M e, ascending (dense: the check's meshes are tiny)."""
    return scipy.linalg.eigh(A.toarray(), M.toarray(), eigvals_only=True)


@exercise(
    "explicit_step_limit",
    reread=_REREAD_LIMIT,
    forbid=(
        "lessons.smoothing.explicit_step_limit",
        "lessons.smoothing.highest_frequency_mode",
        "numerics.eigen.largest_eigenvalue",
    ),
)
def explicit_step_limit(fn):
    """Check ``fn(V, F) -> tau_max`` = 2 / lam_max, lam_max the largest eigenvalue of -M^-1 C
    for the cotangent operator ``(M, C) = laplacian(V, F)`` (closed meshes: no boundary rule)."""
    checked = []
    for label, V, F in step_cases():
        M, C = laplacian(V, F)
        lam = _lam(-C, M)
        lam_max, lam_1 = lam[-1], lam[lam > 1e-9 * lam[-1]][0]
        c_max = np.linalg.eigvalsh(-C.toarray())[-1]
        out = call(fn, V.copy(), F.copy())
        try:
            tau = float(np.asarray(out).reshape(()))
        except (TypeError, ValueError):
            raise Mistake(
                f"the function returned {type(out).__name__} {np.shape(out)}, not one number",
                "return the float 2 / lam_max",
                typical=False,
            ) from None
        if np.isclose(tau, 2 / lam_max, rtol=1e-6):
            checked.append(label)
            continue
        if np.isinf(tau) or tau > 1e6 / lam_max:
            raise Mistake(
                "the limit is infinite or huge: the smallest eigenvalue (0, the constant mode) was used",
                "the strictest condition comes from the largest eigenvalue: tau_max = 2 / lam_max",
            )
        if np.isclose(tau, 2 / lam_1, rtol=1e-6):
            raise Mistake(
                "the smallest non-zero eigenvalue was used instead of the largest",
                "|1 - tau lam| <= 1 must hold for every mode; the highest one is the strictest",
            )
        if np.isclose(tau, 1 / lam_max, rtol=1e-6):
            raise Mistake(
                "the limit is 1 / lam_max, half the true one",
                "|1 - tau lam_max| <= 1 allows tau up to 2 / lam_max (the factor may reach -1)",
            )
        if np.isclose(tau, -2 / lam_max, rtol=1e-6):
            raise Mistake(
                "the sign is flipped: a negative limit",
                "lam_max is the largest eigenvalue of -M^-1 C (>= 0), so 2 / lam_max > 0",
            )
        if np.isclose(tau, 2 / c_max, rtol=1e-6) or np.isclose(tau, 1 / c_max, rtol=1e-6):
            raise Mistake(
                "lam_max was taken from C instead of M^-1 C (the vertex areas are missing)",
                "solve the generalised problem -C e = lam M e, or use M^-1/2 (-C) M^-1/2",
            )
        if np.isclose(tau, lam_max, rtol=1e-6) or np.isclose(tau, 2 * lam_max, rtol=1e-6):
            raise Mistake(
                "the function returns lam_max (or 2 lam_max), not the step 2 / lam_max",
                "the limit is the reciprocal: tau_max = 2 / lam_max",
            )
        raise Mistake(
            f"the limit {tau:.6g} differs from 2 / lam_max = {2 / lam_max:.6g} on {label}",
            "lam_max is the largest eigenvalue of -M^-1 C; the limit is 2 / lam_max",
            typical=False,
        )
    return checked
