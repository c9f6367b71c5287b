"""Checks of the exercises of notebook 01: the uniform Laplacian and the angle-deficit Gaussian curvature.

Each check runs the learner's function on a closed mesh whose valences are all equal (a tetrahedron), an
open one (a grid: boundary vertices and edges), and a closed one whose valences differ and which holds
obtuse triangles (a jittered icosphere). A typical mistake is rebuilt on every mesh from scratch and
named only when the learner's answer matches it on all of them and it differs from the right answer on
one: mistakes that coincide on a single mesh (the mean and a ninth of the incident areas on a
tetrahedron; -valence and -number of triangles on a closed mesh) are told apart by the others.
"""

import numpy as np

from ...lessons.curvature import angle_deficit, boundary_mask
from ...lessons.curvature import gaussian_curvature as geomlib_gaussian_curvature
from ...lessons.laplace import barycentric_areas, laplacian
from ..shapes.surfaces import sphere
from .areas import area_mistake_over
from .result import Mistake, call, close, exercise, matrix_pair, vector

__all__ = ["gaussian_curvature", "uniform_laplacian"]

# a tetrahedron (valence 3 everywhere) and a 3 x 3 vertex grid (valences 2..6, a boundary)
_TET_V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
_TET_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
_GRID_V = np.array([[x, y, 0.0] for y in range(3) for x in range(3)])
_GRID_F = np.array([[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4], [3, 4, 7], [3, 7, 6], [4, 5, 8], [4, 8, 7]])
# closed, valences 5 and 6, six obtuse triangles, every angle deficit at least 0.16
_ICO = sphere(1.0, subdivisions=1, jitter=0.3, seed=3)
_ICO_V, _ICO_F = _ICO.V, _ICO.F

# the rules in the learner's own terms, for the hints
_C_RULE = "C_ij = 1 for each edge ij (however many triangles share it), C_ii = -(number of neighbours of i)"
_M_RULE = "M = diag(valence), the number of neighbours of each vertex"


def _pair_counts(V, F):
    """(n, n) how many triangles list each ordered pair (i, j) as a directed edge i -> j of their boundary."""
    n = len(V)
    D = np.zeros((n, n))
    for a, b in ((0, 1), (1, 2), (2, 0)):
        np.add.at(D, (F[:, a], F[:, b]), 1.0)
    return D


def _uniform_mistakes(V, F):
    """The right dense (M, C) and the typical mistakes of C and of M, rebuilt from the mesh."""
    n = len(V)
    M_ref, C_ref = (A.toarray() for A in laplacian(V, F, weights="uniform"))
    A = C_ref - np.diag(np.diag(C_ref))  # 1 per edge
    valence = np.diag(M_ref)
    D = _pair_counts(V, F)
    per_triangle = D + D.T  # 2 on an interior edge, 1 on a boundary edge
    triangles = np.bincount(F.ravel(), minlength=n).astype(float)
    M_cot, C_cot = (X.toarray() for X in laplacian(V, F))
    c_mistakes = [
        (-C_ref, "the sign of C is flipped", _C_RULE + ", so that C is negative semidefinite"),
        (A, "the diagonal of C is missing (its rows do not sum to zero)", "set C_ii = -(number of neighbours of i)"),
        (A + np.diag(valence), "the diagonal of C has the wrong sign (+valence)", "C_ii = -valence"),
        (
            C_ref / valence[:, None],
            "C is already divided by the valence: that is the Laplacian M^-1 C, not C",
            "keep C_ij = 1 and put the valences in M",
        ),
        (
            per_triangle - np.diag(per_triangle.sum(axis=1)),
            "an edge counts once per triangle: 2 on edges inside the mesh, 1 on boundary edges",
            "each interior edge lies in two triangles; set its entry to 1, do not add",
        ),
        (
            A - np.diag(triangles),
            "the diagonal counts the triangles at a vertex, not its neighbours (the two differ at the boundary)",
            "C_ii = -(number of neighbours of i): a boundary vertex has one neighbour more than triangles",
        ),
        (
            D - np.diag(D.sum(axis=1)),
            "each edge is entered only in the direction the triangles list it, so a boundary edge gets one entry "
            "and C is not symmetric",
            "set both C_ij and C_ji for every edge",
        ),
        (
            C_cot,
            "C holds the cotangent weights (notebook 03's operator), not 1 per edge",
            "the uniform Laplacian ignores the geometry: " + _C_RULE,
        ),
    ]
    m_mistakes = [
        (np.eye(n), "M is the identity", _M_RULE),
        (-M_ref, "M has the wrong sign", "M holds positive valences"),
        (np.diag(1 / valence), "M holds 1/valence: that is M^-1, not M", _M_RULE),
        (
            np.diag(triangles),
            "M counts the triangles at a vertex, not its neighbours (the two differ at the boundary)",
            _M_RULE,
        ),
        (M_cot, "M holds vertex areas (the cotangent Laplacian's M), not the valences", _M_RULE),
    ]
    return M_ref, C_ref, c_mistakes, m_mistakes


