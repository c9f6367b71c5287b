"""Lesson (notebook 07): seeded Gaussian noise on vertex positions, scaled to the mesh's size.

``sigma`` is relative to the bounding-box diagonal d of the input: ``sigma=0.01``
moves vertices by about 1 % of the diagonal whatever the mesh's units; the
absolute standard deviation is ``sigma * d`` (length units). Randomness only
through an explicit ``seed``: the same seed gives the same noise, bit for bit,
and the input arrays are never modified.
"""

import numpy as np

from ..mesh.errors import MeshError
from ..mesh.geometry import bounding_box_diagonal, vertex_normals
from ..mesh.validate import as_mesh, check_choice

__all__ = ["add_noise", "DIRECTIONS"]

DIRECTIONS = ("isotropic", "normal")


def add_noise(V, F, sigma, seed, direction="isotropic"):
    """``V' = V + sigma d xi``: seeded Gaussian noise, sigma relative to the bounding-box diagonal d.

    * ``direction="isotropic"``: ``xi`` is (n, 3) standard normal, so every
      coordinate moves with standard deviation ``sigma d`` (the displacement
      length has mean about ``1.60 sigma d``).
    * ``direction="normal"``: ``xi_i = z_i n_i`` with ``z_i`` standard normal
      and ``n_i`` the area-weighted unit vertex normal of the input: a
      scanner's depth error, no tangential part. A vertex in no face has no
      normal and does not move.

    Parameters
    ----------
    V : (n, 3) float64
        Clean positions (not modified).
    F : (m, 3) int64
        Triangles (only for the normals; the connectivity is unchanged).
    sigma : float
        Noise level, a fraction of the bounding-box diagonal, ``>= 0``.
    seed : int or numpy.random.Generator
        Seed of ``numpy.random.default_rng``.
    direction : {"isotropic", "normal"}

    Returns
    -------
    (n, 3) float64, a new array.
    """
    V, F = as_mesh(V, F)
    try:
        sigma = float(sigma)
    except (TypeError, ValueError):
        raise MeshError(f"sigma must be a number (a fraction of the bounding-box diagonal), got {sigma!r}") from None
    if not np.isfinite(sigma) or sigma < 0:
        raise MeshError(f"sigma must be finite and >= 0 (a fraction of the bounding-box diagonal), got {sigma}")
    check_choice("direction", direction, DIRECTIONS)
    if seed is None:
        raise MeshError("seed is required: pass an integer so that the noise can be reproduced")
    rng = np.random.default_rng(seed)
    s = sigma * bounding_box_diagonal(V)
    if direction == "isotropic":
        return V + s * rng.standard_normal(V.shape)
    return V + (s * rng.standard_normal(len(V)))[:, None] * vertex_normals(V, F)
