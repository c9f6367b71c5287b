"""Checks of the exercises of notebook 07: the noise, the measures, the experiment and the sweep.

``add_noise(fn)``: ``fn(V, F, sigma, seed) -> V'``, Gaussian noise of standard deviation ``s = sigma * d`` per
coordinate (d the bounding-box diagonal of V), independent, seeded, V untouched. Statistical: on a grid of 2,400
vertices (d = 357.1, mean edge 5.72, largest corner |max(V)| = 1,442 and 1 far apart, so the wrong scalings it
names are too) a standard deviation within 6 % of s passes; shared x, y, z are told by their correlation.

``denoising_metrics(fn)``: ``fn(V, V_clean, F) -> {"rms", "normal_mean", "volume_change"}``, geomlib's definitions
(:mod:`geomlib.lessons.metrics`), each measure compared to 1e-6 of itself on two closed meshes. The two volumes
are handed out (:func:`geomlib.enclosed_volume`, written in notebook 06): the mistakes named are in the change.

``denoising_experiment(fn)``: ``fn(V_clean, F, sigma, tau, iterations, seeds) -> (E_mean, E_std)``, per seed noise,
``iterations`` implicit cotangent steps and E against the clean mesh; the mean and the sample standard deviation
(ddof = 1) of the draws' E. One draw is ``seeds=(s, s)``: any correct noise draw passes, so noisy runs on the
shipped sphere (d = 139; E varies by about 1 % between draws) pass within 5 % of geomlib's; a run without noise
(its E the shrinkage alone) is compared exactly and tells N iterations from N - 1 or N + 1. Over three seeds the
mean and spread are compared exactly with those of the learner's own draws, each run alone.

``denoising_sweep(fn)``: ``fn(W, F, V_clean, taus, iterations) -> (tau_best, N_best, E)`` on two noisy
icospheres, every entry of the table exactly.

``taubin_smoothing(fn)``: ``fn(V, F, tau_shrink, tau_inflate, pairs) -> P``, Taubin's pairs on the uniform operator
with the boundary held, against :func:`geomlib.taubin_smoothing` on an open bump and a closed icosphere.
"""

import functools
from pathlib import Path

import numpy as np

from ...lessons.metrics import face_normal_angles, vertex_rms, volume_change
from ...lessons.smoothing import taubin_smoothing as taubin_pairs
from ...mesh.geometry import bounding_box_diagonal, face_cross, face_volumes, mean_edge_length
from .catalogue import Case, Wrong, answer, judge, named, number, positions, run
from .meshes import bump_4x4, irregular_bipyramid, jittered_icosphere, placed
from .result import Mistake, call, case_rng, exercise

__all__ = ["add_noise", "denoising_metrics", "denoising_experiment", "denoising_sweep", "taubin_smoothing"]


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


# ------------------------------------------------------------------ the measures
# away from the origin (placed), closed: an icosphere with one vertex pulled out (74 of its 80 faces keep their
# normal: an unclipped arccos meets a dot a rounding error above 1), a bipyramid shrunk, noisy, an apex pushed through
_KEYS = ("rms", "normal_mean", "volume_change")
_METRICS = named("lessons.metrics", "denoising_metrics vertex_rms face_normal_angles volume_change MeshComparison")
_SWEEPS = named("teaching.experiments.sweep", "smoothing_sweep denoising_comparison")


def _pulled(V, c, ell, rng):  # vertex 0 moved outwards: the volume grows
    return V + np.where(np.arange(len(V))[:, None] == 0, 0.4 * ell * (V[0] - c) / np.linalg.norm(V[0] - c), 0.0)


def _shrunk(
    V, c, ell, rng
):  # and its farthest vertex reflected through the middle: two or more faces turn over 90 degrees
    far = np.argmax(np.linalg.norm(V - c, axis=1))
    V = np.where(np.arange(len(V))[:, None] == far, c - (V - c), V)
    return c + 0.85 * (V - c) + rng.normal(scale=0.15 * ell, size=V.shape)


