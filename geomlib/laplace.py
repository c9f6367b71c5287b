"""Discrete Laplace-Beltrami operators: Delta = M^-1 C, C symmetric negative semidefinite.

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

Policy for bad triangles (never a NaN or an infinity in ``M`` or ``C``):

* Zero-area triangles (``2 area <= ZERO_AREA_RTOL * longest edge^2``, the same
  scale-free test as :func:`geomlib.validate.check_mesh`) have no defined
  angles. They contribute nothing to the cotangent ``C`` or to ``M`` and a
  :class:`~geomlib.errors.MeshWarning` names them. The uniform operator is
  combinatorial: their edges still count there.
* Needle triangles (small but non-zero area) keep their exact cotangents. Those
  are large (bounded by ``1 / ZERO_AREA_RTOL``) but finite, and ``C`` stays
  symmetric and negative semidefinite (it is a sum of per-triangle negative
  semidefinite matrices); clamping them would break the exactness of ``C`` on
  linear functions over flat regions, so it is not done.
* A vertex in no triangle of non-zero area (an isolated vertex) has a zero row
  in ``C`` and a zero in ``M``: ``Delta`` is undefined there, and functions
  that divide by ``M`` say so (NaN with a MeshWarning naming the vertices).
* Non-manifold edges (three or more triangles) receive the sum of all their
  opposite cotangents: still the sum of per-triangle operators.
"""

import warnings

import numpy as np
import scipy.sparse as sp

from .errors import MeshError, MeshWarning, format_indices

try:  # one definition of "zero area" for the whole package
    from .validate import ZERO_AREA_RTOL
except ImportError:  # pragma: no cover - validation module not yet available
    ZERO_AREA_RTOL = 1e-12

#: Kept for backward compatibility: the zero-area threshold (see module docstring).
DEGENERATE_REL_AREA = ZERO_AREA_RTOL

WEIGHTS = ("cotan", "uniform")
AREAS = ("barycentric", "mixed")


def _as_mesh(V, F):
    """Validate and coerce (V, F) with geomlib.validate.as_mesh (MeshError on bad input)."""
    try:
        from .validate import as_mesh
    except ImportError:  # pragma: no cover - validation module not yet available
        V = np.ascontiguousarray(V, dtype=np.float64)
        F = np.ascontiguousarray(F, dtype=np.int64)
        if V.ndim != 2 or V.shape[1] != 3:
            raise MeshError(f"V must have shape (n, 3), not {V.shape}")
        if F.ndim != 2 or F.shape[1] != 3 or len(F) == 0:
            raise MeshError(f"F must have shape (m, 3) with m > 0, not {F.shape}")
        bad = np.flatnonzero(((F < 0) | (F >= len(V))).any(axis=1))
        if len(bad):
            raise MeshError(f"face indices out of range 0..{len(V) - 1} in faces {format_indices(bad)}")
        return V, F
    return as_mesh(V, F)


def _check_options(weights=None, area=None):
    if weights is not None and weights not in WEIGHTS:
        raise MeshError(f"weights must be 'cotan' or 'uniform', not {weights!r}")
    if area is not None and area not in AREAS:
        raise MeshError(f"area must be 'barycentric' or 'mixed', not {area!r}")


