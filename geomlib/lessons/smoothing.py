"""Explicit and implicit Laplacian smoothing: the heat flow dP/dt = Delta P (notebooks 05 and 06).

Convention (the course's, as everywhere in geomlib): ``Delta = M^-1 C`` with
``C`` symmetric, negative semidefinite, rows summing to zero, and ``M``
diagonal (vertex areas in length^2 for ``weights="cotan"``, valences for
``weights="uniform"``); ``Delta x = -2 H n``, so a step along ``Delta x``
moves a vertex against its outward normal where the surface is convex.

* Explicit (forward Euler):  ``P' = P + tau M^-1 C P`` (:func:`explicit_step`).
* Implicit (backward Euler):  ``(M - tau C) P' = M P`` (:func:`implicit_step`),
  a sparse symmetric positive definite system (Desbrun, Meyer, Schroeder and
  Barr 1999), solved by a Cholesky factorisation (:mod:`geomlib.numerics.factor`).
* Taubin's filter (Taubin 1995): pairs of explicit steps, a shrinking ``tau_shrink > 0``
  then an inflating ``tau_inflate < 0`` (:func:`taubin_smoothing`).

Every engine here (:func:`explicit_smoothing`, :func:`implicit_smoothing`,
:class:`ExplicitSmoother`, :class:`ImplicitSmoother`, :func:`taubin_smoothing`, and through
them the sweeps of notebook 07) advances by calling these two functions, with the operator of
:func:`geomlib.lessons.operator.laplace_operator` built once per mesh and options.

Units of the step ``tau``: for the cotangent operator ``Delta`` has units
1/length^2, so ``tau`` is a time of the heat flow in length^2 (scale a mesh by s
and the same smoothing needs s^2 times the step); for the uniform operator it is
dimensionless. Scale-free: ``tau / ell^2`` with ``ell`` the mean edge length, or
the fraction of the explicit stability limit (``step_fraction=``).

Stability of the explicit scheme: an eigenvector component of P (``Delta e =
-lam e``) is multiplied by ``1 - tau lam`` at every step; it stays bounded iff
``tau <= 2 / lam``, so the binding mode is the highest-frequency one and the
limit is ``2 / lam_max`` (:func:`explicit_step_limit`). For the uniform
operator ``lam_max <= 2``, so steps up to 1 are always stable.

Boundary condition (open meshes): ``boundary_condition="fixed"`` (the default)
keeps boundary vertices where they are (a Dirichlet condition: their rows of the
step are replaced by ``P'_B = P_B``); ``"free"`` moves them with the same
operator. A vertex with zero vertex area (used by no face, or only by zero-area
faces) has no Laplacian: every function raises MeshError naming it and the call
that removes it.
"""

import warnings

import numpy as np

from ..mesh.errors import MeshError, MeshWarning, format_indices
from ..mesh.geometry import bounding_box_diagonal, surface_area, volume_and_centroid
from ..mesh.topology import boundary_vertices
from ..mesh.validate import as_mesh, check_choice, real_number, whole_number
from ..numerics.factor import factorise
from ..numerics.progress import Iterations
from .laplace import check_options
from .operator import BOUNDARY_CONDITIONS, SOLVERS, LaplaceOperator, kept_operator, laplace_operator
from .requirements import positive_vertex_areas

__all__ = [
    "explicit_step",
    "implicit_step",
    "explicit_smoothing",
    "implicit_smoothing",
    "explicit_step_limit",
    "highest_frequency_mode",
    "fixed_point",
    "volume_rescaled",
    "ExplicitSmoother",
    "ImplicitSmoother",
    "taubin_smoothing",
]

#: Explicit smoothing stops (see ``on_failure``) when a coordinate moves further
#: than this many bounding-box diagonals from the start: it has diverged.
BLOWUP_FACTOR = 1e6

#: Implicit smoothing with a rebuilt operator stops when the surface area falls
#: below this fraction of the initial area (the mesh has collapsed).
COLLAPSE_AREA_FRACTION = 1e-8

ON_FAILURE = ("raise", "stop")


# --------------------------------------------------------------------------
# the formulas


