"""Lesson (notebooks 01 and 03): discrete mean and Gaussian curvature: pointwise values, H in 1/length, K in 1/length^2.

Sign convention: ``Delta x = -2 H n`` with ``Delta = M^-1 C`` (geomlib.lessons.laplace)
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
* ``discrete_principal_curvatures``: NaN at boundary vertices, where neither the
  signed H nor the deficit is a curvature.

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

Speed (``benchmarks/bench_laplace.py``, 655k-vertex icosphere, libigl's
``gaussian_curvature`` in the same run, 2 cores shared, load average 1.8-3.9):
``gaussian_curvature`` takes 0.77-0.96x libigl's wall-clock time (best of 15;
one run of 12 at load 3.4 gave 1.09x), 0.88-0.96x in CPU time, against 1.7-2.1x
before on the same machine; its peak memory is 1.7x libigl's (1.65x before). The
integrated deficit takes 0.5-0.57x and 1.5x. The angles and the vertex areas come
from one pass over blocks of faces (V checked and transposed once, each block's
edge lengths and areas shared, sums added in place), and the half-edge probes
skip the edge table on a closed mesh.
"""

import warnings

import numpy as np

from ..mesh.errors import MeshError, MeshWarning, format_indices
from ..mesh.geometry import area_weighted_normals
from ..mesh.topology import boundary_edge_counts, edges_at_unpaired_vertices
from ..mesh.validate import as_mesh, check_choice
from .laplace import (
    FaceGeometry,
    assemble_laplacian,
    check_options,
    face_geometry,
    laplacian,
    vertex_areas,
    warn_zero_area,
)

__all__ = [
    "mean_curvature",
    "signed_mean_curvature",
    "gaussian_curvature",
    "principal_curvatures",
    "discrete_principal_curvatures",
    "angle_deficit",
    "angle_sums",
    "corner_angles",
    "face_angles",
    "boundary_mask",
    "BOUNDARY_RULES",
    "MEAN_BOUNDARY_RULES",
]

BOUNDARY_RULES = ("nan", "zero", "turning", "deficit")
MEAN_BOUNDARY_RULES = ("formula", "nan", "zero")


def _warn(message):
    warnings.warn(message, MeshWarning, stacklevel=3)


def boundary_mask(V, F):
    """Boolean (n,): True at the vertices of an edge that belongs to exactly one triangle."""
    V, F = as_mesh(V, F)
    return boundary_edge_counts(F, len(V)) > 0


def mean_curvature(V, F, weights="cotan", area="barycentric", signed=False, boundary="formula"):
    """Pointwise mean curvature H (n,) float64 from ``Delta x = -2 H n``: ``H = 1/2 |Delta x|``.

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64, counter-clockwise seen from outside.
    weights, area
        As in :func:`geomlib.laplacian`.
    signed : bool
        False: ``H = 1/2 |Delta x| >= 0``. True: ``H = -1/2 <Delta x, n>`` with
        ``n`` the area-weighted outward vertex normal: H > 0 on a sphere.
    boundary : {"formula", "nan", "zero"}
        Value at boundary vertices: the formula applied anyway (default; the
        one-ring is incomplete, ``Delta x`` has an in-plane part and the value
        is large even on a flat plane), NaN, or 0.

    Returns
    -------
    H : (n,) float64
        1/length for ``weights="cotan"``. For ``"uniform"`` it is half the
        umbrella vector (Kobbelt et al. 1998; the weights of Taubin 1995): a length, not a curvature. NaN (with a
        MeshWarning) at vertices in no triangle of non-zero area, where M is 0.
        Meyer et al. 2003, section 3.5; Desbrun et al. 1999.
    """
    check_options(weights, area)
    check_choice("boundary", boundary, MEAN_BOUNDARY_RULES)
    V, F = as_mesh(V, F)
    M, C = assemble_laplacian(V, F, weights, area)
    A = M.diagonal()
    if (A <= 0).any():
        _warn(
            f"{(A <= 0).sum()} vertex/vertices belong to no triangle of non-zero area; their curvature "
            f"is undefined and returned as NaN: vertices {format_indices(np.flatnonzero(A <= 0))}"
        )
    DV = (C @ V) / np.where(A > 0, A, np.nan)[:, None]  # Delta x = M^-1 C x
    if signed:
        H = -0.5 * np.einsum("ij,ij->i", DV, area_weighted_normals(V, F))
    else:
        H = 0.5 * np.linalg.norm(DV, axis=1)
    if boundary != "formula":
        on_boundary = boundary_edge_counts(F, len(V)) > 0  # as boundary_mask(V, F)
        H[on_boundary] = np.nan if boundary == "nan" else 0.0
        if on_boundary.all():
            _warn(
                f"every vertex of this mesh lies on the boundary; boundary={boundary!r} gives "
                f"{'NaN' if boundary == 'nan' else '0'} everywhere (boundary='formula' keeps the values)"
            )
    return H


