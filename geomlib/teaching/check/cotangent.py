"""Checks of the exercises of notebook 03: the cotangent matrix from edge lengths alone, the mixed areas, and the
discrete principal curvatures.

``cotangent_matrix`` hands the learner's function the per-face edge lengths ``l`` (m, 3) and ``F`` of an
irregular tetrahedron (closed, no right angle), an irregular bipyramid (closed, obtuse triangles) and a
jittered 4 x 4 grid (open: boundary edges with one triangle), placed anew every run; its typical mistakes are
rebuilt from the right per-corner cotangents and Heron's areas. ``mixed_areas`` names its mistakes from
``check.area_mistakes``, in the words every area check uses. ``discrete_principal_curvatures`` hands in the
mesh and its angle deficits (NaN on the boundary): a jittered icosphere (the discrete H^2 < K at every vertex: the
clamp), a bump and a saddle on 4 x 4 grids (open; H of both signs on the saddle) and a bipyramid (obtuse: mixed
areas differ from barycentric ones). The answer builds the pair from the learner's own C (section 1) and mixed
areas (section 2); the check asks those first (``result.earlier``), so a wrong one is named as the exercise to fix.
"""

import numpy as np
import scipy.sparse as sp

from ...lessons.curvature import boundary_mask, gaussian_curvature, signed_mean_curvature
from ...lessons.curvature import discrete_principal_curvatures as geomlib_principal
from ...lessons.laplace import cotangent_matrix as geomlib_cotangent_matrix
from ...lessons.laplace import edge_lengths, laplacian
from ...mesh.topology import boundary_edges
from .area_mistakes import AREA_MISTAKES, RIGHT_AREAS
from .catalogue import Case, Wrong, agree, judge, mesh_cases, named, run, vector
from .meshes import (
    bump_4x4,
    irregular_bipyramid,
    irregular_tetrahedron,
    jittered_grid_4x4,
    jittered_icosphere,
    obtuse_triangle,
)
from .result import Mistake, case_rng, earlier, exercise

__all__ = ["cotangent_matrix", "mixed_areas", "discrete_principal_curvatures"]

NEXT, PREV = [1, 2, 0], [2, 0, 1]  # the corners j, k that follow corner i
_RULE = "corner i of each face adds 1/2 cot(theta_i) to C_jk and C_kj, (j, k) the edge opposite it"
_ENDS = (
    "each edge gets the cotangent of an angle at one of its own ends, not of the corner opposite it (the lengths or "
    "the corners read in the wrong order)",
    "l[f, i] is the edge opposite corner i; cot theta_i = (l_j^2 + l_k^2 - l_i^2) / (4 A) goes to that edge",
)
_MESHES = (
    ("an irregular tetrahedron", irregular_tetrahedron()),
    ("an irregular bipyramid", irregular_bipyramid()),
    ("a jittered 4 x 4 grid", jittered_grid_4x4()),
)


def _assemble(c, w, both=True, diagonal=True):
    """Dense C of case c with the per-corner weights w (m, 3) on the edges opposite the corners."""
    C = np.zeros((c.n, c.n))
    j, k = c.F[:, NEXT].ravel(), c.F[:, PREV].ravel()
    np.add.at(C, (j, k), w.ravel())
    if both:
        np.add.at(C, (k, j), w.ravel())
    return C - np.diag(C.sum(axis=1)) if diagonal else C


def _cot(c, A=None, squares=True):
    """Per-corner cotangents by the law of cosines over the areas A (default Heron's)."""
    m = c.l**2 if squares else c.l
    return (m[:, NEXT] + m[:, PREV] - m) / (4 * (c.A if A is None else A))[:, None]


def _perimeter_heron(c):
    p = c.l.sum(axis=1)
    return np.sqrt(np.maximum(p * (p - c.l[:, 0]) * (p - c.l[:, 1]) * (p - c.l[:, 2]), 0.0))


def _tan(c):
    with np.errstate(divide="ignore"):  # a right angle has cot 0
        return _assemble(c, 0.5 / c.cot)


