"""Discrete mean and Gaussian curvature (pointwise values, in 1/length and 1/length^2).

Sign convention: ``Delta x = -2 H n`` with ``Delta = M^-1 C`` (geomlib.laplace)
and ``n`` the outward unit normal; ``H > 0`` on a sphere.
"""

import warnings

import numpy as np

from .errors import MeshError, MeshWarning, format_indices
from .laplace import _as_mesh, face_geometry, laplacian


def face_normals(V, F):
    """Unit face normals (m, 3), right-hand rule on (v0, v1, v2); zero for degenerate faces."""
    N = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    length = np.linalg.norm(N, axis=1)
    ok = length > 0
    N[ok] /= length[ok, None]
    N[~ok] = 0.0
    return N


def vertex_normals(V, F):
    """Area-weighted unit vertex normals (n, 3): the normalised sum of the
    incident faces' cross products (outward on a consistently oriented closed
    mesh). Isolated vertices get a zero vector."""
    V, F = _as_mesh(V, F)
    N2 = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])  # 2 A n per face
    n = len(V)
    N = np.column_stack([np.bincount(F.ravel(), weights=np.repeat(N2[:, k], 3), minlength=n)
                         for k in range(3)])
    length = np.linalg.norm(N, axis=1)
    ok = length > 0
    N[ok] /= length[ok, None]
    return N


def _laplace_of_positions(V, F, weights, area):
    M, C = laplacian(V, F, weights=weights, area=area)
    m = M.diagonal()
    CV = C @ V
    isolated = m <= 0
    if isolated.any():
        warnings.warn(
            f"{isolated.sum()} vertex/vertices belong to no triangle of non-zero area; "
            f"their curvature is undefined and returned as NaN: vertices "
            f"{format_indices(np.flatnonzero(isolated))}",
            MeshWarning,
            stacklevel=3,
        )
    with np.errstate(divide="ignore", invalid="ignore"):
        DV = CV / np.where(isolated, np.nan, m)[:, None]
    return DV


def mean_curvature(V, F, weights="cotan", area="barycentric", signed=False):
    """Pointwise mean curvature H (n,) from ``Delta x = -2 H n``: ``H = 1/2 |Delta x|``.

    With ``signed=True``, ``H = -1/2 <Delta x, n>`` with ``n`` the area-weighted
    outward vertex normal, so H > 0 on a sphere and H < 0 where the surface
    bends away from its normal the other way (a saddle region can have either).
    Units 1/length for ``weights="cotan"``; for ``weights="uniform"`` the
    operator carries no metric and ``1/2 |Delta x|`` has units of length (it
    measures the umbrella vector, Taubin 1995), which is why the uniform value
    depends on tessellation and scale.

    Boundary vertices: the value is computed by the same formula, but the
    one-ring is incomplete there, so ``Delta x`` has an in-plane component and
    H is not an estimate of the curvature (it is large even on a flat plane).
    Isolated vertices give NaN with a MeshWarning naming them.
    Meyer et al. 2003, section 3.5; Desbrun et al. 1999.
    """
    V, F = _as_mesh(V, F)
    DV = _laplace_of_positions(V, F, weights, area)
    if signed:
        N = vertex_normals(V, F)
        return -0.5 * np.einsum("ij,ij->i", DV, N)
    return 0.5 * np.linalg.norm(DV, axis=1)


BOUNDARY_RULES = ("nan", "zero", "turning", "deficit")


def angle_sums(V, F):
    """Sum of the triangle angles at each vertex (n,), radians. Degenerate faces add 0."""
    V, F = _as_mesh(V, F)
    _, dblA, cot, degenerate = face_geometry(V, F)
    angles = np.arctan2(np.where(degenerate, 0.0, 1.0)[:, None], cot)
    angles[degenerate] = 0.0
    return np.bincount(F.ravel(), weights=angles.ravel(), minlength=len(V))


def gaussian_curvature(V, F, area="barycentric", boundary="nan", integrated=False):
    """Pointwise Gaussian curvature K (n,) by the angle deficit, in 1/length^2.

    ``K_i = (2 pi - sum_j theta_j) / A_i`` at interior vertices, with ``A_i``
    the barycentric or mixed vertex area (Meyer et al. 2003, section 4).
    With ``integrated=True`` the deficit itself (radians) is returned.

    Boundary vertices (vertices on an edge with only one triangle) have no
    angle deficit in the interior sense. ``boundary`` selects what is returned:

    * ``"nan"`` (default): NaN, because the quantity is undefined there; use
      ``np.nanmean`` etc. or a mask from ``geomlib.boundary_vertices``.
    * ``"zero"``: 0.
    * ``"turning"``: ``(pi - sum theta) / A_i``, the discrete geodesic
      curvature (turning angle) of the boundary; with it, the integrated
      values sum to ``2 pi chi`` (Gauss-Bonnet with the boundary term).
    * ``"deficit"``: the interior formula applied anyway (``2 pi - sum``),
      which is what a naive implementation reports: large and meaningless.
    """
    if boundary not in BOUNDARY_RULES:
        raise MeshError(f"boundary must be one of {BOUNDARY_RULES}, not {boundary!r}")
    V, F = _as_mesh(V, F)
    n = len(V)
    l2, dblA, cot, degenerate = face_geometry(V, F)
    angles = np.arctan2(np.ones_like(cot), cot)  # angle from its cotangent, in (0, pi)
    angles[degenerate] = 0.0
    total = np.bincount(F.ravel(), weights=angles.ravel(), minlength=n)
    deficit = 2.0 * np.pi - total
    on_boundary = _boundary_mask(F, n)
    if boundary == "turning":
        deficit[on_boundary] = np.pi - total[on_boundary]
    elif boundary == "zero":
        deficit[on_boundary] = 0.0
    elif boundary == "nan":
        deficit[on_boundary] = np.nan
    referenced = np.bincount(F.ravel(), minlength=n) > 0
    deficit[~referenced] = np.nan
    if integrated:
        return deficit
    from .laplace import _vertex_areas

    A = _vertex_areas(n, F, l2, dblA, cot, area)
    with np.errstate(divide="ignore", invalid="ignore"):
        return deficit / np.where(A > 0, A, np.nan)


def _boundary_mask(F, n):
    """Vertices on an edge used by exactly one face."""
    E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    key = E[:, 0] * np.int64(n) + E[:, 1]
    uniq, counts = np.unique(key, return_counts=True)
    b = uniq[counts == 1]
    mask = np.zeros(n, bool)
    mask[b // n] = True
    mask[b % n] = True
    return mask


def principal_curvatures(H, K):
    """Principal curvatures ``k1 >= k2`` (each (n,)) from H and K:
    ``k1,2 = H +- sqrt(H^2 - K)``. Where the discrete ``H^2 - K`` is slightly
    negative (it cannot be for a smooth surface) it is clamped to 0, so k1 = k2 = H
    there; pass signed H."""
    H = np.asarray(H, dtype=float)
    K = np.asarray(K, dtype=float)
    d = np.sqrt(np.maximum(H * H - K, 0.0))
    return H + d, H - d
