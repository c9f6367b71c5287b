"""Check of the exercise of notebook 06: implicit smoothing over N steps, the boundary held.

Convention of the workbook: Delta = M^-1 C (C symmetric negative semidefinite,
M diagonal); one implicit (backward Euler) step with the boundary B held solves the
interior block system (M_II - tau C_II) P_I' = M_II P_I + tau C_IB P_B, whose matrix is
the same at every step (factorised once; factorising it again every step is slow, not
wrong, and passes). The cases are those of notebook 05's loop (``check.explicit``): an
open jittered grid and a closed ellipsoid, placed anew each run, with tau three times the
explicit limit, where the explicit step and the implicit one part clearly.
"""

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from ...lessons.laplace import laplacian
from .catalogue import Case, Wrong, agree, judge
from .explicit import (
    closed_ellipsoid,
    eigenvalues,
    explicit_loop,
    interior_blocks,
    loop_answer,
    loop_grid,
    loop_mistakes,
)
from .meshes import placed
from .result import case_rng, exercise

__all__ = ["implicit_loop"]

_REREAD = "section 1 · Backward Euler, derived"

#: How close an answer must come, as a fraction of the largest displacement: an iterative solver at its default
#: tolerance lands within it (scipy's cg about 1e-5 per step); every mistake named lies 1e-2 or more away.
AGREE = 1e-3


def implicit_loop_of(
    c, tau=None, N=None, held=True, rebuild=False, sign=1.0, mass=True, rhs_mass=True, coupling=1.0, weights="cotan"
):
    """N implicit steps from the case's V with the named changes: the right loop, or one of its mistakes."""
    tau, N = c.tau if tau is None else tau, c.N if N is None else N
    P = c.V.copy()
    I = c.I if held else np.arange(len(P))
    B = np.setdiff1d(np.arange(len(P)), I)
    for k in range(N):
        if rebuild or k == 0:
            M, C = laplacian(P if rebuild else c.V, c.F, weights=weights)
            m, C_I = M.diagonal()[I], C.tocsr()[I]
            solve = sla.splu((sp.diags(m if mass else np.ones(len(I))) - sign * tau * C_I[:, I]).tocsc()).solve
        P[I] = solve((m[:, None] if rhs_mass else 1.0) * P[I] + coupling * sign * tau * (C_I[:, B] @ P[B]))
    return P


# fmt: off
IMPLICIT_MISTAKES = loop_mistakes(implicit_loop_of, [
    Wrong("the sign of tau C is flipped: (M_II + tau C_II), indefinite for large tau", "M_II - tau C_II",
          build=lambda c: implicit_loop_of(c, sign=-1.0)),
    Wrong("M is forgotten in the matrix: (I - tau C_II)", "the matrix is M_II - tau C_II",
          build=lambda c: implicit_loop_of(c, mass=False)),
    Wrong("M is forgotten in the matrix and on the right: (I - tau C_II) P_I' = P_I + ...",
          "tau M (P' - P) / tau = tau C P' gives M_II - tau C_II and M_II P_I",
          build=lambda c: implicit_loop_of(c, mass=False, rhs_mass=False)),
    Wrong("the right-hand side holds P_I where M_II P_I belongs", "the right side is M_II P_I + tau C_IB P_B",
          build=lambda c: implicit_loop_of(c, rhs_mass=False)),
    Wrong("the held boundary's term tau C_IB P_B is missing from the right-hand side",
          "moving the known P_B to the right gives + tau C_IB P_B", build=lambda c: implicit_loop_of(c, coupling=0.0)),
    Wrong("the held boundary's term has the wrong sign: - tau C_IB P_B", "it is + tau C_IB P_B",
          build=lambda c: implicit_loop_of(c, coupling=-1.0)),
    Wrong("these are explicit steps P_I + tau M_II^-1 (C P)_I, not implicit ones",
          "evaluate the Laplacian at the new positions: solve the block system", build=explicit_loop),
])
# fmt: on


@exercise(
    "implicit_loop",
    reread=_REREAD,
    forbid=(
        "lessons.smoothing.implicit_step",
        "lessons.smoothing.implicit_smoothing",
        "lessons.smoothing.ImplicitSmoother",
        "lessons.operator.LaplaceOperator",
        "lessons.operator.laplace_operator",
    ),
    own=("lessons.smoothing.implicit_smoothing", "lessons.smoothing.implicit_step", "lessons.operator.LaplaceOperator"),
    allow=("lessons.laplace.laplacian", "mesh.topology.boundary_vertices"),
)
def implicit_loop(fn):
    """Check ``fn(V, F, tau, N) -> P``: N implicit steps by the interior block system, M and C of V built once."""
    rng, cases = case_rng(), []
    grid = placed(*loop_grid(), rng)
    for label, (V, F), N in (
        ("an open jittered grid (20 boundary vertices)", grid, 3),
        ("the same grid", grid, 1),
        ("a closed 42-vertex ellipsoid", placed(*closed_ellipsoid(), rng), 2),
    ):
        m_I, C_I, I, B = interior_blocks(V, F)
        tau = 3 * 2 / eigenvalues(m_I, C_I[:, I])[-1]
        cases.append(Case(label, V=V, F=F, tau=tau, N=N).but(I=I, B=B))
    answers = [loop_answer(fn, c) for c in cases]
    judge(
        IMPLICIT_MISTAKES,
        cases,
        answers,
        right=implicit_loop_of,
        same=lambda a, b, c: agree(a - c.V, b - c.V, c, rtol=AGREE),
    )
    return [c.label for c in cases]