def explicit_step(P, M, C, tau):
    """One explicit (forward Euler) step of the heat flow: ``P' = P + tau M^-1 C P``.

    P (n, 3) or (n,) positions, M (n, n) diagonal, C (n, n) symmetric NSD
    (:func:`geomlib.laplacian`), tau the step (length^2 for cotan weights).
    Stable for ``tau < 2 / lam_max`` (:func:`explicit_step_limit`).
    """
    m = positive_vertex_areas(M, None, "explicit_step")  # the diagonal of M, checked
    return P + tau * ((C @ P).T / m).T  # M^-1 (C P): row i of C P divided by m_i


def implicit_step(P, M, C, tau, solve=None):
    """One implicit (backward Euler) step: solve ``(M - tau C) P' = M P`` for P' (n, 3).

    ``M - tau C`` is symmetric positive definite for every ``tau >= 0``, so
    the step is stable for any tau (Desbrun et al. 1999); it is solved by a
    sparse Cholesky factorisation, or by ``solve(R)``, a solver of the same
    system prepared once for many steps.
    """
    positive_vertex_areas(M, None, "implicit_step")
    if solve is None:
        solve = factorise(M - tau * C).solve
    return solve(M @ P)


def explicit_step_limit(V, F, weights="cotan", area="barycentric", boundary_condition="fixed"):
    """Largest stable step of explicit smoothing: ``2 / lam_max``.

    One explicit step multiplies the mode ``Delta e = -lam e`` by ``1 - tau lam``,
    so the scheme is stable iff ``tau <= 2 / lam_max`` (module docstring);
    strictly above, the top mode grows by ``|1 - tau lam_max|`` per step.

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64
    weights : "cotan" or "uniform"
    area : "barycentric" or "mixed" (cotan vertex areas; see :func:`geomlib.laplacian`)
    boundary_condition : "fixed" or "free"
        With fixed boundary vertices only the interior block of Delta matters
        (its limit is at least that of the free problem, by eigenvalue interlacing).

    Returns
    -------
    float
        In length^2 (cotan) or dimensionless (uniform); ``inf`` when no vertex
        can move. ``lam_max`` is the largest eigenvalue of
        ``S = -M^-1/2 C M^-1/2`` on the moving vertices (the spectrum of
        ``-Delta``), by :func:`geomlib.numerics.eigen.largest_eigenvalue` (relative
        accuracy about 1e-8, from below, so the limit is never underestimated).
        Kept with the mesh's operator, so a slider calls it for free.
    """
    L = laplace_operator(V, F, weights, area, boundary_condition)
    L.require_positive_areas(F, "explicit_step_limit")
    return 2.0 / L.lam_max if L.lam_max > 0 else float("inf")


def highest_frequency_mode(V, F, weights="cotan", area="barycentric", boundary_condition="fixed"):
    """The highest-frequency eigenpair of the Laplacian: ``Delta e = -lam_max e``.

    ``lam_max >= 0`` in 1/length^2 for ``weights="cotan"``, dimensionless for
    ``"uniform"``. With ``boundary_condition="fixed"`` it is the eigenproblem of the
    interior vertices (boundary values held at zero), the operator the explicit
    scheme iterates. Solved in the symmetric form ``S y = lam y``,
    ``S = -M^-1/2 C M^-1/2`` on the moving vertices, ``e = M^-1/2 y``
    (:func:`geomlib.numerics.eigen.largest_eigenpair`, ARPACK, relative accuracy 1e-8).

    Returns
    -------
    lam_max : float
    e : (n,) float64
        The mode, ``e^T M e = 1``, zero on fixed vertices, its entry of largest
        magnitude positive. Explicit smoothing multiplies the component
        ``e^T M P`` by ``1 - tau lam_max`` at every step.
    """
    L = laplace_operator(V, F, weights, area, boundary_condition)
    L.require_positive_areas(F, "highest_frequency_mode")
    lam_max, y = L.top_mode
    e = np.zeros(len(L.m))
    e[L.I] = y / np.sqrt(L.m[L.I])  # e = M^-1/2 y, e^T M e = 1
    if len(L.I) and e[np.argmax(np.abs(e))] < 0:
        e = -e
    return lam_max, e


