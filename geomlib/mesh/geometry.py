"""Elementary measurements of a triangle mesh: one home for each.

Machinery shared by the lessons, the metrics, the smoothers and the viewer:
face normals and areas, total area, enclosed volume, bounding-box diagonal,
mean edge length. Inputs are validated by ``validate.as_mesh``; lengths are in
the mesh's own units.
"""

import numpy as np

from .topology import edges
from .validate import ZERO_AREA_RTOL, as_faces, as_mesh, as_vertices, is_zero_area

__all__ = [
    "corner_positions",
    "cross",
    "face_cross",
    "face_areas",
    "face_normals",
    "zero_area_faces",
    "vertex_normals",
    "area_weighted_normals",
    "surface_area",
    "face_volumes",
    "enclosed_volume",
    "volume_and_centroid",
    "bounding_box_diagonal",
    "mean_edge_length",
    "ROUNDING_RTOL",
    "zero_below_rounding",
]


def corner_positions(V, F):
    """(3, 3, m) float64: ``P[i]`` holds the (x, y, z) rows of corner i of every face (unchecked input).

    Corner-major, coordinate rows: each row is contiguous, which makes the
    per-face formulas below and in geomlib.lessons.laplace fast.
    """
    return np.ascontiguousarray(V.T).take(F.T, axis=1).swapaxes(0, 1)


def cross(a, b):
    """Cross product of (3, m) coordinate rows, written out (several times faster than ``np.cross``)."""
    return np.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def face_cross(V, F):
    """(m, 3) float64: ``(v1 - v0) x (v2 - v0)`` per face, which is 2 A_f n_f (unchecked input)."""
    v0, v1, v2 = corner_positions(V, F)
    return cross(v1 - v0, v2 - v0).T


#: faces per block in :func:`face_blocks` (a few MB of per-corner temporaries at a time)
FACE_BLOCK = 1 << 17


def face_blocks(F, size=FACE_BLOCK):
    """Consecutive blocks of at most ``size`` rows of F, for per-face quantities summed into vertices.

    A sum over faces done block by block holds one block's temporaries at a time: memory
    proportional to ``size``, not to the face count (at 655k vertices a few MB instead of hundreds).
    """
    return (F[start : start + size] for start in range(0, len(F), size))


def zero_area_faces(V, F, rtol=ZERO_AREA_RTOL):
    """Indices (k,) int64 of the faces whose area is zero up to rounding (:func:`geomlib.mesh.validate.is_zero_area`).

    Faces with a repeated vertex never reach here (``validate.as_mesh`` refuses them).
    """
    V, F = as_mesh(V, F)
    v0, v1, v2 = corner_positions(V, F)
    dblA = np.sqrt((cross(v1 - v0, v2 - v0) ** 2).sum(axis=0))
    longest2 = np.max(
        [((v1 - v0) ** 2).sum(axis=0), ((v2 - v1) ** 2).sum(axis=0), ((v0 - v2) ** 2).sum(axis=0)], axis=0
    )
    return np.flatnonzero(is_zero_area(dblA, longest2, rtol))


def face_areas(V, F):
    """(m,) float64: triangle areas A_f = |(v1 - v0) x (v2 - v0)| / 2 (length^2)."""
    V, F = as_mesh(V, F)
    return 0.5 * np.linalg.norm(face_cross(V, F), axis=1)


def face_normals(V, F):
    """(m, 3) float64: unit face normals, right-handed in the corner order (outward for CCW faces).

    A zero-area face has no normal: its row is (0, 0, 0), not NaN.
    """
    V, F = as_mesh(V, F)
    N = face_cross(V, F)
    length = np.linalg.norm(N, axis=1, keepdims=True)
    return np.divide(N, length, out=np.zeros_like(N), where=length > 0)


def vertex_normals(V, F):
    """(n, 3) float64: area-weighted unit vertex normals, outward for CCW faces.

    The normalised sum of the incident faces' ``2 A_f n_f``. A vertex in no
    face of non-zero area has no normal: its row is (0, 0, 0), not NaN.
    """
    V, F = as_mesh(V, F)
    return area_weighted_normals(V, F)


