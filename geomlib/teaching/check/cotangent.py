"""Checks of the exercises of notebook 03 (the cotangent Laplacian and the vertex areas).

The small cases have known answers: an irregular tetrahedron (closed, every
angle different, none right), an irregular triangular bipyramid (closed, valences
3 and 4, three obtuse triangles), one obtuse triangle (mixed areas A/2, A/4, A/4)
and a jittered 4 x 4 grid (open, valences 2 to 6, obtuse triangles and boundary
edges). The reference values come from ``geomlib.lessons.laplace``; the typical
wrong variants are rebuilt here from the per-corner cotangents
(``geomlib.lessons.laplace.face_geometry``) so each can be named when it is met.
Vertex-area mistakes are named by ``geomlib.teaching.check.area_mistakes``, in the same
words as the Gaussian-curvature check of notebook 01.
"""

import numpy as np

from ...lessons import laplace
from ...lessons.laplace import barycentric_areas, cotangent_matrix, face_geometry
from ...mesh.topology import boundary_edges
from .area_mistakes import area_mistake_over
from .catalogue import matrix_pair, vector
from .meshes import irregular_bipyramid, irregular_tetrahedron, jittered_grid_4x4, obtuse_triangle
from .result import Mistake, call, close, exercise

__all__ = ["cotangent_laplacian", "vertex_areas", "mixed_areas"]

_REREAD_C = "section 1 · Cotangent weights, derived"
_REREAD_A = "section 2 · Which area? Barycentric and mixed Voronoi"

_TET_V, _TET_F = irregular_tetrahedron()
_BIPYRAMID_V, _BIPYRAMID_F = irregular_bipyramid()
_OBTUSE_V, _OBTUSE_F = obtuse_triangle()
_GRID_V, _GRID_F = jittered_grid_4x4()
_CASES = (
    ("an irregular tetrahedron", _TET_V, _TET_F),
    ("an irregular bipyramid", _BIPYRAMID_V, _BIPYRAMID_F),
    ("a jittered 4 x 4 grid", _GRID_V, _GRID_F),
)
_AREA_CASES = (("one obtuse triangle", _OBTUSE_V, _OBTUSE_F),) + _CASES


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


def _with_diagonal(W):
    """W with its diagonal replaced so that its rows sum to zero."""
    off = W - np.diag(np.diag(W))
    return off - np.diag(off.sum(axis=1))


def _boundary_variants(V, F, C_ref):
    """[(C, diagnosis, hint)]: the ways a learner's boundary rule departs from the natural one."""
    E = boundary_edges(F)
    on = np.zeros(len(V), bool)
    on[E.ravel()] = True
    rows = np.where(on[:, None], 0.0, C_ref)
    interior_only = C_ref.copy()
    interior_only[E[:, 0], E[:, 1]] = interior_only[E[:, 1], E[:, 0]] = 0.0
    doubled = C_ref.copy()
    doubled[E[:, 0], E[:, 1]] *= 2
    doubled[E[:, 1], E[:, 0]] *= 2
    natural = (
        "this exercise asks for the operator itself, with the natural boundary: a boundary edge has one "
        "triangle and gets 1/2 cot of its one opposite angle, and a boundary vertex keeps its row"
    )
    return [
        (rows, "the rows of the boundary vertices are zeroed: a boundary rule (fixed boundary) built into C", natural),
        (
            np.where(on[:, None] | on[None, :], 0.0, C_ref),
            "the rows and columns of the boundary vertices are zeroed: a boundary rule built into C",
            natural,
        ),
        (
            _with_diagonal(interior_only),
            "boundary edges are left out: an edge with one triangle gets no weight",
            "a boundary edge gets 1/2 cot of the one angle opposite it",
        ),
        (
            _with_diagonal(doubled),
            "boundary edges get cot of their one opposite angle, without the 1/2",
            "C_ij = 1/2 (cot alpha_ij + cot beta_ij); a boundary edge has only alpha_ij: 1/2 cot alpha_ij",
        ),
    ]