def fixed_point(V, F, weights="cotan", area="barycentric"):
    """``P*``, where smoothing with the operator fixed and the boundary fixed ends up: ``C P* = 0`` off the boundary.

    Closed mesh: every vertex at the area-weighted centroid ``sum_i m_i v_i / sum_i m_i``
    (the constant mode, the only one with ``lambda = 0``). Open mesh: the boundary
    vertices stay at V and the interior solves ``C_II P*_I = -C_IB V_B``, the
    membrane spanned by the boundary (harmonic coordinates; for cotan weights a flat
    mesh is its own membrane, by linear precision). Every other mode of
    ``P - P*`` decays under both schemes of notebooks 05 and 06.

    Returns
    -------
    P_star : (n, 3) float64, length units.
    """
    check_options(weights, area)
    V, F = as_mesh(V, F)
    L = kept_operator(V, F, weights, area, "fixed")
    if len(L.B) == 0:
        return np.repeat([L.m @ V / L.m.sum()], len(V), axis=0)
    C_II, C_IB = L.blocks
    P_star = V.copy()
    P_star[L.I] = factorise(-C_II).solve(C_IB @ V[L.B])  # -C_II is positive definite
    return P_star


# --------------------------------------------------------------------------
# argument checks and shared pieces


def _check_tau(tau, name="tau"):
    return real_number(name, tau, 0, why=" (a negative step runs the heat flow backwards and is unstable)")


def _check_iterations(iterations):
    return whole_number("iterations", iterations, 0)


def _tau_or_step(tau, step):
    """``tau``, or ``step``, the same argument under the name of the course's interface
    (``explicit_smoothing(V, F, step, iterations)``), kept for callers that pass it by that name."""
    if step is None:
        return tau
    if tau is not None:
        raise MeshError("give the step once, as tau (step is the same argument)")
    return step


def smoothing_operator(V, F, weights, area, boundary_condition, operator=None):
    """The door of a smoothing call: ``(V, F, L)``, the mesh checked once and its :class:`LaplaceOperator`.

    ``operator=(M, C)``: that pair with the boundary condition (not kept in memory); else the
    operator of the mesh and options, built once and kept (:func:`kept_operator`).
    """
    check_options(weights, area)
    check_choice("boundary_condition", boundary_condition, BOUNDARY_CONDITIONS)
    V, F = as_mesh(V, F)
    if operator is None:
        return V, F, kept_operator(V, F, weights, area, boundary_condition)
    return V, F, LaplaceOperator.of(V, F, weights, area, boundary_condition, operator)


def _done(k, P, callback, bar):
    """Iteration k of a smoothing run is done with the positions P: tell ``callback`` and the progress bar."""
    if callback is not None:
        callback(k, P)
    bar.step(k)
    return P


def _fail(on_failure, message, k, P_last, stacklevel=3):
    """Raise MeshError or warn (naming the frame ``stacklevel`` up) and return the last valid positions."""
    if on_failure == "raise":
        err = MeshError(message + "; the last valid positions are in the error's .V")
        err.V, err.iteration = P_last, k - 1
        raise err
    warnings.warn(
        message + f"; stopped and returned the positions after iteration {k - 1}", MeshWarning, stacklevel=stacklevel
    )
    return P_last


# --------------------------------------------------------------------------
# explicit smoothing


