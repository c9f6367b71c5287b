"""Seeded Gaussian noise on vertex positions, scaled to the mesh's size.

Convention: ``sigma`` is *relative to the bounding-box diagonal* of the input,
so ``sigma=0.01`` displaces vertices by about 1 % of the mesh's diagonal
whatever its units. The absolute standard deviation is
``sigma * bounding_box_diagonal(V)`` (length units of the mesh).

Randomness only through an explicit ``seed``: the same seed gives the same
noise, bit for bit, and the input arrays are never modified.
"""

import numpy as np

from .errors import MeshError
from .metrics import bounding_box_diagonal
from .validate import as_faces, as_vertices

DIRECTIONS = ("isotropic", "normal")


def add_noise(V, F, sigma, seed, direction="isotropic"):
    """Vertex positions plus seeded Gaussian noise, ``sigma`` relative to the bounding-box diagonal.

    ``V' = V + s * xi`` with ``s = sigma * diag`` (``diag`` the bounding-box
    diagonal of V, so ``s`` is in the mesh's length units):

    * ``direction="isotropic"``: ``xi`` is an (n, 3) array of independent
      standard normal numbers, so every coordinate of every vertex moves with
      standard deviation ``s`` (the displacement length is ``s`` times a
      chi distribution with 3 degrees of freedom, mean about ``1.60 s``).
    * ``direction="normal"``: ``xi = z_i n_i`` with ``z_i`` standard normal and
      ``n_i`` the area-weighted unit vertex normal of the *input* mesh, so the
      signed normal displacement has standard deviation ``s`` and the noise
      has no tangential part (a scanner's depth error). Isolated vertices
      (no incident face) have no normal and do not move.

    Parameters
    ----------
    V : (n, 3) float64
        Clean vertex positions (not modified).
    F : (m, 3) int64
        Triangles (only used for the normals; the connectivity is unchanged).
    sigma : float
        Noise level as a fraction of the bounding-box diagonal, ``>= 0``.
    seed : int or numpy.random.Generator
        Seed of ``numpy.random.default_rng``; the same seed gives the same noise.
    direction : "isotropic" or "normal"

    Returns
    -------
    (n, 3) float64
        A new array; the input is never modified.
    """
    V = as_vertices(V)
    F = as_faces(F, len(V))
    try:
        sigma = float(sigma)
    except (TypeError, ValueError):
        raise MeshError(f"sigma must be a number (a fraction of the bounding-box diagonal), got {sigma!r}") from None
    if not np.isfinite(sigma) or sigma < 0:
        raise MeshError(f"sigma must be finite and >= 0 (a fraction of the bounding-box diagonal), got {sigma}")
    if direction not in DIRECTIONS:
        raise MeshError(f"direction must be 'isotropic' or 'normal', not {direction!r}")
    if seed is None:
        raise MeshError("seed is required: pass an integer so that the noise can be reproduced")
    rng = np.random.default_rng(seed)
    s = sigma * bounding_box_diagonal(V)
    if direction == "isotropic":
        return V + s * rng.standard_normal(V.shape)
    from .curvature import vertex_normals

    N = vertex_normals(V, F)
    return V + (s * rng.standard_normal(len(V)))[:, None] * N