def _boundary(c, factor):
    """C with the weights of the boundary edges multiplied by ``factor``, rows summing to zero again."""
    off = c.C - np.diag(np.diag(c.C))
    E = boundary_edges(c.F)
    off[E[:, 0], E[:, 1]] *= factor
    off[E[:, 1], E[:, 0]] *= factor
    return off - np.diag(off.sum(axis=1))


def cotangent_case(label, V, F):
    """A case of ``cotangent_matrix``: inputs l, F; facts n, the right dense C, Heron's areas A, the cotangents."""
    l = edge_lengths(V, F)
    c = Case(label, l=l, F=F).but(n=len(V), C=geomlib_cotangent_matrix(V, F).toarray())
    a, b, d = np.sort(l, axis=1)[:, ::-1].T
    c = c.but(A=0.25 * np.sqrt((a + (b + d)) * (d - (a - b)) * (d + (a - b)) * (a + (b - d))))
    return c.but(cot=_cot(c), on_boundary=np.isin(np.arange(len(V)), boundary_edges(F)))


def cotangent_cases(rng):
    return [cotangent_case(c.label, c.V, c.F) for c in mesh_cases(_MESHES, rng)]


# fmt: off
C_MISTAKES = [
    Wrong("the sign of C is flipped", _RULE + ", so that C is negative semidefinite", build=lambda c: -c.C),
    Wrong("the factor 1/2 is missing: every weight is twice the right one", _RULE, build=lambda c: 2 * c.C),
    Wrong("every weight is half the right one: the 1/2 applied twice, or Heron's 1/4 written 1/2", "A = 1/4 sqrt((a + b + c)(-a + b + c)(a - b + c)(a + b - c)); C_jk = 1/2 (cot alpha + cot beta)", build=lambda c: c.C / 2),
    Wrong("every weight is a quarter of the right one: Heron's formula without its 1/4", "A = 1/4 sqrt((a + b + c)(-a + b + c)(a - b + c)(a + b - c))", build=lambda c: c.C / 4),
    Wrong("Heron's formula is used with the perimeter instead of the half-perimeter s", "A = sqrt(s (s - a)(s - b)(s - c)) with s = (a + b + c) / 2", build=lambda c: _assemble(c, 0.5 * _cot(c, A=_perimeter_heron(c)))),
    Wrong("the diagonal of C is missing (its rows do not sum to zero)", "set C_ii = -sum of C_ij over the neighbours j of i", build=lambda c: c.C - np.diag(np.diag(c.C))),
    *(Wrong(*_ENDS, build=lambda c, end=end: _assemble(c, 0.5 * c.cot[:, end])) for end in (NEXT, PREV)),
    Wrong("the law of cosines is written with the lengths, not their squares", "cos theta_i = (l_j^2 + l_k^2 - l_i^2) / (2 l_j l_k), so cot theta_i = (l_j^2 + l_k^2 - l_i^2) / (4 A)", build=lambda c: _assemble(c, 0.5 * _cot(c, squares=False))),
    Wrong("cos theta is used, not cot theta", "cot = cos / sin, and sin theta_i = 2 A / (l_j l_k): cot theta_i = (l_j^2 + l_k^2 - l_i^2) / (4 A)", build=lambda c: _assemble(c, 0.5 * c.cot * (4 * c.A[:, None]) / (2 * c.l[:, NEXT] * c.l[:, PREV]))),
    Wrong("tan is used instead of cot", "cot theta = cos theta / sin theta = 1 / tan theta", build=lambda c: _tan(c)),
    Wrong("the angles are in degrees where np.tan expects radians", "np.arccos returns radians: 1 / np.tan(theta) as it is, or the law of cosines over 4 A", build=lambda c: _assemble(c, 0.5 / np.tan(np.degrees(np.arctan2(1.0, c.cot))))),
    Wrong("boundary edges are left out: an edge with one triangle gets no weight", "a boundary edge gets 1/2 cot of the one angle opposite it (the natural boundary condition)", build=lambda c: _boundary(c, 0.0)),
    Wrong("boundary edges get cot of their one opposite angle, without the 1/2", "C_jk = 1/2 (cot alpha + cot beta); a boundary edge has only alpha: 1/2 cot alpha", build=lambda c: _boundary(c, 2.0)),
    Wrong("the rows of the boundary vertices are zeroed: a boundary rule built into C", "this exercise asks for the operator itself: a boundary vertex keeps its row, a boundary edge 1/2 cot alpha", build=lambda c: np.where(c.on_boundary[:, None], 0.0, c.C)),
    Wrong("these are the uniform weights (1 for every edge), not the cotangent weights", _RULE, build=lambda c: _assemble(c, np.ones(c.F.shape) / 2)),
    Wrong("each weight is entered at C_jk only, not also at C_kj: C is not symmetric", "add 1/2 cot theta_i to both C_jk and C_kj", build=lambda c: _assemble(c, 0.5 * c.cot, both=False)),
    Wrong("C is not symmetric", "add each triangle's weight to both C_jk and C_kj", when=lambda C, right, c: not np.allclose(C, C.T, atol=1e-9 * np.abs(right).max())),
]
# fmt: on


