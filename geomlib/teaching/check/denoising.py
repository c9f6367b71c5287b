"""Checks of the exercises of notebook 07: the noise, the error, the experiment and the sweep.

``add_noise(fn)`` checks ``fn(V, F, sigma, seed) -> V'``: Gaussian noise with standard
deviation ``s = sigma * d`` per coordinate, ``d`` the bounding-box diagonal of V, independent
per vertex and coordinate, seeded, V untouched. Noise is random, so this check is statistical:
it measures the noise on a regular grid of 2,400 vertices (7,200 numbers, the standard
deviation then known to about 1 %) and accepts a standard deviation within 6 % of ``s``. The
wrong scalings it names are far apart on purpose: on the grid d = 357.1, the mean edge length
ell = 5.72, the length of the largest corner |max(V)| = 1,442 (the grid sits away from the
origin) and 1 differ by large factors. Coordinates of a vertex that move together (one normal
number shared by x, y and z) are told by their correlation, and float32 positions by their
rounding.

``vertex_rms(fn)`` checks ``fn(V, V_clean) -> float``:
``sqrt(mean_i |x_i - x_i^clean|^2) / d_clean`` on cases with exact answers.

``denoising_experiment(fn)`` checks ``fn(V_clean, F, sigma, tau, iterations, seed) -> E``:
seeded noise relative to d, ``iterations`` implicit cotangent steps of ``tau`` from the
noisy mesh, and the vertex RMS error against the *clean* mesh over its d. Any correct noise
draw is accepted (``rng.normal``, another order of the draws), so noisy runs are compared
statistically: on the shipped sphere scaled to d = 139 (2,562 vertices) the error of a correct
run varies by about 1 % from one noise pattern to another, and a value within 5 % of geomlib's
passes. One run has no noise (sigma = 0): its error is the shrinkage alone and is compared
exactly, which tells N iterations from N - 1 or N + 1.

``denoising_sweep(fn)`` checks ``fn(W, F, V_clean, taus, iterations) -> (tau_best, N_best, E)``
on two noisy icospheres, every entry of the table exactly.
"""

import functools
from pathlib import Path

import numpy as np

from ...mesh.geometry import bounding_box_diagonal, mean_edge_length
from .catalogue import Case, Wrong, answer, judge, number, run
from .result import Mistake, call, exercise

__all__ = ["add_noise", "vertex_rms", "denoising_experiment", "denoising_sweep"]


def _grid(nx, ny, spacing, height):
    """A regular grid of nx x ny vertices (spacing apart) on a tilted plane, two triangles per cell."""
    x, y = np.meshgrid(np.arange(nx) * spacing, np.arange(ny) * spacing)
    V = np.column_stack([x.ravel(), y.ravel(), height * x.ravel() / x.max()])
    i = np.arange(nx * ny).reshape(ny, nx)
    a, b, c, d = i[:-1, :-1].ravel(), i[:-1, 1:].ravel(), i[1:, 1:].ravel(), i[1:, :-1].ravel()
    return V, np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])])


def _rms(X, Y):
    return float(np.sqrt(np.mean(np.sum((X - Y) ** 2, axis=1))))


def _scalar(diagnosis, hint, value):
    """A wrong answer that is one number, ``value(case)``."""
    return Wrong(diagnosis, hint, build=lambda c: np.array([value(c)]))


# ------------------------------------------------------------------ the noise
# 60 x 40 vertices 5 apart, moved away from the origin: d = 357.1, ell = 5.72, |max corner| = 1,442
_NOISE_V, _NOISE_F = _grid(60, 40, 5.0, 50.0)
_NOISE_V = _NOISE_V + np.array([1100.0, -900.0, 240.0])
_SIGMA, _SEED, _STD_TOLERANCE = 0.02, 3, 0.06