def signed_mean_curvature(V, F, M, C):
    """Signed mean curvature H (n,) float64 from a Laplacian pair: ``H_i = -1/2 <(M^-1 C x)_i, n_i>``.

    ``(M, C)``: (n, n) matrices of :func:`geomlib.laplacian` (any weights; M diagonal). ``n_i``: the
    area-weighted outward unit vertex normal, the normalised sum of the cross products
    ``(x_j - x_i) x (x_k - x_i)`` of the faces at i (each face in the order F lists it, counter-clockwise
    seen from outside). H > 0 on a sphere. NaN at boundary vertices (one-ring incomplete). Units as
    :func:`mean_curvature`: 1/length for the cotangent pair, a length for the uniform one (Kobbelt et al. 1998).
    This is ``mean_curvature(V, F, weights, signed=True, boundary="nan")`` for the pair of those weights.
    """
    V, F = as_mesh(V, F)
    A = np.asarray(M.diagonal(), dtype=float)
    DX = (C @ V) / np.where(A > 0, A, np.nan)[:, None]  # Delta x = M^-1 C x, NaN where M is 0
    H = -0.5 * np.einsum("ij,ij->i", DX, area_weighted_normals(V, F))
    H[boundary_edge_counts(F, len(V)) > 0] = np.nan
    return H


def corner_angles(V, F):
    """Angles (m, 3) in radians at the corners of each face: :func:`face_angles` of ``face_geometry(V, F)``."""
    return face_angles(face_geometry(V, F))


def face_angles(faces):
    """Corner angles (m, 3) in radians from ``faces = face_geometry(V, F)``.

    ``theta_i = atan2(1, cot theta_i)`` in (0, pi), with ``cot theta_i = <e_j, -e_k> / 2A``
    (accurate for needles, unlike an arccos). A zero-area triangle counts as collinear: pi at
    the corner opposite its longest edge, 0 at the others, so the angles of
    every triangle sum to pi.
    """
    l2, _, cot, degenerate = faces
    theta = np.arctan2(1.0, cot.T)  # (3, m): one row per corner
    flat = np.flatnonzero(degenerate)
    theta[:, flat] = 0.0
    theta[np.argmax(l2.T[:, flat], axis=0), flat] = np.pi
    return theta.T


def angle_sums(V, F):
    """Sum of the triangle angles at each vertex (n,) float64, radians; 0 at unreferenced vertices."""
    return angle_and_area_sums(*as_mesh(V, F))[0]


def angle_and_area_sums(V, F, area=None):
    """Per vertex, from one pass over the faces: the sum of its triangle angles, and its area A_i.

    Returns ``(theta_sum, A)``, each (n,) float64: radians (0 at unreferenced vertices), and
    :func:`geomlib.lessons.laplace.vertex_areas` of the rule ``area`` (None: not measured,
    ``A`` is None). Block by block of faces: angles and areas share each block's edge lengths
    and areas, and only one block's corner temporaries exist at a time. When it measures areas
    it names the zero-area faces (MeshWarning), as ``vertex_areas`` does. Unchecked input:
    (V, F) as ``geomlib.mesh.validate.as_mesh`` returns them.
    """
    theta_sum, A, degenerate = np.zeros(len(V)), None if area is None else np.zeros(len(V)), []
    for block, faces in FaceGeometry.blocks(V, F):
        np.add.at(theta_sum, block.T.ravel(), face_angles(faces).T.ravel())  # in place: no (n,) array per block
        if area is not None:
            A += vertex_areas(V, block, area, faces)
            degenerate.append(faces.degenerate)
        del faces  # before the next block is measured, not after
    if area is not None:
        warn_zero_area(np.concatenate(degenerate), stacklevel=4)
    return theta_sum, A