def _measure_cases():
    rng, cases = case_rng(), []
    for label, mesh, move in (("an icosphere with one vertex pulled out", jittered_icosphere(), _pulled),
                              ("a bipyramid shrunk, made noisy and an apex pushed through", irregular_bipyramid(), _shrunk)):  # fmt: skip
        V_clean, F = placed(*mesh, rng)
        V = move(V_clean, V_clean.mean(axis=0), mean_edge_length(V_clean, F), rng)
        (N, t), (N_clean, t_clean) = ((face_cross(X, F), face_volumes(X, F)) for X in (V, V_clean))
        theta = face_normal_angles(V, V_clean, F)
        right = np.array([vertex_rms(V, V_clean), theta.mean(), volume_change(V, V_clean, F)])
        cases.append(Case(label, V=V, V_clean=V_clean, F=F).but(
            right=right, scale=np.abs(right), e2=np.sum((V - V_clean) ** 2, axis=1), d=bounding_box_diagonal(V_clean),
            d_noisy=bounding_box_diagonal(V), theta=theta, A_clean=np.linalg.norm(N_clean, axis=1) / 2, n=1,
            raw=np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", N, N_clean), -1, 1))), vol=t.sum(),
            vol_clean=t_clean.sum()))  # fmt: skip
    return cases


def _part(i, diagnosis, hint, value):
    """A wrong answer: the right measures with measure ``i`` replaced by ``value(case)``."""
    return Wrong(diagnosis, hint, build=lambda c: np.where(np.arange(3) == i, value(c), c.right) / c.scale)


def _measures(out, c):
    if not isinstance(out, dict) or not set(_KEYS) <= set(out):
        raise Mistake('the function did not return a dict with the keys "rms", "normal_mean" and "volume_change"',
                      'end with return {"rms": E, "normal_mean": ..., "volume_change": ...}', typical=False)  # fmt: skip
    return np.array([number(out[key], f'"{key}"') for key in _KEYS]) / c.scale


# fmt: off
MEASURE_MISTAKES = [
    _part(0, "E is not relative: it is in length units, not divided by the bounding-box diagonal", 'divide by d, the bounding-box diagonal of the clean mesh', lambda c: np.sqrt(c.e2.mean())),
    _part(0, "E is divided by the noisy mesh's diagonal instead of the clean one's", 'd is the bounding-box diagonal of V_clean, the truth we measure against', lambda c: np.sqrt(c.e2.mean()) / c.d_noisy),
    _part(0, 'in E the mean runs over the 3n coordinates instead of the n vertices', "square the length of each vertex's displacement, then average over vertices", lambda c: np.sqrt(c.e2.mean() / 3) / c.d),
    _part(0, 'E is the mean of the distances, not the root of the mean square', 'square each distance, average, then take the square root', lambda c: np.sqrt(c.e2).mean() / c.d),
    _part(0, 'E is not rooted (this is E^2)', 'take the square root of the mean of |x_i - x_i^clean|^2, then divide by d', lambda c: c.e2.mean() / c.d**2),
    _part(1, 'the mean angle is in radians, not degrees', 'np.degrees(angle)', lambda c: np.radians(c.theta.mean())),
    _part(1, 'the normals are not of unit length: arccos of the dot of two cross products is no angle', 'divide each cross product by its length before the dot product', lambda c: c.raw.mean()),
    _part(1, 'the angles are folded to at most 90 degrees (arccos of |n . n_clean|): a face turned over is 180 degrees off, not 0', 'arccos of the clipped dot product itself, without its absolute value', lambda c: np.minimum(c.theta, 180 - c.theta).mean()),
    Wrong('the mean angle is NaN: arccos got a dot product above 1 (normals not of unit length, or a rounding error above 1)', 'normalise the normals and clip the dot product to [-1, 1] before arccos', when=lambda a, r, c: np.isnan(a[1])),
    _part(1, 'the angles are summed over the faces, not averaged', 'the mean over faces: every face counts once', lambda c: c.theta.sum()),
    _part(1, 'the mean angle is weighted by the face areas: every face counts once', 'np.mean over the faces, unweighted', lambda c: c.theta @ c.A_clean / c.A_clean.sum()),
    _part(2, 'the volume change is absolute (length^3), not relative', "divide vol - vol_clean by |vol_clean|", lambda c: c.vol - c.vol_clean),
    _part(2, 'the volume change is divided by the new volume, not the clean one', '(vol - vol_clean) / |vol_clean|', lambda c: (c.vol - c.vol_clean) / c.vol),
    _part(2, 'this is the ratio vol / vol_clean, not the relative change', 'subtract 1: (vol - vol_clean) / |vol_clean|', lambda c: c.vol / c.vol_clean),
    _part(2, 'the sign of the volume change is flipped: a mesh that shrank must give a negative change', '(vol - vol_clean), not (vol_clean - vol)', lambda c: (c.vol_clean - c.vol) / c.vol_clean),
    Wrong('the measures differ from the right ones on {label}', 'E over the clean diagonal, the mean face-normal angle in degrees, the signed relative volume change', typical=False),
]
# fmt: on


