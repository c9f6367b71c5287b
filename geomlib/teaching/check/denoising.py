"""Checks of the exercises of notebook 07: the noise model and the vertex RMS error.

``add_noise(fn)`` checks ``fn(V, F, sigma, seed) -> V'``: Gaussian noise with
standard deviation ``s = sigma * d`` per coordinate, ``d`` the bounding-box
diagonal of V, independent per vertex and coordinate, seeded, V untouched.
Noise is random, so this check is statistical: it measures the noise on a
regular grid of 2,400 vertices (7,200 numbers; the standard deviation is then
known to about 1 %) and accepts a standard deviation within 6 % of ``s``.
The wrong scalings it recognises are far apart on purpose: the grid is
chosen so that d, the mean edge length ell and 1 differ by large factors.

``vertex_rms(fn)`` checks ``fn(V, V_clean) -> float``:
``sqrt(mean_i |x_i - x_i^clean|^2) / d_clean`` on cases with exact answers.

``denoising_experiment(fn)`` checks ``fn(V_clean, F, sigma, tau, iterations, seed) -> E``:
seeded noise relative to d, ``iterations`` implicit cotangent steps of ``tau`` from the
noisy mesh, and the vertex RMS error against the *clean* mesh over its d. Any correct
noise draw is accepted (``rng.normal``, another order of the draws), so the values are
compared statistically: on the shipped sphere scaled to d = 139 (2,562 vertices) the
error of a correct run varies by about 1 % from one noise pattern to another, and a
value within 5 % of geomlib's passes; the typical mistakes land 14 % or more away.
"""

import functools
from pathlib import Path

import numpy as np

from ...mesh.geometry import bounding_box_diagonal, mean_edge_length
from .catalogue import Case, Wrong, judge, number
from .result import Mistake, call, exercise

__all__ = ["add_noise", "vertex_rms", "denoising_experiment", "denoising_sweep"]

NOISE_SECTION = "section 2 · The noise, yours"
RMS_SECTION = "section 3 · The error, yours"
EXPERIMENT_SECTION = "section 4 · The experiment, yours"


def _grid(nx, ny, spacing, height):
    """A regular grid of nx x ny vertices (spacing apart) on a tilted plane, two triangles per cell."""
    x, y = np.meshgrid(np.arange(nx) * spacing, np.arange(ny) * spacing)
    V = np.column_stack([x.ravel(), y.ravel(), height * x.ravel() / x.max()])
    i = np.arange(nx * ny).reshape(ny, nx)
    a, b, c, d = i[:-1, :-1].ravel(), i[:-1, 1:].ravel(), i[1:, 1:].ravel(), i[1:, :-1].ravel()
    F = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return V, F


# 60 x 40 vertices, 5 length units apart: d = 351, ell = 6.0, so the wrong scalings are far apart
_NOISE_V, _NOISE_F = _grid(60, 40, 5.0, 50.0)
_SIGMA, _SEED = 0.02, 3
_STD_TOLERANCE = 0.06


def _array(out, n, what):
    if not isinstance(out, np.ndarray):
        raise Mistake(
            f"{what} returned {type(out).__name__}, not a numpy array of positions",
            "return V + noise, an (n, 3) numpy array",
            typical=False,
        )
    if out.shape != (n, 3):
        raise Mistake(
            f"{what} returned shape {out.shape}, expected ({n}, 3): one position per vertex",
            "add an (n, 3) array of noise to V",
            typical=False,
        )
    return out.astype(float)


def _scale_mistakes(d, ell, sigma):
    """The standard deviation each typical wrong scaling gives, with its diagnosis and hint."""
    s = sigma * d
    return [
        (
            sigma,
            "the noise is not scaled by the bounding box: its standard deviation is sigma itself",
            "sigma is a fraction of the bounding-box diagonal d; multiply the unit noise by s = sigma * d",
        ),
        (
            sigma * ell,
            "the noise is scaled by the mean edge length instead of the bounding-box diagonal",
            "s = sigma * d with d = |max(V) - min(V)|, the bounding-box diagonal",
        ),
        (
            sigma**2 * d,
            "sigma is used as a variance: the standard deviation came out as sigma^2 * d",
            "sigma is the standard deviation; draw standard normals and multiply by sigma * d",
        ),
        (
            s**2,
            "the variance s^2 is used where the standard deviation s belongs",
            "multiply standard normal numbers by s = sigma * d, not by s^2",
        ),
        (
            np.sqrt(s),
            "the square root of s is used: sigma * d was taken as a variance",
            "the standard deviation is s = sigma * d itself",
        ),
        (
            s / np.sqrt(3),
            "each displacement has length about s (a random direction scaled to s), so each "
            "coordinate moves by only s / sqrt(3)",
            "draw each of the three coordinates independently with standard deviation s",
        ),
    ]