def angle_deficit(V, F, theta_sum=None):
    """Integrated Gaussian curvature (n,) in radians: ``2 pi - sum_j theta_j``, the interior rule everywhere.

    Summed over a closed mesh it is exactly ``2 pi chi`` (discrete
    Gauss-Bonnet). At boundary vertices this is not a curvature (see
    :func:`gaussian_curvature` for the boundary rules). NaN, with a
    MeshWarning, at vertices in no triangle. ``theta_sum``: :func:`angle_sums`
    of (V, F) when the caller has it already.
    """
    V, F = as_mesh(V, F)
    return deficit_of(V, F, angle_and_area_sums(V, F)[0] if theta_sum is None else theta_sum)


def deficit_of(V, F, theta_sum):
    """:func:`angle_deficit` of a checked mesh with its angle sums ``theta_sum`` (n,)."""
    deficit = 2.0 * np.pi - theta_sum
    unreferenced = theta_sum == 0  # in a triangle of non-zero area a vertex has an angle > 0
    if unreferenced.any():  # only then count the triangles at each vertex
        unreferenced &= np.bincount(F.ravel(), minlength=len(V)) == 0
    if unreferenced.any():
        _warn(
            f"{unreferenced.sum()} vertex/vertices are in no triangle; K is NaN there: "
            f"vertices {format_indices(np.flatnonzero(unreferenced))}"
        )
        deficit[unreferenced] = np.nan
    return deficit


def gaussian_curvature(V, F, area="barycentric", boundary="nan", integrated=False):
    """Pointwise Gaussian curvature ``K_i = (2 pi - sum_j theta_j) / A_i`` (n,) float64, in 1/length^2.

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64
    area : {"barycentric", "mixed"}
        The vertex area ``A_i`` that turns the deficit into a pointwise value.
    boundary : {"nan", "zero", "turning", "deficit"}
        At boundary vertices (on an edge of one triangle) the deficit is not defined:

        * ``"nan"`` (default): NaN; use ``np.nanmean`` etc.
        * ``"zero"``: 0.
        * ``"turning"``: the turning angle ``pi - sum theta``, the discrete
          geodesic curvature of the boundary; then the integrated values sum
          to ``2 pi chi`` exactly (Gauss-Bonnet with the boundary term). With
          ``b`` boundary edges at the vertex (``b > 2`` at a "bow-tie") it is
          ``2 pi - b pi / 2 - sum theta``, which keeps the identity.
        * ``"deficit"``: the interior formula anyway, what a naive
          implementation reports (about ``pi / A`` too large on a flat boundary).
    integrated : bool
        Return the (corrected) deficit in radians instead of dividing by ``A_i``.

    Returns
    -------
    K : (n,) float64
        NaN, with a MeshWarning, where ``A_i = 0`` (a vertex in no triangle of
        non-zero area). Zero-area triangles count as flat. Edges of three or
        more triangles count as interior edges (MeshWarning).
        Meyer et al. 2003, section 4.
    """
    check_options(area=area)
    if boundary not in BOUNDARY_RULES:
        raise MeshError(f"boundary must be one of {BOUNDARY_RULES}, not {boundary!r}")
    V, F = as_mesh(V, F)
    theta_sum, A = angle_and_area_sums(V, F, None if integrated else area)  # one pass over the faces
    K = deficit_of(V, F, theta_sum)  # 2 pi - sum theta
    if boundary != "deficit":
        b = boundary_edge_counts(F, len(V))  # boundary edges at each vertex: the one boundary rule
        on_boundary = b > 0
        if boundary == "turning":
            K[on_boundary] -= 0.5 * np.pi * b[on_boundary]  # b = 2: pi - sum theta
        else:
            K[on_boundary] = np.nan if boundary == "nan" else 0.0
        E, faces_at_edge = edges_at_unpaired_vertices(F, len(V))  # a closed mesh sorts nothing
        _warn_unusual_boundary(E[faces_at_edge > 2], on_boundary, boundary)
    if integrated:
        return K
    if (A <= 0).any():
        _warn(
            f"{(A <= 0).sum()} vertex/vertices have zero area (in no triangle of non-zero area); "
            f"K is NaN there: vertices {format_indices(np.flatnonzero(A <= 0))}"
        )
    return K / np.where(A > 0, A, np.nan)


def _warn_unusual_boundary(non_manifold_edges, on_boundary, boundary):
    if len(non_manifold_edges):
        listed = ", ".join(f"({a}, {b})" for a, b in non_manifold_edges[:5].tolist())
        more = f" (and {len(non_manifold_edges) - 5} more)" if len(non_manifold_edges) > 5 else ""
        _warn(
            f"{len(non_manifold_edges)} edge(s) belong to three or more triangles; they count as "
            f"interior edges: {listed}{more}"
        )
    if on_boundary.all():
        _warn(
            f"every vertex of this mesh lies on the boundary; the angle deficit is defined nowhere "
            f"(boundary={boundary!r} gives {'NaN everywhere' if boundary == 'nan' else 'the rule at every vertex'})"
        )