def _square(out, n):
    """The n x n matrix the function returned (sparse or dense), a float array."""
    if isinstance(out, tuple):
        raise Mistake(f"the function returned a tuple of {len(out)}, not the matrix C", "return C alone", typical=False)
    try:
        C = out.toarray() if hasattr(out, "toarray") else np.asarray(out, dtype=float)
    except (TypeError, ValueError):
        raise Mistake(f"the function returned {type(out).__name__}, not a matrix", "return C", typical=False) from None
    if C.shape != (n, n):
        raise Mistake(
            f"the function returned shape {np.shape(C)}, expected ({n}, {n}) for a mesh with {n} vertices",
            "return C alone, one row and one column per vertex (n = F.max() + 1)",
            typical=False,
        )
    return C.astype(float)


@exercise(
    "cotangent_matrix",
    reread="section 1 · Cotangent weights, derived, and the prompt's Heron's formula and law of cosines",
    forbid=(
        "lessons.laplace.intrinsic_cotangent_matrix",
        "lessons.laplace.cotangent_matrix",
        "lessons.laplace.laplacian",
    ),
)
def cotangent_matrix(fn):
    """Check ``fn(l, F) -> C`` (n, n), from the edge lengths alone: C_jk = 1/2 (cot alpha + cot beta)."""
    cases = cotangent_cases(case_rng())
    answers = run(fn, cases, _square)
    judge(C_MISTAKES, cases, answers, right=lambda c: c.C)
    return [c.label for c in cases]


def areas_cases(rng):
    return mesh_cases((("one obtuse triangle", obtuse_triangle()), *_MESHES), rng)


def _per_vertex(out, n):
    if np.ndim(out) == 1 and len(out) != n:
        raise Mistake(
            f"the function returned {len(out)} values, not one per vertex ({n}): one per face?",
            "accumulate each corner's piece into its vertex, e.g. with np.add.at or np.bincount",
            typical=False,
        )
    return vector(out, n)


@exercise(
    "mixed_areas",
    reread="section 2 · Which area? Barycentric and mixed Voronoi",
    forbid=(
        "lessons.laplace.mixed_areas",
        "lessons.laplace.vertex_areas",
        "lessons.laplace.voronoi_pieces",
        "lessons.laplace.laplacian",
    ),
    allow=("lessons.laplace.edge_lengths",),
)
def mixed_areas(fn):
    """Check ``fn(V, F) -> (n,)`` mixed areas (Meyer et al. 2003): Voronoi pieces, or A/2 and A/4 if obtuse."""
    cases = areas_cases(case_rng())
    answers = run(fn, cases, _per_vertex)
    judge(AREA_MISTAKES["mixed"], cases, answers, right=RIGHT_AREAS["mixed"])
    return [c.label for c in cases]


def _kappas(H, K, root=lambda d: np.sqrt(np.maximum(d, 0.0))):
    """(2, n): kappa_1 = H + root(H^2 - K) above kappa_2 = H - root(H^2 - K); NaN stays NaN."""
    with np.errstate(invalid="ignore"):
        r = root(H * H - K)
    return np.stack([H + r, H - r])