@exercise("denoising_metrics", reread="section 3 · The measures, yours", forbid=_METRICS, own=named("lessons.metrics", "vertex_rms face_normal_angles volume_change"), allow=("mesh.geometry.enclosed_volume",))  # fmt: skip
def denoising_metrics(fn):
    """Check ``fn(V, V_clean, F) -> {"rms": E, "normal_mean": degrees, "volume_change": signed fraction}``."""
    cases = _measure_cases()
    answers = [_measures(answer(fn, c), c) for c in cases]
    judge(MEASURE_MISTAKES, cases, answers, right=lambda c: c.right / c.scale)
    return [c.label for c in cases]


# ------------------------------------------------------------------ the experiment
# the shipped sphere, scaled and moved so that d (139), the mean edge (3.0) and 1 are far apart; noise of 1.4
# mean edges; a short implicit run that removes a fifth of it. Noisy runs are compared within 5 %; the run
# without noise exactly (1e-6: float32's rounding passes), which tells the iteration count.
_SCALE, _SHIFT = 40.0, np.array([3.0, -2.0, 5.0])
_EXP_SIGMA, _EXP_TAU_ELL2, _EXP_ITERATIONS, _EXP_SEED = 0.03, 0.2, 5, 11
_EXP_TOLERANCE, _EXACT, _SEEDS = 0.05, 1e-6, (11, 12, 13)


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
        Case(label, V=size * V, F=F, sigma=s, tau=size**2 * tau, iterations=k, seeds=(_EXP_SEED, _EXP_SEED)).but(
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
    _scalar('the error is measured against the noisy mesh W (as my_denoising_metrics(P, W, F)), not against the clean mesh, the truth', 'measure the smoothed mesh against V_clean: my_denoising_metrics(P, V_clean, F)', lambda c: _e(c, key='noisy d')),
    _scalar('the error is that of the noisy mesh (the mean over the noisy meshes): the smoothed mesh is not the one measured', 'smooth the noisy mesh and measure the result against V_clean', lambda c: _e(c, key='noise')),
    _scalar('the clean mesh was smoothed instead of the noisy one', 'smooth W = V_clean + noise, then compare with V_clean', lambda c: _e(c, sigma=0.0)),
    Wrong("on {label} the error differs from geomlib's run (by more than 5 %, or at all without noise)", 'smooth with geomlib.implicit_smoothing(W, F, tau, iterations) (cotangent weights)', typical=False),
]
# fmt: on


def _same_e(a, r, c):
    return abs(a[0] - r[0]) <= (_EXACT if c.sigma == 0 else _EXP_TOLERANCE) * abs(r[0])


def _pair(out):
    if not isinstance(out, (tuple, list)) or len(out) != 2:
        raise Mistake("the function did not return the pair (E_mean, E_std)", "end with `return E_mean, E_std`", typical=False)  # fmt: skip
    return number(out[0], "E_mean"), number(out[1], "E_std")


def _spread(m, s, c):
    """(E_mean, E_std) on the scale of the learner's own draws' mean and standard deviation."""
    return np.array([m / c.E.mean(), s / max(np.std(c.E, ddof=1), 1e-300)])


# fmt: off
SPREAD_MISTAKES = [
    Wrong('the same seed made every draw (std 0): each draw takes its own seed', 'for seed in seeds: W = my_add_noise(V_clean, F, sigma, seed)', build=lambda c: _spread(c.E[0], 0.0, c)),
    Wrong('the standard deviation is the population one (ddof = 0): the sample one divides by k - 1', 'np.std(E, ddof=1), k the number of seeds', build=lambda c: _spread(c.E.mean(), np.std(c.E), c)),
    Wrong("the standard deviation is that of the noisy meshes' E, not of the smoothed ones'", 'collect E of the smoothed mesh P for every seed, then take its std', build=lambda c: _spread(c.E.mean(), np.std(c.E_noisy, ddof=1), c)),
    Wrong('on {label} the mean or the std is not that of your own draws, each run alone', 'E_mean = np.mean(E), E_std = np.std(E, ddof=1), E one error per seed', typical=False),
]
# fmt: on