def area_weighted_normals(V, F):
    """:func:`vertex_normals` of a checked mesh ((V, F) as ``validate.as_mesh`` returns them)."""
    v0, v1, v2 = corner_positions(V, F)
    N2 = cross(v1 - v0, v2 - v0)  # (3, m) coordinate rows of 2 A_f n_f
    corners = F.T.ravel()  # corner by corner, matching np.tile of each row
    N = np.stack([np.bincount(corners, np.tile(N2[k], 3), minlength=len(V)) for k in range(3)], axis=1)
    length = np.sqrt(np.einsum("ij,ij->i", N, N))[:, None]
    return np.divide(N, length, out=np.zeros_like(N), where=length > 0)


def surface_area(V, F):
    """Total area of the triangles (length^2)."""
    return float(face_areas(V, F).sum())


def face_volumes(V, F, N=None):
    """(m,) float64: signed volume ``v0 . (v1 x v2) / 6`` of the tetrahedron each face spans with the origin.

    Computed as ``v0 . N / 6`` with ``N = (v1 - v0) x (v2 - v0)`` (:func:`face_cross`; the
    terms in v0 drop out of the triple product), so a caller that has N passes it and
    the faces are not gathered twice. Length^3; unchecked input.
    """
    N = face_cross(V, F) if N is None else N
    return np.einsum("ij,ij->i", V[F[:, 0]], N) / 6.0


def enclosed_volume(V, F, N=None):
    """Signed enclosed volume ``1/6 sum_f v0 . (v1 x v2)`` (length^3), by the divergence theorem.

    Positive for a closed mesh whose faces are counter-clockwise seen from
    outside; on an open mesh it depends on the origin (not checked here).
    ``N``: :func:`face_cross` of (V, F), when the caller has it already.
    """
    V, F = as_mesh(V, F)
    return float(face_volumes(V, F, N).sum())


def volume_and_centroid(V, F):
    """Signed enclosed volume (length^3) and the centroid (3,) of the enclosed solid.

    Face f and the origin span a tetrahedron of signed volume
    ``vol_f = v0 . (v1 x v2) / 6`` (:func:`face_volumes`) and centroid
    ``(v0 + v1 + v2) / 4``; the solid is their signed sum. Where the volume is
    zero or not finite the centroid is the mean of the vertices.
    """
    V, F = as_mesh(V, F)
    vol_f = face_volumes(V, F)
    vol = float(vol_f.sum())
    if vol == 0 or not np.isfinite(vol):
        return vol, V.mean(axis=0)
    v0, v1, v2 = corner_positions(V, F)
    return vol, (v0 + v1 + v2) @ vol_f / (4.0 * vol)


def bounding_box_diagonal(V):
    """Length of the diagonal of the axis-aligned bounding box, ``|max(V) - min(V)|`` (length)."""
    V = as_vertices(V)
    return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))


def mean_edge_length(V, F):
    """Mean length of the mesh's edges, each edge counted once (length)."""
    V = as_vertices(V)
    F = as_faces(F, len(V))
    E = edges(F)
    return float(np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1).mean())


#: Relative size below which a value counts as zero to rounding. Rounding positions of size |x| leaves
#: errors of a few 1e-16 |x| / ell in H ell, K ell^2 or a displacement / ell; 1e-9 is far above that and far
#: below anything a mesh resolves (K ell^2 = 1e-9 is a sphere of radius 30 000 edges).
ROUNDING_RTOL = 1e-9


def zero_below_rounding(values, scale, rtol=ROUNDING_RTOL):
    """``values`` with every entry of magnitude at most ``rtol * scale`` set to +0.0; NaN stays NaN.

    Counts and signs of values that are zero to rounding must be zero: a flat mesh
    has no vertex "with K < 0" and no H of "-0". ``scale`` is the quantity's own
    size on the mesh, in its units: ``1 / ell`` for H, ``1 / ell**2`` for K, ``ell``
    for a length (``ell = mean_edge_length(V, F)``).

    Returns
    -------
    ndarray of float64, of the shape of ``values`` (a new array).
    """
    out = np.array(values, dtype=float)
    out[np.abs(out) <= rtol * abs(float(scale))] = 0.0
    return out
