"""Checks of the exercises of notebook 06: implicit smoothing over N steps, the boundary held; the volume kept.

Convention of the workbook: Delta = M^-1 C (C symmetric negative semidefinite,
M diagonal); one implicit (backward Euler) step with the boundary B held solves the
interior block system (M_II - tau C_II) P_I' = M_II P_I + tau C_IB P_B, whose matrix is
the same at every step (factorised once; factorising it again every step is slow, not
wrong, and passes). The cases are those of notebook 05's loop (``check.explicit``): an
open jittered grid and a closed ellipsoid, placed anew each run, with tau three times the
explicit limit, where the explicit step and the implicit one part clearly.

``volume_kept(fn)`` checks ``fn(P, F, V) -> P'``: P scaled about the centroid c of the solid it
encloses by s = (vol_0 / vol)^(1/3) and moved to V's centroid c_0, ``c_0 + s (P - c)``, volumes and
centroids by the divergence theorem (signed tetrahedra with the origin). The cases are closed
meshes placed away from the origin (so some tetrahedra count negative) and squeezed unevenly.
"""

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from ...lessons.laplace import laplacian
from .catalogue import Case, Wrong, agree, judge, positions, run
from .explicit import (
    closed_ellipsoid,
    eigenvalues,
    explicit_loop,
    interior_blocks,
    loop_answer,
    loop_grid,
    loop_mistakes,
)
from .meshes import jittered_icosphere, placed
from .result import case_rng, exercise

__all__ = ["implicit_loop", "volume_kept"]

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


# ------------------------------------------------------------------ the volume kept (section 3)
_VOLUME_REREAD = "section 3 · Shrinkage, measured, and the volume kept"


def _solid(X, F, weight=np.asarray, corner=4.0):
    """(volume, centroid) of the solid X encloses: signed tetrahedra with the origin (``weight`` of their
    volumes, ``corner``: the divisor of their corner sums); the catalogue's wrong ones change the two."""
    x0, x1, x2 = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]
    vol_f = weight(np.einsum("ij,ij->i", x0, np.cross(x1, x2)) / 6.0)
    return vol_f.sum(), (x0 + x1 + x2).T @ vol_f / (corner * vol_f.sum())


def volume_rescaled_of(c, power=1 / 3, inverted=False, about="solid", back=True, weight=np.asarray, corner=4.0):
    """The case's P rescaled to V's volume with the named changes: the right answer, or one of its mistakes."""
    (vol0, c0), (vol, cP) = _solid(c.V, c.F, weight, corner), _solid(c.P, c.F, weight, corner)
    if about == "vertices":
        c0, cP = c.V.mean(axis=0), c.P.mean(axis=0)
    elif about == "origin":
        c0 = cP = np.zeros(3)
    s = ((vol / vol0) if inverted else (vol0 / vol)) ** power
    return (c0 if back else cP) + s * (c.P - cP)


# fmt: off
VOLUME_MISTAKES = [
    Wrong("P is returned as it came: nothing was rescaled", "scale P - c by s = (vol(V) / vol(P))^(1/3), then add c_0",
          build=lambda c: c.P),
    Wrong("the scale is the volume ratio itself, not its cube root: the volume is off by that ratio cubed",
          "volume scales with the cube of a length: s = (vol_0 / vol)^(1/3)", build=lambda c: volume_rescaled_of(c, power=1.0)),
    Wrong("the scale is the square root of the volume ratio (an area's rule), not its cube root",
          "volume scales with the cube of a length: s = (vol_0 / vol)^(1/3)", build=lambda c: volume_rescaled_of(c, power=0.5)),
    Wrong("the ratio is upside down: (vol / vol_0)^(1/3) shrinks a shrunk mesh further",
          "a mesh that lost volume must grow: s = (vol_0 / vol)^(1/3) > 1", build=lambda c: volume_rescaled_of(c, inverted=True)),
    Wrong("the mesh is scaled about the origin, not about the centroid of its solid: it moves as it grows",
          "scale P - c about the centroid c, then add the input's centroid c_0",
          build=lambda c: volume_rescaled_of(c, about="origin")),
    Wrong("the mesh is scaled about its centroid but not moved back to the input's centroid c_0",
          "return c_0 + s (P - c), with c_0 the centroid of V's solid", build=lambda c: volume_rescaled_of(c, back=False)),
    Wrong("the centroids are the means of the vertices, not the centroids of the enclosed solids",
          "the solid's centroid is sum_f vol_f (x_0 + x_1 + x_2 + 0) / 4 over sum_f vol_f",
          build=lambda c: volume_rescaled_of(c, about="vertices")),
    Wrong("a tetrahedron's centroid is taken as (x_0 + x_1 + x_2) / 3: the fourth corner, the origin, is left out",
          "the centroid of the tetrahedron (0, x_0, x_1, x_2) is (x_0 + x_1 + x_2) / 4",
          build=lambda c: volume_rescaled_of(c, corner=3.0)),
    Wrong("the tetrahedra's volumes are taken as absolute values: those seen from the origin through the back of the "
          "mesh must count negative", "keep the sign of x_0 . (x_1 x x_2) / 6 and sum",
          build=lambda c: volume_rescaled_of(c, weight=np.abs)),
    Wrong("the result differs from the rescaled P on {label}",
          "c_0 + (vol_0 / vol)^(1/3) (P - c), volumes and centroids by signed tetrahedra with the origin", typical=False),
]
# fmt: on


def _squeezed(V, rng):
    """V squeezed unevenly about a point off its centre, moved and jittered: a mesh that lost volume."""
    A = np.diag(rng.uniform(0.7, 0.95, size=3)) + rng.uniform(-0.05, 0.05, size=(3, 3))
    pivot = V.mean(axis=0) + rng.uniform(-0.3, 0.3, size=3)
    ell = float(np.linalg.norm(V[0] - V[1]))
    return pivot + (V - pivot) @ A.T + rng.uniform(-1.0, 1.0, size=3) + rng.uniform(-0.05, 0.05, size=V.shape) * ell


def volume_kept_cases(rng):
    """The cases of ``volume_kept``: two closed meshes placed with ``rng``, each with a squeezed copy P."""
    cases = []
    for label, (V, F) in (
        ("a jittered 42-vertex icosphere", jittered_icosphere()),
        ("a closed 42-vertex ellipsoid", closed_ellipsoid()),
    ):
        V, F = placed(V, F, rng)
        cases.append(Case(label, P=_squeezed(V, rng), F=F, V=V))
    return cases


@exercise(
    "volume_kept",
    reread=_VOLUME_REREAD,
    forbid=(
        "lessons.smoothing.volume_rescaled",
        "mesh.geometry.volume_and_centroid",
        "mesh.geometry.enclosed_volume",
    ),
    own=("lessons.smoothing.volume_rescaled",),
)
def volume_kept(fn):
    """Check ``fn(P, F, V) -> P'``: P scaled about its solid's centroid to V's volume, moved to V's centroid."""
    cases = volume_kept_cases(case_rng())
    answers = run(fn, cases, lambda out, n: positions(out, n, nan_hint="the volume of P is zero where it divides"))
    judge(VOLUME_MISTAKES, cases, answers, right=volume_rescaled_of)
    return [c.label + " (squeezed and moved)" for c in cases]