def explicit_smoothing(
    V, F, tau=None, iterations=1, weights="cotan", *,
    step=None, step_fraction=None,  # the step, in another name or unit
    area="barycentric", boundary_condition="fixed", operator=None,  # the operator
    progress=None, callback=None, on_failure="raise",  # the run
):  # fmt: skip
    """Explicit Laplacian smoothing: ``P <- P + tau M^-1 C P``, repeated ``iterations`` times.

    Forward Euler on the heat flow ``dP/dt = Delta P`` with ``Delta = M^-1 C``
    (C negative semidefinite, ``Delta x = -2 H n``) built once from V and kept
    fixed; stable only for ``tau < 2 / lam_max`` (:func:`explicit_step_limit`).
    Every iteration is one :func:`explicit_step`.

    Parameters
    ----------
    V : (n, 3) float64
        Vertex positions (not modified).
    F : (m, 3) int64
    tau : float >= 0, optional
        The step: length^2 for ``weights="cotan"``, dimensionless for
        ``"uniform"``. Give either ``tau`` or ``step_fraction``.
    iterations : int >= 0
    weights : "cotan" or "uniform"
    step : float >= 0, optional
        Another name for ``tau``, the course's name for it (``explicit_smoothing(V, F, step=..., iterations=...)``).
    step_fraction : float >= 0, optional
        The step as a fraction of the stability limit (scale-free): below 1 is stable.
    area : "barycentric" or "mixed"
    boundary_condition : "fixed" (default) or "free"
    operator : (M, C), optional
        A pair built already from (V, F) (:func:`geomlib.laplacian`), stepped instead of
        assembling one, as trimesh's smoothers take a Laplacian operator; ``weights`` and
        ``area`` then only name it.
    progress : None, True or False
        Progress bar (tqdm.auto); None: shown when the first iteration predicts
        more than ``geomlib.numerics.progress.SECONDS``.
    callback : callable(k, P), optional
        Called after every iteration k = 1..iterations with the (n, 3)
        positions (do not modify them).
    on_failure : "raise" or "stop"
        When the scheme diverges (a coordinate leaves ``BLOWUP_FACTOR``
        bounding-box diagonals or becomes non-finite): raise MeshError (with
        ``.V``, the last valid positions, and ``.iteration``) or warn
        (MeshWarning) and return them.

    Returns
    -------
    (n, 3) float64

    Raises
    ------
    MeshError
        Bad tau, step_fraction (both or neither given), iterations or option;
        vertices with zero area; divergence with ``on_failure="raise"``.

    Warns
    -----
    MeshWarning
        Once per call when the step exceeds the stability limit (named).

    References: Taubin 1995; Desbrun, Meyer, Schroeder and Barr 1999.
    """
    # _smooth, not smooth: the warnings then name the caller of explicit_smoothing
    return ExplicitSmoother(V, F, weights, area, boundary_condition, operator=operator)._smooth(
        _tau_or_step(tau, step), iterations, step_fraction, progress, callback, on_failure
    )


class ExplicitSmoother:
    """Explicit smoothing with the operator of V kept fixed: ``M`` and ``C`` assembled once, stepped many times.

    :func:`explicit_smoothing` in two parts, for a slider or a sweep that
    smooths one mesh with many steps and iteration counts: the constructor
    takes the Laplacian of V (:func:`geomlib.lessons.operator.laplace_operator`;
    at 164k vertices its assembly costs about 30 steps), and every :meth:`smooth`
    runs :func:`explicit_step` from V with its own step.

    Parameters
    ----------
    V, F, weights, area, boundary_condition, operator : as in :func:`explicit_smoothing`.

    Raises
    ------
    MeshError
        Bad mesh or option; vertices with zero area (named).
    """

    def __init__(self, V, F, weights="cotan", area="barycentric", boundary_condition="fixed", *, operator=None):
        self.V, self.F, self.L = smoothing_operator(V, F, weights, area, boundary_condition, operator)
        self.L.require_positive_areas(self.F, "explicit_smoothing")

    def smooth(self, tau=None, iterations=1, *, step_fraction=None, progress=None, callback=None, on_failure="raise"):
        """Run ``iterations`` explicit steps from V; arguments, result, errors and warnings as in
        :func:`explicit_smoothing`. Returns a new (n, 3) array."""
        return self._smooth(tau, iterations, step_fraction, progress, callback, on_failure)

    def _smooth(self, tau, iterations, step_fraction, progress, callback, on_failure):
        # reached from smooth and from explicit_smoothing alike, so that the warnings of _tau and
        # _fail (stacklevel 4) name the reader's line that called either
        iterations = _check_iterations(iterations)
        check_choice("on_failure", on_failure, ON_FAILURE)
        tau = self._tau(tau, step_fraction)
        M, C = self.L.M_step, self.L.C_step  # the fixed vertices' rows read P'_B = P_B
        far = BLOWUP_FACTOR * max(bounding_box_diagonal(self.V), np.finfo(float).tiny)
        P, bar = self.V.copy(), Iterations(iterations, progress, "explicit smoothing")
        try:
            for k in range(1, iterations + 1):
                P_next = explicit_step(P, M, C, tau)
                if not np.abs(P_next - self.V).max() <= far:  # one pass: NaN fails the comparison, inf exceeds far
                    message = (
                        f"explicit smoothing diverged at iteration {k} (step "
                        f"{tau:.6g}): coordinates left {BLOWUP_FACTOR:g} bounding-box diagonals"
                    )
                    return _fail(on_failure, message, k, P, stacklevel=4)
                P = _done(k, P_next, callback, bar)
        finally:
            bar.close()
        return P

    def _tau(self, tau, step_fraction):
        """The step from ``tau`` or ``step_fraction``; warns when it exceeds the limit."""
        if (tau is None) == (step_fraction is None):
            raise MeshError("give exactly one of tau and step_fraction")
        L = self.L
        if step_fraction is not None:
            fraction = _check_tau(step_fraction, "step_fraction")
            return fraction * 2.0 / L.lam_max if L.lam_max > 0 else 0.0
        tau = _check_tau(tau)
        # Gershgorin on the rows of M^-1 C: lam_max <= max_i (|C_ii| + sum_j!=i |C_ij|) / M_ii, so
        # steps below 2 / that bound are certainly stable and need no eigenvalue computation
        # (L.lam_max computes it on first use). With a negative (obtuse) cotangent weight the
        # row's |C_ij| add up to more than |C_ii|: the shorter max 2 |C_ii| / M_ii is then no bound.
        # The sums run over every column: with a fixed boundary they bound the interior block's rows too.
        radius = abs(L.C[L.moving]).sum(axis=1).A1  # |C_ii| + sum_{j != i} |C_ij|
        if tau > 0 and L.moving.any() and tau * np.max(radius / L.m[L.moving]) > 2.0:
            limit = 2.0 / L.lam_max if L.lam_max > 0 else float("inf")
            if tau > limit * (1 + 1e-12):
                warnings.warn(
                    f"explicit step {tau:.6g} exceeds the stability limit {limit:.6g} "
                    f"(= 2 / lambda_max, {L.weights} weights, boundary {L.boundary_condition}): the "
                    f"highest-frequency component grows by {abs(1 - 2 * tau / limit):.4g} "
                    f"per iteration",
                    MeshWarning,
                    stacklevel=4,
                )
        return tau