class _Noise:
    """What the learner's noise function did on a case: its four calls, and the statistics of the first."""

    def __init__(self, fn, V, F):
        draw = lambda sigma, seed, what: _array(call(fn, V.copy(), F.copy(), sigma, seed), len(V), what)  # noqa: E731
        self.out = draw(_SIGMA, _SEED, "the function")
        self.again, self.other = draw(_SIGMA, _SEED, "a second call"), draw(_SIGMA, _SEED + 1, "another seed")
        self.zero, self.V = draw(0.0, _SEED, "the call with sigma = 0"), V
        D = self.out.astype(float) - V
        self.D, self.std = D, float(D.std()) if D.any() else 0.0
        z = D / max(self.std, 1e-300)
        self.mean, self.axes, self.kurtosis = z.mean(axis=0), z.std(axis=0), float(np.mean(z**4))
        self.correlation = float(np.abs(np.corrcoef(D.T) - np.eye(3)).max()) if np.all(D.std(axis=0) > 0) else 0.0


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
    return out


def _near(a, b, tolerance=_STD_TOLERANCE):
    return abs(a - b) <= tolerance * abs(b)


def _std_is(factor):
    """A ``when`` that the noise's standard deviation is ``factor(case)``."""
    return lambda a, s, c: _near(a.std, factor(c))


# fmt: off
NOISE_MISTAKES = [
    Wrong('two calls with the same seed gave different noise: it is not seeded (not reproducible)', 'draw from rng = np.random.default_rng(seed), not from np.random directly', when=lambda a, s, c: not np.array_equal(a.out, a.again)),
    Wrong('another seed gave the same noise: the seed is ignored', 'pass the seed to np.random.default_rng(seed)', when=lambda a, s, c: np.array_equal(a.out, a.other)),
    Wrong('the positions are float32: rounded to 7 digits, a precision problem, not noise', "keep float64: numpy's standard_normal gives float64; drop the dtype=np.float32 (or astype)", when=lambda a, s, c: a.out.dtype == np.float32 or np.array_equal(a.out, a.out.astype(np.float32))),
    Wrong('sigma = 0 still moved the vertices', 'the noise must be sigma * d times the unit noise', when=lambda a, s, c: not np.allclose(a.zero, a.V, rtol=0, atol=1e-12 * c.d)),
    Wrong('the vertices did not move', 'add the noise to V and return the result', when=lambda a, s, c: a.std == 0, typical=False),
    Wrong('every vertex moved by the same vector: the whole mesh was shifted, not made noisy', 'draw an (n, 3) array of noise, one independent vector per vertex', when=lambda a, s, c: np.allclose(a.D, a.D[0], rtol=0, atol=1e-09 * c.d)),
    Wrong('the noise is not centred', 'use standard normal numbers (mean 0), e.g. rng.standard_normal((n, 3))', when=lambda a, s, c: np.abs(a.mean).max() > 5 / np.sqrt(c.n)),
    Wrong('x, y and z of a vertex move together: one normal number is shared by the three coordinates', 'draw an independent number for every coordinate: rng.standard_normal((n, 3))', when=lambda a, s, c: a.correlation > 0.5),
    Wrong('the coordinates are not equally noisy', 'every coordinate of every vertex gets its own standard normal number times s', when=lambda a, s, c: np.abs(a.axes - 1).max() > _STD_TOLERANCE),
    Wrong('the noise is not scaled by the bounding box: its standard deviation is sigma itself', 'sigma is a fraction of the bounding-box diagonal d; multiply the unit noise by s = sigma * d', when=_std_is(lambda c: _SIGMA)),
    Wrong('the noise is scaled by the mean edge length instead of the bounding-box diagonal', 's = sigma * d with d = |max(V) - min(V)|, the bounding-box diagonal', when=_std_is(lambda c: _SIGMA * c.ell)),
    Wrong('the noise is scaled by the length of the largest corner |max(V)|, not by the diagonal |max(V) - min(V)|', 'd = np.linalg.norm(V.max(axis=0) - V.min(axis=0))', when=_std_is(lambda c: _SIGMA * c.corner)),
    Wrong('sigma is used as a variance: the standard deviation came out as sigma^2 * d', 'sigma is the standard deviation; draw standard normals and multiply by sigma * d', when=_std_is(lambda c: _SIGMA ** 2 * c.d)),
    Wrong('the variance s^2 is used where the standard deviation s belongs', 'multiply standard normal numbers by s = sigma * d, not by s^2', when=_std_is(lambda c: (_SIGMA * c.d) ** 2)),
    Wrong('the square root of s is used: sigma * d was taken as a variance', 'the standard deviation is s = sigma * d itself', when=_std_is(lambda c: np.sqrt(_SIGMA * c.d))),
    Wrong('each displacement has length about s (a random direction scaled to s), so each coordinate moves by only s / sqrt(3)', 'draw each of the three coordinates independently with standard deviation s', when=lambda a, s, c: _std_is(lambda c: s / np.sqrt(3))(a, s, c) and np.ptp(np.linalg.norm(a.D, axis=1)) <= 1e-6 * c.d),
    Wrong('the noise is not Gaussian (a normal distribution has kurtosis 3, a uniform one 1.8)', 'use rng.standard_normal, not rng.random or rng.uniform', when=lambda a, s, c: a.kurtosis < 2.5),
    Wrong('the standard deviation per coordinate differs from s = sigma * d', 'multiply standard normal numbers by sigma times the bounding-box diagonal of V', when=lambda a, s, c: not _near(a.std, s), typical=False),
]
# fmt: on


