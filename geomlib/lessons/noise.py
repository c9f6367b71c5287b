"""Lesson (notebook 07): seeded Gaussian noise on vertex positions, scaled to the mesh's size,
the denoising experiment built on it (noise, smoothing, the error against the clean mesh), and
the sweep over the step and the iteration count that finds the experiment's best setting.

``sigma`` is relative to the bounding-box diagonal d of the input: ``sigma=0.01``
moves vertices by about 1 % of the diagonal whatever the mesh's units; the
absolute standard deviation is ``sigma * d`` (length units). Randomness only
through an explicit ``seed``: the same seed gives the same noise, bit for bit,
and the input arrays are never modified.
"""

import numpy as np

from ..mesh.errors import MeshError
from ..mesh.geometry import bounding_box_diagonal, vertex_normals
from ..mesh.topology import boundary_vertices
from ..mesh.validate import as_mesh, check_choice, real_number, whole_number
from ..numerics.factor import factorise
from .laplace import assemble_laplacian
from .metrics import vertex_rms
from .smoothing import explicit_smoothing, implicit_smoothing, implicit_step

__all__ = ["add_noise", "denoising_experiment", "denoising_spread", "denoising_sweep", "DIRECTIONS"]

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
    sigma = real_number("sigma", sigma, 0, why=" (a fraction of the bounding-box diagonal)")
    check_choice("direction", direction, DIRECTIONS)
    if seed is None:
        raise MeshError("seed is required: pass an integer so that the noise can be reproduced")
    rng = np.random.default_rng(seed)
    s = sigma * bounding_box_diagonal(V)
    if direction == "isotropic":
        return V + s * rng.standard_normal(V.shape)
    return V + (s * rng.standard_normal(len(V)))[:, None] * vertex_normals(V, F)


def denoising_experiment(V_clean, F, sigma, tau, iterations, seed, method="implicit", weights="cotan", **options):
    """The denoising experiment: noise, smoothing, and the error against the *clean* mesh.

    ``W = add_noise(V_clean, F, sigma, seed)`` (sigma relative to the bounding-box
    diagonal d), then ``iterations`` smoothing steps of size ``tau`` from W with W's
    operator (implicit: ``(M - tau C) P' = M P``; explicit: ``P' = P + tau M^-1 C P``),
    then ``E = vertex_rms(P, V_clean)``: the vertex RMS distance to the clean mesh,
    over the clean mesh's d. E is scale-free: scaling V_clean by s and tau by s^2
    (cotan weights) gives the same E.

    Parameters
    ----------
    V_clean : (n, 3) float64, F : (m, 3) int64
    sigma : float, the noise level (a fraction of d)
    tau : float, the step (length^2 for cotan weights, dimensionless for uniform)
    iterations : int >= 0
    seed : int, of the noise
    method : "implicit" or "explicit"; weights : "cotan" or "uniform"
    **options : passed to the smoother (``callback``, ``on_failure``, ...)

    Returns
    -------
    (E, W, P): the relative error (float), the noisy and the smoothed positions.
    """
    check_choice("method", method, ("implicit", "explicit"))
    W = add_noise(V_clean, F, sigma, seed)
    smooth = implicit_smoothing if method == "implicit" else explicit_smoothing
    P = smooth(W, F, tau, iterations, weights, **options)
    return vertex_rms(P, V_clean), W, P


def denoising_spread(V_clean, F, sigma, tau, iterations, seeds, **options):
    """The experiment over several noise draws: the mean and the spread of the error E.

    One draw's E depends on its noise pattern, so an evaluation reports E over draws:
    ``E_s = denoising_experiment(V_clean, F, sigma, tau, iterations, s)[0]`` for each seed
    ``s`` (implicit smoothing, cotangent weights unless ``weights=`` says otherwise), then
    their mean and their sample standard deviation (``ddof=1``: the spread of the draws'
    population estimated from these few).

    Parameters
    ----------
    V_clean, F, sigma, tau, iterations : as :func:`denoising_experiment`
    seeds : sequence of at least 2 ints, one noise draw each
    **options : passed to :func:`denoising_experiment` (``method``, ``weights``, ...)

    Returns
    -------
    (E_mean, E_std) : floats, relative errors (fractions of the clean mesh's diagonal)
    """
    seeds = [whole_number(f"seeds[{i}]", s) for i, s in enumerate(seeds)]
    if len(seeds) < 2:
        raise MeshError(f"seeds: a spread needs at least 2 draws, got {len(seeds)}")
    E = [denoising_experiment(V_clean, F, sigma, tau, iterations, s, **options)[0] for s in seeds]
    return float(np.mean(E)), float(np.std(E, ddof=1))


def denoising_sweep(W, F, V_clean, taus, iterations):
    """The error of implicit smoothing of the noisy W after every iteration count, for every step.

    For each step ``tau`` of ``taus``: ``P_0 = W`` and ``(M - tau C) P_k = M P_{k-1}`` with the
    cotangent M and C of W (kept fixed, as :func:`implicit_smoothing` keeps them), factorised once
    per step; ``E[i, k] = vertex_rms(P_k, V_clean)`` after ``k`` steps of ``taus[i]``, k = 0 (the
    noisy mesh) to ``iterations``. One run per step covers every count.

    Parameters
    ----------
    W : (n, 3) float64, the noisy positions; F : (m, 3) int64, a closed mesh (no boundary)
    V_clean : (n, 3) float64, the truth (E is relative to its bounding-box diagonal)
    taus : sequence of float > 0, steps in length^2
    iterations : int >= 0

    Returns
    -------
    (tau, N, E): the step and the count of the smallest error, and E, (len(taus), iterations + 1).
    """
    W, F = as_mesh(W, F)
    if len(boundary_vertices(F, len(W))):
        raise MeshError("denoising_sweep takes a closed mesh: this one has a boundary (its vertices would move)")
    taus = [float(t) for t in taus]
    if not taus or not all(np.isfinite(t) and t > 0 for t in taus):
        raise MeshError(f"taus must be one or more finite steps > 0, got {taus}")
    iterations = whole_number("iterations", iterations, 0)
    M, C = assemble_laplacian(W, F)
    E = np.empty((len(taus), int(iterations) + 1))
    for i, tau in enumerate(taus):
        solve = factorise(M - tau * C).solve  # once per step, reused by every iteration
        P = W
        E[i, 0] = vertex_rms(P, V_clean)
        for k in range(1, int(iterations) + 1):
            P = implicit_step(P, M, C, tau, solve)
            E[i, k] = vertex_rms(P, V_clean)
    i, k = np.unravel_index(np.argmin(E), E.shape)
    return taus[i], int(k), E