YOURS = ("my_cotangent_matrix", "my_mixed_areas")  # the learner's routines of sections 1 and 2


def _differs(out, right):
    try:
        return not agree(
            np.reshape(out.toarray() if hasattr(out, "toarray") else np.asarray(out, float), right.shape), right
        )
    except (TypeError, ValueError):
        return True


def principal_cases(rng, fn=None):
    """The cases of ``discrete_principal_curvatures``, and whether the C and areas of ``fn``'s notebook are wrong."""
    meshes = (("a jittered icosphere", jittered_icosphere()), ("a bump on a 4 x 4 grid", bump_4x4()))
    meshes += (("a saddle on a 4 x 4 grid", jittered_grid_4x4()), ("an irregular bipyramid", irregular_bipyramid()))
    cases = []
    for c in mesh_cases(meshes, rng):
        (M, C), bary = laplacian(c.V, c.F, area="mixed"), laplacian(c.V, c.F)[0].diagonal()
        A, deficit = M.diagonal(), gaussian_curvature(c.V, c.F, integrated=True)  # NaN on the boundary
        right = np.stack(geomlib_principal(c.V, c.F, M, C, deficit))
        H_of = lambda areas, C=C, c=c: signed_mean_curvature(c.V, c.F, sp.diags(areas), C)  # noqa: E731
        case = Case(c.label, V=c.V, F=c.F, deficit=deficit).but(C=C.toarray(), A=A, H=H_of(A), K=deficit / A)
        case = case.but(H_I=H_of(np.ones(len(A))), H_inv=H_of(1 / A), H_bary=H_of(bary), bary=bary, kappas=right)
        case = case.but(boundary=boundary_mask(c.V, c.F), where=np.isfinite(right), interior=np.isfinite(right))
        yours = [
            earlier(fn, YOURS[0], edge_lengths(c.V, c.F), c.F.copy()),
            earlier(fn, YOURS[1], c.V.copy(), c.F.copy()),
        ]
        case = case.but(C_wrong=yours[0] is not None and _differs(yours[0], case.C))
        case = case.but(A_wrong=yours[1] is not None and _differs(yours[1], A))
        cases.append(case)
    return cases


