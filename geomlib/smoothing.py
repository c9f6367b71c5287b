"""Explicit and implicit Laplacian smoothing (diffusion / mean curvature flow).

Convention (the course's, as everywhere in geomlib): ``Delta = M^-1 C`` with
``C`` symmetric, negative semidefinite, rows summing to zero, and ``M``
diagonal (vertex areas in length^2 for ``weights="cotan"``, valences for
``weights="uniform"``); ``Delta x = -2 H n``, so a step along ``Delta x``
moves a vertex against its outward normal where the surface is convex.

* Explicit (forward Euler on dP/dt = Delta P):  ``P <- (I + step Delta) P``.
* Implicit (backward Euler):  ``(M - step C) P' = M P``, a sparse symmetric
  positive definite system (Desbrun, Meyer, Schroeder and Barr 1999).

Units of ``step``: for the cotangent operator ``Delta`` has units 1/length^2,
so ``step`` is a time of the heat flow in length^2 (scale a mesh by s and the
same smoothing needs s^2 times the step). For the uniform operator ``Delta``
is dimensionless and so is ``step``. A scale-free step is
``step / mean_edge_length^2`` (cotan) or a fraction of the explicit stability
limit (``step_fraction=``).

Stability of the explicit scheme. ``Delta`` is similar to the symmetric
``M^-1/2 C M^-1/2``, so its eigenvalues are real, ``-lambda_k`` with
``0 = lambda_0 <= ... <= lambda_max``. An eigenvector component of ``P`` is
multiplied by ``1 - step lambda_k`` at every iteration; it stays bounded iff
``|1 - step lambda_k| <= 1``, i.e. ``step <= 2 / lambda_k``. The binding mode
is the highest-frequency one, hence the limit ``step < 2 / lambda_max``
(:func:`explicit_step_limit`). For the uniform operator ``lambda_max <= 2``
(the eigenvalues of ``D^-1 A`` lie in [-1, 1]), so steps up to 1 are always
stable and step 1 is plain neighbour averaging.

Boundary (open meshes): ``boundary="fixed"`` (the default) keeps boundary
vertices where they are and smooths the interior with them as a Dirichlet
condition; ``boundary="free"`` moves them with the same operator (the
boundary curve then shrinks too). Vertices in no non-degenerate triangle
(isolated) have no Laplacian (``M_ii = 0``) and are always kept fixed.
"""

import hashlib
import numbers
import time
import warnings

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from .errors import MeshError, MeshWarning, format_indices
from .laplace import _as_mesh, laplacian

#: Explicit smoothing stops (see ``on_failure``) when a coordinate moves further
#: than this many bounding-box diagonals from the start: it has diverged.
BLOWUP_FACTOR = 1e6

#: Implicit smoothing with a rebuilt operator stops when the surface area falls
#: below this fraction of the initial area (the mesh has collapsed).
COLLAPSE_AREA_FRACTION = 1e-8

#: ``progress=None`` shows a progress bar when the run is estimated (from the
#: first iteration) to take longer than this many seconds.
PROGRESS_SECONDS = 1.0

_WEIGHTS = ("cotan", "uniform")
_BOUNDARY = ("fixed", "free")


# --------------------------------------------------------------------------
# argument checks

def _check_step(step, name="step"):
    if isinstance(step, (bool, np.bool_)) or not isinstance(step, numbers.Real):
        raise MeshError(f"{name} must be a real number, not {type(step).__name__} {step!r}")
    step = float(step)
    if not np.isfinite(step):
        raise MeshError(f"{name} must be finite, not {step!r}")
    if step < 0:
        raise MeshError(f"{name} must be >= 0 (a negative step runs the heat flow backwards "
                        f"and is unstable), not {step!r}")
    return step


def _check_iterations(iterations):
    if isinstance(iterations, (bool, np.bool_)) or not isinstance(iterations, numbers.Integral):
        raise MeshError(f"iterations must be a whole number, not {type(iterations).__name__} "
                        f"{iterations!r}")
    if iterations < 0:
        raise MeshError(f"iterations must be >= 0, not {iterations}")
    return int(iterations)


def _check_choice(value, name, choices):
    if value not in choices:
        raise MeshError(f"{name} must be one of {', '.join(repr(c) for c in choices)}, not {value!r}")
    return value