def _noise_ok(a, s, c):
    return not any(w.when(a, s, c) for w in NOISE_MISTAKES)


@exercise("add_noise", reread="section 2 · The noise, yours", forbid=("lessons.noise.add_noise",))
def add_noise(fn):
    """Check ``fn(V, F, sigma, seed) -> V'``: V + sigma * d * (independent standard normals)."""
    V, F = _NOISE_V, _NOISE_F
    case = Case(f"a {len(V)}-vertex grid", V=V, F=F).but(
        d=bounding_box_diagonal(V), ell=mean_edge_length(V, F), corner=float(np.linalg.norm(V.max(axis=0))), n=len(V)
    )
    judge(NOISE_MISTAKES, [case], [_Noise(fn, V, F)], right=lambda c: _SIGMA * c.d, same=_noise_ok)
    return [
        f"{case.label} (s = sigma * d within {_STD_TOLERANCE:.0%}, centred, Gaussian, independent per vertex and coordinate)",
        "reproducibility with a seed",
        "V left unchanged",
        "sigma = 0",
    ]


# ------------------------------------------------------------------ the error
# a tetrahedron with one vertex moved by 3 (exact answer 1.5 / d), a lopsided displacement field, no change;
# each away from the origin
_TET = np.array([[0.0, 0, 0], [2, 0, 0], [0, 1, 0], [0, 0, 4]]) + np.array([7.0, -3.0, 11.0])


def _rms_cases():
    moved = _TET.copy()
    moved[1, 0] += 3.0  # also widens the noisy bounding box
    grid = _grid(7, 5, 1.0, 2.0)[0] + np.array([-20.0, 4.0, 9.0])
    bumped = grid + np.random.default_rng(5).standard_normal(grid.shape) * np.linspace(0.05, 1.5, len(grid))[:, None]
    cases = [
        Case(label, V=V, V_clean=W)
        for label, V, W in (
            ("a tetrahedron with one vertex moved by 3", moved, _TET),
            ("a grid with displacements of very different sizes", bumped, grid),
            ("a mesh compared with itself", grid.copy(), grid),
        )
    ]
    return [c.but(e2=np.sum((c.V - c.V_clean) ** 2, axis=1), d=bounding_box_diagonal(c.V_clean), n=1) for c in cases]


# fmt: off
RMS_MISTAKES = [
    _scalar('the result is negative', 'a root mean square is >= 0', lambda c: -np.sqrt(c.e2.mean()) / c.d),
    _scalar('the result is not relative: it is in length units, not divided by the bounding-box diagonal', 'divide by d, the bounding-box diagonal of the clean mesh', lambda c: np.sqrt(c.e2.mean())),
    _scalar('this is the mean of the distances, not the root of the mean square', 'square each distance, average, then take the square root', lambda c: np.sqrt(c.e2).mean() / c.d),
    _scalar('the mean squared error is not rooted', 'take the square root of the mean of |x_i - x_i^clean|^2', lambda c: c.e2.mean() / c.d),
    _scalar('the mean squared error is not rooted (this is RMS^2)', 'take the square root of the mean before comparing', lambda c: c.e2.mean() / c.d ** 2),
    _scalar('the squared distances are summed, not averaged', 'divide the sum by the number of vertices n before the square root', lambda c: np.sqrt(c.e2.sum()) / c.d),
    _scalar('the distances are summed, not averaged (and not squared)', 'RMS = sqrt(mean_i |x_i - x_i^clean|^2)', lambda c: np.sqrt(c.e2).sum() / c.d),
    _scalar('the mean runs over the 3n coordinates instead of the n vertices', "square the length of each vertex's displacement, then average over vertices", lambda c: np.sqrt(c.e2.mean() / 3) / c.d),
    _scalar("divided by the noisy mesh's diagonal instead of the clean one", 'd is the bounding-box diagonal of V_clean, the truth we measure against', lambda c: np.sqrt(c.e2.mean()) / bounding_box_diagonal(c.V)),
    Wrong('the result differs from sqrt(mean_i |x_i - x_i^clean|^2) / d on {label}', "d is the clean mesh's bounding-box diagonal", typical=False),
]
# fmt: on