@exercise("add_noise", reread=NOISE_SECTION, forbid=("lessons.noise.add_noise",))
def add_noise(fn):
    """Check ``fn(V, F, sigma, seed) -> V'``: V + sigma * d * (independent standard normals)."""
    V, F = _NOISE_V, _NOISE_F
    n = len(V)
    d, ell = bounding_box_diagonal(V), mean_edge_length(V, F)
    V_in = V.copy()
    out = call(fn, V_in, F.copy(), _SIGMA, _SEED)
    if out is V_in:
        raise Mistake(
            "the function returned the array it was given: V was modified in place",
            "work on a copy: return V + noise, never V += noise",
        )
    out = _array(out, n, "the function")
    if not np.array_equal(V_in, V):
        raise Mistake(
            "V was modified in place (the caller's clean mesh changed)",
            "return a new array, V + noise, and leave V as it was",
        )
    again = _array(call(fn, V.copy(), F.copy(), _SIGMA, _SEED), n, "a second call")
    if not np.array_equal(out, again):
        raise Mistake(
            "two calls with the same seed gave different noise: it is not seeded (not reproducible)",
            "draw from rng = np.random.default_rng(seed), not from np.random directly",
        )
    other = _array(call(fn, V.copy(), F.copy(), _SIGMA, _SEED + 1), n, "a call with another seed")
    if np.array_equal(out, other):
        raise Mistake(
            "another seed gave the same noise: the seed is ignored", "pass the seed to np.random.default_rng(seed)"
        )
    zero = _array(call(fn, V.copy(), F.copy(), 0.0, _SEED), n, "the call with sigma = 0")
    D = out - V
    if np.allclose(D, D[0], rtol=0, atol=1e-12 * d) and not np.allclose(D, 0):
        raise Mistake(
            "every vertex moved by the same vector: the whole mesh was shifted, not made noisy",
            "draw an (n, 3) array of noise, one independent vector per vertex",
        )
    if not np.allclose(zero, V, rtol=0, atol=1e-12 * d):
        raise Mistake("sigma = 0 still moved the vertices", "the noise must be sigma * d times the unit noise")
    if np.allclose(D, 0):
        raise Mistake("the vertices did not move", "add the noise to V and return the result", typical=False)
    std = float(D.std())
    mean = D.mean(axis=0)
    if np.any(np.abs(mean) > 5 * std / np.sqrt(n)):
        raise Mistake(
            f"the noise is not centred: its mean is {np.round(mean / std, 2)} standard deviations",
            "use standard normal numbers (mean 0), e.g. rng.standard_normal((n, 3))",
        )
    per_axis = D.std(axis=0) / std
    if np.any(np.abs(per_axis - 1) > _STD_TOLERANCE):
        raise Mistake(
            f"the coordinates are not equally noisy (standard deviations x, y, z in the ratio {np.round(per_axis, 2)})",
            "every coordinate of every vertex gets its own standard normal number times s",
        )
    s = _SIGMA * d
    if abs(std / s - 1) > _STD_TOLERANCE:
        for wrong, diagnosis, hint in _scale_mistakes(d, ell, _SIGMA):
            if abs(std / wrong - 1) <= _STD_TOLERANCE:
                raise Mistake(diagnosis, hint)
        raise Mistake(
            f"the noise has standard deviation {std:.3g} per coordinate, expected s = sigma * d = "
            f"{_SIGMA:g} * {d:.4g} = {s:.4g} (within {_STD_TOLERANCE:.0%})",
            "multiply standard normal numbers by sigma times the bounding-box diagonal of V",
            typical=False,
        )
    z = (D / std).ravel()
    kurtosis = float(np.mean(z**4))
    if kurtosis < 2.5:
        raise Mistake(
            f"the noise is not Gaussian (kurtosis {kurtosis:.2f}; a normal distribution has 3, a uniform one 1.8)",
            "use rng.standard_normal, not rng.random or rng.uniform",
        )
    return [
        f"a {n}-vertex grid (s = sigma * d within {_STD_TOLERANCE:.0%}, centred, Gaussian, independent per vertex)",
        "reproducibility with a seed",
        "V left unchanged",
        "sigma = 0",
    ]