def _check_cotangent_C(C, C_ref, V, F, label):
    off = ~np.eye(len(V), dtype=bool)
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
    for A in (barycentric_areas(V, F), laplace.mixed_areas(V, F)):
        if close(C, C_ref / A[:, None]):
            raise Mistake(
                "C is already divided by the vertex areas: that is M^-1 C (the operator Delta), not C",
                "keep C_ij = 1/2 (cot alpha_ij + cot beta_ij) and put the areas in M",
            )
    uniform = (C_ref != 0).astype(float)
    if close(C[off], uniform[off]):
        raise Mistake(
            "these are the uniform weights (1 for every edge), not the cotangent weights",
            "C_ij = 1/2 (cot alpha_ij + cot beta_ij), from the two angles opposite the edge ij",
        )
    tan = _weights(V, F, lambda p, q, r: r, of=lambda cot: 1.0 / cot)
    if close(C[off], tan[off]) or close(C[off], -tan[off]):
        raise Mistake("tan is used instead of cot", "cot theta = cos theta / sin theta = 1 / tan theta")
    for wrong, diagnosis, hint in _boundary_variants(V, F, C_ref):
        if not close(wrong, C_ref) and (close(C, wrong) or close(C[off], wrong[off])):
            raise Mistake(diagnosis, hint)
    if not close(C, C.T):
        raise Mistake("C is not symmetric", "add each triangle's weight to both C_ij and C_ji")
    if not close(C, C_ref):
        raise Mistake(
            f"C differs from the cotangent Laplacian on {label}",
            "each triangle (i, j, k) adds cot(angle at k) / 2 to C_ij and C_ji, and subtracts the "
            "same from C_ii and C_jj",
            typical=False,
        )


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
    found = []
    for label, V, F in _CASES:
        M, C = matrix_pair(call(fn, V.copy(), F.copy()), n=len(V))
        _check_cotangent_C(C, cotangent_matrix(V, F).toarray(), V, F, label)
        found.append((label, V, F, M))
    for label, V, F, M in found:
        if close(M, np.eye(len(V))):
            raise Mistake("M is the identity", "M = diag(A_i), a third of the areas of the triangles around i")
        if np.count_nonzero(M[~np.eye(len(V), dtype=bool)]):
            raise Mistake("M is not diagonal", "M = diag(A_i): the lumped (diagonal) mass matrix")
    mistake = area_mistake_over([(np.diag(M), V, F) for _, V, F, M in found], "barycentric")
    if mistake:
        raise Mistake(f"the areas on the diagonal of M are wrong: {mistake[0]}", mistake[1])
    for label, V, F, M in found:
        if not close(np.diag(M), barycentric_areas(V, F)):
            raise Mistake(
                f"M differs from the barycentric areas on {label}",
                "M_ii = 1/3 of the sum of the areas of the triangles around i",
                typical=False,
            )
    return [label for label, *_ in found]


def _areas(fn, V, F):
    out = call(fn, V.copy(), F.copy())
    if np.ndim(out) == 1 and len(out) == len(F) != len(V):
        raise Mistake(
            f"the function returned one value per face ({len(F)}), not one per vertex ({len(V)})",
            "accumulate each face's share into its three vertices, e.g. with np.add.at or np.bincount",
        )
    return vector(out, len(V), "the function")


def _check_areas(fn, asked, reference, hint):
    """Run ``fn`` on every case; name the area mistake it makes on all of them, or where it differs."""
    found = [(label, _areas(fn, V, F), V, F) for label, V, F in _AREA_CASES]
    mistake = area_mistake_over([(A, V, F) for _, A, V, F in found], asked)
    if mistake:
        raise Mistake(*mistake)
    for label, A, V, F in found:
        ref = reference(V, F)
        if not close(A, ref):
            raise Mistake(
                f"the areas differ from the {asked} areas on {label} (sum {A.sum():.6g}, surface area {ref.sum():.6g})",
                hint,
                typical=False,
            )
    return [label for label, *_ in found]


@exercise(
    "vertex_areas",
    reread=_REREAD_A,
    forbid=(
        "lessons.laplace.barycentric_areas",
        "lessons.laplace.vertex_areas",
        "lessons.laplace.laplacian",
    ),
)
def vertex_areas(fn):
    """Check ``fn(V, F) -> (n,)`` barycentric vertex areas: A_i = 1/3 of the incident triangle areas."""
    return _check_areas(
        fn, "barycentric", barycentric_areas, "A_i = 1/3 of the sum of the areas of the triangles around i"
    )


@exercise(
    "mixed_areas",
    reread=_REREAD_A,
    forbid=(
        "lessons.laplace.mixed_areas",
        "lessons.laplace.vertex_areas",
        "lessons.laplace.laplacian",
    ),
)
def mixed_areas(fn):
    """Check ``fn(V, F) -> (n,)`` mixed areas (Meyer et al. 2003): Voronoi, or A/2 and A/4 in obtuse triangles."""
    return _check_areas(
        fn,
        "mixed",
        laplace.mixed_areas,
        "non-obtuse triangle: 1/8 (|e_ij|^2 cot(angle at k) + |e_ik|^2 cot(angle at j)); "
        "obtuse: A_f/2 at the obtuse corner, A_f/4 at the others",
    )
