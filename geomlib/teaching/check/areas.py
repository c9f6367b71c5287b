"""The vertex-area mistakes, named from the areas alone: one diagnosis for every check that uses A_i.

Three checks meet a learner's vertex areas: ``vertex_areas`` and ``mixed_areas`` (notebook 03)
return them, ``cotangent_laplacian`` (03) puts them on the diagonal of M, and
``gaussian_curvature`` (01) divides the angle deficit by them (the check reads them back as
``deficit / K``). Each asks this module, so the three name a mistake in the same words::

    found = area_mistake(A, V, F)                 # or area_mistake_over([(A, V, F), ...])
    if found:
        raise Mistake(*found)

The typical mistakes are rebuilt here from the mesh and compared with the areas handed in.
Some of them coincide on a particular mesh: on a tetrahedron every vertex has three triangles,
so the mean of the incident A_f/3 is exactly "a ninth"; on a mesh without obtuse triangles the
plain Voronoi areas are the mixed ones. A mistake is named only when the areas match it on
every mesh tried and it differs from the right areas on one of them; checks hand in meshes
whose valences differ and which hold obtuse triangles (``test_check_areas`` holds that every
two mistakes differ on the meshes each check uses).

Two causes give the same areas and cannot be told apart from them: a triangle counted twice,
and its area taken as the length of the cross product (2 A_f) without the 1/2. The diagnosis
of "twice" names both.
"""

import numpy as np

from ...lessons.laplace import barycentric_areas, face_geometry, mixed_areas, voronoi_pieces

__all__ = ["area_mistake", "area_mistake_over", "typical_areas", "corner_sums", "ASKED"]

ASKED = ("barycentric", "mixed")

_RULE = {
    "barycentric": "A_i = 1/3 of the sum of the areas A_f of the triangles around i",
    "mixed": "per triangle, corner i gets its Voronoi piece 1/8 (|e_ij|^2 cot(angle at k) + |e_ik|^2 cot(angle at j)), "
    "or, in an obtuse triangle, A_f/2 at the obtuse corner and A_f/4 at the other two",
}
_OBTUSE_TRUTH = (
    "in an obtuse triangle the circumcentre lies outside, so the Voronoi pieces are no longer regions inside "
    "the triangle (a piece is even negative where the other two angles differ by more than 90 degrees)"
)


def corner_sums(n, F, pieces):
    """(n,) the per-corner values ``pieces`` (m, 3) summed into the vertices."""
    return np.bincount(np.asarray(F).ravel(), weights=np.asarray(pieces, dtype=float).ravel(), minlength=n)


def typical_areas(V, F, asked="barycentric"):
    """(right, [(areas, diagnosis, hint), ...]): the right (n,) areas and the typical mistakes, in naming order."""
    n = len(V)
    _, dblA, cot, degenerate = face_geometry(V, F)
    bary, mixed = barycentric_areas(V, F), mixed_areas(V, F)
    right = bary if asked == "barycentric" else mixed
    triangles = np.bincount(np.asarray(F)[~degenerate].ravel(), minlength=n)  # incident triangles per vertex
    Af = (dblA / 2)[:, None]
    obtuse_corner = cot < 0
    obtuse_face = obtuse_corner.any(axis=1, keepdims=True)
    plain = corner_sums(n, F, voronoi_pieces(V, F))
    rule = _RULE[asked]
    out = [
        (
            3 * bary,
            "each vertex gets the full area of its incident triangles (the sum of A_f is not divided by 3)",
            "a triangle gives a third of its area to each of its three corners" if asked == "barycentric" else rule,
        ),
        (
            bary / 3,
            "each vertex gets a ninth of its incident triangle areas (divided by 3 twice)",
            "divide by 3 once: " + rule,
        ),
        (
            np.divide(right, triangles, out=np.zeros(n), where=triangles > 0),
            "each vertex gets the mean of its triangles' pieces (A_f/3 each) instead of their sum"
            if asked == "barycentric"
            else "each vertex gets the mean of its triangles' pieces instead of their sum",
            "add the pieces of all the triangles around i (np.bincount or np.add.at), do not average them",
        ),
        (
            2 * right,
            "every area is twice the right one (a triangle counted twice, or its area taken as the length of the "
            "cross product, 2 A_f, without the 1/2)",
            "A_f = |(x_j - x_i) x (x_k - x_i)| / 2; if you halve it, look for a loop that meets each triangle "
            "twice at a vertex (over edges or half-edges)",
        ),
        (
            6 * bary,
            "each vertex gets the length of the cross product (2 A_f) of every incident triangle: "
            "neither halved nor divided by 3",
            rule,
        ),
    ]
    if asked == "barycentric":
        out.append(
            (
                mixed,
                "these are the mixed (Voronoi) areas, not the barycentric ones",
                "the barycentric area gives every corner the same third of its triangle",
            )
        )
        out.append(
            (
                plain,
                "these are the plain Voronoi areas (the circumcentric pieces, no obtuse rule), not the "
                "barycentric ones",
                "the barycentric area gives every corner the same third of its triangle",
            )
        )
    else:
        out.append(
            (
                bary,
                "these are the barycentric areas (a third of each triangle), not the mixed ones",
                "use the Voronoi piece 1/8 (|e_ij|^2 cot + |e_ik|^2 cot) in triangles without an obtuse angle",
            )
        )
        out.append(
            (
                plain,
                "the obtuse rule is missing: these are the plain Voronoi areas, summed also over obtuse triangles",
                _OBTUSE_TRUTH + "; give A_f/2 to the obtuse corner and A_f/4 to the other two",
            )
        )
        out.append(
            (
                corner_sums(n, F, np.where(obtuse_face, np.where(obtuse_corner, Af / 4, Af / 2), voronoi_pieces(V, F))),
                "the halves are swapped in obtuse triangles: the obtuse corner gets A_f/4",
                "the obtuse corner gets A_f/2, the two acute corners A_f/4 each",
            )
        )
        out.append(
            (
                corner_sums(n, F, np.where(obtuse_corner, Af / 2, voronoi_pieces(V, F))),
                "the obtuse rule is applied only at the obtuse corner; the other two corners of an obtuse triangle "
                "still get their Voronoi pieces",
                "in an obtuse triangle the two acute corners get A_f/4 each",
            )
        )
    return right, out


