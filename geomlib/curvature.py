"""Discrete mean and Gaussian curvature: pointwise values, H in 1/length, K in 1/length^2.

Sign convention: ``Delta x = -2 H n`` with ``Delta = M^-1 C`` (geomlib.laplace)
and ``n`` the outward unit normal; ``H > 0`` and ``K > 0`` on a sphere.

Boundary rules, in one place (each function's docstring repeats its own):

* ``mean_curvature``: ``boundary="formula"`` (default) applies ``1/2 |Delta x|``
  everywhere. At a boundary vertex the one-ring is incomplete, ``Delta x`` has a
  large in-plane component and the value is not a curvature estimate (it is
  large even on a flat plane). ``"nan"`` masks boundary vertices, ``"zero"``
  sets them to 0.
* ``gaussian_curvature``: ``boundary="nan"`` (default) masks boundary vertices,
  because the angle deficit ``2 pi - sum theta`` is not defined there;
  ``"zero"``; ``"turning"``: the boundary turning angle ``pi - sum theta``
  (the discrete geodesic curvature of the boundary), with which the integrated
  values sum to ``2 pi chi`` exactly (Gauss-Bonnet with the boundary term);
  ``"deficit"``: the interior formula applied anyway (what a naive
  implementation reports, about ``pi / A`` too large on a flat boundary).

A boundary vertex is a vertex of an edge that belongs to exactly one triangle.

Bad input (each named in a MeshWarning, never a silent NaN): a vertex in no
triangle of non-zero area gets NaN (its area is 0, nothing can be divided by
it); a zero-area triangle counts as flat and collinear (angle pi at the corner
opposite its longest edge, 0 at the others), so Gauss-Bonnet stays exact; at a
non-manifold vertex (several fans of triangles) the deficit is
``2 pi - sum theta`` over all its triangles, which keeps the total equal to
``2 pi chi`` of the mesh as given but is not a pointwise curvature estimate;
edges with three or more triangles count as interior and are reported when
they unbalance the orientation around a vertex (always so for an odd number of
triangles; ``geomlib.check_mesh`` lists them all).

Memory: ``gaussian_curvature`` works through the faces in blocks, so its peak
memory is O(n) plus one block (about libigl's footprint), and it finds boundary
vertices with two exact integer sums per vertex instead of an edge table
(see ``_deficits_and_probes``); only vertices the sums flag get the exact edge
count.
"""

import warnings

import numpy as np
import scipy.sparse as sp

from .errors import MeshError, MeshWarning, format_indices
from .laplace import _as_mesh, _check_options, _geometry, _vertex_areas, face_geometry, laplacian

__all__ = [
    "mean_curvature",
    "gaussian_curvature",
    "principal_curvatures",
    "angle_sums",
    "vertex_normals",
    "face_normals",
    "boundary_mask",
    "BOUNDARY_RULES",
    "MEAN_BOUNDARY_RULES",
]

BOUNDARY_RULES = ("nan", "zero", "turning", "deficit")
MEAN_BOUNDARY_RULES = ("formula", "nan", "zero")


def face_normals(V, F):
    """Unit face normals (m, 3) float64, right-hand rule on (v0, v1, v2); zero for zero-length cross products."""
    N = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    length = np.linalg.norm(N, axis=1)
    ok = length > 0
    N[ok] /= length[ok, None]
    N[~ok] = 0.0
    return N


def vertex_normals(V, F):
    """Area-weighted unit vertex normals (n, 3) float64, outward for CCW faces.

    The normalised sum of the incident faces' cross products (outward on a
    consistently oriented closed mesh). Isolated vertices get a zero vector.
    """
    V, F = _as_mesh(V, F)
    N2 = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])  # 2 A n per face
    n = len(V)
    N = np.column_stack([np.bincount(F.ravel(), weights=np.repeat(N2[:, k], 3), minlength=n)
                         for k in range(3)])
    length = np.linalg.norm(N, axis=1)
    ok = length > 0
    N[ok] /= length[ok, None]
    return N


def _edge_counts(F, n):
    """Per-vertex number of boundary edges (n,) int and the non-manifold edges (k, 2).

    Counts the triangles of every undirected edge with one sparse assembly
    (a counting sort, O(n + m)), no np.unique.
    """
    it = np.int32 if n < np.iinfo(np.int32).max else np.int64
    I = np.concatenate([F[:, 0], F[:, 1], F[:, 2]])
    J = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])
    lo = np.minimum(I, J).astype(it)
    hi = np.maximum(I, J).astype(it)
    E = sp.coo_matrix((np.ones(len(lo), np.int32), (lo, hi)), shape=(n, n)).tocsr()
    E.sum_duplicates()
    rows = np.repeat(np.arange(n, dtype=it), np.diff(E.indptr))
    one = E.data == 1
    b = np.bincount(rows[one], minlength=n) + np.bincount(E.indices[one], minlength=n)
    many = E.data > 2
    nonmanifold = np.column_stack([rows[many], E.indices[many]]).astype(np.int64)
    return b, nonmanifold


