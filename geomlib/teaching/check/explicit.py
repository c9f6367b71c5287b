"""Checks of notebook 05: lambda_max by power iteration, and the smoothing loop with the boundary held.

Delta = M^-1 C (C symmetric negative semidefinite), lam >= 0 the eigenvalues of -C e = lam M e; one explicit step
P' = P + tau M^-1 C P is stable for tau < 2 / lam_max. With the boundary B held the loop iterates the interior
block, P_I <- P_I + tau M_II^-1 (C_II P_I + C_IB P_B), whose limit is 2 / lam_max of (M_II, C_II). Cases, placed
anew each run by a random similarity (``case_rng``): an irregular tetrahedron, the 42-vertex ellipsoid scaled by 3
and an open 6 x 6 grid jittered in the plane and in height (20 boundary vertices; the jitter gives the cotangent
operator a shape of its own, so a rebuilt operator, the uniform one and a moving boundary all end up elsewhere).
"""

import numpy as np
import scipy.sparse as sp

from ...lessons.laplace import laplacian
from ...mesh.topology import boundary_vertices
from ..shapes import surfaces
from .catalogue import Case, Wrong, agree, judge, named, number, positions
from .meshes import irregular_tetrahedron, placed
from .result import Mistake, call, case_rng, exercise
from .solvers import DENSE, GENERALISED, refusing

__all__ = ["lam_max", "smoothing_loop"]


def loop_grid():
    """An open 6 x 6 grid, jittered in the plane and in height: 36 vertices, 20 on the boundary."""
    rng = np.random.default_rng(29)
    u, v = np.meshgrid(np.linspace(0.0, 1.0, 6), np.linspace(0.0, 1.0, 6), indexing="ij")
    V = np.column_stack([u.ravel(), v.ravel(), 0.06 * rng.standard_normal(36)])
    V[:, :2] += 0.04 * rng.uniform(-1, 1, (36, 2))
    q = np.arange(36).reshape(6, 6)[:-1, :-1].ravel()
    return V, np.concatenate([np.column_stack([q, q + 6, q + 7]), np.column_stack([q, q + 7, q + 1])])


def closed_ellipsoid():
    e = surfaces.ellipsoid(3.0, 2.1, 1.5, subdivisions=1)
    return e.V, e.F


def interior_blocks(V, F, weights="cotan"):
    """(m_I, C_I, I, B): the interior areas and rows of C, the interior and boundary vertices."""
    M, C = laplacian(V, F, weights=weights)
    B = boundary_vertices(F, len(V))
    I = np.setdiff1d(np.arange(len(V)), B)
    return M.diagonal()[I], C.tocsr()[I], I, B


def eigenvalues(m, C):
    """All eigenvalues of -C e = lam M e (ascending) for diagonal m: dense, the cases are tiny."""
    d = 1 / np.sqrt(m)
    return np.linalg.eigvalsh(-(d[:, None] * C.toarray() * d[None, :]))


# ---------------------------------------------------------------- lambda_max by power iteration


def _lam_of(c, scale):
    """lam_max of -D C D with D = diag(m^scale): the mistakes of the reduction's exponent."""
    d = c.m**scale
    return np.linalg.eigvalsh(-(d[:, None] * c.C.toarray() * d[None, :]))[-1]


# fmt: off
LAM_MAX_MISTAKES = [
    Wrong('the function returns the step limit 2 / lam_max, not lam_max', 'return lam_max itself', build=lambda c: 2 / c.lam[-1]),
    Wrong('the smallest eigenvalue was found, not the largest', 'power iteration finds the largest', build=lambda c: c.lam[0]),
    Wrong('the sign of C is flipped: the value is -lam_max, the largest in size of M^-1/2 C M^-1/2', 'Q = -M^-1/2 C M^-1/2: C is negative semidefinite', build=lambda c: -c.lam[-1]),
    Wrong('M is left out: this is the largest eigenvalue of -C itself', 'Q = -M^-1/2 C M^-1/2', build=lambda c: _lam_of(c, 0.0)),
    Wrong('M^-1 stands on both sides (-M^-1 C M^-1), not M^-1/2', 'Q = -M^-1/2 C M^-1/2', build=lambda c: _lam_of(c, -1.0)),
    Wrong('M multiplies instead of dividing (-M^1/2 C M^1/2)', 'Q = -M^-1/2 C M^-1/2', build=lambda c: _lam_of(c, 0.5)),
    Wrong("this is Gershgorin's bound max_i (|C_ii| + sum_j |C_ij|) / M_ii, not the eigenvalue it bounds", 'iterate until the Rayleigh quotient settles', build=lambda c: np.max(abs(c.C).sum(axis=1).A1 / c.m)),
    Wrong('the iteration stopped too early: the Rayleigh quotient is still below lam_max on {label}', 'iterate until it changes by less than 1e-12 of itself', when=lambda a, r, c: 0.5 * r < a < r * (1 - _LAM_RTOL)),
    Wrong('lam_max differs from the largest eigenvalue of -C e = lam M e on {label}', typical=False),
]
# fmt: on