@exercise(
    "denoising_experiment",
    reread="section 4 · The experiment, yours",
    forbid=(*named("lessons.noise", "denoising_experiment denoising_spread add_noise"), *_METRICS, *_SWEEPS),
    own=named("lessons.noise", "denoising_spread denoising_experiment"),
    allow=("lessons.smoothing.implicit_smoothing", "mesh.geometry.enclosed_volume"),  # the latter in your measures
)
def denoising_experiment(fn):
    """Check ``fn(V_clean, F, sigma, tau, iterations, seeds) -> (E_mean, E_std)`` (module docstring)."""
    cases = _experiment_cases()
    E = lambda c, k=_EXP_SEED, **kw: _pair(answer(fn, c, seeds=(k, k), **kw))[0]  # one draw, seed k
    answers = [np.array([E(c)]) for c in cases]
    if not np.isclose(E(cases[1]), answers[1][0], rtol=1e-9, atol=0):
        raise Mistake(
            "two calls with the same seeds gave different errors: the noise is not seeded, so the experiment cannot be repeated",
            "draw each noise with my_add_noise(V_clean, F, sigma, seed), seed from seeds",
        )
    if E(cases[1], _EXP_SEED + 1) == answers[1][0] and not np.isclose(answers[2][0], answers[1][0], rtol=1e-9):
        raise Mistake("other seeds gave the very same error: the seeds are ignored", "for seed in seeds: my_add_noise(V_clean, F, sigma, seed)")  # fmt: skip
    judge(EXPERIMENT_MISTAKES, cases, answers, right=lambda c: np.array([_e(c)]), same=_same_e)
    c = Case(f"{cases[1].label} over the seeds {_SEEDS}", **{**cases[1].inputs, "seeds": _SEEDS}).but(**cases[1].facts)
    c = c.but(E=np.array([E(c, k) for k in _SEEDS]), E_noisy=np.array([E(c, k, iterations=0) for k in _SEEDS]))
    spread = _spread(*_pair(answer(fn, c)), c)
    judge(SPREAD_MISTAKES, [c], [spread], right=lambda c: _spread(c.E.mean(), np.std(c.E, ddof=1), c))
    return [f"a sphere of 2,562 vertices, d = 139, one draw: {', '.join(c.label for c in cases)}", c.label]  # fmt: skip


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
    _wrong('the error is measured against the noisy mesh W (E[:, 0] is 0), not against V_clean', 'E[i, k] = my_denoising_metrics(P, V_clean, F)["rms"]', lambda c: _best(c.tables['noisy'], c.taus)),
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
    Wrong('the table or the best setting differs from the right one on {label}', 'E[i, k] = the error E after k implicit steps of taus[i]', typical=False),
]
# fmt: on


@exercise(
    "denoising_sweep",
    reread="section 5 · The sweep, yours",
    forbid=(
        *named("lessons.noise", "denoising_sweep denoising_experiment"),
        *named("lessons.smoothing", "implicit_smoothing ImplicitSmoother"),
        *_METRICS,
        *_SWEEPS,
    ),
    allow=("lessons.laplace.laplacian", "mesh.geometry.enclosed_volume"),  # the latter in your measures
)
def denoising_sweep(fn):
    """Check ``fn(W, F, V_clean, taus, iterations) -> (tau_best, N_best, E)`` (section 5 of notebook 07)."""
    cases = _sweep_cases()
    answers = [_sweep_flat(answer(fn, c), c) for c in cases]
    judge(SWEEP_MISTAKES, cases, answers, right=lambda c: _sweep_flat(c.right, c))
    return [c.label + f" ({len(c.taus)} steps, {c.iterations} iterations)" for c in cases]


# ------------------------------------------------------------------ Taubin's pairs
# an open bump (its boundary held) and a closed icosphere, placed anew; pairs and steps chosen so that every
# wrong count and step of the catalogue differs from the right one on one of them
_TAUBIN_CASES = (
    ("a 4 x 4 bump (open)", bump_4x4, 0.5, -0.53, 3),
    ("a jittered icosphere", jittered_icosphere, 0.33, -0.34, 4),
)


def _taubin_cases():
    rng, cases = case_rng(), []
    for label, mesh, tau_shrink, tau_inflate, pairs in _TAUBIN_CASES:
        V, F = placed(*mesh(), rng, jitter=0.1)
        cases.append(Case(label, V=V, F=F, tau_shrink=tau_shrink, tau_inflate=tau_inflate, pairs=pairs))
    return [c.but(right=taubin_pairs(c.V, c.F, c.tau_shrink, c.tau_inflate, c.pairs)) for c in cases]


def _pairs_run(c, taus=None, weights="uniform", held=True, divide=True, rebuild=False):
    """Explicit steps of ``taus`` (default: the pairs of the case) on (c.V, c.F), done right or in a wrong way."""
    from ...lessons.laplace import laplacian
    from ...mesh.topology import boundary_vertices

    taus = [c.tau_shrink, c.tau_inflate] * c.pairs if taus is None else taus
    move = np.ones(len(c.V), bool)
    move[boundary_vertices(c.F, len(c.V))] = not held
    P, (M, C) = c.V.copy(), laplacian(c.V, c.F, weights)
    for tau in taus:
        M, C = laplacian(P, c.F, weights) if rebuild else (M, C)
        m = M.diagonal() if divide else np.ones(len(P))
        P[move] += tau * (C @ P)[move] / m[move, None]
    return P