def _geometry(V, F, columns=None, with_cot=True):
    """Face geometry in (3, m) layout (one row per corner): l2, dblA, cot, degenerate.

    Computed coordinate by coordinate on contiguous arrays (no np.cross, no
    (m, 3) temporaries), which is what makes the assembly as fast as libigl's.
    ``columns`` = (X, Y, Z) coordinate arrays (views are fine) when the caller
    processes the faces block by block and wants to avoid a copy per block.
    """
    X, Y, Z = np.ascontiguousarray(V.T) if columns is None else columns
    i0, i1, i2 = np.ascontiguousarray(F.T)
    x0, x1, x2 = X[i0], X[i1], X[i2]
    y0, y1, y2 = Y[i0], Y[i1], Y[i2]
    z0, z1, z2 = Z[i0], Z[i1], Z[i2]
    # edge vectors opposite corners 0, 1, 2
    ax, ay, az = x2 - x1, y2 - y1, z2 - z1
    bx, by, bz = x0 - x2, y0 - y2, z0 - z2
    cx, cy, cz = x1 - x0, y1 - y0, z1 - z0
    m = len(F)
    l2 = np.empty((3, m))
    l2[0] = ax * ax + ay * ay + az * az
    l2[1] = bx * bx + by * by + bz * bz
    l2[2] = cx * cx + cy * cy + cz * cz
    # twice the area: |(P1 - P0) x (P2 - P0)| = |c x (-b)|
    nx = bz * cy - by * cz
    ny = bx * cz - bz * cx
    nz = by * cx - bx * cy
    dblA = np.sqrt(nx * nx + ny * ny + nz * nz)
    degenerate = dblA <= ZERO_AREA_RTOL * l2.max(axis=0)
    if not with_cot:  # callers that need only lengths and areas (angle sums, barycentric areas)
        return l2, dblA, None, degenerate
    # cot(angle at i) = <e_j, e_k> / |e_j x e_k| = (l_j^2 + l_k^2 - l_i^2) / (2 * 2A)
    denom = 2.0 * np.where(degenerate, 1.0, dblA)
    s = l2.sum(axis=0)
    cot = (s - 2.0 * l2) / denom
    cot[:, degenerate] = 0.0
    return l2, dblA, cot, degenerate


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
        Zero-area faces: ``dblA <= ZERO_AREA_RTOL * (longest edge)^2``.
    """
    l2, dblA, cot, degenerate = _geometry(V, F)
    return l2.T, dblA, cot.T, degenerate


def _warn_degenerate(degenerate, stacklevel=3):
    if degenerate.any():
        idx = np.flatnonzero(degenerate)
        warnings.warn(
            f"{len(idx)} zero-area triangle(s) contribute nothing to the cotangent "
            f"Laplacian and the vertex areas: faces {format_indices(idx)}",
            MeshWarning,
            stacklevel=stacklevel,
        )


def _index_dtype(n):
    return np.int32 if n < np.iinfo(np.int32).max else np.int64


def _cot_matrix(n, F, cot):
    """Assemble C from the (3, m) corner cotangents: edge (j, k) opposite corner i
    gets 1/2 cot(angle at i), from each of its triangles."""
    it = _index_dtype(n)
    Ft = np.ascontiguousarray(F.T, dtype=it)
    m = F.shape[0]
    nnz = 6 * m + n
    rows = np.empty(nnz, it)
    cols = np.empty(nnz, it)
    vals = np.empty(nnz)
    # off-diagonal: edge (1,2) <- corner 0, (2,0) <- corner 1, (0,1) <- corner 2; both orders
    for c, (j, k) in enumerate(((1, 2), (2, 0), (0, 1))):
        s = slice(c * m, (c + 1) * m)
        t = slice((3 + c) * m, (4 + c) * m)
        rows[s], cols[s] = Ft[j], Ft[k]
        rows[t], cols[t] = Ft[k], Ft[j]
        np.multiply(cot[c], 0.5, out=vals[s])
        vals[t] = vals[s]
    off = vals[: 6 * m]
    diag = -np.bincount(rows[: 6 * m], weights=off, minlength=n)
    rows[6 * m:] = cols[6 * m:] = np.arange(n, dtype=it)
    vals[6 * m:] = diag
    C = sp.coo_matrix((vals, (rows, cols)), shape=(n, n)).tocsr()
    return C


def cotangent_weights(V, F):
    """Symmetric cotangent matrix C (n, n): ``C_ij = 1/2 (cot alpha_ij + cot beta_ij)``.

    Negative semidefinite, rows summing to zero (``C_ii = -sum_j C_ij``). On a
    boundary edge only one angle exists and the weight is ``1/2 cot alpha``.
    Zero-area triangles contribute nothing (MeshWarning); see the module
    docstring for needle triangles. Pinkall and Polthier 1993; Meyer et al.
    2003, eq. (8).

    Returns
    -------
    C : (n, n) scipy.sparse CSR float64
    """
    V, F = _as_mesh(V, F)
    _, _, cot, degenerate = _geometry(V, F)
    _warn_degenerate(degenerate)
    return _cot_matrix(len(V), F, cot)


def _vertex_areas(n, F, l2, dblA, cot, area, degenerate=None):
    """Vertex areas from (3, m) geometry arrays."""
    A = 0.5 * dblA
    if degenerate is not None:
        A = np.where(degenerate, 0.0, A)
    if area == "barycentric":
        per_vertex = np.bincount(F.ravel(), weights=np.repeat(A / 3.0, 3), minlength=n)
        return per_vertex
    if area != "mixed":
        _check_options(area=area)
    # Voronoi part of the triangle at corner i: 1/8 (l_j^2 cot_j + l_k^2 cot_k)
    # (Meyer et al. 2003, eq. 7); obtuse triangles: A/2 at the obtuse corner and
    # A/4 at the other two (their Fig. 4, "mixed" area).
    lc = l2 * cot
    per_corner = np.empty_like(l2)
    per_corner[0] = (lc[1] + lc[2]) * 0.125
    per_corner[1] = (lc[2] + lc[0]) * 0.125
    per_corner[2] = (lc[0] + lc[1]) * 0.125
    obtuse = cot < 0
    any_obtuse = obtuse.any(axis=0)
    if any_obtuse.any():
        Aq = np.broadcast_to(0.25 * A, per_corner.shape)
        per_corner = np.where(any_obtuse, np.where(obtuse, 2.0 * Aq, Aq), per_corner)
    if degenerate is not None:
        per_corner[:, degenerate] = 0.0
    return np.bincount(F.T.ravel(), weights=per_corner.ravel(), minlength=n)


def vertex_areas(V, F, area="barycentric"):
    """Vertex areas (n,) float64 in length^2: the diagonal of the cotangent M.

    ``area="barycentric"``: a third of the area of every incident triangle.
    ``area="mixed"``: the mixed Voronoi area of Meyer et al. 2003 (Fig. 4):
    the Voronoi region inside non-obtuse triangles, and half (at the obtuse
    corner) or a quarter (at the other corners) of an obtuse triangle's area.
    Both sum to the total surface area. Zero-area triangles contribute 0, so a
    vertex that is in no other triangle gets area 0.
    """
    _check_options(area=area)
    V, F = _as_mesh(V, F)
    l2, dblA, cot, degenerate = _geometry(V, F)
    _warn_degenerate(degenerate)
    return _vertex_areas(len(V), F, l2, dblA, cot, area, degenerate)


def uniform_adjacency(n, F):
    """Adjacency matrix (n, n) CSR float64 with 1 for every edge ij (each edge once)."""
    F = np.asarray(F)
    it = _index_dtype(n)
    I = np.concatenate([F[:, 0], F[:, 1], F[:, 2]]).astype(it)
    J = np.concatenate([F[:, 1], F[:, 2], F[:, 0]]).astype(it)
    keep = I != J  # a face repeating a vertex adds no self-loop
    I, J = I[keep], J[keep]
    A = sp.coo_matrix((np.ones(2 * len(I)), (np.concatenate([I, J]), np.concatenate([J, I]))),
                      shape=(n, n)).tocsr()
    A.data[:] = 1.0  # an interior edge was counted twice (once per triangle)
    return A


def laplacian(V, F, weights="cotan", area="barycentric"):
    """Discrete Laplace-Beltrami operator ``Delta = M^-1 C`` as the pair (M, C); C is NSD.

    C is symmetric, negative semidefinite, rows sum to zero; off-diagonal
    ``1/2 (cot alpha_ij + cot beta_ij)`` for ``weights="cotan"`` and 1 for
    ``weights="uniform"``. M is diagonal: vertex areas in length^2 for
    "cotan" (``area="barycentric"``: a third of the incident triangle areas;
    ``area="mixed"``: Meyer et al. 2003) and the valence for "uniform" (then
    ``area`` is ignored). With this sign ``Delta x = -2 H n`` for the outward
    unit normal n, H > 0 on a sphere.

    Parameters
    ----------
    V : (n, 3) float64
        Vertex positions.
    F : (m, 3) int64
        Triangles, counter-clockwise seen from outside.
    weights : {"cotan", "uniform"}
    area : {"barycentric", "mixed"}

    Returns
    -------
    M : (n, n) scipy.sparse diagonal (DIA) float64
    C : (n, n) scipy.sparse CSR float64

    Raises
    ------
    MeshError
        Unknown ``weights`` or ``area``; malformed V or F (see
        :func:`geomlib.validate.as_mesh`).

    Notes
    -----
    Boundary edges have one triangle and get ``1/2 cot alpha``; boundary
    vertices are treated like any other (the operator is then the one with
    natural Neumann boundary conditions). Zero-area triangles contribute
    nothing (MeshWarning naming them); isolated vertices get a zero row in C
    and a zero in M; nothing in M or C is ever NaN or infinite (module
    docstring). Vectorised assembly, O(n + m).

    References: Pinkall and Polthier 1993; Desbrun, Meyer, Schroeder and
    Barr 1999; Meyer, Desbrun, Schroeder and Barr 2003, "Discrete
    differential-geometry operators for triangulated 2-manifolds".
    """
    _check_options(weights, area)
    V, F = _as_mesh(V, F)
    n = len(V)
    if weights == "uniform":
        A = uniform_adjacency(n, F)
        deg = np.diff(A.indptr).astype(np.float64)
        C = (A - sp.diags(deg, format="csr")).tocsr()
        C.sort_indices()
        return sp.diags(deg), C
    l2, dblA, cot, degenerate = _geometry(V, F)
    _warn_degenerate(degenerate)
    C = _cot_matrix(n, F, cot)
    M = sp.diags(_vertex_areas(n, F, l2, dblA, cot, area, degenerate))
    return M, C


def uniform_laplacian(V, F):
    """(M, C) of the uniform Laplacian: C_ij = 1 on edges, C_ii = -valence, M = diag(valence)."""
    return laplacian(V, F, weights="uniform")


def cotangent_matrix(V, F):
    """C of the cotangent Laplacian: C_ij = (cot alpha_ij + cot beta_ij) / 2, rows summing to zero."""
    return laplacian(V, F, weights="cotan")[1]


def barycentric_areas(V, F):
    """(n,) vertex areas: a third of the areas of the incident triangles."""
    return vertex_areas(V, F, area="barycentric")


def mixed_areas(V, F):
    """(n,) mixed Voronoi vertex areas (Meyer et al. 2003)."""
    return vertex_areas(V, F, area="mixed")