_LIMIT = "explicit_step_limit highest_frequency_mode"
_OWN = "explicit_smoothing explicit_step ExplicitSmoother"
_LAM_RTOL = 1e-5  # power iteration stopped at 1e-12 of change lands far closer; the mistakes lie far away


@exercise(
    "lam_max",
    reread="section 2 · Why the step has a limit",
    forbid=named("lessons.smoothing", _LIMIT) + named("numerics.eigen", "largest_eigenvalue largest_eigenpair"),
    own=("numerics.eigen.largest_eigenvalue",),
)
def lam_max(fn):
    """Check ``fn(M, C) -> lam_max``, the largest eigenvalue of ``-C e = lam M e``, found by products with Q."""
    rng, cases = case_rng(), []
    for label, (V, F) in (
        ("an irregular tetrahedron", irregular_tetrahedron()),
        ("a 42-vertex ellipsoid", closed_ellipsoid()),
    ):
        M, C = laplacian(*placed(V, F, rng))
        cases.append(Case(label, M=M, C=C.tocsr()).but(m=M.diagonal()))
    m_I, C_I, I, _ = interior_blocks(*placed(*loop_grid(), rng))
    block = "the interior block of an open grid (rows not summing to 0)"
    cases.append(Case(block, M=sp.diags(m_I), C=C_I[:, I]).but(m=m_I))
    cases = [c.but(lam=eigenvalues(c.m, c.C), n=len(c.m)) for c in cases]
    why = "find lam_max by products with Q: power iteration, or a Lanczos solver (scipy's eigsh) on Q"
    with refusing({**GENERALISED, **DENSE}, fn, why):
        answers = [number(call(fn, c.M.copy(), c.C.copy()), hint="return lam_max, one float") for c in cases]
    same = lambda a, b, c: abs(a - b) <= _LAM_RTOL * max(abs(b), 1e-3 * c.lam[-1])  # noqa: E731
    judge(LAM_MAX_MISTAKES, cases, answers, right=lambda c: c.lam[-1], same=same)
    return [c.label for c in cases]


# ---------------------------------------------------------------- the smoothing loop, boundary held, tau < the limit


def explicit_loop(c, tau=None, N=None, held=True, rebuild=False, areas=-1.0, weights="cotan", coupled=True):
    """N explicit steps from the case's V with the named changes: the right loop, or one of its mistakes."""
    tau, N = c.tau if tau is None else tau, c.N if N is None else N
    P = c.V.copy()
    I = c.I if held else np.arange(len(P))
    for _ in range(N):
        if rebuild or _ == 0:
            M, C = laplacian(P if rebuild else c.V, c.F, weights=weights)
            m, C_I = M.diagonal()[I] ** areas, C.tocsr()[I]
            if not coupled:
                C_I = C_I[:, I]
        P[I] += tau * m[:, None] * (C_I @ (P if coupled else P[I]))
    return P


def loop_mistakes(run, own):
    """The catalogue of a loop: the mistakes an explicit and an implicit loop share, ``run(case, **changes)``
    building each, with the loop's ``own`` entries among them and the catch-alls last."""
    # fmt: off
    return [
        Wrong('no step was taken: the input positions come back', 'return the positions the loop computed', build=lambda c: c.V),
        Wrong('the loop takes one step too few', 'range(N) runs exactly N steps', build=lambda c: run(c, N=c.N - 1)),
        Wrong('the loop takes one step too many', 'range(N) runs exactly N steps', build=lambda c: run(c, N=c.N + 1)),
        Wrong('the boundary moves: every vertex is updated', 'update only the interior rows I', build=lambda c: run(c, held=False)),
        Wrong('M and C are rebuilt from the moving mesh at every step (curvature flow), not built once from V', 'call laplacian(V, F) once, before the loop', build=lambda c: run(c, rebuild=True)),
        Wrong('the loop takes half a step, tau / 2', 'the step is tau itself', build=lambda c: run(c, tau=c.tau / 2)),
        Wrong('the loop smooths with the uniform operator; the task asks for the cotangent one', 'laplacian(V, F) with its default weights', build=lambda c: run(c, weights='uniform')),
        *own,
        Wrong('the boundary vertices moved on {label}', 'hold them: update only the interior rows', when=lambda a, right, c: not agree(a[c.B], c.V[c.B])),
        Wrong("the positions after N steps differ from the loop's on {label}", typical=False),
    ]
    # fmt: on