_RULE_K = "kappa_1,2 = H +- sqrt(max(H^2 - K, 0)), H = signed_mean_curvature(V, F, M, C), K_i = deficit_i / M_ii"
_CLAMP = "clamp where the discrete H^2 < K: sqrt(max(H^2 - K, 0)), so that kappa_1 = kappa_2 = H there"
_MIXED = "M = diag(my_mixed_areas(V, F)), the mixed areas of section 2, in H and in K"
_EARLIER = "fix section {0} first: check.{1}({2}) names its mistake; then run this check again"
# fmt: off
KAPPA_MISTAKES = [
    Wrong("your my_cotangent_matrix (section 1) returns a wrong C on {label}, and your kappas are built on it", _EARLIER.format(1, "cotangent_matrix", YOURS[0]), when=lambda k, right, c: c.C_wrong),
    Wrong("your my_mixed_areas (section 2) returns wrong areas on {label}, and your kappas are built on them", _EARLIER.format(2, "mixed_areas", YOURS[1]), when=lambda k, right, c: c.A_wrong),
    Wrong("kappa_1 and kappa_2 are swapped: kappa_1 < kappa_2", "kappa_1 = H + sqrt(max(H^2 - K, 0)) is the larger", build=lambda c: c.kappas[::-1]),
    Wrong("K is the deficit itself, not divided by the area (integrated, not pointwise)", "the deficit is an angle (radians); K_i = deficit_i / M_ii is per unit area", build=lambda c: _kappas(c.H, c.deficit)),
    Wrong("H^2 - K is not clamped: its square root is NaN where the discrete H^2 < K", _CLAMP, build=lambda c: _kappas(c.H, c.K, np.sqrt)),
    Wrong("|H^2 - K| is used where the discrete H^2 < K, not the clamp to 0", _CLAMP, build=lambda c: _kappas(c.H, c.K, lambda d: np.sqrt(np.abs(d)))),
    Wrong("the square root is missing: H +- (H^2 - K)", _RULE_K, build=lambda c: _kappas(c.H, c.K, lambda d: np.maximum(d, 0.0))),
    Wrong("the sign of H is lost: |H| drops the side the surface bends to", "signed_mean_curvature is negative where the surface bends away from the outward normal: keep its sign", build=lambda c: _kappas(np.abs(c.H), c.K)),
    Wrong("H has the wrong sign: signed_mean_curvature already holds the -1/2 and the outward normal", "H = signed_mean_curvature(V, F, M, C) as it is (H > 0 on a sphere)", build=lambda c: _kappas(-c.H, c.K)),
    Wrong("M is the identity in H: H is not divided by the vertex areas", _MIXED, build=lambda c: _kappas(c.H_I, c.K)),
    Wrong("M is the identity: neither H nor K is divided by the vertex areas", _MIXED, build=lambda c: _kappas(c.H_I, c.deficit)),
    Wrong("M holds the barycentric areas (a third of each triangle), not the mixed ones", _MIXED, build=lambda c: _kappas(c.H_bary, c.deficit / c.bary)),
    Wrong("M^-1 is handed to signed_mean_curvature where M is asked for: H is multiplied by the areas, not divided", "signed_mean_curvature(V, F, M, C) divides by M itself: M = diag(areas)", build=lambda c: _kappas(c.H_inv, c.K)),
    Wrong("kappa_1 < kappa_2 at a vertex of {label}", "kappa_1 = H + sqrt(...) >= kappa_2 = H - sqrt(...)", when=lambda k, right, c: (k[0][c.where[0]] < k[1][c.where[0]]).any()),
    Wrong("kappa_1, kappa_2 differ from H +- sqrt(max(H^2 - K, 0)) at interior vertices of {label}", _RULE_K, typical=False),
]
# fmt: on
KAPPA_BOUNDARY = [
    Wrong(
        "kappa_1, kappa_2 have values at boundary vertices, where H and the deficit (and so K) are NaN",
        "let the NaN through: np.maximum and np.sqrt keep it (np.fmax, np.nan_to_num and a mask on H^2 < K do not)",
    ),
]


def _pair(out, n):
    """(2, n) float array from the pair (kappa_1, kappa_2) the function returned."""
    if not isinstance(out, (tuple, list, np.ndarray)) or len(out) != 2:
        raise Mistake(
            f"the function returned {type(out).__name__} of {np.shape(out)}, not the pair (kappa_1, kappa_2)",
            "end with `return k1, k2`, each of shape (n,)",
            typical=False,
        )
    return np.stack([vector(k, n, f"the function, as kappa_{i + 1},") for i, k in enumerate(out)])


@exercise(
    "discrete_principal_curvatures",
    reread="section 5 · Principal curvatures",
    forbid=(
        *named("lessons.curvature", "mixed_principal_curvatures discrete_principal_curvatures principal_curvatures"),
        *named("lessons.curvature", "mean_curvature"),
        *named("lessons.laplace", "laplacian cotangent_matrix intrinsic_cotangent_matrix mixed_areas vertex_areas"),
    ),
    own=named("lessons.curvature", "mixed_principal_curvatures discrete_principal_curvatures principal_curvatures"),
    allow=("lessons.laplace.edge_lengths", "lessons.curvature.signed_mean_curvature"),
    yours=YOURS,
)
def discrete_principal_curvatures(fn):
    """Check ``fn(V, F, deficit) -> (kappa_1, kappa_2)``: your C and mixed areas, H +- sqrt(max(H^2 - K, 0))."""
    cases = principal_cases(case_rng(), fn)
    answers = run(fn, cases, _pair)
    judge(KAPPA_MISTAKES, cases, answers, right=lambda c: c.kappas)
    judge(KAPPA_BOUNDARY, [c.but(where=~c.interior) for c in cases], answers, right=lambda c: c.kappas)
    return [c.label for c in cases]