def _named(answers, rights, mistakes_per_mesh):
    """The (diagnosis, hint) of the mistake the answers match on every mesh and that is wrong on one, or None."""
    for k in range(len(mistakes_per_mesh[0])):
        wrong = [mistakes[k][0] for mistakes in mistakes_per_mesh]
        if all(close(a, w, rtol=1e-6, atol=1e-9) for a, w in zip(answers, wrong)) and any(
            not close(w, r) for w, r in zip(wrong, rights)
        ):
            return mistakes_per_mesh[0][k][1:]
    return None


_UNIFORM_CASES = (
    ("a tetrahedron", _TET_V, _TET_F),
    ("a 3 x 3 grid", _GRID_V, _GRID_F),
    ("a jittered icosphere", _ICO_V, _ICO_F),
)


@exercise(
    "uniform_laplacian",
    reread="section 2 · The uniform Laplacian, derived",
    forbid=("lessons.laplace.uniform_laplacian", "lessons.laplace.laplacian", "lessons.laplace.uniform_adjacency"),
)
def uniform_laplacian(fn):
    """Check ``fn(V, F) -> (M, C)``: C_ij = 1 on edges, C_ii = -valence, M = diag(valence)."""
    Ms, Cs, M_refs, C_refs, c_all, m_all = [], [], [], [], [], []
    for label, V, F in _UNIFORM_CASES:
        M, C = matrix_pair(call(fn, V.copy(), F.copy()), n=len(V))
        M_ref, C_ref, c_mistakes, m_mistakes = _uniform_mistakes(V, F)
        for kept, x in zip((Ms, Cs, M_refs, C_refs, c_all, m_all), (M, C, M_ref, C_ref, c_mistakes, m_mistakes)):
            kept.append(x)
    found = _named(Cs, C_refs, c_all)
    if found:
        raise Mistake(*found)
    for (label, _, _), C, C_ref in zip(_UNIFORM_CASES, Cs, C_refs):
        if not close(C, C.T, rtol=1e-6, atol=1e-9):
            raise Mistake(f"C is not symmetric on {label}", "set both C_ij and C_ji for every edge")
        if not close(C, C_ref, rtol=1e-6, atol=1e-9):
            raise Mistake(f"C differs from the uniform Laplacian on {label}", _C_RULE, typical=False)
    found = _named(Ms, M_refs, m_all)
    if found:
        raise Mistake(*found)
    for (label, _, _), M, M_ref in zip(_UNIFORM_CASES, Ms, M_refs):
        if not close(M, M_ref, rtol=1e-6, atol=1e-9):
            raise Mistake(f"M differs from diag(valence) on {label}", _M_RULE, typical=False)
    return [label for label, _, _ in _UNIFORM_CASES]


# an open case: a 4 x 4 grid lifted into a bump, so that interior K is clearly non-zero and the boundary
# rule matters (valences 3..6 along the boundary, 6 inside)
_BUMP_V = np.array([[x, y, np.exp(-((x - 1.5) ** 2 + (y - 1.5) ** 2))] for y in range(4) for x in range(4)])
_BUMP_F = np.array(
    [
        f
        for y in range(3)
        for x in range(3)
        for f in ([4 * y + x, 4 * y + x + 1, 4 * y + x + 5], [4 * y + x, 4 * y + x + 5, 4 * y + x + 4])
    ]
)
_K_CASES = (
    ("a tetrahedron", _TET_V, _TET_F),
    ("a bump on a 4 x 4 grid", _BUMP_V, _BUMP_F),
    ("a jittered icosphere", _ICO_V, _ICO_F),
)
# Legitimate rounding: pi to 7 digits moves a deficit by 7e-7, single-precision angles by about 1e-6. K is
# compared in the deficit's own unit (K_i A_i, radians), so a vertex whose deficit is small is not held to a
# relative tolerance its rounding cannot meet; the mistakes below change a deficit by a tenth or more.
_DEFICIT_TOL = 1e-5