def _boundary_mask(F, n):
    """(n,) bool: vertices on an edge used by exactly one triangle."""
    E = np.sort(F[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    key = E[:, 0] * np.int64(n) + E[:, 1]
    uniq, count = np.unique(key, return_counts=True)
    once = uniq[count == 1]
    mask = np.zeros(n, dtype=bool)
    mask[once // n] = True
    mask[once % n] = True
    return mask


def _moving_mask(F, m, boundary):
    """Vertices that move: positive M entry, and not on the boundary if fixed."""
    moving = m > 0
    if boundary == "fixed":
        moving &= ~_boundary_mask(F, len(m))
    return moving


def _operator(V, F, weights, area):
    """(m, C): diagonal of M as an (n,) array and C as CSR."""
    M, C = laplacian(V, F, weights=weights, area=area)
    return np.asarray(M.diagonal(), dtype=np.float64), sp.csr_matrix(C)


def _diagonal(V):
    ext = V.max(axis=0) - V.min(axis=0) if len(V) else np.zeros(3)
    return float(np.linalg.norm(ext))


# --------------------------------------------------------------------------
# the stability limit

_LIMIT_CACHE = {}
_LIMIT_CACHE_SIZE = 16


def _key(V, F, *extra):
    h = hashlib.blake2b(digest_size=16)
    h.update(np.ascontiguousarray(V).view(np.uint8))
    h.update(np.ascontiguousarray(F).view(np.uint8))
    h.update(repr(extra).encode())
    return h.hexdigest()


def _lanczos_max(S, rtol=1e-8, maxiter=500):
    """Largest eigenvalue of a symmetric matrix by plain Lanczos.

    The largest Ritz value approaches lambda_max from below; the iteration stops
    when it changes by less than ``rtol`` (relative) over ten steps. Extreme Ritz
    values stay accurate without reorthogonalisation, and a cluster of
    near-equal top eigenvalues (the uniform Laplacian of a regular mesh) still
    gives lambda_max to within the cluster's width. A fixed start vector makes
    the result reproducible. (Elementwise sums instead of BLAS dot products:
    they are as fast at these sizes and do not compete for cores.)
    """
    from scipy.linalg import eigvalsh_tridiagonal

    n = S.shape[0]
    q = np.random.default_rng(0).standard_normal(n)
    q /= np.sqrt((q * q).sum())
    q_prev = np.zeros(n)
    beta = 0.0
    alphas, betas, history = [], [], []
    for k in range(min(maxiter, n)):
        w = S @ q - beta * q_prev
        a = float((q * w).sum())
        w -= a * q
        alphas.append(a)
        beta = float(np.sqrt((w * w).sum()))
        last = k == min(maxiter, n) - 1 or beta <= 1e-14 * abs(a)
        if k % 5 == 4 or last:
            theta = eigvalsh_tridiagonal(np.array(alphas), np.array(betas),
                                         select="i", select_range=(k, k))[0]
            history.append(theta)
            if last or (len(history) > 2 and history[-1] - history[-3] <= rtol * abs(theta)):
                return float(theta)
        betas.append(beta)
        q_prev, q = q, w / beta
    return float(history[-1])


def _moving_block(m, C, moving):
    """S = M^-1/2 (-C) M^-1/2 on the moving vertices: symmetric, spectrum of -Delta."""
    idx = np.flatnonzero(moving)
    s = 1.0 / np.sqrt(m[idx])
    S = (-C[idx][:, idx]).multiply(s[:, None]).multiply(s[None, :]).tocsr()
    return idx, s, S


def _top_eigenvalue(m, C, moving):
    idx, s, S = _moving_block(m, C, moving)
    if len(idx) == 0:
        return 0.0
    if len(idx) <= 600:
        return float(np.linalg.eigvalsh(S.toarray())[-1])
    return _lanczos_max(S)


def _top_mode(m, C, moving):
    """Largest lambda of -Delta restricted to the moving vertices, and its mode."""
    idx, s, S = _moving_block(m, C, moving)
    k = len(idx)
    if k == 0:
        return 0.0, np.zeros(len(m))
    if k <= 600:
        lam, vec = np.linalg.eigh(S.toarray())
        lam, y = lam[-1], vec[:, -1]
    else:
        v0 = np.random.default_rng(0).standard_normal(k)
        lam, vec = sla.eigsh(S, k=1, which="LA", v0=v0, tol=1e-8, ncv=min(k - 1, 40))
        lam, y = lam[0], vec[:, 0]
    e = np.zeros(len(m))
    e[idx] = s * y  # back to an eigenvector of Delta, M-normalised: e^T M e = 1
    if e[np.argmax(np.abs(e))] < 0:  # a reproducible sign
        e = -e
    return float(lam), e


def highest_frequency_mode(V, F, weights="cotan", area="barycentric", boundary="fixed"):
    """The highest-frequency eigenpair of the Laplacian: ``Delta e = -lambda_max e``.

    Convention: ``Delta = M^-1 C`` (C negative semidefinite), so
    ``lambda_max >= 0`` is the largest eigenvalue magnitude; in 1/length^2 for
    ``weights="cotan"``, dimensionless for ``"uniform"``. With
    ``boundary="fixed"`` the eigenproblem is that of the interior vertices
    (boundary values held at zero), which is the operator the explicit scheme
    iterates.

    Returns
    -------
    lam_max : float
    e : (n,) float64
        The mode, ``e^T M e = 1``, zero on fixed (boundary or isolated) vertices.
        Explicit smoothing multiplies the component ``e^T M P`` by
        ``1 - step lam_max`` at every iteration.
    """
    V, F = _as_mesh(V, F)
    _check_choice(weights, "weights", _WEIGHTS)
    _check_choice(boundary, "boundary", _BOUNDARY)
    m, C = _operator(V, F, weights, area)
    return _top_mode(m, C, _moving_mask(F, m, boundary))


def explicit_step_limit(V, F, weights="cotan", area="barycentric", boundary="fixed"):
    """Largest stable step of explicit smoothing: ``2 / lambda_max``.

    Convention: ``Delta = M^-1 C``, eigenvalues ``-lambda_k <= 0``; one explicit
    step multiplies mode k by ``1 - step lambda_k``, so the scheme is stable iff
    ``step <= 2 / lambda_max`` (module docstring). Strictly below the limit the
    highest-frequency component decays, strictly above it grows by the factor
    ``|1 - step lambda_max| > 1`` per iteration.

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64
    weights : "cotan" or "uniform"
    area : "barycentric" or "mixed" (cotan vertex areas; see :func:`geomlib.laplacian`)
    boundary : "fixed" or "free"
        With fixed boundary vertices only the interior block of Delta matters
        (its limit is at least that of the free problem, by eigenvalue interlacing).

    Returns
    -------
    float
        The limit in length^2 (cotan) or dimensionless (uniform); ``inf`` when
        no vertex can move. Cached per mesh and options, so repeated calls are cheap.

    Notes
    -----
    lambda_max comes from a dense eigensolver up to 600 moving vertices and
    from Lanczos iterations above (relative accuracy about 1e-8, or the width
    of a cluster of top eigenvalues; from below, so the limit is never
    underestimated by more than that); the mesh
    scales it as 1/length^2, so the limit of the cotan operator scales as
    length^2, while the uniform limit lies between 1 and about 1.5 on any
    triangle mesh.
    """
    V, F = _as_mesh(V, F)
    _check_choice(weights, "weights", _WEIGHTS)
    _check_choice(boundary, "boundary", _BOUNDARY)
    key = _key(V, F, weights, area, boundary)
    if key in _LIMIT_CACHE:
        return _LIMIT_CACHE[key]
    m, C = _operator(V, F, weights, area)
    lam = _top_eigenvalue(m, C, _moving_mask(F, m, boundary))
    limit = 2.0 / lam if lam > 0 else float("inf")
    if len(_LIMIT_CACHE) >= _LIMIT_CACHE_SIZE:
        _LIMIT_CACHE.pop(next(iter(_LIMIT_CACHE)))
    _LIMIT_CACHE[key] = limit
    return limit


# --------------------------------------------------------------------------
# progress bars and failure handling

class _Progress:
    """Times the first iteration, then shows a tqdm bar if the run looks long."""

    def __init__(self, iterations, progress, desc):
        self.iterations, self.progress, self.desc = iterations, progress, desc
        self.bar = None
        self.start = time.perf_counter()
        if progress is True and iterations > 0:
            self._open(0)

    def _open(self, done):
        from tqdm.auto import tqdm
        self.bar = tqdm(total=self.iterations, initial=done, desc=self.desc, leave=False)

    def step(self, k):
        """Call after iteration k (1-based) has finished."""
        if self.bar is not None:
            self.bar.update(1)
        elif self.progress is None and k == 1 and self.iterations > 1:
            estimate = (time.perf_counter() - self.start) * self.iterations
            if estimate > PROGRESS_SECONDS:
                self._open(1)

    def close(self):
        if self.bar is not None:
            self.bar.close()


def _fail(on_failure, message, k, P_last):
    """Raise MeshError or warn and return the last valid positions."""
    if on_failure == "raise":
        err = MeshError(message + "; the last valid positions are in the error's .V")
        err.V, err.iteration = P_last, k - 1
        raise err
    warnings.warn(message + f"; stopped and returned the positions after iteration {k - 1}",
                  MeshWarning, stacklevel=3)
    return P_last


# --------------------------------------------------------------------------
# explicit smoothing

def explicit_smoothing(V, F, step=None, iterations=1, weights="cotan", *, step_fraction=None,
                       area="barycentric", boundary="fixed", progress=None, callback=None,
                       on_failure="raise"):
    """Explicit Laplacian smoothing, ``P <- (I + step Delta) P``, repeated.

    Convention: ``Delta = M^-1 C`` (C negative semidefinite, ``Delta x = -2 H n``),
    built once from the input positions and kept fixed. Forward Euler on the
    heat flow ``dP/dt = Delta P``: stable only for ``step < 2 / lambda_max``
    (:func:`explicit_step_limit`).

    Parameters
    ----------
    V : (n, 3) float64
        Vertex positions (not modified).
    F : (m, 3) int64
        Triangles.
    step : float >= 0, optional
        Time step: length^2 for ``weights="cotan"`` (scale the mesh by s, use
        s^2 times the step), dimensionless for ``"uniform"``. Give either
        ``step`` or ``step_fraction``.
    iterations : int >= 0
    weights : "cotan" or "uniform"
    step_fraction : float >= 0, optional
        The step as a fraction of the computed stability limit (scale-free):
        ``step = step_fraction * explicit_step_limit(...)``; below 1 is stable.
    area : "barycentric" or "mixed"
        Vertex areas of the cotan operator.
    boundary : "fixed" (default) or "free"
        Fixed boundary vertices stay put; free ones move with the operator.
    progress : None, True or False
        Progress bar (tqdm.auto): None shows one when the run is estimated to
        take more than ``PROGRESS_SECONDS`` from its first iteration.
    callback : callable(k, P), optional
        Called after every iteration k = 1..iterations with the (n, 3) positions
        (do not modify them), e.g. to record the growth of a mode.
    on_failure : "raise" or "stop"
        When the scheme diverges (a coordinate leaves ``BLOWUP_FACTOR`` bounding-box
        diagonals or becomes non-finite): raise MeshError (with ``.V``, the last
        valid positions, and ``.iteration``) or warn (MeshWarning) and return them.

    Returns
    -------
    (n, 3) float64 ndarray
        The smoothed positions.

    Raises
    ------
    MeshError
        Negative, NaN or non-numeric step or step_fraction, both or neither
        given, negative or non-integer iterations, unknown option, divergence
        with ``on_failure="raise"``.

    Warns
    -----
    MeshWarning
        Once per call when the step exceeds the stability limit (the limit is
        named): the run goes on, and the highest-frequency component grows.

    References: Taubin 1995; Desbrun, Meyer, Schroeder and Barr 1999.
    """
    V, F = _as_mesh(V, F)
    iterations = _check_iterations(iterations)
    _check_choice(weights, "weights", _WEIGHTS)
    _check_choice(boundary, "boundary", _BOUNDARY)
    _check_choice(on_failure, "on_failure", ("raise", "stop"))
    if (step is None) == (step_fraction is None):
        raise MeshError("give exactly one of step and step_fraction")
    if step_fraction is not None:
        step_fraction = _check_step(step_fraction, "step_fraction")
        limit = explicit_step_limit(V, F, weights, area, boundary)
        step = step_fraction * limit if np.isfinite(limit) else 0.0
    else:
        step = _check_step(step)

    m, C = _operator(V, F, weights, area)
    moving = _moving_mask(F, m, boundary)
    scale = np.zeros(len(m))
    scale[moving] = step / m[moving]
    # Gershgorin: lambda_max <= max 2 |C_ii| / M_ii, so steps below 2 / that bound
    # are certainly stable and need no eigenvalue computation.
    if moving.any() and step > 0:
        bound = float(np.max(2.0 * np.abs(C.diagonal()[moving]) / m[moving]))
        if step * bound > 2.0:
            limit = explicit_step_limit(V, F, weights, area, boundary)
            if step > limit * (1 + 1e-12):
                warnings.warn(
                    f"explicit step {step:.6g} exceeds the stability limit {limit:.6g} "
                    f"(= 2 / lambda_max, {weights} weights, boundary {boundary}): "
                    f"the highest-frequency component grows by {abs(1 - 2 * step / limit):.4g} "
                    f"per iteration", MeshWarning, stacklevel=2)

    P = V.copy()
    if iterations == 0 or step == 0:
        if callback is not None:
            for k in range(1, iterations + 1):
                callback(k, P)
        return P
    A = sp.diags(scale) @ C  # step M^-1 C on the moving rows, zero rows elsewhere
    origin = V.mean(axis=0)
    limit_abs = BLOWUP_FACTOR * max(_diagonal(V), np.finfo(float).tiny)
    bar = _Progress(iterations, progress, "explicit smoothing")
    try:
        for k in range(1, iterations + 1):
            Q = P + A @ P
            if not np.isfinite(Q).all() or np.abs(Q - origin).max() > limit_abs:
                return _fail(on_failure,
                             f"explicit smoothing diverged at iteration {k} (step {step:.6g}): "
                             f"coordinates left {BLOWUP_FACTOR:g} bounding-box diagonals", k, P)
            P = Q
            if callback is not None:
                callback(k, P)
            bar.step(k)
    finally:
        bar.close()
    return P


# --------------------------------------------------------------------------
# implicit smoothing

def _volume_centroid(P, F):
    """Signed enclosed volume and the centroid of the enclosed solid."""
    a, b, c = P[F[:, 0]], P[F[:, 1]], P[F[:, 2]]
    v = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0  # signed tetrahedra with the origin
    vol = float(v.sum())
    if vol == 0 or not np.isfinite(vol):
        return vol, P.mean(axis=0)
    centroid = (v[:, None] * (a + b + c)).sum(axis=0) / (4.0 * vol)
    return vol, centroid


def _area(P, F):
    a = P[F[:, 0]]
    return 0.5 * float(np.linalg.norm(np.cross(P[F[:, 1]] - a, P[F[:, 2]] - a), axis=1).sum())


#: Above this many unknowns the implicit system is ordered by geometric nested
#: dissection before the LU factorisation (below it SuperLU's own COLAMD is as good).
NESTED_DISSECTION_MIN = 4000


def _nested_dissection(X, A, leaf=32):
    """Fill-reducing ordering of a mesh matrix by geometric nested dissection.

    Every part of more than ``leaf`` vertices is split at the median of its
    longest bounding-box axis; the vertices of the lower half with a neighbour
    (a nonzero of A) in the upper half form the separator, ordered after both
    halves. On a surface mesh separators have O(sqrt(n)) vertices, so the
    factors of ``M - step C`` fill in far less than with a column ordering
    (about half the nonzeros and a third of the factorisation time of
    SuperLU's COLAMD at 160k vertices). Vectorised one tree level at a time.

    Returns the permutation ``p`` (new position -> vertex), i.e. use ``A[p][:, p]``.
    """
    n = len(X)
    T = sp.triu(A, 1).tocoo()
    ei, ej = T.row.astype(np.int64), T.col.astype(np.int64)
    label = np.zeros(n, np.int64)   # the part a vertex is in (binary path)
    key = np.zeros(n, np.int64)     # base-3 digits: 0 lower half, 1 upper half, 2 separator
    active = np.ones(n, bool)
    for _ in range(38):  # 3**38 < 2**63
        key *= 3
        idx = np.flatnonzero(active)
        if len(idx) == 0:
            break
        _, inv, counts = np.unique(label[idx], return_inverse=True, return_counts=True)
        big = counts[inv] > leaf
        active[idx[~big]] = False
        idx = idx[big]
        if len(idx) == 0:
            break
        _, inv, counts = np.unique(inv[big], return_inverse=True, return_counts=True)
        P = X[idx]
        starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
        by_part = np.argsort(inv, kind="stable")
        lo = np.minimum.reduceat(P[by_part], starts, axis=0)
        hi = np.maximum.reduceat(P[by_part], starts, axis=0)
        axis = np.argmax(hi - lo, axis=1)[inv]
        coord = P[np.arange(len(idx)), axis]
        order = np.lexsort((coord, inv))
        rank = np.empty(len(idx), np.int64)
        rank[order] = np.arange(len(idx)) - starts[inv[order]]
        upper = (rank >= counts[inv] // 2).astype(np.int64)
        side = np.full(n, -1, np.int64)
        side[idx] = upper
        part = np.full(n, -1, np.int64)
        part[idx] = inv
        cross = (part[ei] >= 0) & (part[ei] == part[ej]) & (side[ei] != side[ej])
        a, b = ei[cross], ej[cross]
        separator = np.unique(np.where(side[a] == 0, a, b))
        key[idx] += upper
        label[idx] = label[idx] * 2 + upper
        key[separator] += 2
        active[separator] = False
    return np.argsort(key, kind="stable")


class _SPDFactor:
    """Sparse LU of a symmetric positive definite matrix, in a given symmetric order.

    With an ordering ``perm`` SuperLU is told to keep it (natural column order,
    symmetric mode, diagonal pivots: an SPD matrix needs no pivoting), so the
    factor is the Cholesky-like one of ``A[perm][:, perm]``.
    """

    def __init__(self, A, perm=None):
        self.perm = perm
        if perm is None:
            self.lu = sla.splu(A.tocsc())
        else:
            Ap = A.tocsr()[perm][:, perm].tocsc()
            self.lu = sla.splu(Ap, permc_spec="NATURAL", diag_pivot_thresh=0.0,
                               options=dict(SymmetricMode=True))

    def solve(self, B):
        if self.perm is None:
            return self.lu.solve(B)
        X = np.empty_like(B)
        X[self.perm] = self.lu.solve(np.ascontiguousarray(B[self.perm]))
        return X


class ImplicitSmoother:
    """Implicit smoothing with a fixed operator, factorisations cached per step.

    Convention: ``(M - step C) P' = M P`` with M, C of :func:`geomlib.laplacian`
    built once from the positions given here (C negative semidefinite, so the
    matrix is symmetric positive definite for every step >= 0). With fixed
    boundary vertices only the interior block is solved,
    ``(M_II - step C_II) P'_I = M_I P_I + step C_IB P_B``.

    Meant for sliders: build it once outside the callback; every new step value
    costs one sparse LU factorisation (scipy ``splu``, in a nested-dissection
    order computed once), cached (the last ``cache_size`` step values), and
    every iteration one pair of triangular solves. :meth:`smooth` also keeps
    the iterates of the last ``history_size`` (step, keep_volume) settings, so
    moving an iteration slider costs only the iterations not yet computed and
    returning to a setting seen before costs nothing.

    Parameters
    ----------
    V, F, weights, area, boundary : as in :func:`implicit_smoothing`.
    cache_size : int
        How many factorisations to keep.
    history_size : int
        For how many settings to keep the iterates (0: none).
    """

    def __init__(self, V, F, weights="cotan", area="barycentric", boundary="fixed", cache_size=16,
                 history_size=4):
        V, F = _as_mesh(V, F)
        _check_choice(weights, "weights", _WEIGHTS)
        _check_choice(boundary, "boundary", _BOUNDARY)
        self.V, self.F = V, F
        self.weights, self.area, self.boundary = weights, area, boundary
        self.m, C = _operator(V, F, weights, area)
        self.moving = _moving_mask(F, self.m, boundary)
        self.I = np.flatnonzero(self.moving)
        B = np.flatnonzero(~self.moving)
        C = C.tocsr()
        self.C_II = C[self.I][:, self.I].tocsc()
        self.CP_B = C[self.I][:, B] @ V[B]  # C_IB P_B, constant while P_B stays fixed
        self.cache_size = int(cache_size)
        self.history_size = int(history_size)
        self._lu = {}
        self._history = {}
        self._perm = None

    @property
    def perm(self):
        """The fill-reducing order of the unknowns (None for small systems)."""
        if self._perm is None and len(self.I) > NESTED_DISSECTION_MIN:
            self._perm = _nested_dissection(self.V[self.I], self.C_II)
        return self._perm

    def factor(self, step):
        """The LU factorisation of ``M_II - step C_II`` (cached)."""
        step = _check_step(step)
        if step in self._lu:
            lu = self._lu.pop(step)
        else:
            A = (sp.diags(self.m[self.I]) - step * self.C_II).tocsc()
            try:
                lu = _SPDFactor(A, self.perm)
            except RuntimeError as exc:  # "Factor is exactly singular"
                raise MeshError(f"implicit smoothing: the system M - {step:.6g} C is singular "
                                f"({exc})") from None
            while len(self._lu) >= self.cache_size:
                self._lu.pop(next(iter(self._lu)))
        self._lu[step] = lu  # most recently used last
        return lu

    def prepare(self, steps, iterations=0, keep_volume=False):
        """Factorise for every step value in ``steps`` now (e.g. all positions of a
        slider), and with ``iterations > 0`` also compute and keep that many
        iterates for each, so that a slider callback only looks them up (or
        solves for iterations beyond them). Grows both caches to hold them all."""
        steps = [_check_step(s) for s in steps]
        iterations = _check_iterations(iterations)
        self.cache_size = max(self.cache_size, len(steps))
        if iterations:
            self.history_size = max(self.history_size, len(steps))
        for s in steps:
            self.factor(s)
            if iterations:
                self.smooth(s, iterations, keep_volume=keep_volume, progress=False)
        return self

    def step_once(self, P, step, lu=None):
        """One implicit step from positions P (boundary rows taken from self.V)."""
        lu = self.factor(step) if lu is None else lu
        Q = self.V.copy()
        rhs = self.m[self.I, None] * P[self.I] + step * self.CP_B
        Q[self.I] = lu.solve(rhs)
        return Q

    def smooth(self, step, iterations=1, keep_volume=False, progress=None, callback=None,
               P=None):
        """Run ``iterations`` implicit steps from P (default: the positions given).

        Returns a new (n, 3) array. Without P and callback the iterates are kept
        (``history_size``) and a later call continues from the last one stored.
        """
        step = _check_step(step)
        iterations = _check_iterations(iterations)
        remember = P is None and callback is None and self.history_size > 0
        P = self.V.copy() if P is None else np.array(P, dtype=np.float64)
        if iterations == 0:
            return P
        keeper = _VolumeKeeper(P, self.F) if keep_volume else None
        start = 0
        if remember:
            key = (step, bool(keep_volume))
            history = self._history.pop(key, [])
            self._history[key] = history  # most recently used last
            while len(self._history) > self.history_size:
                self._history.pop(next(iter(self._history)))
            if len(history) >= iterations:
                return history[iterations - 1].copy()
            if history:
                start, P = len(history), history[-1]
        lu = self.factor(step)
        bar = _Progress(iterations - start, progress, "implicit smoothing")
        try:
            for k in range(start + 1, iterations + 1):
                P = self.step_once(P, step, lu)
                if keeper is not None:
                    try:
                        P = keeper(P, k)
                    except _Collapse as exc:
                        raise MeshError(f"implicit smoothing stopped: {exc}") from None
                if remember:
                    history.append(P)
                if callback is not None:
                    callback(k, P)
                bar.step(k - start)
        finally:
            bar.close()
        return P.copy() if remember else P


class _VolumeKeeper:
    """Rescale about the centroid so that volume and centroid stay those of the start
    (Desbrun et al. 1999, section 5.3)."""

    def __init__(self, P, F):
        b = _boundary_mask(F, len(P))
        if b.any():
            raise MeshError("keep_volume needs a closed mesh (the enclosed volume of an open "
                            f"mesh is undefined); boundary vertices: "
                            f"{format_indices(np.flatnonzero(b))}")
        self.F = F
        self.vol0, self.c0 = _volume_centroid(P, F)
        if not self.vol0 > 0:
            raise MeshError(f"keep_volume: the enclosed volume is {self.vol0:.6g}, not positive "
                            "(faces must be counter-clockwise seen from outside)")

    def __call__(self, P, k):
        vol, c = _volume_centroid(P, self.F)
        if not (vol > 0 and np.isfinite(vol)):
            raise _Collapse(f"the enclosed volume became {vol:.6g} at iteration {k}")
        return self.c0 + (P - c) * (self.vol0 / vol) ** (1.0 / 3.0)


class _Collapse(Exception):
    pass


def implicit_smoothing(V, F, step, iterations=1, weights="cotan", *, area="barycentric",
                       boundary="fixed", rebuild=False, keep_volume=False, solver="lu",
                       progress=None, callback=None, on_failure="raise"):
    """Implicit Laplacian smoothing, ``(M - step C) P' = M P``, repeated.

    Convention: M, C of :func:`geomlib.laplacian` (``Delta = M^-1 C``, C symmetric
    negative semidefinite), so ``M - step C`` is symmetric positive definite for
    every ``step >= 0``: backward Euler on ``dP/dt = Delta P`` is stable for any
    step (Desbrun, Meyer, Schroeder and Barr 1999).

    Parameters
    ----------
    V : (n, 3) float64
        Vertex positions (not modified).
    F : (m, 3) int64
        Triangles.
    step : float >= 0
        Time step: length^2 for ``weights="cotan"``, dimensionless for
        ``"uniform"``. Scale-free: ``step / mean_edge_length**2``.
    iterations : int >= 0
    weights : "cotan" or "uniform"
    area : "barycentric" or "mixed"
    boundary : "fixed" (default) or "free"
        Fixed: boundary vertices keep their positions and the interior block
        ``(M_II - step C_II) P'_I = M_I P_I + step C_IB P_B`` is solved.
    rebuild : bool
        False (default): the operator of the input mesh is kept, the matrix
        factorised once and the factorisation reused for every iteration.
        True: M and C are rebuilt from the current positions every iteration
        (implicit mean curvature flow, Desbrun et al. 1999); it can fail: as the
        surface shrinks triangles degenerate and the mesh collapses. Then the run
        stops (see ``on_failure``) instead of returning a NaN mesh.
    keep_volume : bool
        After every iteration rescale about the centroid of the enclosed solid
        so that the enclosed volume and that centroid stay those of the input
        (Desbrun et al. 1999, section 5.3). Closed meshes only.
    solver : "lu" or "cg"
        For the fixed operator. "lu": sparse LU (scipy ``splu``), exact to
        rounding; the rebuilt operator always uses it. "cg": conjugate
        gradients with a Jacobi preconditioner, warm-started from the current
        positions, relative residual 1e-10 (fast on well-shaped meshes and
        small steps, slower on stretched triangles and huge steps).
    progress : None, True or False
        Progress bar (tqdm.auto); None shows one when the first iteration
        predicts more than ``PROGRESS_SECONDS``.
    callback : callable(k, P), optional
        Called after every iteration with the (n, 3) positions.
    on_failure : "raise" or "stop"
        What happens when ``rebuild=True`` (or ``keep_volume``) meets a
        degenerate triangle, a collapsed surface (area below
        ``COLLAPSE_AREA_FRACTION`` of the start), a singular matrix or a
        non-finite result: raise MeshError (with ``.V``, the last valid
        positions, and ``.iteration``) or warn (MeshWarning) and return them.

    Returns
    -------
    (n, 3) float64 ndarray

    Raises
    ------
    MeshError
        Negative, NaN or non-numeric step; negative or non-integer iterations;
        unknown option; keep_volume on an open mesh; a failure (above) with
        ``on_failure="raise"``.
    """
    V, F = _as_mesh(V, F)
    step = _check_step(step)
    iterations = _check_iterations(iterations)
    _check_choice(weights, "weights", _WEIGHTS)
    _check_choice(boundary, "boundary", _BOUNDARY)
    _check_choice(solver, "solver", ("lu", "cg"))
    _check_choice(on_failure, "on_failure", ("raise", "stop"))
    keeper = _VolumeKeeper(V, F) if keep_volume else None
    if iterations == 0 or step == 0:
        return V.copy()

    if not rebuild and solver == "lu":
        smoother = ImplicitSmoother(V, F, weights, area, boundary, cache_size=1, history_size=0)
        lu = smoother.factor(step)
        advance = lambda P: smoother.step_once(P, step, lu)  # noqa: E731
    elif not rebuild:
        advance = _CGSystem(V, F, weights, area, boundary, step).step_once
    else:
        advance = _RebuiltStep(V, F, weights, area, boundary, step)

    P = V.copy()
    area0 = _area(V, F)
    bar = _Progress(iterations, progress, "implicit smoothing")
    try:
        for k in range(1, iterations + 1):
            try:
                Q = advance(P)
                if keeper is not None:
                    Q = keeper(Q, k)
            except _Collapse as exc:
                return _fail(on_failure, f"implicit smoothing stopped: {exc}", k, P)
            if not np.isfinite(Q).all():
                return _fail(on_failure, f"implicit smoothing stopped: non-finite positions "
                             f"at iteration {k}", k, P)
            if rebuild and _area(Q, F) < COLLAPSE_AREA_FRACTION * area0:
                return _fail(on_failure, f"implicit smoothing stopped: the mesh collapsed "
                             f"(area below {COLLAPSE_AREA_FRACTION:g} of the start) at "
                             f"iteration {k}", k, P)
            P = Q
            if callback is not None:
                callback(k, P)
            bar.step(k)
    finally:
        bar.close()
    return P


class _CGSystem:
    """Fixed-operator implicit step solved by warm-started Jacobi-preconditioned CG."""

    RTOL = 1e-10

    def __init__(self, V, F, weights, area, boundary, step):
        s = ImplicitSmoother(V, F, weights, area, boundary)
        self.s, self.step = s, step
        self.A = (sp.diags(s.m[s.I]) - step * s.C_II).tocsr()
        d = self.A.diagonal()
        self.P_jacobi = sp.diags(1.0 / d)

    def step_once(self, P):
        s = self.s
        rhs = s.m[s.I, None] * P[s.I] + self.step * s.CP_B
        Q = s.V.copy()
        for j in range(P.shape[1]):
            x, info = sla.cg(self.A, rhs[:, j], x0=P[s.I, j], rtol=self.RTOL, atol=0.0,
                             M=self.P_jacobi, maxiter=20 * len(s.I) + 100)
            if info != 0:
                raise MeshError(f"implicit smoothing: CG did not converge (info {info}); "
                                "use solver='lu'")
            Q[s.I, j] = x
        return Q


class _RebuiltStep:
    """One implicit step with M and C rebuilt from the current positions."""

    def __init__(self, V, F, weights, area, boundary, step):
        self.V0, self.F = V, F
        self.weights, self.area, self.boundary, self.step = weights, area, boundary, step
        self.k = 0
        self.perm, self.I = None, None

    def __call__(self, P):
        self.k += 1
        with warnings.catch_warnings():
            warnings.simplefilter("error", MeshWarning)
            try:
                m, C = _operator(P, self.F, self.weights, self.area)
            except MeshWarning as w:  # degenerate (zero-area) triangles
                raise _Collapse(f"at iteration {self.k} {w}") from None
        moving = _moving_mask(self.F, m, self.boundary)
        I, B = np.flatnonzero(moving), np.flatnonzero(~moving)
        C = C.tocsr()
        C_II = C[I][:, I]
        A = (sp.diags(m[I]) - self.step * C_II).tocsc()
        rhs = m[I, None] * P[I] + self.step * (C[I][:, B] @ P[B])
        if len(I) > NESTED_DISSECTION_MIN and (self.I is None or not np.array_equal(I, self.I)):
            # the sparsity pattern does not change with the positions: order once
            self.I, self.perm = I, _nested_dissection(P[I], C_II)
        Q = P.copy()
        try:
            Q[I] = _SPDFactor(A, self.perm if len(I) > NESTED_DISSECTION_MIN else None).solve(rhs)
        except RuntimeError as exc:
            raise _Collapse(f"the matrix M - step C became singular at iteration {self.k} "
                            f"({exc})") from None
        return Q


def explicit_step(P, M, C, tau):
    """One explicit step P + tau M^-1 C P for (n, 3) positions P."""
    return P + tau * (C @ P) / M.diagonal()[:, None]


def implicit_step(P, M, C, tau):
    """One implicit step: solve (M - tau C) P' = M P for the (n, 3) positions P'."""
    return sla.spsolve((M - tau * C).tocsc(), M @ P)