def _steps(c, shrink, inflate, pairs=None):
    return [shrink, inflate] * (c.pairs if pairs is None else pairs)


# fmt: off
TAUBIN_MISTAKES = [
    Wrong("the inflate step has the wrong sign: both steps shrink", "tau_inflate < 0 is given negative: add tau_inflate M^-1 C P, as the shrink step adds tau_shrink M^-1 C P", build=lambda c: _pairs_run(c, _steps(c, c.tau_shrink, -c.tau_inflate))),
    Wrong("the same step twice: each pair is two shrink steps of tau_shrink", "the second step of a pair uses tau_inflate", build=lambda c: _pairs_run(c, _steps(c, c.tau_shrink, c.tau_shrink))),
    Wrong("only the shrink step: the inflate step is missing", "a pair is a step of tau_shrink, then one of tau_inflate", build=lambda c: _pairs_run(c, [c.tau_shrink] * c.pairs)),
    Wrong("both steps are taken from the same P (P + (tau_shrink + tau_inflate) M^-1 C P): the inflate step must act on the shrunk positions", "update P with the shrink step, then apply the inflate step to that new P", build=lambda c: _pairs_run(c, [c.tau_shrink + c.tau_inflate] * c.pairs)),
    Wrong("the sign of the Laplacian is flipped: the shrink step inflates", "P + tau M^-1 C P with C negative semidefinite (its diagonal negative)", build=lambda c: _pairs_run(c, _steps(c, -c.tau_shrink, -c.tau_inflate))),
    Wrong("steps were counted instead of pairs: `pairs` explicit steps in all", "repeat the pair (shrink, then inflate) `pairs` times: 2 * pairs steps", build=lambda c: _pairs_run(c, _steps(c, c.tau_shrink, c.tau_inflate)[: c.pairs])),
    Wrong("one pair short", "range(pairs), from 0: pairs repetitions", build=lambda c: _pairs_run(c, _steps(c, c.tau_shrink, c.tau_inflate, c.pairs - 1))),
    Wrong("one pair too many", "range(pairs): exactly pairs repetitions", build=lambda c: _pairs_run(c, _steps(c, c.tau_shrink, c.tau_inflate, c.pairs + 1))),
    Wrong("the boundary vertices moved: they are held where they are", "update only the interior vertices (not those of geomlib.boundary_vertices(F, n))", build=lambda c: _pairs_run(c, held=False)),
    Wrong("M^-1 is missing: P + tau C P, not P + tau M^-1 C P", "divide each row of C P by the valence M_ii", build=lambda c: _pairs_run(c, divide=False)),
    Wrong("cotangent weights: Taubin's filter here uses the uniform operator", 'geomlib.laplacian(V, F, "uniform")', build=lambda c: _pairs_run(c, weights="cotan")),
    Wrong("cotangent weights, rebuilt from the moved mesh at every step: Taubin's filter here uses the uniform operator", 'geomlib.laplacian(V, F, "uniform"), built once (it depends on F alone)', build=lambda c: _pairs_run(c, weights="cotan", rebuild=True)),
    Wrong("the positions differ from Taubin's pairs on {label}", "pairs times: P <- P + tau_shrink M^-1 C P, then P <- P + tau_inflate M^-1 C P, boundary held", typical=False),
]
# fmt: on


@exercise(
    "taubin_smoothing",
    reread="section 6 · Taubin's filter, yours",
    forbid=named("lessons.smoothing", "taubin_smoothing explicit_step explicit_smoothing ExplicitSmoother") + _SWEEPS,
    allow=("lessons.laplace.laplacian", "mesh.topology.boundary_vertices"),
)
def taubin_smoothing(fn):
    """Check ``fn(V, F, tau_shrink, tau_inflate, pairs) -> P`` against geomlib's :func:`taubin_smoothing`."""
    cases = _taubin_cases()
    answers = run(
        fn, cases, lambda out, n: positions(out, n, nan_hint="a step past the limit diverges: check the signs")
    )
    judge(TAUBIN_MISTAKES, cases, answers, right=lambda c: c.right)
    return [f"{c.label}, {c.pairs} pairs ({c.tau_shrink}, {c.tau_inflate})" for c in cases]
