"""The vertex-area mistakes as data: one catalogue per area asked, the same words for every check that uses A_i.

Two checks meet a learner's vertex areas: ``mixed_areas`` (notebook 03) returns them, and
``gaussian_curvature`` (01) divides the angle deficit by them. Each reads
:data:`AREA_MISTAKES` (``Wrong`` entries of ``check.catalogue``, built from a case's V and F)
through the one matcher, so the two name a mistake in the same words::

    judge(AREA_MISTAKES["barycentric"], cases, answers, right=lambda c: barycentric_areas(c.V, c.F))

Some mistakes coincide on a particular mesh: on a tetrahedron every vertex has three triangles,
so the mean of the incident A_f/3 is exactly "a ninth"; on a mesh without obtuse triangles the
plain Voronoi areas are the mixed ones. The matcher names a mistake only when the areas match it
on every mesh and it differs from the right areas on one of them; checks hand in meshes whose
valences differ and which hold obtuse triangles (``test_check_areas`` holds that every two
mistakes differ on the meshes each check uses).

Two causes give the same areas and cannot be told apart from them: a triangle counted twice,
and its area taken as the length of the cross product (2 A_f) without the 1/2. The diagnosis
of "twice" names both.
"""

import numpy as np

from ...lessons.laplace import barycentric_areas, face_geometry, mixed_areas, voronoi_pieces
from .catalogue import Case, Wrong, agree, first_mistake

__all__ = ["AREA_MISTAKES", "RIGHT_AREAS", "area_mistake_over"]

RIGHT_AREAS = {"barycentric": lambda c: barycentric_areas(c.V, c.F), "mixed": lambda c: mixed_areas(c.V, c.F)}

_RULE = {
    "barycentric": "A_i = 1/3 of the sum of the areas A_f of the triangles around i",
    "mixed": "per triangle, corner i gets its Voronoi piece 1/8 (|e_ij|^2 cot(angle at k) + |e_ik|^2 cot(angle at j)), "
    "or, in an obtuse triangle, A_f/2 at the obtuse corner and A_f/4 at the other two",
}
_OBTUSE_TRUTH = (
    "in an obtuse triangle the circumcentre lies outside, so the Voronoi pieces are no longer regions inside "
    "the triangle (a piece is even negative where the other two angles differ by more than 90 degrees)"
)
_THIRD = "the barycentric area gives every corner the same third of its triangle"


def _mean(asked):
    """Each vertex gets the mean of its (non-degenerate) triangles' pieces instead of their sum."""

    def build(c):
        degenerate = face_geometry(c.V, c.F)[3]
        triangles = np.bincount(np.asarray(c.F)[~degenerate].ravel(), minlength=len(c.V))
        right = RIGHT_AREAS[asked](c)
        return np.divide(right, triangles, out=np.zeros(len(c.V)), where=triangles > 0)

    return build


def _obtuse_pieces(c, obtuse_corner_gets, acute_corner_gets):
    """Corner sums with the Voronoi pieces, replaced in obtuse triangles by the given shares of A_f."""
    _, dblA, cot, _ = face_geometry(c.V, c.F)
    Af, obtuse_corner = (dblA / 2)[:, None], cot < 0
    acute = voronoi_pieces(c.V, c.F) if acute_corner_gets is None else acute_corner_gets * Af
    pieces = np.where(obtuse_corner, obtuse_corner_gets * Af, acute)
    if acute_corner_gets is not None:
        pieces = np.where(obtuse_corner.any(axis=1, keepdims=True), pieces, voronoi_pieces(c.V, c.F))
    return _corner_sums(len(c.V), c.F, pieces)


def _corner_sums(n, F, pieces):
    """(n,) the per-corner values ``pieces`` (m, 3) summed into the vertices."""
    return np.bincount(np.asarray(F).ravel(), weights=np.asarray(pieces, dtype=float).ravel(), minlength=n)


def _plain(c):
    return _corner_sums(len(c.V), c.F, voronoi_pieces(c.V, c.F))