def _edge_list(E, limit=5):
    head = ", ".join(f"({a}, {b})" for a, b in E[:limit].tolist())
    return head + (f" (and {len(E) - limit} more)" if len(E) > limit else "")


def boundary_mask(V, F):
    """Boolean (n,): True at vertices of an edge that belongs to exactly one triangle."""
    V, F = _as_mesh(V, F)
    return _boundary_mask(F, len(V))


def _warn(message, stacklevel=3):
    warnings.warn(message, MeshWarning, stacklevel=stacklevel + 1)


def _laplace_of_positions(V, F, weights, area):
    M, C = laplacian(V, F, weights=weights, area=area)
    m = M.diagonal()
    CV = C @ V
    isolated = m <= 0
    if isolated.any():
        _warn(
            f"{isolated.sum()} vertex/vertices belong to no triangle of non-zero area; "
            f"their curvature is undefined and returned as NaN: vertices "
            f"{format_indices(np.flatnonzero(isolated))}",
        )
    with np.errstate(divide="ignore", invalid="ignore"):
        DV = CV / np.where(isolated, np.nan, m)[:, None]
    return DV


def mean_curvature(V, F, weights="cotan", area="barycentric", signed=False, boundary="formula"):
    """Pointwise mean curvature H (n,) float64 from ``Delta x = -2 H n``: ``H = 1/2 |Delta x|``.

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64, counter-clockwise seen from outside.
    weights, area
        As in :func:`geomlib.laplacian`.
    signed : bool
        False: ``H = 1/2 |Delta x| >= 0``. True: ``H = -1/2 <Delta x, n>``
        with ``n`` the area-weighted outward vertex normal, so H > 0 on a
        sphere and H < 0 where the surface bends away from its normal.
    boundary : {"formula", "nan", "zero"}
        Value at boundary vertices: the formula applied anyway (default; not a
        curvature estimate there, see below), NaN, or 0.

    Returns
    -------
    H : (n,) float64
        In 1/length for ``weights="cotan"``. For ``weights="uniform"`` the
        operator carries no metric and ``1/2 |Delta x|`` is half the length of
        the umbrella vector (Taubin 1995): units of length, dependent on the
        tessellation and the scale, not a curvature.

    Notes
    -----
    Boundary vertices: the one-ring is incomplete, so ``Delta x`` has an
    in-plane component and the formula's value is large even on a flat plane.
    Vertices in no triangle of non-zero area give NaN with a MeshWarning
    naming them. Meyer et al. 2003, section 3.5; Desbrun et al. 1999.
    """
    _check_options(weights, area)
    if boundary not in MEAN_BOUNDARY_RULES:
        raise MeshError(f"boundary must be one of {MEAN_BOUNDARY_RULES}, not {boundary!r}")
    V, F = _as_mesh(V, F)
    DV = _laplace_of_positions(V, F, weights, area)
    if signed:
        N = vertex_normals(V, F)
        H = -0.5 * np.einsum("ij,ij->i", DV, N)
    else:
        H = 0.5 * np.sqrt(np.einsum("ij,ij->i", DV, DV))
    if boundary != "formula":
        on_boundary = _boundary_mask(F, len(V))
        H[on_boundary] = np.nan if boundary == "nan" else 0.0
        if on_boundary.all():
            _warn(f"every vertex of this mesh lies on the boundary; boundary={boundary!r} gives "
                  f"{'NaN' if boundary == 'nan' else '0'} everywhere (boundary='formula' keeps the values)")
    return H


def _angles(l2, dblA, degenerate):
    """Corner angles (3, m) in radians from the (3, m) geometry.

    ``atan2(2A, l_j^2 + l_k^2 - l_i^2)`` (accurate for needles). A zero-area
    triangle counts as collinear: pi at the corner opposite its longest edge,
    0 at the others, so every triangle's angles sum to pi.
    """
    dot = 0.5 * l2.sum(axis=0) - l2  # <e_j, e_k> at each corner
    theta = np.arctan2(np.broadcast_to(dblA, l2.shape), dot)
    if degenerate.any():
        d = np.flatnonzero(degenerate)
        theta[:, d] = 0.0
        theta[np.argmax(l2[:, d], axis=0), d] = np.pi
    return theta


