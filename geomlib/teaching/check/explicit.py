"""Checks of the exercises of notebook 05 (one explicit step and its stability limit).

Convention of the workbook: Delta = M^-1 C (C symmetric negative semidefinite,
M diagonal), lam >= 0 the eigenvalues of -M^-1 C, one explicit step
P' = P + tau M^-1 C P, stable for tau < 2 / lam_max.
"""

import numpy as np
import scipy.linalg
import scipy.sparse as sp

from ...lessons.laplace import laplacian
from ..shapes import surfaces
from .catalogue import positions
from .result import Mistake, call, close, exercise

__all__ = ["explicit_step", "explicit_step_limit", "smoothing_loop"]

_REREAD_STEP = "section 1 · The heat flow, one explicit step at a time"
_REREAD_LIMIT = "section 2 · Why the step has a limit"
_REREAD_LOOP = "section 3 · The smoothing loop, boundary held"

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


#: What NaN or infinite positions from a step mean: a division by zero (a dense ``1 / M`` divides by its
#: zeros off the diagonal); the check's meshes have positive areas and its steps are stable.
_STEP_NAN_HINT = "divide row i of C P by M_ii (M.diagonal(), positive on these meshes), not by a dense 1 / M"


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
            out = positions(call(fn, P.copy(), M.copy(), C.copy(), tau), len(V), nan_hint=_STEP_NAN_HINT)
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
            _uniform_step(out, P, C, tau)
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


def _uniform_step(out, P, C, tau):
    """Raise the Mistake of a uniform step (neighbour averaging) written for the cotangent C it was given."""
    c = -C.diagonal()[:, None]  # |C_ii|: the valence for uniform weights, a sum of cotangents here
    A = sp.csr_matrix(C, copy=True)
    A.setdiag(0)
    A.eliminate_zeros()
    A.data[:] = 1.0  # the neighbours, every weight 1
    valence = np.asarray(A.sum(axis=1))
    if close(out, P + tau * (C @ P) / c):
        raise Mistake(
            "the step divides C P by |C_ii|, which is the valence M_ii only for the uniform operator; "
            "C here holds cotangent weights, and its M holds vertex areas",
            "divide by the M you are given: P + tau (C P) / M_ii",
        )
    if close(out, P + tau * (A @ P / valence - P)) or close(out, P + tau * (C @ P) / valence):
        raise Mistake(
            "this is the uniform step (every neighbour weighs 1, divided by the valence) given a cotangent C: "
            "the weights C_ij and the vertex areas M_ii are not used",
            "use the matrices you are given: P + tau M^-1 C P",
        )


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
    allow=("lessons.laplace.laplacian",),
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


def loop_case():
    """An open, noisy 6 x 6 grid (20 boundary vertices) whose in-plane jitter gives the cotangent
    operator a shape of its own, so that a rebuilt operator, the uniform one and a moving boundary
    all end up elsewhere."""
    rng = np.random.default_rng(29)
    u, v = np.meshgrid(np.linspace(0.0, 1.0, 6), np.linspace(0.0, 1.0, 6), indexing="ij")
    V = np.column_stack([u.ravel(), v.ravel(), 0.06 * rng.standard_normal(36)])
    V[:, :2] += 0.04 * rng.uniform(-1, 1, (36, 2))
    q = np.arange(36).reshape(6, 6)[:-1, :-1].ravel()
    F = np.concatenate([np.column_stack([q, q + 6, q + 7]), np.column_stack([q, q + 7, q + 1])])
    return V, F


def _smoothed(V, F, tau, iterations, weights="cotan", rebuild=False, fixed=None, areas=True):
    """``iterations`` explicit steps, the rows of ``fixed`` held; M and C of V, or of every iterate
    (``areas=False``: C P not divided by the vertex areas)."""
    P = V.copy()
    moving = np.ones(len(V), dtype=bool) if fixed is None else ~fixed
    M, C = laplacian(V, F, weights=weights)
    for _ in range(iterations):
        if rebuild:
            M, C = laplacian(P, F, weights=weights)
        m = M.diagonal()[:, None] if areas else 1.0
        P = P + tau * moving[:, None] * (C @ P) / m
    return P


def _boundary_mask(F, n):
    edges = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    unique, count = np.unique(edges, axis=0, return_counts=True)
    mask = np.zeros(n, dtype=bool)
    mask[unique[count == 1].ravel()] = True
    return mask