def principal_curvatures(H, K):
    """Principal curvatures ``kappa_1 >= kappa_2`` (each (n,) float64) from signed H and K.

    ``kappa_1,2 = H +- sqrt(H^2 - K)``. Where the discrete ``H^2 - K`` is
    negative (impossible on a smooth surface, common for discrete estimates
    near umbilics) it is clamped to 0, so ``kappa_1 = kappa_2 = H`` there.
    Pass the signed H (``mean_curvature(..., signed=True)``); NaN in either
    input gives NaN.
    """
    H = np.asarray(H, dtype=float)
    K = np.asarray(K, dtype=float)
    with np.errstate(invalid="ignore"):
        root = np.sqrt(np.maximum(H * H - K, 0.0))
    return H + root, H - root


def discrete_principal_curvatures(V, F, M, C, deficit):
    """Principal curvatures ``kappa_1 >= kappa_2`` per vertex, each (n,) float64 in 1/length, from (M, C) and K.

    Meyer et al. 2003, section 5: on a smooth surface ``H = (kappa_1 + kappa_2) / 2`` and
    ``K = kappa_1 kappa_2``, so the two are the roots of ``kappa^2 - 2 H kappa + K = 0``,
    ``kappa_1,2 = H +- sqrt(H^2 - K)``. Here H is the signed mean curvature of the pair,
    ``H_i = -1/2 <(M^-1 C x)_i, n_i>`` (:func:`signed_mean_curvature`: ``Delta x = -2 H n``, n the
    area-weighted outward normal, so H > 0 and both kappas > 0 on a sphere), and K the pointwise
    angle deficit ``K_i = deficit_i / M_ii``. Where the discrete ``H^2 - K`` is negative (near
    umbilics) it is clamped to 0 (:func:`principal_curvatures`).

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64, counter-clockwise seen from outside.
    M, C : (n, n) matrices of :func:`geomlib.laplacian` (M diagonal: the vertex areas, length^2).
    deficit : (n,) float64
        The integrated Gaussian curvature ``2 pi - sum of the angles at i`` in radians
        (:func:`angle_deficit`, or ``gaussian_curvature(V, F, integrated=True)``).

    Returns
    -------
    (kappa_1, kappa_2) : each (n,) float64, pointwise, ``kappa_1 >= kappa_2``.
        NaN at boundary vertices (the one-ring is open: neither H nor the deficit is a curvature
        there, whatever ``deficit`` holds), and where ``M_ii = 0`` or the deficit is NaN.
    """
    V, F = as_mesh(V, F)
    n = len(V)
    for name, X in (("M", M), ("C", C)):
        if getattr(X, "shape", None) != (n, n):
            raise MeshError(
                f"{name} has shape {getattr(X, 'shape', None)}, expected ({n}, {n}) for a mesh of {n} vertices"
            )
    deficit = np.asarray(deficit, dtype=float)
    if deficit.shape != (n,):
        raise MeshError(f"deficit has shape {deficit.shape}, expected ({n},): one angle deficit per vertex")
    A = np.asarray(M.diagonal(), dtype=float)
    if (A < 0).any():
        raise MeshError(f"M has negative vertex areas at vertices {format_indices(np.flatnonzero(A < 0))}")
    H = signed_mean_curvature(V, F, M, C)  # NaN on the boundary and where M_ii = 0
    with np.errstate(divide="ignore", invalid="ignore"):  # where M_ii = 0, H is NaN and so are the kappas
        K = deficit / A  # pointwise: the deficit per unit area
    return principal_curvatures(H, K)


def mixed_principal_curvatures(V, F, deficit):
    """Notebook 03's ``kappa_1 >= kappa_2``, each (n,) float64 in 1/length, from the mesh and its angle deficits.

    :func:`discrete_principal_curvatures` of the cotangent pair with the mixed Voronoi areas
    (``laplacian(V, F, area="mixed")``, Meyer et al. 2003): the pair built from the edge lengths and
    the mixed areas, ``H`` its signed mean curvature, ``K = deficit / M_ii``. NaN at boundary vertices.
    """
    M, C = laplacian(V, F, area="mixed")
    return discrete_principal_curvatures(V, F, M, C, deficit)
