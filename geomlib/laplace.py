"""Discrete Laplace-Beltrami operators: Delta = M^-1 C.

Convention used everywhere in geomlib (the course's notation and sign):

* ``C`` is symmetric, negative semidefinite, its rows sum to zero. Off the
  diagonal ``C_ij = 1/2 (cot alpha_ij + cot beta_ij)`` for the cotangent
  operator (Pinkall and Polthier 1993; Meyer et al. 2003) and ``C_ij = 1`` for
  the uniform (graph) operator, for every edge ij; ``C_ii = -sum_j C_ij``.
* ``M`` is diagonal: the vertex area for the cotangent operator (a third of the
  incident triangle areas for ``area="barycentric"``, the mixed Voronoi area of
  Meyer et al. 2003 for ``area="mixed"``), and the valence (number of
  neighbours) for the uniform operator.
* ``Delta = M^-1 C`` so that ``Delta x = -2 H n`` with ``n`` the outward unit
  normal and ``H > 0`` on a sphere.

Degenerate triangles: a triangle whose area is zero (to rounding, see
``DEGENERATE_REL_AREA``) has no defined angles. It contributes nothing to ``C``
or ``M`` and a :class:`~geomlib.errors.MeshWarning` names it; needle triangles
of small but non-zero area keep their (large, finite) cotangents. Nothing in
``M`` or ``C`` is ever NaN or infinite. A vertex that belongs to no
non-degenerate triangle (an isolated vertex) has a zero row in ``C`` and a zero
entry in ``M``: ``Delta`` is undefined there and functions that divide by ``M``
say so.
"""

import warnings

import numpy as np
import scipy.sparse as sp

from .errors import MeshWarning, format_indices

#: A triangle counts as degenerate when twice its area is below this fraction of
#: the mean squared edge length of the mesh (rounding level for float64 input).
DEGENERATE_REL_AREA = 1e-14


def _as_mesh(V, F):
    try:
        from .validate import as_mesh
    except ImportError:  # validation module not yet available
        return np.ascontiguousarray(V, dtype=np.float64), np.ascontiguousarray(F, dtype=np.int64)
    return as_mesh(V, F)


def face_geometry(V, F):
    """Per-face squared edge lengths, doubled areas and corner cotangents.

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64

    Returns
    -------
    l2 : (m, 3) float64
        ``l2[f, i]`` is the squared length of the edge opposite corner ``i``.
    dblA : (m,) float64
        Twice the triangle area, ``|(v1 - v0) x (v2 - v0)|``.
    cot : (m, 3) float64
        ``cot[f, i]`` is the cotangent of the angle at corner ``i``,
        ``(l_j^2 + l_k^2 - l_i^2) / (4 A)``; zero on degenerate faces.
    degenerate : (m,) bool
        Faces treated as having zero area (see ``DEGENERATE_REL_AREA``).
    """
    P0, P1, P2 = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    e0 = P2 - P1  # opposite corner 0
    e1 = P0 - P2  # opposite corner 1
    e2 = P1 - P0  # opposite corner 2
    l2 = np.empty((len(F), 3))
    l2[:, 0] = np.einsum("ij,ij->i", e0, e0)
    l2[:, 1] = np.einsum("ij,ij->i", e1, e1)
    l2[:, 2] = np.einsum("ij,ij->i", e2, e2)
    dblA = np.linalg.norm(np.cross(e2, -e1), axis=1)
    scale = l2.mean() if len(F) else 0.0
    degenerate = dblA <= DEGENERATE_REL_AREA * scale
    denom = np.where(degenerate, 1.0, 2.0 * dblA)
    cot = np.empty_like(l2)
    cot[:, 0] = (l2[:, 1] + l2[:, 2] - l2[:, 0]) / denom
    cot[:, 1] = (l2[:, 2] + l2[:, 0] - l2[:, 1]) / denom
    cot[:, 2] = (l2[:, 0] + l2[:, 1] - l2[:, 2]) / denom
    cot[degenerate] = 0.0
    return l2, dblA, cot, degenerate


def _warn_degenerate(degenerate):
    if degenerate.any():
        idx = np.flatnonzero(degenerate)
        warnings.warn(
            f"{len(idx)} degenerate (zero-area) triangle(s) contribute nothing to the "
            f"Laplacian and the vertex areas: faces {format_indices(idx)}",
            MeshWarning,
            stacklevel=3,
        )


def cotangent_weights(V, F):
    """Symmetric cotangent matrix C (n, n): ``C_ij = 1/2 (cot alpha_ij + cot beta_ij)``.

    Negative semidefinite, rows summing to zero (``C_ii = -sum_j C_ij``). On a
    boundary edge only one angle exists and the weight is ``1/2 cot alpha``.
    Degenerate triangles contribute nothing (module docstring).
    Pinkall and Polthier 1993; Meyer et al. 2003, eq. (8).

    Returns scipy.sparse CSR, float64.
    """
    V, F = _as_mesh(V, F)
    _, _, cot, degenerate = face_geometry(V, F)
    _warn_degenerate(degenerate)
    return _cot_matrix(len(V), F, cot)