# fmt: off
LOOP_MISTAKES = loop_mistakes(explicit_loop, [
    Wrong('the sign of the step is flipped: the loop runs the heat flow backwards', 'P_I += tau M_II^-1 (C P)_I', build=lambda c: explicit_loop(c, tau=-c.tau)),
    Wrong('C P is not divided by the vertex areas: M is forgotten', 'divide row i of C P by M_ii', build=lambda c: explicit_loop(c, areas=0.0)),
    Wrong('C P is multiplied by the vertex areas instead of divided', 'divide row i of C P by M_ii', build=lambda c: explicit_loop(c, areas=1.0)),
    Wrong("the held boundary's pull C_IB P_B is left out: only C_II P_I moves the interior", '(C P)_I = C_II P_I + C_IB P_B: the interior rows of C with every column', build=lambda c: explicit_loop(c, coupled=False)),
])
# fmt: on


@exercise(
    "smoothing_loop",
    reread="section 3 · The smoothing loop, boundary held",
    forbid=named("lessons.smoothing", f"{_OWN} {_LIMIT} implicit_smoothing ImplicitSmoother")
    + named("lessons.operator", "LaplaceOperator laplace_operator")
    + ("numerics.eigen.largest_eigenvalue",),
    own=named("lessons.smoothing", _OWN),
    allow=("lessons.laplace.laplacian", "mesh.topology.boundary_vertices"),
)
def smoothing_loop(fn):
    """Check ``fn(V, F, tau, N) -> P``: N explicit steps, M and C of V built once, the boundary held, and a
    step at or past 2 / lam_max of the interior block refused with an exception, one just below it taken."""
    rng, cases = case_rng(), []
    grid = placed(*loop_grid(), rng)
    for label, (V, F), N in (
        ("an open jittered grid (20 boundary vertices)", grid, 4),
        ("the same grid", grid, 1),
        ("a closed 42-vertex ellipsoid", placed(*closed_ellipsoid(), rng), 3),
    ):
        m_I, C_I, I, B = interior_blocks(V, F)
        limit = 2 / eigenvalues(m_I, C_I[:, I])[-1]
        cases.append(Case(label, V=V, F=F, tau=0.45 * limit, N=N).but(I=I, B=B, limit=limit))
    answers = [loop_answer(fn, c) for c in cases]
    judge(LOOP_MISTAKES, cases, answers, right=explicit_loop, same=lambda a, b, c: agree(a - c.V, b - c.V, c))
    past = cases[0]
    try:
        call(fn, past.V.copy(), past.F.copy(), 1.05 * past.limit, 1)
    except Mistake as m:
        if not m.diagnosis.startswith(_RAISED):  # any exception refuses the step; other mistakes stand
            raise
    else:
        ran = f"a step of 1.05 times the limit 2 / lam_max = {past.limit:.4g} ran instead of being refused"
        raise Mistake(ran, "before the first step: if tau >= 2 / lam_max (of M_II, C_II), raise ValueError naming both")
    near = 0.95  # past the whole pair's limit on the grid: 2 / lam_max of (M, C) is 0.89 of the block's
    try:
        call(fn, past.V.copy(), past.F.copy(), near * past.limit, 1)
    except Mistake as m:
        if not m.diagnosis.startswith(_RAISED + "ValueError"):
            raise
        raise Mistake(
            f"a stable step, {near} times the limit, was refused: the limit comes from the whole pair (M, C), "
            "not from its interior block",
            "lam_max of (M_II, C_II), the rows and columns of the interior vertices",
        ) from None
    return [c.label for c in cases] + ["a step past the limit, refused", f"a step of {near} times it, taken"]


_RAISED = "the function raised "  # how result.call names an exception of the learner's function


def loop_answer(fn, c, stable=0.45):
    """The positions ``fn`` returns on case ``c``; a ValueError at this stable step named as a refused step."""
    try:
        out = call(fn, c.V.copy(), c.F.copy(), c.tau, c.N)
    except Mistake as m:
        if not m.diagnosis.startswith(_RAISED + "ValueError"):
            raise
        raise Mistake(
            f"a step of {stable} times the limit was refused on {c.label} ({m.diagnosis[len(_RAISED) :]})",
            "the limit is 2 / lam_max of the block (M_II, C_II): check my_lam_max there",
        ) from None
    return positions(out, c.n, nan_hint="a stable loop stays finite: look for a division by zero")