# a tetrahedron with one vertex moved by 3 (exact answer 1.5 / d) and a lopsided displacement field
_TET = np.array([[0.0, 0, 0], [2, 0, 0], [0, 1, 0], [0, 0, 4]])


def _rms_cases():
    moved = _TET.copy()
    moved[1, 0] += 3.0  # also widens the noisy bounding box
    grid, _ = _grid(7, 5, 1.0, 2.0)
    rng = np.random.default_rng(5)
    bumped = grid + rng.standard_normal(grid.shape) * np.linspace(0.05, 1.5, len(grid))[:, None]
    return [
        ("a tetrahedron with one vertex moved by 3", moved, _TET),
        ("a grid with displacements of very different sizes", bumped, grid),
        ("a mesh compared with itself", grid.copy(), grid),
    ]


def _rms_mistakes(V, V_clean):
    e2 = np.einsum("ij,ij->i", V - V_clean, V - V_clean)
    d, d_noisy = bounding_box_diagonal(V_clean), bounding_box_diagonal(V)
    rms = np.sqrt(e2.mean())
    return [
        (
            rms,
            "the result is not relative: it is in length units, not divided by the bounding-box diagonal",
            "divide by d, the bounding-box diagonal of the clean mesh",
        ),
        (
            np.sqrt(e2).mean() / d,
            "this is the mean of the distances, not the root of the mean square",
            "square each distance, average, then take the square root",
        ),
        (
            e2.mean() / d,
            "the mean squared error is not rooted",
            "take the square root of the mean of |x_i - x_i^clean|^2",
        ),
        (
            e2.mean() / d**2,
            "the mean squared error is not rooted (this is RMS^2)",
            "take the square root of the mean before comparing",
        ),
        (
            np.sqrt(e2.sum()) / d,
            "the squared distances are summed, not averaged",
            "divide the sum by the number of vertices n before the square root",
        ),
        (
            np.sqrt(e2).sum() / d,
            "the distances are summed, not averaged (and not squared)",
            "RMS = sqrt(mean_i |x_i - x_i^clean|^2)",
        ),
        (
            rms / np.sqrt(3) / d,
            "the mean runs over the 3n coordinates instead of the n vertices",
            "square the length of each vertex's displacement, then average over vertices",
        ),
        (
            rms / d_noisy,
            "divided by the noisy mesh's diagonal instead of the clean one",
            "d is the bounding-box diagonal of V_clean, the truth we measure against",
        ),
    ]


@exercise(
    "vertex_rms",
    reread=RMS_SECTION,
    forbid=("lessons.metrics.vertex_rms", "lessons.metrics.denoising_metrics", "lessons.metrics.MeshComparison"),
)
def vertex_rms(fn):
    """Check ``fn(V, V_clean) -> float``: sqrt(mean_i |x_i - x_i^clean|^2) / d(V_clean)."""
    checked = []
    for label, V, V_clean in _rms_cases():
        value = _number(
            call(fn, V.copy(), V_clean.copy()),
            "the function",
            "average over all vertices and return one float, the RMS distance divided by the diagonal",
        )
        d = bounding_box_diagonal(V_clean)
        e2 = np.einsum("ij,ij->i", V - V_clean, V - V_clean)
        expected = np.sqrt(e2.mean()) / d
        if np.isclose(value, expected, rtol=1e-9, atol=1e-15):
            checked.append(label)
            continue
        if np.isclose(value, -expected, rtol=1e-9):
            raise Mistake("the result is negative", "a root mean square is >= 0")
        for wrong, diagnosis, hint in _rms_mistakes(V, V_clean):
            if np.isclose(value, wrong, rtol=1e-9, atol=1e-15):
                raise Mistake(diagnosis, hint)
        raise Mistake(
            f"on {label} the result is {value:.6g}, expected {expected:.6g}",
            "RMS = sqrt(mean_i |x_i - x_i^clean|^2) / d, d the clean mesh's bounding-box diagonal",
            typical=False,
        )
    return checked