# --------------------------------------------------------------------------
# Taubin's filter


def taubin_smoothing(V, F, tau_shrink, tau_inflate, pairs, weights="uniform", *, callback=None, on_failure="raise"):
    """Taubin's lambda|mu filter: ``pairs`` times an explicit step of ``tau_shrink`` then one of ``tau_inflate``.

    Each step is :func:`explicit_step`, ``P' = P + tau M^-1 C P``, with the operator of V built
    once and kept (the uniform one, Taubin's, depends on F alone). In the eigenbasis of
    ``-M^-1 C`` (``lam >= 0``) one pair multiplies the mode of ``lam`` by
    ``(1 - tau_shrink lam)(1 - tau_inflate lam)``: near 1 for small ``lam`` (the shape is kept,
    where explicit smoothing shrinks it) and below 1 in magnitude for the high modes, the noise
    (Taubin, "A signal processing approach to fair surface design", SIGGRAPH 1995; his lambda
    and mu are ``tau_shrink`` and ``tau_inflate``). The two steps commute: the order within a
    pair does not matter. Boundary vertices are held where they are (``boundary_condition="fixed"``).

    V (n, 3) float64 (not modified), F (m, 3) int64; ``tau_shrink > 0 > tau_inflate``, in the
    operator's units (dimensionless for "uniform", length^2 for "cotan"); ``pairs >= 0``;
    ``callback(k, P)`` after pair k; ``on_failure`` as in :func:`explicit_smoothing` (a run
    whose coordinates leave ``BLOWUP_FACTOR`` bounding-box diagonals has diverged). Returns the
    new (n, 3) positions. Raises MeshError for steps of the wrong signs, a bad count or option,
    vertices with zero area, or a divergence with ``on_failure="raise"``.
    """
    if not real_number("tau_shrink", tau_shrink) > 0 > real_number("tau_inflate", tau_inflate):
        raise MeshError(f"Taubin's pair needs tau_shrink > 0 > tau_inflate, not ({tau_shrink!r}, {tau_inflate!r})")
    pairs = whole_number("pairs", pairs, 0)
    check_choice("on_failure", on_failure, ON_FAILURE)
    V, F, L = smoothing_operator(V, F, weights, "barycentric", "fixed")
    L.require_positive_areas(F, "taubin_smoothing")
    M, C = L.M_step, L.C_step  # the fixed vertices' rows of C are zero: they stay in place
    far = BLOWUP_FACTOR * max(bounding_box_diagonal(V), np.finfo(float).tiny)
    P = V.copy()
    for k in range(1, pairs + 1):
        P_next = explicit_step(explicit_step(P, M, C, tau_shrink), M, C, tau_inflate)  # shrink, then inflate
        if not np.abs(P_next - V).max() <= far:  # NaN fails the comparison too
            return _fail(on_failure, f"Taubin smoothing diverged at pair {k}", k, P)
        P = P_next
        if callback is not None:
            callback(k, P)
    return P