def angle_sums(V, F):
    """Sum of the triangle angles at each vertex (n,) float64, radians.

    Zero-area triangles count as collinear (pi at the corner opposite the
    longest edge). Unreferenced vertices get 0.
    """
    V, F = _as_mesh(V, F)
    l2, dblA, _, degenerate = _geometry(V, F)
    theta = _angles(l2, dblA, degenerate)
    return np.bincount(F.T.ravel(), weights=theta.ravel(), minlength=len(V))


#: Faces per block in gaussian_curvature: the per-face temporaries are allocated
#: one block at a time, so the peak memory stays O(n) plus one block.
BLOCK_FACES = 1 << 15


def _block_size(m):
    return int(min(max(m // 16, 4096), 4 * BLOCK_FACES))


def _deficits_and_probes(V, F, n, area):
    """Angle sums, vertex areas (or None) and two boundary probes, block by block.

    The probes: every corner (v; next, prev) of a face adds ``next - prev``
    (probe 1) and ``next^2 - prev^2`` (probe 2) to vertex v, in exact integer
    arithmetic carried in float64 (exact below 2^53, so for n < 9e7). Around
    an interior vertex of a consistently oriented manifold every neighbour is
    once "next" and once "prev", and both probes are exactly 0; an open fan
    leaves ``end - start`` != 0. So a vertex with both probes 0 has no
    boundary edge (unless several open fans meet there in a pattern that
    cancels both sums), and every vertex with a non-zero probe is checked
    exactly afterwards, so nothing is ever classified as boundary wrongly.
    """
    m = len(F)
    theta_sum = np.zeros(n)
    A = np.zeros(n) if area is not None else None
    p1 = np.zeros(n)
    p2 = np.zeros(n)
    any_degenerate = False
    step = _block_size(m)
    columns = (V[:, 0], V[:, 1], V[:, 2])  # strided views: no copy of V per block
    for start in range(0, m, step):
        Fb = F[start:start + step]
        l2, dblA, cot, degenerate = _geometry(V, Fb, columns, with_cot=(area == "mixed"))
        any_degenerate |= bool(degenerate.any())
        theta = _angles(l2, dblA, degenerate)
        Ft = Fb.T
        idx = Ft.ravel()
        theta_sum += np.bincount(idx, weights=theta.ravel(), minlength=n)
        if A is not None:
            A += _vertex_areas(n, Fb, l2, dblA, cot, area, degenerate)
        del l2, dblA, cot, theta
        Ff = Ft.astype(np.float64)
        diff = Ff[[1, 2, 0]] - Ff[[2, 0, 1]]  # next - prev at each corner
        p1 += np.bincount(idx, weights=diff.ravel(), minlength=n)
        diff *= Ff[[1, 2, 0]] + Ff[[2, 0, 1]]  # next^2 - prev^2
        p2 += np.bincount(idx, weights=diff.ravel(), minlength=n)
        del Ff, diff
    return theta_sum, A, (p1 != 0) | (p2 != 0), any_degenerate


def _boundary_counts(F, n, candidates):
    """Exact boundary-edge counts (n,) and non-manifold edges, checking only the
    faces at candidate vertices (all edges at a candidate vertex are among them)."""
    b = np.zeros(n, np.int64)
    if not candidates.any():
        return b, np.empty((0, 2), np.int64)
    Fc = F[candidates[F].any(axis=1)]
    bc, nonmanifold = _edge_counts(Fc, n)
    b[candidates] = bc[candidates]
    if len(nonmanifold):
        nonmanifold = nonmanifold[candidates[nonmanifold].any(axis=1)]
    return b, nonmanifold


def gaussian_curvature(V, F, area="barycentric", boundary="nan", integrated=False):
    """Pointwise Gaussian curvature K (n,) float64 by the angle deficit, in 1/length^2.

    ``K_i = (2 pi - sum_j theta_j) / A_i`` at interior vertices, with ``A_i``
    the barycentric or mixed vertex area (Meyer et al. 2003, section 4;
    the deficit is exact for Gauss-Bonnet: its sum is ``2 pi chi``).

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64
    area : {"barycentric", "mixed"}
        The vertex area that normalises the deficit (geomlib.laplace).
    boundary : {"nan", "zero", "turning", "deficit"}
        The value at boundary vertices (vertices of an edge with only one
        triangle), where the angle deficit is not defined:

        * ``"nan"`` (default): NaN, the quantity is undefined; use
          ``np.nanmean`` etc.
        * ``"zero"``: 0.
        * ``"turning"``: the turning angle ``pi - sum theta`` (divided by
          ``A_i`` unless ``integrated``), the discrete geodesic curvature of
          the boundary. With it the integrated values sum to ``2 pi chi``
          exactly (discrete Gauss-Bonnet with the boundary term). At a vertex
          with ``b`` boundary edges (a non-manifold "bow-tie") the term is
          ``2 pi - b pi / 2 - sum theta``, which keeps the identity.
        * ``"deficit"``: the interior formula ``2 pi - sum theta`` applied
          anyway: what a naive implementation reports; large and meaningless.
    integrated : bool
        Return the deficit itself (radians, a curvature integrated over the
        vertex area) instead of the pointwise value.

    Returns
    -------
    K : (n,) float64

    Notes
    -----
    Vertices in no triangle, or only in zero-area triangles, have area 0:
    their pointwise K is NaN and a MeshWarning names them (an unreferenced
    vertex's integrated value is NaN too). Zero-area triangles count as
    collinear (pi at one corner) so the total stays ``2 pi chi``. A mesh whose
    every vertex lies on the boundary gets a MeshWarning (with the default
    rule every value is NaN). See the module docstring for non-manifold
    vertices and edges.
    """
    _check_options(area=area)
    if boundary not in BOUNDARY_RULES:
        raise MeshError(f"boundary must be one of {BOUNDARY_RULES}, not {boundary!r}")
    V, F = _as_mesh(V, F)
    n = len(V)
    # block-wise: peak memory O(n) plus one block of faces (libigl-like footprint)
    theta_sum, A, candidates, any_degenerate = _deficits_and_probes(V, F, n, None if integrated else area)
    deficit = np.subtract(2.0 * np.pi, theta_sum, out=theta_sum)
    if any_degenerate:
        _l2, _dblA, _cot, degenerate = _geometry(V, F)
        _warn(f"{degenerate.sum()} zero-area triangle(s) count as flat (angle pi opposite the longest "
              f"edge) and add no area: faces {format_indices(np.flatnonzero(degenerate))}")
        del _l2, _dblA, _cot
    if boundary != "deficit":
        b, nonmanifold = _boundary_counts(F, n, candidates)
        on_boundary = b > 0
        if len(nonmanifold):
            _warn(f"{len(nonmanifold)} edge(s) belong to three or more triangles; they count as "
                  f"interior edges: {_edge_list(nonmanifold)}")
        if on_boundary.any():
            if boundary == "turning":
                deficit[on_boundary] -= 0.5 * np.pi * b[on_boundary]
            else:
                deficit[on_boundary] = np.nan if boundary == "nan" else 0.0
            if on_boundary.all():
                _warn(f"every vertex of this mesh lies on the boundary; the angle deficit is defined "
                      f"nowhere (boundary={boundary!r} gives "
                      f"{'NaN everywhere' if boundary == 'nan' else 'the rule at every vertex'})")
    referenced = np.bincount(F.ravel(), minlength=n) > 0
    if not referenced.all():
        deficit[~referenced] = np.nan
    if integrated:
        if not referenced.all():
            _warn(f"{(~referenced).sum()} vertex/vertices are in no triangle; K is NaN there: "
                  f"vertices {format_indices(np.flatnonzero(~referenced))}")
        return deficit
    no_area = A <= 0
    if no_area.any():
        _warn(f"{no_area.sum()} vertex/vertices have zero area (in no triangle of non-zero area); "
              f"K is NaN there: vertices {format_indices(np.flatnonzero(no_area))}")
        A[no_area] = np.nan
    return np.divide(deficit, A, out=deficit)


def principal_curvatures(H, K):
    """Principal curvatures ``k1 >= k2`` (each (n,) float64) from signed H and K.

    ``k1,2 = H +- sqrt(H^2 - K)``. Where the discrete ``H^2 - K`` is negative
    (impossible for a smooth surface, common for discrete estimates at
    umbilics) it is clamped to 0, so ``k1 = k2 = H`` there. Pass the signed
    H (``mean_curvature(..., signed=True)``); NaN in either input gives NaN.
    """
    H = np.asarray(H, dtype=float)
    K = np.asarray(K, dtype=float)
    with np.errstate(invalid="ignore"):
        d = np.sqrt(np.maximum(H * H - K, 0.0))
    return H + d, H - d


def _boundary_mask(F, n):
    """Vertices on an edge used by exactly one face (boolean (n,))."""
    F = np.asarray(F)
    Ft = F.T
    idx = Ft.ravel()
    nxt = Ft[[1, 2, 0]].ravel().astype(np.float64)
    prv = Ft[[2, 0, 1]].ravel().astype(np.float64)
    candidates = (np.bincount(idx, weights=nxt - prv, minlength=n) != 0) | (
        np.bincount(idx, weights=(nxt - prv) * (nxt + prv), minlength=n) != 0)
    return _boundary_counts(F, n, candidates)[0] > 0


def angle_deficit(V, F):
    """(n,) integrated Gaussian curvature 2 pi - sum of the angles at each vertex (interior rule everywhere)."""
    return gaussian_curvature(V, F, boundary="deficit", integrated=True)