# the experiment's cases: the shipped sphere, scaled and moved so that d (139), the mean edge
# (3.0) and 1 are far apart; noise 1.4 mean edges; a short implicit run that removes a fifth of it
_SCALE, _SHIFT = 40.0, np.array([3.0, -2.0, 5.0])
_EXP_SIGMA, _EXP_TAU_ELL2, _EXP_ITERATIONS, _EXP_SEED = 0.03, 0.2, 5, 11
_EXP_TOLERANCE = 0.05


@functools.lru_cache(maxsize=1)
def _sphere():
    from ...mesh.io import load_mesh

    V, F = load_mesh(Path(__file__).resolve().parents[2] / "meshes" / "sphere.obj")  # shipped package data
    V, F = _SCALE * V + _SHIFT, F
    V.flags.writeable = F.flags.writeable = False  # kept for every check: the learner gets copies
    return V, F


@functools.lru_cache(maxsize=8)  # the check runs three times per exercise (check, partial credit, reveal)
def _experiment(sigma, tau, iterations, seed):
    """geomlib's run of the experiment on the check's sphere, and the pieces its typical mistakes are made of."""
    from ...lessons.noise import add_noise
    from ...lessons.smoothing import implicit_smoothing

    V, F = _sphere()
    W = add_noise(V, F, sigma, seed)
    P = implicit_smoothing(W, F, tau, iterations)
    d = bounding_box_diagonal(V)
    rms = lambda X, Y: float(np.sqrt(np.mean(np.sum((X - Y) ** 2, axis=1))))  # noqa: E731
    return {"right": rms(P, V) / d, "noisy": rms(P, W) / d, "noise": rms(W, V) / d, "P": P, "W": W, "d": d}


def _number(out, what, hint="return the one relative error, a float"):
    """``out`` as a float, or the catch-all Mistake of an array or a non-number that ``what`` returned."""
    if isinstance(out, np.ndarray) and out.size != 1:
        raise Mistake(f"{what} returned an array of shape {out.shape}, not one number", hint, typical=False)
    try:
        return float(out)
    except (TypeError, ValueError):
        raise Mistake(f"{what} returned {type(out).__name__}, not a number", hint, typical=False) from None


def _near(value, target):
    return abs(value - target) <= _EXP_TOLERANCE * abs(target)


