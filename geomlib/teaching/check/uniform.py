"""Checks of the exercises of notebook 01: the uniform Laplacian and the angle-deficit Gaussian curvature."""

import numpy as np

from ...lessons.curvature import angle_deficit, boundary_mask
from ...lessons.curvature import gaussian_curvature as geomlib_gaussian_curvature
from ...lessons.laplace import barycentric_areas, laplacian, mixed_areas
from .result import Mistake, call, close, exercise, matrix_pair, vector

__all__ = ["gaussian_curvature", "uniform_laplacian"]

# a tetrahedron (valence 3 everywhere) and a 3 x 3 vertex grid (valences 2..6)
_TET_V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
_TET_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
_GRID_V = np.array([[x, y, 0.0] for y in range(3) for x in range(3)])
_GRID_F = np.array([[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4], [3, 4, 7], [3, 7, 6], [4, 5, 8], [4, 8, 7]])


@exercise(
    "uniform_laplacian",
    reread="section 2 · The uniform Laplacian, derived",
    forbid=("lessons.laplace.uniform_laplacian", "lessons.laplace.laplacian", "lessons.laplace.uniform_adjacency"),
)
def uniform_laplacian(fn):
    """Check ``fn(V, F) -> (M, C)``: C_ij = 1 on edges, C_ii = -valence, M = diag(valence)."""
    checked = []
    for label, V, F in (("a tetrahedron", _TET_V, _TET_F), ("a 3 x 3 grid", _GRID_V, _GRID_F)):
        M, C = matrix_pair(call(fn, V.copy(), F.copy()), n=len(V))
        M_ref, C_ref = (A.toarray() for A in laplacian(V, F, weights="uniform"))
        off = ~np.eye(len(V), dtype=bool)
        if close(C, -C_ref):
            raise Mistake(
                "the sign of C is flipped",
                "C_ij = +1 for each edge ij and C_ii = -valence, so that C is negative semidefinite",
            )
        if close(C[off], C_ref[off]) and np.allclose(np.diag(C), 0):
            raise Mistake(
                "the diagonal of C is missing (its rows do not sum to zero)", "set C_ii = -(number of neighbours of i)"
            )
        if close(C, C_ref / np.diag(M_ref)[:, None]):
            raise Mistake(
                "C is already divided by the valence: that is M^-1 C, not C", "keep C_ij = 1 and put the valences in M"
            )
        if close(C[off], 2 * C_ref[off]):
            raise Mistake(
                "every edge is counted twice (off-diagonal entries are 2)",
                "each edge appears in two triangles; set its entry to 1, do not add",
            )
        if not close(C, C.T):
            raise Mistake("C is not symmetric", "set both C_ij and C_ji for every edge")
        if not close(C, C_ref):
            raise Mistake(
                f"C differs from the uniform Laplacian on {label}",
                "C_ij = 1 for neighbours, C_ii = -valence, 0 elsewhere",
                typical=False,
            )
        if close(M, np.eye(len(V))):
            raise Mistake("M is the identity", "M = diag(valence), the number of neighbours of each vertex")
        if close(M, -M_ref):
            raise Mistake("M has the wrong sign", "M holds positive valences")
        if not close(M, M_ref):
            raise Mistake(f"M differs from diag(valence) on {label}", "M_ii = number of neighbours of i", typical=False)
        checked.append(label)
    return checked


# a closed case with unequal curvature (the corner tetrahedron above) and an open one: a 4 x 4 grid
# lifted into a bump, so that interior K is non-zero and the boundary rule matters
_BUMP_V = np.array([[x, y, 0.4 * np.exp(-((x - 1.5) ** 2 + (y - 1.5) ** 2))] for y in range(4) for x in range(4)])
_BUMP_F = np.array(
    [
        f
        for y in range(3)
        for x in range(3)
        for f in ([4 * y + x, 4 * y + x + 1, 4 * y + x + 5], [4 * y + x, 4 * y + x + 5, 4 * y + x + 4])
    ]
)


def _same(a, b, mask):
    """a == b on ``mask`` (both finite there)."""
    return bool(np.all(np.isfinite(a[mask]))) and close(a[mask], b[mask], rtol=1e-7, atol=1e-9)


@exercise(
    "gaussian_curvature",
    reread="section 3 · Gaussian curvature from the angle deficit",
    forbid=(
        "lessons.curvature.gaussian_curvature",
        "lessons.curvature.angle_deficit",
        "lessons.curvature.angle_sums",
        "lessons.curvature.angle_and_area_sums",
    ),
)
def gaussian_curvature(fn):
    """Check ``fn(V, F) -> (n,)``: K_i = (2 pi - sum of angles) / (a third of the incident areas), NaN on the boundary."""
    checked = []
    for label, V, F in (("a tetrahedron", _TET_V, _TET_F), ("a bump on a 4 x 4 grid", _BUMP_V, _BUMP_F)):
        K = vector(call(fn, V.copy(), F.copy()), len(V), "the function")
        K_ref = geomlib_gaussian_curvature(V, F)
        deficit = angle_deficit(V, F)
        A = barycentric_areas(V, F)
        inner = ~boundary_mask(V, F)
        if not _same(K, K_ref, inner):
            diagnoses = [
                (
                    -K_ref,
                    "the sign of the deficit is flipped (sum of angles - 2 pi)",
                    "K_i = (2 pi - sum of angles) / A_i: positive where the fan closes up, as on a sphere",
                ),
                (
                    K_ref / 3,
                    "the vertex area is not divided by 3 (the full area of the incident triangles)",
                    "A_i = one third of the areas of the triangles around vertex i",
                ),
                (
                    3 * K_ref,
                    "the vertex area is divided by 3 twice, or is a ninth of the incident areas",
                    "A_i = one third of the sum of the incident triangle areas",
                ),
                (
                    np.degrees(K_ref),
                    "the angles are in degrees (360 - sum of angles)",
                    "use radians: 2 pi - sum of angles, with np.arccos giving radians",
                ),
                (
                    deficit,
                    "the deficit is not divided by the vertex area (integrated, not pointwise, K)",
                    "divide 2 pi - sum of angles by A_i",
                ),
                (
                    deficit / mixed_areas(V, F),
                    "the mixed Voronoi area is used instead of the barycentric one",
                    "this exercise divides by the barycentric area, a third of the incident triangle areas",
                ),
            ]
            for wrong, diagnosis, hint in diagnoses:
                if _same(K, wrong, inner):
                    raise Mistake(diagnosis, hint)
            raise Mistake(
                f"K differs from the angle-deficit curvature at interior vertices of {label}",
                "K_i = (2 pi - sum of the angles at i) / (a third of the incident triangle areas)",
                typical=False,
            )
        boundary = ~inner
        if boundary.any() and not np.all(np.isnan(K[boundary])):
            if _same(K, deficit / A, boundary):
                raise Mistake(
                    "the interior formula is applied at boundary vertices (the wrong boundary rule)",
                    "the fan of a boundary vertex is open: 2 pi - sum of angles measures the missing "
                    "half-plane, not curvature; return NaN there",
                )
            raise Mistake(
                "boundary vertices have a value (the wrong boundary rule)",
                "K is not defined at a boundary vertex: return NaN there (np.nan)",
            )
        checked.append(label)
    return checked