@exercise(
    "vertex_rms",
    reread="section 3 · The error, yours",
    forbid=("lessons.metrics.vertex_rms", "lessons.metrics.denoising_metrics", "lessons.metrics.MeshComparison"),
)
def vertex_rms(fn):
    """Check ``fn(V, V_clean) -> float``: sqrt(mean_i |x_i - x_i^clean|^2) / d(V_clean)."""
    cases = _rms_cases()
    hint = "average over all vertices and return one float, the RMS distance divided by the diagonal"
    answers = run(fn, cases, lambda out, n: np.array([number(out, hint=hint)]))
    judge(RMS_MISTAKES, cases, answers, right=lambda c: np.array([np.sqrt(c.e2.mean()) / c.d]))
    return [c.label for c in cases]


# ------------------------------------------------------------------ the experiment
# the shipped sphere, scaled and moved so that d (139), the mean edge (3.0) and 1 are far apart; noise of 1.4
# mean edges; a short implicit run that removes a fifth of it. Noisy runs are compared within 5 %; the run
# without noise exactly (1e-6: float32's rounding passes), which tells the iteration count.
_SCALE, _SHIFT = 40.0, np.array([3.0, -2.0, 5.0])
_EXP_SIGMA, _EXP_TAU_ELL2, _EXP_ITERATIONS, _EXP_SEED = 0.03, 0.2, 5, 11
_EXP_TOLERANCE, _EXACT = 0.05, 1e-6


@functools.lru_cache(maxsize=1)
def _sphere():
    from ...mesh.io import load_mesh

    V, F = load_mesh(Path(__file__).resolve().parents[2] / "meshes" / "sphere.obj")  # shipped package data
    V = _SCALE * V + _SHIFT
    V.flags.writeable = F.flags.writeable = False  # kept for every check: the learner gets copies
    return V, F


@functools.lru_cache(maxsize=64)  # the check runs three times per exercise (check, partial credit, reveal)
def _run(sigma, tau, iterations, directions=False):
    """geomlib's experiment on the check's sphere: E, and E measured against the noisy mesh and of the noisy
    mesh itself; ``directions``: each vertex moved by sigma d along a random direction instead."""
    from ...lessons.noise import add_noise as noise
    from ...lessons.smoothing import implicit_smoothing

    V, F = _sphere()
    d = bounding_box_diagonal(V)
    X = np.random.default_rng(_EXP_SEED).standard_normal(V.shape)
    W = V + sigma * d * X / np.linalg.norm(X, axis=1, keepdims=True) if directions else noise(V, F, sigma, _EXP_SEED)
    P = implicit_smoothing(W, F, tau, iterations)
    pairs = {"right": (P, V, d), "noisy": (P, W, d), "noisy d": (P, W, bounding_box_diagonal(W)), "noise": (W, V, d)}
    return {key: _rms(A, B) / diagonal for key, (A, B, diagonal) in pairs.items()}


def _experiment_cases():
    V, F = _sphere()
    d, ell, n = bounding_box_diagonal(V), mean_edge_length(V, F), _EXP_ITERATIONS
    tau = _EXP_TAU_ELL2 * ell**2
    table = [("0 iterations (the noise itself)", 1.0, _EXP_SIGMA, 0), (f"{n} iterations", 1.0, _EXP_SIGMA, n)]
    table += [(f"no noise, {n} iterations", 1.0, 0.0, n), ("a tenth of the size (tau / 100)", 0.1, _EXP_SIGMA, n)]
    return [
        Case(label, V=size * V, F=F, sigma=s, tau=size**2 * tau, iterations=k, seed=_EXP_SEED).but(
            size=size, d=size * d, ell=size * ell, tau1=tau
        )
        for label, size, s, k in table
    ]