@exercise(
    "denoising_experiment",
    reread=EXPERIMENT_SECTION,
    forbid=(
        "lessons.noise.denoising_experiment",
        "lessons.noise.add_noise",
        "lessons.metrics.vertex_rms",
        "lessons.metrics.denoising_metrics",
        "lessons.metrics.MeshComparison",
        "teaching.experiments.sweep.smoothing_sweep",
        "teaching.experiments.sweep.denoising_comparison",
    ),
    allow=("lessons.smoothing.implicit_smoothing",),
)
def denoising_experiment(fn):
    """Check ``fn(V_clean, F, sigma, tau, iterations, seed) -> E`` (module docstring)."""
    V, F = _sphere()
    ell = mean_edge_length(V, F)
    tau = _EXP_TAU_ELL2 * ell**2
    args = (_EXP_SIGMA, tau, _EXP_ITERATIONS, _EXP_SEED)
    first = _number(call(fn, V.copy(), F.copy(), *args), "the function")
    again = _number(call(fn, V.copy(), F.copy(), *args), "a second call")
    if first != again and not np.isclose(first, again, rtol=1e-9, atol=0):
        raise Mistake(
            f"two calls with the same seed gave different errors ({first:.6g} and {again:.6g}): the noise is "
            "not seeded, so the experiment cannot be repeated",
            "draw the noise from np.random.default_rng(seed)",
        )
    other = _number(call(fn, V.copy(), F.copy(), _EXP_SIGMA, tau, _EXP_ITERATIONS, _EXP_SEED + 1), "another seed")
    if other == first:
        quiet = _number(call(fn, V.copy(), F.copy(), 0.0, tau, _EXP_ITERATIONS, _EXP_SEED), "the call with sigma = 0")
        if np.isclose(quiet, first, rtol=1e-9, atol=0):
            raise Mistake(
                "the error does not depend on the noise at all: the clean mesh was smoothed instead of the noisy one",
                "smooth W = V_clean + noise, then compare with V_clean",
            )
        raise Mistake("another seed gave the very same error: the seed is ignored", "pass seed to default_rng(seed)")
    # no smoothing: the error is the noise itself, about sqrt(3) sigma whatever the mesh
    zero = _experiment(_EXP_SIGMA, tau, 0, _EXP_SEED)
    at_zero = _number(call(fn, V.copy(), F.copy(), _EXP_SIGMA, tau, 0, _EXP_SEED), "the call with 0 iterations")
    d = zero["d"]
    if abs(at_zero) <= 1e-9 * zero["right"]:
        raise Mistake(
            "with 0 iterations the error is 0: it is measured against the noisy mesh (the input of the "
            "smoothing), not against the clean mesh, the truth",
            "return the RMS distance between the smoothed mesh and V_clean",
        )
    wrong_at_zero = [
        (
            zero["right"] * d,
            "the error is absolute (length units): it is not divided by the clean mesh's bounding-box diagonal",
            "divide the RMS distance by d, the bounding-box diagonal of V_clean",
        ),
        (
            zero["right"] / d,
            "the noise is not relative to the bounding-box diagonal: its standard deviation is sigma itself",
            "scale the standard normal numbers by sigma * d, d the diagonal of V_clean",
        ),
        (
            zero["right"] * ell / d,
            "the noise is scaled by the mean edge length instead of the bounding-box diagonal",
            "scale the standard normal numbers by sigma * d",
        ),
        (
            zero["right"] / np.sqrt(3),
            "the error is a third too small in square: either each vertex moved by a random direction of length "
            "sigma * d (then each coordinate moves by only sigma * d / sqrt(3)), or the mean runs over the 3n "
            "coordinates instead of the n vertices",
            "draw every coordinate with standard deviation sigma * d, and average |p_i - x_i|^2 over vertices",
        ),
    ]
    if not _near(at_zero, zero["right"]):
        for target, diagnosis, hint in wrong_at_zero:
            if _near(at_zero, target):
                raise Mistake(diagnosis, hint)
        raise Mistake(
            f"with 0 iterations (no smoothing) the error is {at_zero:.4g}, expected the noise itself, about "
            f"{zero['right']:.4g} (sqrt(3) sigma) within {_EXP_TOLERANCE:.0%}",
            "E = sqrt(mean_i |p_i - x_i|^2) / d with P the noisy mesh here",
            typical=False,
        )
    run = _experiment(*args)
    if not _near(first, run["right"]):
        clean_smoothed = _experiment(0.0, tau, _EXP_ITERATIONS, _EXP_SEED)["right"]
        absolute = _experiment(_EXP_SIGMA / d, tau, _EXP_ITERATIONS, _EXP_SEED)["right"] * d
        for target, diagnosis, hint in [
            (
                absolute,
                "the noise and the error are not both relative to the bounding-box diagonal: the noise's standard "
                "deviation is sigma itself and the error is in length units",
                "noise of standard deviation sigma * d, and the RMS error divided by d",
            ),
            (
                run["noisy"],
                "the error is measured against the noisy mesh, not against the clean mesh, the truth",
                "return the RMS distance between the smoothed mesh and V_clean",
            ),
            (
                run["noise"],
                "the error is that of the noisy mesh: the smoothed mesh is not the one measured",
                "smooth the noisy mesh and measure the result against V_clean",
            ),
            (
                clean_smoothed,
                "the clean mesh was smoothed instead of the noisy one",
                "smooth W = V_clean + noise, then compare with V_clean",
            ),
        ]:
            if _near(first, target):
                raise Mistake(diagnosis, hint)
        raise Mistake(
            f"after {_EXP_ITERATIONS} implicit steps the error is {first:.4g}, expected about {run['right']:.4g} "
            f"(within {_EXP_TOLERANCE:.0%})",
            "smooth with geomlib.implicit_smoothing(W, F, tau, iterations) (cotangent weights)",
            typical=False,
        )
    # the relative error does not depend on the mesh's units: a tenth of the size, tau / 100
    small = _number(call(fn, V / 10, F.copy(), _EXP_SIGMA, tau / 100, _EXP_ITERATIONS, _EXP_SEED), "a smaller mesh")
    if not _near(small, first):
        raise Mistake(
            f"the same mesh at a tenth of the size (tau / 100) gave {small:.4g} instead of {first:.4g}: the noise "
            "and the error are not both relative to the bounding-box diagonal",
            "noise of standard deviation sigma * d, and the RMS error divided by d",
        )
    return [
        "a sphere of 2,562 vertices, d = 139 (within 5 % of geomlib's run)",
        "0 iterations",
        "the seed",
        "a tenth of the size",
    ]