def _catalogue(asked):
    rule, right = _RULE[asked], RIGHT_AREAS[asked]
    bary = RIGHT_AREAS["barycentric"]
    shared = [
        Wrong(
            "each vertex gets the full area of its incident triangles (the sum of A_f is not divided by 3)",
            "a triangle gives a third of its area to each of its three corners" if asked == "barycentric" else rule,
            build=lambda c: 3 * bary(c),
        ),
        Wrong(
            "each vertex gets a ninth of its incident triangle areas (divided by 3 twice)",
            "divide by 3 once: " + rule,
            build=lambda c: bary(c) / 3,
        ),
        Wrong(
            "each vertex gets the mean of its triangles' pieces (A_f/3 each) instead of their sum"
            if asked == "barycentric"
            else "each vertex gets the mean of its triangles' pieces instead of their sum",
            "add the pieces of all the triangles around i (np.bincount or np.add.at), do not average them",
            build=_mean(asked),
        ),
        Wrong(
            "every area is twice the right one (a triangle counted twice, or its area taken as the length of the "
            "cross product, 2 A_f, without the 1/2)",
            "A_f = |(x_j - x_i) x (x_k - x_i)| / 2; if you halve it, look for a loop that meets each triangle "
            "twice at a vertex (over edges or half-edges)",
            build=lambda c: 2 * right(c),
        ),
        Wrong(
            "each vertex gets the length of the cross product (2 A_f) of every incident triangle: "
            "neither halved nor divided by 3",
            rule,
            build=lambda c: 6 * bary(c),
        ),
    ]
    if asked == "barycentric":
        return shared + [
            Wrong("these are the mixed (Voronoi) areas, not the barycentric ones", _THIRD, build=RIGHT_AREAS["mixed"]),
            Wrong(
                "these are the plain Voronoi areas (the circumcentric pieces, no obtuse rule), not the barycentric ones",
                _THIRD,
                build=_plain,
            ),
        ]
    return shared + [
        Wrong(
            "these are the barycentric areas (a third of each triangle), not the mixed ones",
            "use the Voronoi piece 1/8 (|e_ij|^2 cot + |e_ik|^2 cot) in triangles without an obtuse angle",
            build=bary,
        ),
        Wrong(
            "the obtuse rule is missing: these are the plain Voronoi areas, summed also over obtuse triangles",
            _OBTUSE_TRUTH + "; give A_f/2 to the obtuse corner and A_f/4 to the other two",
            build=_plain,
        ),
        Wrong(
            "the halves are swapped in obtuse triangles: the obtuse corner gets A_f/4",
            "the obtuse corner gets A_f/2, the two acute corners A_f/4 each",
            build=lambda c: _obtuse_pieces(c, 1 / 4, 1 / 2),
        ),
        Wrong(
            "the obtuse rule is applied only at the obtuse corner; the other two corners of an obtuse triangle "
            "still get their Voronoi pieces",
            "in an obtuse triangle the two acute corners get A_f/4 each",
            build=lambda c: _obtuse_pieces(c, 1 / 2, None),
        ),
    ]


#: {"barycentric": [Wrong, ...], "mixed": [...]}: the typical mistakes of each area asked, in naming order
AREA_MISTAKES = {asked: _catalogue(asked) for asked in RIGHT_AREAS}


def area_mistake_over(cases, asked="barycentric", rtol=1e-6):
    """(diagnosis, hint) of the typical mistake that gives these areas on every mesh, or None.

    ``cases``: (A, V, F) or (A, V, F, where), the learner's areas (n,) on the mesh (V, F), known
    only at ``where`` (default all). None when the areas are right or no typical mistake matches.
    """
    if asked not in AREA_MISTAKES:
        raise ValueError(f"asked must be one of {tuple(AREA_MISTAKES)}, got {asked!r}")
    cases = [(*case, None)[:4] for case in cases]
    made = [Case("", V=np.asarray(V), F=np.asarray(F)) for _, V, F, _ in cases]
    made = [c if where is None else c.but(where=np.asarray(where, bool)) for c, (*_, where) in zip(made, cases)]
    answers = [np.asarray(A, dtype=float).reshape(-1) for A, *_ in cases]
    found = first_mistake(
        AREA_MISTAKES[asked], made, answers, RIGHT_AREAS[asked], lambda a, b, c: agree(a, b, c, rtol=rtol)
    )
    return None if found is None or not found.typical else (found.diagnosis, found.hint)