# --------------------------------------------------------------------------
# implicit smoothing


class ImplicitSmoother:
    """Implicit smoothing with the operator of V kept fixed: factorise once per step, solve many times.

    Convention: ``(M - tau C) P' = M P`` with M, C of :func:`geomlib.laplacian`
    built once from V (C negative semidefinite, so the matrix is symmetric
    positive definite for every tau >= 0). Every iteration is one
    :func:`implicit_step`, given the factorised solve of its system; with fixed
    boundary vertices (B) only the interior (I) is factorised:
    ``(M_II - tau C_II) P'_I = M_I P_I + tau C_IB P_B``
    (:meth:`geomlib.lessons.operator.LaplaceOperator.step_solver`).

    Meant for sliders (build it outside the callback): every new step value
    costs one sparse Cholesky factorisation (:mod:`geomlib.numerics.factor`), kept for
    the last ``cache_size`` step values, and every iteration one pair of
    triangular solves. :meth:`smooth` also keeps the iterates of the last
    ``history_size`` (tau, keep_volume) settings, so moving an iteration
    slider costs only the iterations not yet computed, and returning to a
    setting seen before costs nothing; :meth:`prepare` does all of this ahead.

    Parameters
    ----------
    V, F, weights, area, boundary_condition, operator : as in :func:`implicit_smoothing`.
    cache_size : int
        How many factorisations to keep.
    history_size : int
        For how many settings to keep the iterates (0: none).
    """

    def __init__(
        self,
        V,
        F,
        weights="cotan",
        area="barycentric",
        boundary_condition="fixed",
        cache_size=16,
        history_size=4,
        *,
        operator=None,
    ):
        self.V, self.F, self.L = smoothing_operator(V, F, weights, area, boundary_condition, operator)
        self.L.require_positive_areas(self.F, "ImplicitSmoother")
        self.cache_size, self.history_size = int(cache_size), int(history_size)
        self._factors, self._history = {}, {}

    def factor(self, tau):
        """The Cholesky factorisation of ``M_II - tau C_II`` (cached per tau)."""
        tau = _check_tau(tau)
        factor = self._factors.pop(tau, None) or self.L.factorise(tau)
        while len(self._factors) >= self.cache_size:
            self._factors.pop(next(iter(self._factors)))
        self._factors[tau] = factor  # most recently used last
        return factor

    def prepare(self, taus, iterations=0, keep_volume=False):
        """Factorise for every step value in ``taus`` now (e.g. all positions of a slider),
        and with ``iterations > 0`` also compute and keep that many iterates of each, so
        that a slider callback only looks them up. Grows both caches to hold them all.
        Shows a progress bar when the first step value predicts more than
        ``geomlib.numerics.progress.SECONDS`` in all."""
        taus = [_check_tau(t) for t in taus]
        iterations = _check_iterations(iterations)
        self.cache_size = max(self.cache_size, len(taus))
        if iterations:
            self.history_size = max(self.history_size, len(taus))
        bar = Iterations(len(taus), None, "factorising the step values")
        try:
            for j, tau in enumerate(taus, 1):
                self.factor(tau)
                if iterations:
                    self.smooth(tau, iterations, keep_volume=keep_volume, progress=False)
                bar.step(j)
        finally:
            bar.close()
        return self

    def smooth(self, tau, iterations=1, keep_volume=False, progress=None, callback=None, P=None):
        """Run ``iterations`` implicit steps from P (default: V); returns a new (n, 3) array.

        Without P and callback the iterates are kept (``history_size``) and a
        later call continues from the last one stored.
        """
        tau = _check_tau(tau)
        iterations = _check_iterations(iterations)
        remember = P is None and callback is None and self.history_size > 0
        P = self.V.copy() if P is None else np.array(P, dtype=np.float64)
        if iterations == 0:
            return P
        keeper = _VolumeKeeper(P, self.F) if keep_volume else None
        history = []
        if remember:
            history = self._history.pop((tau, bool(keep_volume)), [])
            self._history[(tau, bool(keep_volume))] = history  # most recently used last
            while len(self._history) > self.history_size:
                self._history.pop(next(iter(self._history)))
            if len(history) >= iterations:
                return history[iterations - 1].copy()
            P = history[-1] if history else P
        start, L = len(history), self.L
        solve = L.step_solver(tau, self.factor(tau))
        bar = Iterations(iterations - start, progress, "implicit smoothing")
        try:
            for k in range(start + 1, iterations + 1):
                P = implicit_step(P, L.M_step, L.C_step, tau, solve)
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