def _agree(a, b, where, rtol):
    scale = max(float(np.abs(b[where]).max(initial=0.0)), 1e-300)
    return bool(np.allclose(a[where], b[where], rtol=rtol, atol=rtol * scale))


def area_mistake_over(cases, asked="barycentric", rtol=1e-6):
    """(diagnosis, hint) of the typical mistake that gives these areas on every mesh, or None.

    Parameters
    ----------
    cases : iterable of (A, V, F) or (A, V, F, where)
        The learner's vertex areas A (n,) on the mesh (V, F); ``where`` (n,) bool: the vertices
        at which A is known (default all; the Gaussian-curvature check knows A only where K is
        defined and the deficit is not zero). A NaN outside ``where`` is ignored.
    asked : {"barycentric", "mixed"}
        The areas the exercise asks for.
    rtol : float
        Relative tolerance of a match (a 7-digit pi in the deficit moves A by about 1e-7).

    Returns None when the areas are right, or when no typical mistake matches on every mesh
    (the caller then says only that they differ).
    """
    if asked not in ASKED:
        raise ValueError(f"asked must be one of {ASKED}, got {asked!r}")
    matched, wrong_somewhere = None, False
    for case in cases:
        A, V, F = (np.asarray(x) for x in case[:3])
        A = A.astype(float).reshape(-1)
        where = np.ones(len(V), bool) if len(case) < 4 or case[3] is None else np.asarray(case[3], bool)
        if not np.isfinite(A[where]).all():
            return None
        right, variants = typical_areas(V, F, asked)
        if not _agree(A, right, where, rtol):
            wrong_somewhere = True
        hits = [(_agree(A, values, where, rtol), not _agree(values, right, where, rtol)) for values, _, _ in variants]
        matched = hits if matched is None else [(m[0] and h[0], m[1] or h[1]) for m, h in zip(matched, hits)]
        names = [(d, h) for _, d, h in variants]
    if not wrong_somewhere or matched is None:
        return None
    for (match, differs), found in zip(matched, names):
        if match and differs:
            return found
    return None


def area_mistake(A, V, F, asked="barycentric", where=None, rtol=1e-6):
    """(diagnosis, hint) naming the typical mistake that gives the vertex areas A (n,) on (V, F), or None.

    One mesh: :func:`area_mistake_over` with the single case ``(A, V, F, where)``. On a mesh where two
    mistakes give the same areas (every vertex of a tetrahedron has three triangles) the first in the
    order above is named; give several meshes to :func:`area_mistake_over` to tell them apart.
    """
    return area_mistake_over([(A, V, F, where)], asked, rtol)
