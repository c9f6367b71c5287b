"""Experiment driver of notebook 07: Laplacian smoothing swept over noise levels, schemes, steps, iterations.

Not a lesson and not a building block: it strings together :func:`geomlib.add_noise`,
the smoothers of :mod:`geomlib.lessons.smoothing` and the metrics of
:mod:`geomlib.lessons.metrics`, and records every metric of every setting in a
:class:`SmoothingSweep`. The scale-free step of each scheme is
:func:`scale_free_step`.
"""

import multiprocessing
import sys
import time
import warnings

import numpy as np

from ..lessons.laplace import WEIGHTS
from ..lessons.metrics import HAUSDORFF_SAMPLES_PER_FACE, MeshComparison
from ..lessons.noise import add_noise
from ..lessons.smoothing import ExplicitSmoother, ImplicitSmoother, explicit_step_limit
from ..mesh.errors import MeshError, MeshWarning
from ..mesh.validate import check_choice
from ..numerics.cores import CORES
from .steps import absolute_step

__all__ = [
    "SCHEMES",
    "EXPLICIT_FRACTIONS",
    "IMPLICIT_STEPS",
    "SWEEP_ITERATIONS",
    "SWEEP_KEYS",
    "WORKERS",
    "HAUSDORFF_SAMPLES_PER_FACE",
    "scale_free_step",
    "SmoothingSweep",
    "smoothing_sweep",
]

#: The smoothing methods a scheme can name.
METHODS = ("explicit", "implicit")

#: (method, weights) pairs compared by :func:`smoothing_sweep`.
SCHEMES = (("explicit", "uniform"), ("explicit", "cotan"), ("implicit", "uniform"), ("implicit", "cotan"))

#: Explicit steps of the sweep, as fractions of the stability limit
#: ``2 / lambda_max`` of the mesh being smoothed (below 1 is stable).
EXPLICIT_FRACTIONS = (0.1, 0.25, 0.5, 0.9)

#: Implicit steps of the sweep, scale-free (see :func:`scale_free_step`).
IMPLICIT_STEPS = (0.1, 0.3, 1.0)

#: Iteration counts at which the sweep measures every run.
SWEEP_ITERATIONS = (1, 2, 3, 5, 8, 13, 20, 30, 50)

#: Processes a sweep runs its noise levels in (:func:`smoothing_sweep`): the levels are
#: independent; two where this process may use two cores (the machines the workbook is
#: measured on have 2), else one.
WORKERS = min(2, CORES)

#: The fork context of multiprocessing on Linux; None elsewhere (Windows cannot fork, and on
#: macOS system libraries may crash in a forked child), where a sweep runs in one process.
_FORK = multiprocessing.get_context("fork") if sys.platform.startswith("linux") else None

#: Metric keys recorded by the sweep (all of :meth:`MeshComparison.evaluate`
#: except the Hausdorff estimate, which is measured for chosen results only).
SWEEP_KEYS = ("rms", "normal_mean", "normal_p95", "area_change", "volume_change", "sharp_edge_error")


def scale_free_step(V, F, method, weights, value):
    """The smoothing step (units of :mod:`geomlib.lessons.smoothing`) for a scale-free ``value``.

    * explicit: ``value`` is a fraction of the stability limit of this mesh,
      ``step = value * explicit_step_limit(V, F, weights)``.
    * implicit, uniform weights: ``Delta`` is dimensionless, ``step = value``.
    * implicit, cotangent weights: ``step = value * h^2 / 4`` with ``h`` the
      mean edge length of this mesh. On an equilateral mesh the cotangent
      Laplacian is the uniform one divided by ``h^2 / 4``, so the same
      ``value`` diffuses by the same amount with either weights, at any scale.

    For the cotangent operator of a *noisy* mesh the explicit limit collapses
    (noise makes obtuse triangles with large cotangents), which is why the
    implicit step is not tied to it.
    """
    check_choice("method", method, METHODS)
    check_choice("weights", weights, WEIGHTS)
    if method == "explicit":
        return float(value) * explicit_step_limit(V, F, weights)
    return absolute_step(value / 4.0 if weights == "cotan" else value, "ell^2", V, F, weights)