def _cot_matrix(n, F, cot):
    # edge (j, k) is opposite corner i; its weight gets 1/2 cot(angle at i)
    I = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])
    J = np.concatenate([F[:, 2], F[:, 0], F[:, 1]])
    w = 0.5 * np.concatenate([cot[:, 0], cot[:, 1], cot[:, 2]])
    rows = np.concatenate([I, J, np.arange(n)])
    cols = np.concatenate([J, I, np.arange(n)])
    diag = -np.bincount(I, weights=w, minlength=n) - np.bincount(J, weights=w, minlength=n)
    vals = np.concatenate([w, w, diag])
    return sp.csr_matrix((vals, (rows, cols)), shape=(n, n))


def vertex_areas(V, F, area="barycentric"):
    """Vertex areas (n,) in length^2: the diagonal of the cotangent M.

    ``area="barycentric"``: a third of the area of every incident triangle.
    ``area="mixed"``: the mixed Voronoi area of Meyer et al. 2003 (Fig. 4):
    the Voronoi region inside non-obtuse triangles, and half (at the obtuse
    corner) or a quarter (at the other corners) of an obtuse triangle's area.
    Both sum to the total surface area. Degenerate triangles contribute 0.
    """
    V, F = _as_mesh(V, F)
    l2, dblA, cot, degenerate = face_geometry(V, F)
    _warn_degenerate(degenerate)
    return _vertex_areas(len(V), F, l2, dblA, cot, area)


def _vertex_areas(n, F, l2, dblA, cot, area):
    A = 0.5 * np.where(np.isfinite(dblA), dblA, 0.0)
    if area == "barycentric":
        per_corner = np.repeat(A[:, None] / 3.0, 3, axis=1)
    elif area == "mixed":
        # Voronoi part at corner i: 1/8 (l_j^2 cot_j + l_k^2 cot_k)
        per_corner = np.empty_like(l2)
        per_corner[:, 0] = (l2[:, 1] * cot[:, 1] + l2[:, 2] * cot[:, 2]) / 8.0
        per_corner[:, 1] = (l2[:, 2] * cot[:, 2] + l2[:, 0] * cot[:, 0]) / 8.0
        per_corner[:, 2] = (l2[:, 0] * cot[:, 0] + l2[:, 1] * cot[:, 1]) / 8.0
        obtuse = cot < 0  # angle > 90 degrees at that corner
        any_obtuse = obtuse.any(axis=1)
        per_corner[any_obtuse] = A[any_obtuse, None] / 4.0
        per_corner[obtuse] = np.repeat(A[:, None], 3, axis=1)[obtuse] / 2.0
    else:
        from .errors import MeshError

        raise MeshError(f"area must be 'barycentric' or 'mixed', not {area!r}")
    return np.bincount(F.ravel(), weights=per_corner.ravel(), minlength=n)


def uniform_adjacency(n, F):
    """Adjacency matrix (n, n) with 1 for every edge ij (each edge once). CSR float64."""
    I = np.concatenate([F[:, 0], F[:, 1], F[:, 2]])
    J = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])
    A = sp.csr_matrix((np.ones(2 * len(I)), (np.concatenate([I, J]), np.concatenate([J, I]))),
                      shape=(n, n))
    A.data[:] = 1.0  # an interior edge was counted twice
    return A


def laplacian(V, F, weights="cotan", area="barycentric"):
    """Discrete Laplace-Beltrami operator ``Delta = M^-1 C`` as the pair (M, C).

    C is symmetric, negative semidefinite, rows sum to zero; off-diagonal
    ``1/2 (cot alpha_ij + cot beta_ij)`` for ``weights="cotan"`` and 1 for
    ``weights="uniform"``. M is diagonal: vertex areas in length^2 for
    "cotan" (``area="barycentric"``: a third of the incident triangle areas;
    ``area="mixed"``: Meyer et al. 2003) and the valence for "uniform" (then
    ``area`` is ignored). With this sign ``Delta x = -2 H n`` for the outward
    unit normal n, H > 0 on a sphere.

    Parameters
    ----------
    V : (n, 3) float64 vertex positions.
    F : (m, 3) int64 triangles.
    weights : "cotan" or "uniform"
    area : "barycentric" or "mixed"

    Returns
    -------
    M : (n, n) scipy.sparse diagonal (DIA) float64
    C : (n, n) scipy.sparse CSR float64

    Notes
    -----
    Degenerate (zero-area) triangles contribute nothing and are named in a
    MeshWarning; isolated vertices get a zero row in C and a zero in M.
    References: Meyer, Desbrun, Schroeder and Barr 2003, "Discrete
    differential-geometry operators for triangulated 2-manifolds";
    Desbrun, Meyer, Schroeder and Barr 1999.
    """
    from .errors import MeshError

    if weights not in ("cotan", "uniform"):
        raise MeshError(f"weights must be 'cotan' or 'uniform', not {weights!r}")
    if area not in ("barycentric", "mixed"):
        raise MeshError(f"area must be 'barycentric' or 'mixed', not {area!r}")
    V, F = _as_mesh(V, F)
    n = len(V)
    if weights == "uniform":
        A = uniform_adjacency(n, F)
        deg = np.asarray(A.sum(axis=1)).ravel()
        C = (A - sp.diags(deg)).tocsr()
        M = sp.diags(deg)
        return M, C
    l2, dblA, cot, degenerate = face_geometry(V, F)
    _warn_degenerate(degenerate)
    C = _cot_matrix(n, F, cot)
    M = sp.diags(_vertex_areas(n, F, l2, dblA, cot, area))
    return M, C