@exercise(
    "smoothing_loop",
    reread=_REREAD_LOOP,
    forbid=(
        "lessons.smoothing.explicit_smoothing",
        "lessons.smoothing.ExplicitSmoother",
        "lessons.smoothing.implicit_smoothing",
        "lessons.smoothing.ImplicitSmoother",
        "lessons.operator.LaplaceOperator",
        "lessons.operator.laplace_operator",
    ),
    own=("lessons.smoothing.explicit_smoothing", "lessons.smoothing.ExplicitSmoother"),
    allow=("lessons.laplace.laplacian", "mesh.topology.boundary_vertices"),
)
def smoothing_loop(fn):
    """Check ``fn(V, F, tau, iterations) -> P``: ``iterations`` explicit steps P <- P + tau M^-1 C P
    with the cotangent M and C built once from V, the boundary vertices held where they are."""
    V, F = loop_case()
    fixed = _boundary_mask(F, len(V))
    M, C = laplacian(V, F)
    I = ~fixed
    lam_max = scipy.linalg.eigh(-C.toarray()[np.ix_(I, I)], np.diag(M.diagonal()[I]), eigvals_only=True)[-1]
    tau, scale = 0.5 * 2 / lam_max, np.abs(V).max()
    cases = [("an open noisy grid (20 boundary vertices)", V, F, fixed, 4), ("the same grid, 1 step", V, F, fixed, 1)]
    ell = surfaces.ellipsoid(1.0, 0.7, 0.5, subdivisions=1)
    cases.append(("a closed ellipsoid (42 vertices)", ell.V, ell.F, np.zeros(len(ell.V), dtype=bool), 3))
    checked = []
    for label, V, F, fixed, n in cases:
        if label.startswith("a closed"):
            M, C = laplacian(V, F)
            tau = 0.5 * 2 / scipy.linalg.eigh(-C.toarray(), M.toarray(), eigvals_only=True)[-1]
        out = positions(call(fn, V.copy(), F.copy(), tau, n), len(V), nan_hint=_LOOP_NAN_HINT)
        right = _smoothed(V, F, tau, n, fixed=fixed)
        if close(out, right, rtol=0, atol=1e-9 * scale):
            checked.append(label)
            continue
        _loop_mistake(out, V, F, tau, n, fixed, label)
    return checked


# the check steps at half the limit, so a right loop stays finite: NaN comes from a division by zero
_LOOP_NAN_HINT = (
    "the check steps at half the stability limit, where a right loop stays finite: look for a division by zero "
    "(divide by M.diagonal(), positive here, not by a dense 1 / M or by areas zeroed on the boundary rows) "
    "or positions that start unset (np.empty) instead of a copy of V"
)


def _loop_mistake(out, V, F, tau, n, fixed, label):
    """Raise the Mistake that explains ``out``: the nearest named variant of the loop, or a catch-all."""
    atol = 1e-9 * np.abs(V).max()
    if close(out, V, rtol=0, atol=atol):
        raise Mistake(
            f"the function returns the input positions unchanged: no step was taken (iterations = {n})",
            "return the positions the loop computed, not V",
        )
    free = np.zeros(len(V), dtype=bool)
    for rebuild in (False, True):
        for held in (fixed, free):
            for count in (n, n - 1, n + 1):
                if (rebuild, held is fixed, count) == (False, True, n):
                    continue
                if close(out, _smoothed(V, F, tau, count, rebuild=rebuild, fixed=held), rtol=0, atol=atol):
                    raise Mistake(*_loop_diagnosis(rebuild, held is fixed or not fixed.any(), count, n))
    if close(out, _smoothed(V, F, -tau, n, fixed=fixed), rtol=0, atol=atol):
        raise Mistake(
            "the sign of the step is flipped: the loop runs the heat flow backwards and roughens the mesh",
            "P <- P + tau M^-1 C P; C is negative semidefinite",
        )
    if close(out, _smoothed(V, F, tau, n, fixed=fixed, areas=False), rtol=0, atol=atol):
        raise Mistake(
            "C P is not divided by the vertex areas: the loop steps with C where M^-1 C belongs",
            "divide row i of C P by M_ii",
        )
    if close(out, _smoothed(V, F, tau, n, weights="uniform", fixed=fixed), rtol=0, atol=atol):
        raise Mistake(
            "the loop smooths with the uniform operator; the task asks for the cotangent one",
            "laplacian(V, F) with its default weights gives the cotangent M and C",
        )
    if fixed.any() and not close(out[fixed], V[fixed], rtol=0, atol=atol):
        moved = np.linalg.norm(out[fixed] - V[fixed], axis=1).max()
        raise Mistake(
            f"the boundary vertices moved (the furthest by {moved:.3g}) on {label}",
            "hold them: leave their rows out of the update, or put them back after every step",
        )
    raise Mistake(
        f"the positions after {n} steps differ from the loop of P <- P + tau M^-1 C P on {label} "
        f"(largest difference {np.abs(out - _smoothed(V, F, tau, n, fixed=fixed)).max():.3g})",
        "build M and C once from V, then repeat the step `iterations` times, boundary rows held",
        typical=False,
    )


def _loop_diagnosis(rebuild, boundary_held, count, n):
    """(diagnosis, hint) of a loop that differs from the task in the ways named."""
    parts, hints = [], []
    if rebuild:
        parts.append(
            "M and C are rebuilt from the moving mesh at every step, where the task builds them once "
            "from the input (that is curvature flow, not the fixed-operator smoothing asked for)"
        )
        hints.append("call laplacian(V, F) once, before the loop")
    if not boundary_held:
        parts.append("the boundary moves: every vertex was updated")
        hints.append("hold the boundary vertices (leave their rows out, or put them back after every step)")
    if count != n:
        parts.append(
            f"the loop takes {count} steps for iterations = {n}"
            + (" (one too few)" if count < n else " (one too many)")
        )
        hints.append("range(iterations) runs exactly `iterations` steps")
    return "; ".join(parts), "; ".join(hints)