class SmoothingSweep:
    """Results of :func:`smoothing_sweep`: every metric for every setting.

    Attributes
    ----------
    sigmas : (a,) float64
        Noise levels (fractions of the bounding-box diagonal).
    schemes : list of (method, weights)
    step_values : dict method -> tuple
        The scale-free step values (:func:`scale_free_step`).
    steps : (a, s, b) float64
        The actual step used for noise level i, scheme j, step value k.
    iterations : (c,) int64
    values : dict key -> (a, s, b, c) float64
        ``values["rms"][i, j, k, l]``: the metric after ``iterations[l]``
        iterations. NaN where a run stopped early (divergence).
    noisy : dict key -> (a,) float64
        The metrics of the noisy input itself.
    seconds : float
        Wall-clock time of the sweep.
    worker_seconds : float
        Processor time of its worker process (``workers=2``), which ``time.process_time()``
        of the calling process does not count.
    """

    def __init__(self, sigmas, schemes, step_values, iterations):
        self.sigmas = np.asarray(sigmas, dtype=np.float64)
        self.schemes = list(schemes)
        self.step_values = dict(step_values)
        self.iterations = np.asarray(iterations, dtype=np.int64)
        b = max(len(v) for v in self.step_values.values())
        shape = (len(self.sigmas), len(self.schemes), b, len(self.iterations))
        self.steps = np.full(shape[:3], np.nan)
        self.values = {key: np.full(shape, np.nan) for key in SWEEP_KEYS}
        self.noisy = {key: np.full(len(self.sigmas), np.nan) for key in SWEEP_KEYS}
        self.seconds = float("nan")
        self.worker_seconds = 0.0

    def best(self, i, key="rms", schemes=None):
        """The setting with the smallest ``key`` at noise level ``i``.

        Parameters
        ----------
        i : int
            Index into ``sigmas``.
        key : str
            A metric of ``values`` (smaller is better; for signed changes the
            absolute value counts).
        schemes : list of (method, weights), optional
            Restrict the search to these schemes.

        Returns
        -------
        dict with ``method``, ``weights``, ``step_value``, ``step``,
        ``iterations``, the metrics of that setting (every key of ``values``)
        and ``index`` (j, k, l) into ``values``.
        """
        allowed = [j for j, s in enumerate(self.schemes) if schemes is None or s in schemes]
        block = np.abs(self.values[key][i])
        mask = np.full(block.shape, np.inf)
        mask[allowed] = 0.0
        block = np.where(np.isnan(block), np.inf, block) + mask
        j, k, l = np.unravel_index(int(np.argmin(block)), block.shape)
        method, weights = self.schemes[j]
        out = {
            "method": method,
            "weights": weights,
            "step_value": self.step_values[method][k],
            "step": float(self.steps[i, j, k]),
            "iterations": int(self.iterations[l]),
            "index": (int(j), int(k), int(l)),
        }
        out.update({name: float(v[i, j, k, l]) for name, v in self.values.items()})
        return out


def smoothing_sweep(
    V_clean,
    F,
    sigmas,
    seed,
    schemes=SCHEMES,
    explicit_fractions=EXPLICIT_FRACTIONS,
    implicit_steps=IMPLICIT_STEPS,
    iterations=SWEEP_ITERATIONS,
    direction="isotropic",
    comparison=None,
    progress=True,
    workers=None,
):
    """Add noise at each level, smooth it with every scheme, step and iteration count, measure.

    For every noise level ``sigma`` (a fraction of the bounding-box
    diagonal) the noisy mesh is ``add_noise(V_clean, F, sigma, seed,
    direction)`` (the same seed at every level: the same noise pattern,
    growing). Every scheme ``(method, weights)`` then smooths it with every
    step value (:func:`scale_free_step`) for ``max(iterations)`` iterations,
    and the mesh is measured against the clean one after each count in
    ``iterations`` (:meth:`MeshComparison.evaluate` without the Hausdorff
    estimate). One run per (noise level, scheme, step) covers all iteration
    counts. The operators are those of the noisy mesh, assembled once per
    (noisy mesh, weights) and kept fixed, as in
    :func:`geomlib.explicit_smoothing` and :func:`geomlib.implicit_smoothing`
    (:class:`geomlib.lessons.smoothing.ExplicitSmoother`,
    :class:`geomlib.lessons.smoothing.ImplicitSmoother`); implicit runs factorise
    ``M - step C`` once per step and noisy mesh, and with uniform weights once per
    step for all noise levels (that operator depends on F alone).

    Parameters
    ----------
    V_clean : (n, 3) float64
    F : (m, 3) int64
    sigmas : sequence of float
    seed : int
    schemes : sequence of (method, weights)
    explicit_fractions, implicit_steps : sequence of float
        Scale-free step values of the explicit and implicit runs.
    iterations : sequence of int
        Increasing iteration counts at which to measure.
    direction : "isotropic" or "normal"
        Of the noise (:func:`geomlib.add_noise`).
    comparison : MeshComparison, optional
        Reuse one built for (V_clean, F).
    progress : bool
        A tqdm.auto progress bar over the runs.
    workers : 1 or 2, optional
        Processes the noise levels run in (default :data:`WORKERS`): with 2, every other
        level runs in a forked worker process, on the second core (on Linux; elsewhere 1).
        The results are the same.

    Returns
    -------
    SmoothingSweep
    """
    C = comparison if comparison is not None else MeshComparison(V_clean, F)
    iterations = np.asarray(sorted(set(int(k) for k in iterations)), dtype=np.int64)
    if len(iterations) == 0 or iterations[0] < 1:
        raise MeshError("iterations must be positive whole numbers")
    step_values = {"explicit": tuple(explicit_fractions), "implicit": tuple(implicit_steps)}
    for method, weights in schemes:
        check_choice("method", method, METHODS)
        check_choice("weights", weights, WEIGHTS)
    out = SmoothingSweep(sigmas, schemes, step_values, iterations)
    runs = sum(len(step_values[m]) for m, _ in schemes) * len(out.sigmas)
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=runs, desc="smoothing sweep")

    def sweep(levels, bar):
        _sweep_levels(C, out, levels, seed, direction, schemes, step_values, iterations, bar)

    start = time.perf_counter()
    try:
        levels = list(range(len(out.sigmas)))
        if (WORKERS if workers is None else workers) > 1 and len(levels) > 1 and _FORK is not None:
            _with_a_worker(sweep, levels, out, bar)
        else:
            sweep(levels, bar)
    finally:
        if bar is not None:
            bar.close()
    out.seconds = time.perf_counter() - start
    return out