def _same_K(K, K_ref, A, mask):
    """K and K_ref agree on ``mask`` (both finite there) to _DEFICIT_TOL radians of angle deficit."""
    K, K_ref, A = K[mask], K_ref[mask], A[mask]
    return bool(np.all(np.isfinite(K))) and bool(
        np.all(np.abs(K - K_ref) * A <= _DEFICIT_TOL + 1e-6 * np.abs(K_ref * A))
    )


def _learner_areas(K, deficit, inner):
    """The vertex areas the learner divided by, read back as deficit / K where that can be read."""
    where = inner & np.isfinite(K) & (np.abs(deficit) > 0.05) & (K != 0)
    A = np.full(len(K), np.nan)
    A[where] = deficit[where] / K[where]
    return A, where


@exercise(
    "gaussian_curvature",
    reread="section 3 · Gaussian curvature from the angle deficit",
    forbid=(
        "lessons.curvature.gaussian_curvature",
        "lessons.curvature.angle_deficit",
        "lessons.curvature.angle_sums",
        "lessons.curvature.angle_and_area_sums",
        "lessons.curvature.corner_angles",
        "lessons.laplace.barycentric_areas",
        "lessons.laplace.vertex_areas",
    ),
    own=("lessons.curvature.gaussian_curvature", "lessons.curvature.angle_deficit"),
)
def gaussian_curvature(fn):
    """Check ``fn(V, F) -> (n,)``: K_i = (2 pi - sum of angles) / (a third of the incident areas), NaN on the boundary."""
    runs = []
    for label, V, F in _K_CASES:
        K = vector(call(fn, V.copy(), F.copy()), len(V), "the function")
        A, deficit, inner = barycentric_areas(V, F), angle_deficit(V, F), ~boundary_mask(V, F)
        runs.append((label, V, F, K, geomlib_gaussian_curvature(V, F), A, deficit, inner))
    wrong_inside = [run for run in runs if not _same_K(run[3], run[4], run[5], run[7])]
    if wrong_inside:
        for sign, diagnosis, hint in (
            (
                -1.0,
                "the sign of the deficit is flipped (sum of angles - 2 pi)",
                "K_i = (2 pi - sum of angles) / A_i: positive where the fan closes up, as on a sphere",
            ),
            (
                180 / np.pi,
                "the angles are in degrees (360 - sum of angles)",
                "use radians: 2 pi - sum of angles, with np.arccos giving radians",
            ),
        ):
            if all(_same_K(K, sign * K_ref, A, inner) for _, _, _, K, K_ref, A, _, inner in runs):
                raise Mistake(diagnosis, hint)
        if all(_same_K(K, deficit, np.ones(len(K)), inner) for _, _, _, K, _, _, deficit, inner in runs):
            raise Mistake(
                "the deficit is not divided by the vertex area (integrated, not pointwise, K)",
                "divide 2 pi - sum of angles by A_i",
            )
        read = [(*_learner_areas(K, deficit, inner), V, F) for _, V, F, K, _, _, deficit, inner in runs]
        found = area_mistake_over([(A, V, F, where) for A, where, V, F in read], "barycentric", rtol=1e-4)
        if found:
            raise Mistake(found[0], found[1])
        label = wrong_inside[0][0]
        valued = [run[0] for run in runs if np.isfinite(run[3][~run[7]]).any()]
        also = f"; and boundary vertices of {valued[0]} have values, where K is not defined (NaN)" if valued else ""
        raise Mistake(
            f"K differs from the angle-deficit curvature at interior vertices of {label}{also}",
            "K_i = (2 pi - sum of the angles at i) / (a third of the incident triangle areas)",
            typical=False,
        )
    for label, V, F, K, _, A, deficit, inner in runs:
        boundary = ~inner
        if boundary.any() and not np.all(np.isnan(K[boundary])):
            if _same_K(K, deficit / A, A, boundary):
                raise Mistake(
                    "the interior formula is applied at boundary vertices (no boundary rule)",
                    "the fan of a boundary vertex is open: 2 pi - sum of angles measures the missing "
                    "half-plane, not curvature; return NaN there",
                )
            raise Mistake(
                "boundary vertices have a value (the wrong boundary rule)",
                "K is not defined at a boundary vertex: return NaN there (np.nan)",
            )
    return [run[0] for run in runs]