def _e(c, sigma=None, iterations=None, key="right", directions=False):
    """The experiment of case ``c`` with another noise level, count or noise (the sphere at full size: E is
    relative, the same at a tenth of the size)."""
    sigma = c.sigma if sigma is None else sigma
    return _run(sigma, c.tau1, c.iterations if iterations is None else max(iterations, 0), directions)[key]


# fmt: off
EXPERIMENT_MISTAKES = [
    _scalar('one iteration short: the run without noise shrank the sphere by N - 1 steps, not N', 'smooth for exactly `iterations` steps: range(iterations)', lambda c: _e(c, iterations=c.iterations - 1)),
    _scalar('one iteration too many: the run without noise shrank the sphere by N + 1 steps', 'smooth for exactly `iterations` steps', lambda c: _e(c, iterations=c.iterations + 1)),
    _scalar("the error is absolute (length units): it is not divided by the clean mesh's bounding-box diagonal", 'divide the RMS distance by d, the bounding-box diagonal of V_clean', lambda c: _e(c) * c.d),
    _scalar('the noise is not relative to the bounding-box diagonal: its standard deviation is sigma itself', 'scale the standard normal numbers by sigma * d, d the diagonal of V_clean', lambda c: _e(c, sigma=c.sigma / c.d)),
    _scalar("the noise and the error are not both relative to the bounding-box diagonal: the noise's standard deviation is sigma itself and the error is in length units", 'noise of standard deviation sigma * d, and the RMS error divided by d', lambda c: _e(c, sigma=c.sigma / c.d) * c.d),
    _scalar('the noise is scaled by the mean edge length instead of the bounding-box diagonal', 'scale the standard normal numbers by sigma * d', lambda c: _e(c, sigma=c.sigma * c.ell / c.d)),
    _scalar('the error is sqrt(3) too small (its square a third of the right one): the mean runs over the 3n coordinates instead of the n vertices', 'average |p_i - x_i|^2 over the n vertices', lambda c: _e(c) / np.sqrt(3)),
    _scalar('the noise is sqrt(3) too small (its square a third of the right one): each vertex moved by a random direction of length sigma * d, so each coordinate moves by only sigma * d / sqrt(3)', 'draw every coordinate with standard deviation sigma * d', lambda c: _e(c, directions=True)),
    _scalar('the error is measured against the noisy mesh (the input of the smoothing), not against the clean mesh, the truth', 'return the RMS distance between the smoothed mesh and V_clean', lambda c: _e(c, key='noisy')),
    _scalar('the error is measured against the noisy mesh W (as my_vertex_rms(P, W)), not against the clean mesh, the truth', 'return my_vertex_rms(P, V_clean): the smoothed mesh against V_clean', lambda c: _e(c, key='noisy d')),
    _scalar('the error is that of the noisy mesh: the smoothed mesh is not the one measured', 'smooth the noisy mesh and measure the result against V_clean', lambda c: _e(c, key='noise')),
    _scalar('the clean mesh was smoothed instead of the noisy one', 'smooth W = V_clean + noise, then compare with V_clean', lambda c: _e(c, sigma=0.0)),
    Wrong("on {label} the error differs from geomlib's run (by more than 5 %, or at all without noise)", 'smooth with geomlib.implicit_smoothing(W, F, tau, iterations) (cotangent weights)', typical=False),
]
# fmt: on


def _same_e(a, r, c):
    return abs(a[0] - r[0]) <= (_EXACT if c.sigma == 0 else _EXP_TOLERANCE) * abs(r[0])