def _sweep_levels(C, out, levels, seed, direction, schemes, step_values, iterations, bar):
    """The runs of :func:`smoothing_sweep` at the noise levels ``levels`` (indices), recorded into ``out``."""
    where = {int(k): l for l, k in enumerate(iterations)}
    last = int(iterations[-1])
    # the uniform operator depends on F alone: one implicit smoother, and its factorisation of each
    # M - step C, serves every noise level (it smooths each noisy mesh from P = Vn)
    shared = {}
    for i in levels:
        Vn = add_noise(C.V_clean, C.F, out.sigmas[i], seed, direction=direction)
        for key, value in C.evaluate(Vn, hausdorff=False).items():
            out.noisy[key][i] = value
        for j, (method, weights) in enumerate(schemes):
            smoother = shared.get((method, weights))
            if smoother is None:
                smoother = (ImplicitSmoother if method == "implicit" else ExplicitSmoother)(Vn, C.F, weights)
                if method == "implicit" and weights == "uniform":
                    shared[method, weights] = smoother
            for k, value in enumerate(step_values[method]):
                step = scale_free_step(Vn, C.F, method, weights, value)
                out.steps[i, j, k] = step

                def record(it, P, i=i, j=j, k=k):
                    if it in where:
                        for name, v in C.evaluate(P, hausdorff=False).items():
                            out.values[name][i, j, k, where[it]] = v

                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", MeshWarning)
                    if method == "explicit":
                        smoother.smooth(step, last, callback=record, on_failure="stop", progress=False)
                    else:
                        smoother.smooth(step, last, callback=record, progress=False, P=Vn)
                if bar is not None:
                    bar.update(1)


def _with_a_worker(sweep, levels, out, bar):
    """``sweep(levels, bar)`` on both cores: every other noise level in a forked worker process.

    The levels are independent runs, so the worker needs nothing but what the fork copies; it
    sends back its rows of ``out`` and its processor time (``out.worker_seconds``). Warnings in
    the worker are dropped: it has no notebook to show them in.
    """
    mine, theirs = levels[0::2], levels[1::2]
    receive, send = _FORK.Pipe(duplex=False)

    def work():
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                cpu = time.process_time()
                sweep(theirs, None)
                rows = {("values", k): v[theirs] for k, v in out.values.items()}
                rows.update({("noisy", k): v[theirs] for k, v in out.noisy.items()})
                send.send(("rows", (out.steps[theirs], rows), time.process_time() - cpu))
        except BaseException as exc:  # raised in this process below, as a sweep without a worker would
            send.send(("error", f"{type(exc).__name__}: {exc}", 0.0))

    worker = _FORK.Process(target=work, daemon=True)
    worker.start()
    send.close()  # the worker holds the only write end now: if it dies, recv() ends instead of waiting forever
    try:
        sweep(mine, bar)
        try:
            kind, result, cpu = receive.recv()
        except EOFError:
            kind, result, cpu = (
                "error",
                f"it ended without an answer (exit code {worker.join() or worker.exitcode})",
                0.0,
            )
    finally:
        worker.join()
        receive.close()
    if kind == "error":
        raise MeshError(f"the smoothing sweep's worker process failed: {result}")
    out.steps[theirs], rows = result
    for (part, key), value in rows.items():
        getattr(out, part)[key][theirs] = value
    out.worker_seconds += cpu
    if bar is not None:
        bar.update(sum(len(out.step_values[m]) for m, _ in out.schemes) * len(theirs))