# ------------------------------------------------------------------ the sweep over step and count
SWEEP_SECTION = "section 5 · The sweep, yours"
# the cases: icospheres of 642 and 162 vertices, scaled and moved away from the origin, with noise of 1.4 mean
# edges; three steps around the best, six iterations. Their tables, right and wrong, are made once per kernel.
_SWEEP_TAUS_ELL2, _SWEEP_ITERATIONS = (0.05, 0.2, 0.8), 6


def _sweep_table(W, F, truth, taus, iterations, weights="cotan", step="implicit", carry=False, rebuild=False):
    """E[i, k] for a sweep done right (the defaults) or in one of the catalogue's wrong ways."""
    from scipy.sparse.linalg import splu

    from ...lessons.laplace import laplacian

    d = bounding_box_diagonal(truth)
    rms = lambda P: float(np.sqrt(np.mean(np.sum((P - truth) ** 2, axis=1)))) / d  # noqa: E731
    E, P, (M, C) = np.empty((len(taus), iterations + 1)), W, laplacian(W, F, weights)
    for i, tau in enumerate(taus):
        P = P if carry else W
        E[i, 0] = rms(P)
        for k in range(1, iterations + 1):
            if rebuild:
                M, C = laplacian(P, F, weights)
            if step == "explicit":
                P = P + tau * (C @ P) / M.diagonal()[:, None]
            else:
                A = M + tau * C if step == "plus" else M - tau * C
                P = splu(A.tocsc()).solve(P if step == "rhs P" else M @ P)
            E[i, k] = rms(P)
    return E


#: the wrong tables the catalogue names, by the options of _sweep_table that make them
_VARIANTS = {
    "carry": {"carry": True},
    "rebuild": {"rebuild": True},
    "explicit": {"step": "explicit"},
    "plus": {"step": "plus"},
    "rhs P": {"step": "rhs P"},
    "uniform": {"weights": "uniform"},
}


def _best(E, taus, count_from=0, pick=np.argmin, index=False):
    i, k = np.unravel_index(pick(E), E.shape)
    return (i if index else taus[i]), int(k) + count_from, E


@functools.lru_cache(maxsize=1)
def _sweep_cases():
    from ..shapes.surfaces import icosphere

    cases = []
    for label, (V0, F0), scale in (
        ("an icosphere of 642 vertices", icosphere(3), 40.0),
        ("one of 162", icosphere(2), 3.0),
    ):
        V0, F0 = np.asarray(V0, float) * scale + np.array([-4.0, 9.0, 2.0]), np.asarray(F0)
        ell = mean_edge_length(V0, F0)
        W = V0 + 1.4 * ell * np.random.default_rng(17).standard_normal(V0.shape)
        taus = [t * ell**2 for t in _SWEEP_TAUS_ELL2]
        tables = {v: _sweep_table(W, F0, V0, taus, _SWEEP_ITERATIONS, **kw) for v, kw in _VARIANTS.items()}
        tables["noisy"] = _sweep_table(W, F0, W, taus, _SWEEP_ITERATIONS)
        case = Case(label, W=W, F=F0, V_clean=V0, taus=taus, iterations=_SWEEP_ITERATIONS)
        cases.append(case.but(right=_best(_sweep_table(W, F0, V0, taus, _SWEEP_ITERATIONS), taus), tables=tables))
    return cases


def _sweep_flat(out, case):
    """(tau_best, N_best, E) as one float vector, each part on the scale of its right value."""
    if not isinstance(out, (tuple, list)) or len(out) != 3:
        raise Mistake(
            "the function did not return the triple (tau_best, N_best, E)",
            "end with `return tau_best, N_best, E`",
            typical=False,
        )
    E = np.asarray(out[2], dtype=float) if not isinstance(out[2], (int, float)) else None
    if E is None or E.ndim != 2:
        raise Mistake(
            "E is not a table (a 2-D array)",
            "E[i, k]: one row per step, one column per count 0..iterations",
            typical=False,
        )
    tau, count = number(out[0], "tau_best"), number(out[1], "N_best")
    return np.concatenate([[tau / case.taus[-1], count / case.iterations], E.ravel() / case.right[2].max()])


