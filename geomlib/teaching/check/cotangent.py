"""Checks of the exercises of notebook 03 (the cotangent Laplacian and the vertex areas).

The small cases have known answers: an irregular tetrahedron (closed, every
angle different, none right), one obtuse triangle (mixed areas A/2, A/4, A/4)
and a jittered 4 x 4 grid (open, with obtuse triangles and boundary edges).
The reference values come from ``geomlib.lessons.laplace``; the typical wrong
variants are rebuilt here from the per-corner cotangents
(``geomlib.lessons.laplace.face_geometry``) so each can be named when it is met.
"""

import numpy as np

from ...lessons import laplace
from ...lessons.laplace import face_geometry, laplacian
from .result import Mistake, call, close, exercise, matrix_pair, vector

__all__ = ["cotangent_laplacian", "vertex_areas", "mixed_areas"]

_REREAD_C = "section 1 · Cotangent weights, derived"
_REREAD_A = "section 2 · Which area? Barycentric and mixed Voronoi"

_TET_V = np.array([[0.0, 0.0, 0.0], [1.3, 0.1, 0.0], [0.4, 1.1, 0.2], [0.3, 0.4, 0.9]])
_TET_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
_OBTUSE_V = np.array([[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [1.0, 1.0, 0.0]])  # obtuse at vertex 2, area 2
_OBTUSE_F = np.array([[0, 1, 2]])


def _jittered_grid():
    rng = np.random.default_rng(3)
    V = np.array([[x, y, 0.1 * x * y] for y in range(4) for x in range(4)], dtype=float)
    V[:, :2] += rng.uniform(-0.3, 0.3, size=(16, 2))
    F = []
    for y in range(3):
        for x in range(3):
            a = 4 * y + x
            F += [[a, a + 1, a + 5], [a, a + 5, a + 4]]
    return V, np.array(F)


_GRID_V, _GRID_F = _jittered_grid()
_CASES = (("an irregular tetrahedron", _TET_V, _TET_F), ("a jittered 4 x 4 grid", _GRID_V, _GRID_F))


def _weights(V, F, corner, of=lambda cot: cot):
    """Off-diagonal weights: for every ordered pair (i, j) of corners of a face, 1/2 of(cot) at ``corner(i, j, k)``.

    ``corner`` picks which of the three corners (local indices p, q, r; r opposite the edge) supplies the angle:
    ``r`` is the cotangent formula, ``p`` or ``q`` the typical mistakes.
    """
    _, _, cot, _ = face_geometry(V, F)
    W = np.zeros((len(V), len(V)))
    for p, q, r in ((0, 1, 2), (1, 0, 2), (1, 2, 0), (2, 1, 0), (2, 0, 1), (0, 2, 1)):
        np.add.at(W, (F[:, p], F[:, q]), 0.5 * of(cot[:, corner(p, q, r)]))
    return W


def _wrong_angle_variants(V, F):
    """Off-diagonals of C with the angle at i, at j, or at a face-order end of the edge, instead of opposite."""
    return [
        _weights(V, F, lambda p, q, r: p),
        _weights(V, F, lambda p, q, r: q),
        _weights(V, F, lambda p, q, r: (r + 1) % 3),
        _weights(V, F, lambda p, q, r: (r + 2) % 3),
    ]


@exercise(
    "cotangent_laplacian",
    reread=_REREAD_C,
    forbid=(
        "lessons.laplace.cotangent_matrix",
        "lessons.laplace.laplacian",
        "lessons.laplace.barycentric_areas",
        "lessons.laplace.vertex_areas",
    ),
    own=("lessons.laplace.cotangent_matrix",),
)
def cotangent_laplacian(fn):
    """Check ``fn(V, F) -> (M, C)``: C_ij = (cot alpha_ij + cot beta_ij) / 2, C_ii = -sum_j C_ij, M barycentric."""
    checked = []
    for label, V, F in _CASES:
        M, C = matrix_pair(call(fn, V.copy(), F.copy()), n=len(V))
        M_ref, C_ref = (A.toarray() for A in laplacian(V, F, weights="cotan", area="barycentric"))
        off = ~np.eye(len(V), dtype=bool)
        tan = _weights(V, F, lambda p, q, r: r, of=lambda cot: 1.0 / cot)
        if close(C, -C_ref):
            raise Mistake(
                "the sign of C is flipped",
                "C_ij = +(cot alpha_ij + cot beta_ij) / 2 off the diagonal, so that C is negative "
                "semidefinite and Delta x = -2 H n",
            )
        if close(C, 2 * C_ref) or close(C[off], 2 * C_ref[off]):
            raise Mistake(
                "the factor 1/2 is missing (every weight is twice the right one)",
                "C_ij = 1/2 (cot alpha_ij + cot beta_ij)",
            )
        if close(C[off], C_ref[off]) and np.allclose(np.diag(C), 0):
            raise Mistake(
                "the diagonal of C is missing (its rows do not sum to zero)",
                "set C_ii = -sum of C_ij over the neighbours j of i",
            )
        if any(close(C[off], W[off]) for W in _wrong_angle_variants(V, F)):
            raise Mistake(
                "the cotangent of the wrong angle is used: an angle at i or j, an end of the edge ij",
                "use the two angles opposite the edge ij, at the third corner of each triangle",
            )
        if close(C[off], tan[off]) or close(C[off], -tan[off]):
            raise Mistake("tan is used instead of cot", "cot theta = cos theta / sin theta = 1 / tan theta")
        if not close(C, C.T):
            raise Mistake("C is not symmetric", "add each triangle's weight to both C_ij and C_ji")
        if not close(C, C_ref):
            raise Mistake(
                f"C differs from the cotangent Laplacian on {label}",
                "each triangle (i, j, k) adds cot(angle at k) / 2 to C_ij and C_ji, and subtracts the "
                "same from C_ii and C_jj",
                typical=False,
            )
        if close(M, np.eye(len(V))):
            raise Mistake("M is the identity", "M = diag(A_i), a third of the areas of the triangles around i")
        _check_area_scale(M, M_ref, "M")
        if np.count_nonzero(M[off]):
            raise Mistake("M is not diagonal", "M = diag(A_i): the lumped (diagonal) mass matrix")
        if not close(M, M_ref):
            raise Mistake(
                f"M differs from the barycentric areas on {label}",
                "M_ii = 1/3 of the sum of the areas of the triangles around i",
                typical=False,
            )
        checked.append(label)
    return checked


def _check_area_scale(A, ref, what):
    """The two scale mistakes of barycentric areas (A or M against the reference ``ref``)."""
    if close(A, 3 * ref):
        raise Mistake(
            f"{what} is not divided by 3: each vertex gets the whole area of its triangles",
            "a triangle gives a third of its area to each of its corners",
        )
    if close(A, 2 * ref) or close(A, 6 * ref):
        raise Mistake(
            f"{what} uses twice the triangle area (the length of the cross product is 2 A)",
            "a triangle's area is |(x_j - x_i) x (x_k - x_i)| / 2",
        )


def _areas(fn, V, F, what):
    out = call(fn, V.copy(), F.copy())
    if np.ndim(out) == 1 and len(out) == len(F) != len(V):
        raise Mistake(
            f"{what} returned one value per face ({len(F)}), not one per vertex ({len(V)})",
            "accumulate each face's share into its three vertices, e.g. with np.add.at or np.bincount",
        )
    return vector(out, len(V), what)


@exercise(
    "vertex_areas",
    reread=_REREAD_A,
    forbid=(
        "lessons.laplace.barycentric_areas",
        "lessons.laplace.vertex_areas",
        "lessons.laplace.laplacian",
        "lessons.laplace.measured_areas",
    ),
)
def vertex_areas(fn):
    """Check ``fn(V, F) -> (n,)`` barycentric vertex areas: A_i = 1/3 of the incident triangle areas."""
    checked = []
    for label, V, F in (("one obtuse triangle", _OBTUSE_V, _OBTUSE_F),) + _CASES:
        A = _areas(fn, V, F, "the function")
        ref = laplace.vertex_areas(V, F, "barycentric")
        _check_area_scale(A, ref, "the area")
        if label == "one obtuse triangle" and close(A, laplace.vertex_areas(V, F, "mixed")):
            raise Mistake(
                "these are the mixed (Voronoi) areas, not the barycentric ones",
                "the barycentric area gives every corner the same third",
            )
        if not close(A, ref):
            raise Mistake(
                f"the areas differ from the barycentric areas on {label} "
                f"(sum {A.sum():.6g}, surface area {ref.sum():.6g})",
                "A_i = 1/3 of the sum of the areas of the triangles around i",
                typical=False,
            )
        checked.append(label)
    return checked


def _voronoi_pieces(V, F):
    """Per-corner Voronoi areas 1/8 (l_j^2 cot_j + l_k^2 cot_k), negative where the circumcentre is outside."""
    l2, _, cot, _ = face_geometry(V, F)
    lc = l2 * cot
    return np.stack([lc[:, 1] + lc[:, 2], lc[:, 2] + lc[:, 0], lc[:, 0] + lc[:, 1]], axis=1) / 8


def _is(A, variant, ref):
    """A equals a wrong variant that differs from the reference on this case."""
    return close(A, variant) and not close(variant, ref)


def _per_corner_sum(n, F, pieces):
    return np.bincount(F.ravel(), weights=pieces.ravel(), minlength=n)


@exercise(
    "mixed_areas",
    reread=_REREAD_A,
    forbid=(
        "lessons.laplace.mixed_areas",
        "lessons.laplace.vertex_areas",
        "lessons.laplace.laplacian",
        "lessons.laplace.measured_areas",
    ),
)
def mixed_areas(fn):
    """Check ``fn(V, F) -> (n,)`` mixed areas (Meyer et al. 2003): Voronoi, or A/2 and A/4 in obtuse triangles."""
    checked = []
    for label, V, F in (("one obtuse triangle", _OBTUSE_V, _OBTUSE_F),) + _CASES:
        A = _areas(fn, V, F, "the function")
        ref = laplace.vertex_areas(V, F, "mixed")
        _, dblA, cot, _ = face_geometry(V, F)
        Af = (dblA / 2)[:, None]
        obtuse_corner, obtuse_face = cot < 0, (cot < 0).any(axis=1, keepdims=True)
        voronoi = _voronoi_pieces(V, F)
        swapped = np.where(obtuse_face, np.where(obtuse_corner, Af / 4, Af / 2), voronoi)
        only_at_obtuse = np.where(obtuse_corner, Af / 2, voronoi)
        if _is(A, _per_corner_sum(len(V), F, voronoi), ref):
            raise Mistake(
                "the obtuse rule is missing: these are the plain Voronoi areas, negative at corners "
                "of obtuse triangles",
                "in an obtuse triangle give A_f/2 to the obtuse corner and A_f/4 to the other two",
            )
        if _is(A, laplace.vertex_areas(V, F, "barycentric"), ref):
            raise Mistake(
                "these are the barycentric areas (a third of each triangle), not the mixed ones",
                "use the Voronoi piece 1/8 (|e_ij|^2 cot + |e_ik|^2 cot) in non-obtuse triangles",
            )
        if _is(A, _per_corner_sum(len(V), F, swapped), ref):
            raise Mistake(
                "the halves are swapped in obtuse triangles: the obtuse corner gets A_f/4",
                "the obtuse corner gets A_f/2, the two acute corners A_f/4 each",
            )
        if _is(A, _per_corner_sum(len(V), F, only_at_obtuse), ref):
            raise Mistake(
                "the obtuse rule is applied only at the obtuse corner; the other two corners of an "
                "obtuse triangle still get their Voronoi pieces",
                "in an obtuse triangle the two acute corners get A_f/4 each",
            )
        if close(A, 3 * ref) or close(A, 2 * ref):
            raise Mistake(
                "the areas are a whole multiple of the right ones",
                "check the factors: 1/8 in the Voronoi piece, A_f = |cross| / 2",
            )
        if not close(A, ref):
            raise Mistake(
                f"the areas differ from the mixed areas on {label} (sum {A.sum():.6g}, surface area {ref.sum():.6g})",
                "non-obtuse triangle: 1/8 (|e_ij|^2 cot(angle at k) + |e_ik|^2 cot(angle at j)); "
                "obtuse: A_f/2 at the obtuse corner, A_f/4 at the others",
                typical=False,
            )
        checked.append(label)
    return checked