class _Collapse(Exception):
    pass


def volume_rescaled(P, F, V):
    """P scaled about the centroid of the solid it encloses by ``(vol(V) / vol(P))^(1/3)`` and moved to V's centroid.

    The volume rescaling of Desbrun et al. 1999 (``keep_volume=True``): the result
    encloses V's volume and its solid's centroid is V's. Volumes and centroids by the
    divergence theorem (:func:`geomlib.mesh.geometry.volume_and_centroid`), so F must be
    closed and counter-clockwise seen from outside. P, V: (n, 3) positions in the same
    length units; returns a new (n, 3) array. Raises MeshError when P encloses no
    positive volume.
    """
    vol0, c0 = volume_and_centroid(V, F)
    vol, c = volume_and_centroid(P, F)
    if not (vol > 0 and np.isfinite(vol)):
        raise MeshError(f"the enclosed volume became {vol:.6g}: nothing to rescale")
    return c0 + (P - c) * (vol0 / vol) ** (1.0 / 3.0)


class _VolumeKeeper:
    """Rescale about the centroid so that the enclosed volume and its centroid stay
    those of the start (:func:`volume_rescaled`)."""

    def __init__(self, P, F):
        b = boundary_vertices(F, len(P))
        if len(b):
            raise MeshError(
                "keep_volume needs a closed mesh (the enclosed volume of an open mesh "
                f"is undefined); boundary vertices: {format_indices(b)}"
            )
        self.F, self.V0 = F, np.array(P, dtype=np.float64)
        self.vol0 = volume_and_centroid(P, F)[0]
        if not self.vol0 > 0:
            raise MeshError(
                f"keep_volume: the enclosed volume is {self.vol0:.6g}, not positive "
                "(faces must be counter-clockwise seen from outside)"
            )

    def __call__(self, P, k):
        try:
            return volume_rescaled(P, self.F, self.V0)
        except MeshError as exc:
            raise _Collapse(f"{exc} at iteration {k}") from None