def _as(case, tau_N_E):
    return _sweep_flat(tau_N_E, case)


def _wrong(diagnosis, hint, make):
    return Wrong(diagnosis, hint, build=lambda c: _as(c, make(c)))


SWEEP_MISTAKES = [
    _wrong(
        "the error is measured against the noisy mesh W (E[:, 0] is 0), not against V_clean",
        "E = my_vertex_rms(P, V_clean)",
        lambda c: _best(c.tables["noisy"], c.taus),
    ),
    _wrong(
        "each step's run starts where the previous step's ended, not from the noisy mesh W",
        "set P = W before each step's iterations",
        lambda c: _best(c.tables["carry"], c.taus),
    ),
    _wrong(
        "M and C are rebuilt from the smoothed mesh at every iteration: the sweep keeps W's operator",
        "build M, C = laplacian(W, F) once, before the loops",
        lambda c: _best(c.tables["rebuild"], c.taus),
    ),
    _wrong(
        "these are explicit steps, P + tau M^-1 C P, not implicit ones",
        "solve (M - tau C) P' = M P at every iteration",
        lambda c: _best(c.tables["explicit"], c.taus),
    ),
    _wrong(
        "the sign of tau C is flipped: (M + tau C) P' = M P",
        "the implicit step solves (M - tau C) P' = M P",
        lambda c: _best(c.tables["plus"], c.taus),
    ),
    _wrong(
        "the right-hand side is P, not M P",
        "solve (M - tau C) P' = M P: the areas multiply P too",
        lambda c: _best(c.tables["rhs P"], c.taus),
    ),
    _wrong(
        "uniform weights: the sweep smooths with the cotangent Laplacian",
        "M, C = geomlib.laplacian(W, F), whose weights are cotangent",
        lambda c: _best(c.tables["uniform"], c.taus),
    ),
    _wrong(
        "the table has no column for 0 iterations: E[i, k] is the error after k + 1 steps",
        "E has iterations + 1 columns, k = 0 being W itself",
        lambda c: (c.right[0], c.right[1] - 1, c.right[2][:, 1:]),
    ),
    _wrong(
        "the table is transposed: its rows are counts and its columns steps",
        "E[i, k]: row i for taus[i], column k for k steps",
        lambda c: (c.right[0], c.right[1], c.right[2].T),
    ),
    _wrong(
        "the best setting is the largest error (argmax), not the smallest",
        "np.argmin over the whole table",
        lambda c: _best(c.right[2], c.taus, pick=np.argmax),
    ),
    _wrong(
        "N_best is one too many: the count of column k is k, not k + 1",
        "the column index k is the number of steps",
        lambda c: _best(c.right[2], c.taus, count_from=1),
    ),
    _wrong(
        "tau_best is the index of the best step, not the step itself",
        "return taus[i], not i",
        lambda c: _best(c.right[2], c.taus, index=True),
    ),
    Wrong(
        "the table or the best setting differs from the right one on {label}",
        "E[i, k] = my_vertex_rms after k implicit steps of taus[i]",
        typical=False,
    ),
]


@exercise(
    "denoising_sweep",
    reread=SWEEP_SECTION,
    forbid=(
        "lessons.noise.denoising_sweep",
        "lessons.smoothing.implicit_smoothing",
        "lessons.smoothing.ImplicitSmoother",
        "lessons.noise.denoising_experiment",
        "lessons.metrics.vertex_rms",
        "lessons.metrics.MeshComparison",
        "teaching.experiments.sweep.smoothing_sweep",
        "teaching.experiments.sweep.denoising_comparison",
    ),
    allow=("lessons.laplace.laplacian",),
)
def denoising_sweep(fn):
    """Check ``fn(W, F, V_clean, taus, iterations) -> (tau_best, N_best, E)`` (section 5 of notebook 07)."""
    cases = _sweep_cases()
    answers = [
        _sweep_flat(call(fn, *(x.copy() if hasattr(x, "copy") else x for x in c.inputs.values())), c) for c in cases
    ]
    judge(SWEEP_MISTAKES, cases, answers, right=lambda c: _as(c, c.right))
    return [c.label + f" ({len(c.taus)} steps, {c.iterations} iterations)" for c in cases]