@exercise(
    "denoising_experiment",
    reread="section 4 · The experiment, yours",
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
    cases = _experiment_cases()
    E = lambda c, **kw: number(answer(fn, c, **kw), hint="return the one relative error, a float")
    answers = [np.array([E(c)]) for c in cases]
    if not np.isclose(E(cases[1]), answers[1][0], rtol=1e-9, atol=0):
        raise Mistake(
            "two calls with the same seed gave different errors: the noise is not seeded, so the experiment cannot be repeated",
            "draw the noise from np.random.default_rng(seed)",
        )
    if E(cases[1], seed=_EXP_SEED + 1) == answers[1][0] and not np.isclose(answers[2][0], answers[1][0], rtol=1e-9):
        raise Mistake("another seed gave the very same error: the seed is ignored", "pass seed to default_rng(seed)")
    judge(EXPERIMENT_MISTAKES, cases, answers, right=lambda c: np.array([_e(c)]), same=_same_e)
    return [f"a sphere of 2,562 vertices, d = 139: {', '.join(c.label for c in cases)}"]


# ------------------------------------------------------------------ the sweep over step and count
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
_VARIANTS = {"carry": {"carry": True}, "rebuild": {"rebuild": True}, "uniform": {"weights": "uniform"}}
_VARIANTS |= {step: {"step": step} for step in ("explicit", "plus", "rhs P")}


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


def _wrong(diagnosis, hint, make):
    """A wrong triple (tau_best, N_best, E), ``make(case)``."""
    return Wrong(diagnosis, hint, build=lambda c: _sweep_flat(make(c), c))


# fmt: off
SWEEP_MISTAKES = [
    _wrong('the error is measured against the noisy mesh W (E[:, 0] is 0), not against V_clean', 'E = my_vertex_rms(P, V_clean)', lambda c: _best(c.tables['noisy'], c.taus)),
    _wrong("each step's run starts where the previous step's ended, not from the noisy mesh W", "set P = W before each step's iterations", lambda c: _best(c.tables['carry'], c.taus)),
    _wrong("M and C are rebuilt from the smoothed mesh at every iteration: the sweep keeps W's operator", 'build M, C = laplacian(W, F) once, before the loops', lambda c: _best(c.tables['rebuild'], c.taus)),
    _wrong('these are explicit steps, P + tau M^-1 C P, not implicit ones', "solve (M - tau C) P' = M P at every iteration", lambda c: _best(c.tables['explicit'], c.taus)),
    _wrong("the sign of tau C is flipped: (M + tau C) P' = M P", "the implicit step solves (M - tau C) P' = M P", lambda c: _best(c.tables['plus'], c.taus)),
    _wrong('the right-hand side is P, not M P', "solve (M - tau C) P' = M P: the areas multiply P too", lambda c: _best(c.tables['rhs P'], c.taus)),
    _wrong('uniform weights: the sweep smooths with the cotangent Laplacian', 'M, C = geomlib.laplacian(W, F), whose weights are cotangent', lambda c: _best(c.tables['uniform'], c.taus)),
    _wrong('the table has no column for 0 iterations: E[i, k] is the error after k + 1 steps', 'E has iterations + 1 columns, k = 0 being W itself', lambda c: (c.right[0], c.right[1], c.right[2][:, 1:])),
    _wrong('the table is transposed: its rows are counts and its columns steps', 'E[i, k]: row i for taus[i], column k for k steps', lambda c: (c.right[0], c.right[1], c.right[2].T)),
    _wrong('the best setting is the largest error (argmax), not the smallest', 'np.argmin over the whole table', lambda c: _best(c.right[2], c.taus, pick=np.argmax)),
    _wrong('N_best is one too many: the count of column k is k, not k + 1', 'the column index k is the number of steps', lambda c: _best(c.right[2], c.taus, count_from=1)),
    _wrong('tau_best is the index of the best step, not the step itself', 'return taus[i], not i', lambda c: _best(c.right[2], c.taus, index=True)),
    Wrong('the table or the best setting differs from the right one on {label}', 'E[i, k] = my_vertex_rms after k implicit steps of taus[i]', typical=False),
]
# fmt: on


@exercise(
    "denoising_sweep",
    reread="section 5 · The sweep, yours",
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
    answers = [_sweep_flat(answer(fn, c), c) for c in cases]
    judge(SWEEP_MISTAKES, cases, answers, right=lambda c: _sweep_flat(c.right, c))
    return [c.label + f" ({len(c.taus)} steps, {c.iterations} iterations)" for c in cases]