def _rebuilt_step(P, F, weights, area, boundary_condition, tau, k):
    """One :func:`implicit_step` with M and C rebuilt from the current positions (mean curvature flow)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", MeshWarning)
        try:
            L = LaplaceOperator.of(P, F, weights, area, boundary_condition)  # of P, so not kept in memory
            L.require_positive_areas(F, "implicit_smoothing")
            return implicit_step(P, L.M_step, L.C_step, tau, L.step_solver(tau))
        except (MeshWarning, MeshError) as exc:  # degenerate triangles, M - tau C singular
            raise _Collapse(f"at iteration {k}: {exc}") from None


def implicit_smoothing(
    V, F, tau=None, iterations=1, weights="cotan", *,
    step=None,  # the step in another name
    area="barycentric", boundary_condition="fixed", operator=None, rebuild=False,  # the operator
    keep_volume=False, solver="cholesky", progress=None, callback=None, on_failure="raise",  # the run
):  # fmt: skip
    """Implicit Laplacian smoothing: solve ``(M - tau C) P' = M P``, repeated.

    Backward Euler on ``dP/dt = Delta P``, ``Delta = M^-1 C`` (C symmetric
    negative semidefinite), so ``M - tau C`` is symmetric positive definite
    for every ``tau >= 0`` and the scheme is stable for any step (Desbrun,
    Meyer, Schroeder and Barr 1999). Every iteration is one :func:`implicit_step`.

    Parameters
    ----------
    V : (n, 3) float64
        Vertex positions (not modified).
    F : (m, 3) int64
    tau : float >= 0
        The step: length^2 for ``weights="cotan"``, dimensionless for
        ``"uniform"``. Scale-free: ``tau / ell^2`` (mean edge length ell).
    iterations : int >= 0
    weights : "cotan" or "uniform"
    step : float >= 0, optional
        Another name for ``tau``, the course's name for it (``implicit_smoothing(V, F, step=..., iterations=...)``).
    area : "barycentric" or "mixed"
    boundary_condition : "fixed" (default) or "free"
        Fixed: boundary vertices keep their positions and the interior block
        ``(M_II - tau C_II) P'_I = M_I P_I + tau C_IB P_B`` is solved.
    operator : (M, C), optional
        As in :func:`explicit_smoothing`; not with ``rebuild``.
    rebuild : bool
        False (default): the operator of V is kept and factorised once. True: M
        and C are rebuilt from the current positions every iteration (implicit
        mean curvature flow); as the surface shrinks its area goes to zero (a
        non-convex one may pinch off first) and triangles degenerate: then the
        run stops (see ``on_failure``) instead of returning a NaN mesh.
    keep_volume : bool
        After every iteration rescale about the centroid of the enclosed solid
        so that volume and centroid stay those of V (the volume rescaling of
        Desbrun et al. 1999). Closed meshes only.
    solver : "cholesky" or "cg"
        For the fixed operator: a sparse Cholesky factorisation, exact to
        rounding; or conjugate gradients with a Jacobi preconditioner,
        warm-started, relative residual 1e-10 (fast on well-shaped meshes and
        small steps, slow on stretched triangles and huge steps). The rebuilt
        operator always factorises.
    progress : None, True or False
        Progress bar (tqdm.auto); None: shown when the first iteration predicts
        more than ``geomlib.numerics.progress.SECONDS``.
    callback : callable(k, P), optional
        Called after every iteration with the (n, 3) positions.
    on_failure : "raise" or "stop"
        What happens when ``rebuild=True`` (or ``keep_volume``) meets a
        degenerate triangle, a collapsed surface (area below
        ``COLLAPSE_AREA_FRACTION`` of the start), a singular matrix or a
        non-finite result: raise MeshError (with ``.V``, the last valid
        positions, and ``.iteration``) or warn (MeshWarning) and return them.

    Returns the new positions, (n, 3) float64. Raises MeshError for a bad tau, iterations or
    option, vertices with zero area, keep_volume on an open mesh, or a failure (above) with
    ``on_failure="raise"``.
    """
    tau, iterations = _check_tau(_tau_or_step(tau, step)), _check_iterations(iterations)
    check_choice("solver", solver, SOLVERS)
    check_choice("on_failure", on_failure, ON_FAILURE)
    if rebuild and operator is not None:
        raise MeshError("rebuild=True assembles the operator from the current positions: give no operator")
    V, F, L = smoothing_operator(V, F, weights, area, boundary_condition, operator)
    L.require_positive_areas(F, "implicit_smoothing")
    keeper = _VolumeKeeper(V, F) if keep_volume else None
    if not rebuild and (iterations == 0 or tau == 0):
        return V.copy()
    solve = None if rebuild else L.step_solver(tau, solver=solver)
    P, area0 = V.copy(), surface_area(V, F) if rebuild else None
    bar = Iterations(iterations, progress, "implicit smoothing")
    try:
        for k in range(1, iterations + 1):
            try:
                if rebuild:
                    P_next = _rebuilt_step(P, F, weights, area, boundary_condition, tau, k)
                else:
                    P_next = implicit_step(P, L.M_step, L.C_step, tau, solve)
                if keeper is not None:
                    P_next = keeper(P_next, k)
            except _Collapse as exc:
                return _fail(on_failure, f"implicit smoothing stopped: {exc}", k, P)
            if not np.isfinite(P_next).all():
                return _fail(on_failure, f"implicit smoothing stopped: non-finite positions at iteration {k}", k, P)
            if rebuild and surface_area(P_next, F) < COLLAPSE_AREA_FRACTION * area0:
                return _fail(
                    on_failure,
                    f"implicit smoothing stopped: the mesh collapsed (area "
                    f"below {COLLAPSE_AREA_FRACTION:g} of the start) at iteration {k}",
                    k,
                    P,
                )
            P = _done(k, P_next, callback, bar)
    finally:
        bar.close()
    return P
