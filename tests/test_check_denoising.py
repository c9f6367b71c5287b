"""The exercise checks of notebook 07: they accept the reference, and name each typical mistake."""

import numpy as np
import pytest
from diagnoses import assert_diagnosed

import geomlib
from geomlib import check


def bounding_box_diagonal(V):  # the answers below are written with numpy, as the ground rules ask
    return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))


def mean_edge_length(V, F):
    return float(np.linalg.norm(V[F] - V[np.roll(F, 1, axis=1)], axis=2).mean())


@pytest.fixture(autouse=True)
def lenient(monkeypatch):
    """Checks return their diagnosis instead of raising (as for a learner, not the strict notebook run)."""
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")


def _normals(V, sigma, seed):
    return np.random.default_rng(seed).standard_normal(V.shape)


def noise_reference(V, F, sigma, seed):
    return V + sigma * bounding_box_diagonal(V) * _normals(V, sigma, seed)


# typical wrong noise models, each with a phrase its diagnosis must contain
WRONG_NOISE = {
    "not scaled": (lambda V, F, sigma, seed: V + sigma * _normals(V, sigma, seed), "not scaled by the bounding box"),
    "mean edge": (
        lambda V, F, sigma, seed: V + sigma * mean_edge_length(V, F) * _normals(V, sigma, seed),
        "mean edge length",
    ),
    "sigma as variance": (
        lambda V, F, sigma, seed: V + sigma**2 * bounding_box_diagonal(V) * _normals(V, sigma, seed),
        "variance",
    ),
    "variance for std": (
        lambda V, F, sigma, seed: V + (sigma * bounding_box_diagonal(V)) ** 2 * _normals(V, sigma, seed),
        "variance s^2",
    ),
    "same vector": (
        lambda V, F, sigma, seed: V + sigma * bounding_box_diagonal(V) * np.random.default_rng(seed).standard_normal(3),
        "same vector",
    ),
    "in place": (
        lambda V, F, sigma, seed: V.__iadd__(sigma * bounding_box_diagonal(V) * _normals(V, sigma, seed)),
        "changed its input V in place",
    ),
    "in place, copy returned": (
        lambda V, F, sigma, seed: np.copy(V.__iadd__(sigma * bounding_box_diagonal(V) * _normals(V, sigma, seed))),
        "changed its input V in place",
    ),
    "not seeded": (
        lambda V, F, sigma, seed: V + sigma * bounding_box_diagonal(V) * np.random.standard_normal(V.shape),
        "not seeded",
    ),
    "uniform": (
        lambda V, F, sigma, seed: (
            V + sigma * bounding_box_diagonal(V) * np.sqrt(3) * np.random.default_rng(seed).uniform(-1, 1, V.shape)
        ),
        "not Gaussian",
    ),
    "uniform in [-s, s] (its standard deviation s / sqrt(3), as a random direction's)": (
        lambda V, F, sigma, seed: (
            V + sigma * bounding_box_diagonal(V) * np.random.default_rng(seed).uniform(-1, 1, V.shape)
        ),
        "not Gaussian",
    ),
    "random direction of length s": (
        lambda V, F, sigma, seed: (
            V
            + sigma
            * bounding_box_diagonal(V)
            * (lambda X: X / np.linalg.norm(X, axis=1, keepdims=True))(_normals(V, sigma, seed))
        ),
        "length about s",
    ),
    "list": (lambda V, F, sigma, seed: noise_reference(V, F, sigma, seed).tolist(), "not a numpy array"),
    "scaled by the largest corner": (
        lambda V, F, sigma, seed: V + sigma * np.linalg.norm(V.max(axis=0)) * _normals(V, sigma, seed),
        "largest corner",
    ),
    "one draw per vertex for x, y and z": (
        lambda V, F, sigma, seed: (
            V + sigma * bounding_box_diagonal(V) * np.random.default_rng(seed).standard_normal((len(V), 1))
        ),
        "move together",
    ),
    "float32": (lambda V, F, sigma, seed: noise_reference(V, F, sigma, seed).astype(np.float32), "float32"),
    "float32 values in float64": (
        lambda V, F, sigma, seed: noise_reference(V, F, sigma, seed).astype(np.float32).astype(float),
        "float32",
    ),
    "one coordinate": (
        lambda V, F, sigma, seed: V + sigma * bounding_box_diagonal(V) * _normals(V, sigma, seed) * [1, 1, 0],
        "not equally noisy",
    ),
}


def rms_reference(V, V_clean):
    return float(np.sqrt(np.mean(np.sum((V - V_clean) ** 2, axis=1)))) / bounding_box_diagonal(V_clean)


def _unit(X, F):
    N = np.cross(X[F[:, 1]] - X[F[:, 0]], X[F[:, 2]] - X[F[:, 0]])
    return N / np.linalg.norm(N, axis=1, keepdims=True)


def _volume(X, F):
    return float(np.sum(X[F[:, 0]] * np.cross(X[F[:, 1]], X[F[:, 2]]))) / 6


def metrics_from(rms=rms_reference, angle=lambda cos: np.degrees(np.arccos(np.clip(cos, -1, 1))).mean(),
                 change=lambda vol, vol_clean: (vol - vol_clean) / abs(vol_clean)):  # fmt: skip
    """The three measures, each part replaceable by a wrong one."""

    def fn(V, V_clean, F):
        cos = np.sum(_unit(V, F) * _unit(V_clean, F), axis=1)
        return {
            "rms": rms(V, V_clean),
            "normal_mean": angle(cos),
            "volume_change": change(_volume(V, F), _volume(V_clean, F)),
        }

    return fn


WRONG_METRICS = {
    "not relative": (metrics_from(rms=lambda V, W: rms_reference(V, W) * bounding_box_diagonal(W)), "not relative"),
    "noisy diagonal": (
        metrics_from(rms=lambda V, W: rms_reference(V, W) * bounding_box_diagonal(W) / bounding_box_diagonal(V)),
        "noisy mesh's diagonal",
    ),
    "radians": (metrics_from(angle=lambda cos: np.arccos(np.clip(cos, -1, 1)).mean()), "radians"),
    "unclipped": (metrics_from(angle=lambda cos: np.degrees(np.arccos(cos + 1e-15)).mean()), "NaN"),
    "summed angles": (metrics_from(angle=lambda cos: np.degrees(np.arccos(np.clip(cos, -1, 1))).sum()), "summed"),
    "absolute volume": (metrics_from(change=lambda vol, vol_clean: vol - vol_clean), "volume change is absolute"),
    "ratio": (metrics_from(change=lambda vol, vol_clean: vol / vol_clean), "ratio vol / vol_clean"),
    "flipped": (metrics_from(change=lambda vol, vol_clean: (vol_clean - vol) / vol_clean), "sign of the volume"),
    "a tuple": (lambda V, W, F: tuple(metrics_from()(V, W, F).values()), "did not return a dict"),
}


def test_reference_metrics_pass_and_are_geomlibs():
    assert check.denoising_metrics(metrics_from()).passed
    V, F = geomlib.load_mesh(geomlib.data_path("sphere.obj"))
    W = geomlib.add_noise(V, F, 0.01, 3)
    mine, theirs = metrics_from()(W, V, F), geomlib.denoising_metrics(W, V, F)
    assert all(np.isclose(mine[k], theirs[k], rtol=1e-9) for k in mine)


def test_the_measures_have_exact_answers_on_a_scaled_tetrahedron():
    V_clean = np.array([[0.0, 0, 0], [2, 0, 0], [0, 1, 0], [0, 0, 4]]) + 5.0  # away from the origin
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    c = V_clean.mean(axis=0)
    m = metrics_from()(c + 0.5 * (V_clean - c), V_clean, F)  # halved about its centroid: normals kept, volume / 8
    assert m["normal_mean"] == pytest.approx(0.0, abs=1e-6) and m["volume_change"] == pytest.approx(-7 / 8)
    assert m["rms"] == pytest.approx(0.5 * np.sqrt(np.mean(np.sum((V_clean - c) ** 2, axis=1))) / np.sqrt(21))


@pytest.mark.parametrize("name", sorted(WRONG_METRICS))
def test_wrong_metrics_are_diagnosed(name):
    fn, phrase = WRONG_METRICS[name]
    assert_diagnosed(check.denoising_metrics(fn), phrase, "Reread section 3 · The measures, yours")


def test_every_catalogue_entry_is_named_when_handed_in():
    from diagnoses import replaying

    from geomlib.teaching.check.denoising import MEASURE_MISTAKES, _measure_cases
    from geomlib.teaching.check.result import _SEED

    for seed in (1, 2):
        _SEED.update(asked=seed, used=None)
        cases = _measure_cases()
        for entry in (w for w in MEASURE_MISTAKES if w.build is not None):
            wrong = replaying(
                cases,
                lambda c, entry=entry: dict(zip(("rms", "normal_mean", "volume_change"), entry.build(c) * c.scale)),
            )
            assert_diagnosed(check.denoising_metrics(wrong, seed=seed), entry.diagnosis)


def test_reference_noise_passes():
    result = check.add_noise(noise_reference)
    assert result.passed, result.message
    assert "grid" in result.message


def test_rng_normal_with_a_scale_passes_too():
    def normal(V, F, sigma, seed):
        return V + np.random.default_rng(seed).normal(0.0, sigma * bounding_box_diagonal(V), V.shape)

    assert check.add_noise(normal).passed


@pytest.mark.parametrize("name", sorted(WRONG_NOISE))
def test_wrong_noise_is_diagnosed(name):
    fn, phrase = WRONG_NOISE[name]
    assert_diagnosed(check.add_noise(fn), phrase, "Reread section 2 · The noise, yours")


@pytest.mark.parametrize("exercise", [check.add_noise, check.denoising_metrics, check.denoising_experiment])
def test_stub_is_not_written_yet(exercise):
    def stub(*args):
        raise NotImplementedError("Your turn")

    assert_diagnosed(exercise(stub), "not written yet")


def test_strict_mode_raises_for_written_wrong_function(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "1")
    with pytest.raises(check.CheckFailed, match="not relative"):
        check.denoising_metrics(WRONG_METRICS["not relative"][0])


# --- the experiment: noise, implicit smoothing, the error against the clean mesh ---------------


def _rms(P, V):
    return float(np.sqrt(np.mean(np.sum((P - V) ** 2, axis=1))))


def _sample(E, E_noisy):
    return float(np.mean(E)), float(np.std(E, ddof=1))


def experiment(noise, measure, smooth_noisy=True, spread=_sample, draws=lambda seeds: seeds):
    """An experiment from its parts, written fresh: noise(V, sigma, seed) -> W, measure(P, W, V) -> float per
    draw, spread(E, E_noisy) -> (E_mean, E_std) over them, draws(seeds) the seeds actually drawn."""

    def fn(V, F, sigma, tau, iterations, seeds):
        E, E_noisy = [], []
        for seed in draws(seeds):
            W = noise(V, sigma, seed)
            P = geomlib.implicit_smoothing(W if smooth_noisy else V, F, tau, iterations)
            E.append(measure(P, W, V))
            E_noisy.append(relative(W, W, V))
        return spread(np.array(E), np.array(E_noisy))

    return fn


def seeded(V, sigma, seed):
    return V + sigma * bounding_box_diagonal(V) * np.random.default_rng(seed).standard_normal(V.shape)


def relative(P, W, V):
    return _rms(P, V) / bounding_box_diagonal(V)


def edge_noise(V, F, sigma, tau, iterations, seeds):
    ell = np.linalg.norm(V[F[:, [1, 2, 0]]] - V[F], axis=2).mean()  # every edge twice on a closed mesh: the mean edge
    E = []
    for seed in seeds:
        W = V + sigma * ell * np.random.default_rng(seed).standard_normal(V.shape)
        E.append(relative(geomlib.implicit_smoothing(W, F, tau, iterations), W, V))
    return np.mean(E), np.std(E, ddof=1)


# correct variants: another draw of the same noise, columns drawn first, a float32 error
RIGHT_EXPERIMENTS = {
    "reference": experiment(seeded, relative),
    "rng.normal": experiment(
        lambda V, s, seed: V + np.random.default_rng(seed).normal(0, s * bounding_box_diagonal(V), V.shape), relative
    ),
    "columns first": experiment(
        lambda V, s, seed: (
            V + s * bounding_box_diagonal(V) * np.random.default_rng(seed + 1).standard_normal((3, len(V))).T
        ),
        relative,
    ),
    "float32 error": experiment(seeded, lambda P, W, V: np.float32(relative(P, W, V))),
}

WRONG_EXPERIMENTS = {
    "against the noisy mesh": (
        experiment(seeded, lambda P, W, V: _rms(P, W) / bounding_box_diagonal(V)),
        "against the noisy mesh",
    ),
    "against the noisy mesh, over its own diagonal (my_denoising_metrics(P, W, F))": (
        experiment(seeded, lambda P, W, V: _rms(P, W) / bounding_box_diagonal(W)),
        "against the noisy mesh W",
    ),
    "unseeded": (
        experiment(lambda V, s, seed: V + s * bounding_box_diagonal(V) * np.random.standard_normal(V.shape), relative),
        "not seeded",
    ),
    "seed ignored": (experiment(lambda V, s, seed: seeded(V, s, 0), relative), "seeds are ignored"),
    "seeds by their index": (experiment(seeded, relative, draws=lambda seeds: range(len(seeds))), "seeds are ignored"),
    "the same seed for every draw": (
        experiment(seeded, relative, draws=lambda seeds: [seeds[0]] * len(seeds)),
        "same seed made every draw",
    ),
    "ddof = 2": (
        experiment(seeded, relative, spread=lambda E, En: (E.mean(), E.std(ddof=2))),
        "not that of your own draws",
    ),
    "population std": (
        experiment(seeded, relative, spread=lambda E, En: (E.mean(), E.std())),
        "population one (ddof = 0)",
    ),
    "the std of the noisy meshes": (
        experiment(seeded, relative, spread=lambda E, En: (E.mean(), En.std(ddof=1))),
        "standard deviation is that of the noisy meshes",
    ),
    "the mean of the noisy meshes": (
        experiment(seeded, relative, spread=lambda E, En: (En.mean(), E.std(ddof=1))),
        "error is that of the noisy mesh",
    ),
    "absolute error": (experiment(seeded, lambda P, W, V: _rms(P, V)), "error is absolute"),
    "noise not relative": (
        experiment(lambda V, s, seed: V + s * np.random.default_rng(seed).standard_normal(V.shape), relative),
        "noise is not relative to the bounding-box diagonal",
    ),
    "noise by the edge length": (edge_noise, "mean edge length"),
    "noise and error both absolute": (
        experiment(
            lambda V, s, seed: V + s * np.random.default_rng(seed).standard_normal(V.shape), lambda P, W, V: _rms(P, V)
        ),
        "not both relative",
    ),
    "the noisy mesh measured": (
        experiment(seeded, lambda P, W, V: relative(W, W, V)),
        "error is that of the noisy mesh",
    ),
    "the clean mesh smoothed": (experiment(seeded, relative, smooth_noisy=False), "clean mesh was smoothed"),
    "a random direction of length sigma d": (
        experiment(
            lambda V, s, seed: (
                V
                + s
                * bounding_box_diagonal(V)
                * (lambda X: X / np.linalg.norm(X, axis=1, keepdims=True))(
                    np.random.default_rng(seed).standard_normal(V.shape)
                )
            ),
            relative,
        ),
        "sqrt(3) too small",
    ),
    "returns the meshes": (
        experiment(seeded, relative, spread=lambda E, En: (E.mean(), E.std(ddof=1), En)),
        "not return the pair",
    ),
    "one iteration short": (
        lambda V, F, s, tau, n, seeds: experiment(seeded, relative)(V, F, s, tau, max(n - 1, 0), seeds),
        "one iteration short",
    ),
    "one iteration too many": (
        lambda V, F, s, tau, n, seeds: experiment(seeded, relative)(V, F, s, tau, n + 1, seeds),
        "one iteration too many",
    ),
    "mean over the 3n coordinates": (
        experiment(seeded, lambda P, W, V: float(np.sqrt(np.mean((P - V) ** 2))) / bounding_box_diagonal(V)),
        "3n coordinates",
    ),
}


@pytest.mark.parametrize("name", sorted(RIGHT_EXPERIMENTS))
def test_correct_experiments_pass(name):
    result = check.denoising_experiment(RIGHT_EXPERIMENTS[name])
    assert result.passed, result.message


@pytest.mark.parametrize("name", sorted(WRONG_EXPERIMENTS))
def test_wrong_experiments_are_diagnosed(name):
    fn, phrase = WRONG_EXPERIMENTS[name]
    assert_diagnosed(check.denoising_experiment(fn), phrase, "Reread section 4 · The experiment, yours")


def test_typical_experiment_mistakes_earn_partial_credit_and_catch_alls_do_not():
    assert check.denoising_experiment.evaluate(WRONG_EXPERIMENTS["against the noisy mesh"][0]).partial
    assert check.denoising_experiment.evaluate(WRONG_EXPERIMENTS["unseeded"][0]).partial
    assert check.denoising_experiment.evaluate(WRONG_EXPERIMENTS["population std"][0]).partial
    assert not check.denoising_experiment.evaluate(WRONG_EXPERIMENTS["returns the meshes"][0]).partial


def test_the_experiment_is_scale_free_and_its_error_at_zero_iterations_is_the_noise():
    V, F = geomlib.load_mesh(geomlib.data_path("sphere.obj"))
    E, W, P = geomlib.denoising_experiment(V, F, 0.02, 0.0, 0, seed=4)
    assert np.array_equal(P, W) and E == pytest.approx(np.sqrt(3) * 0.02, rel=0.03)  # sqrt(3) sigma, statistically
    tau = 0.1 * geomlib.mean_edge_length(V, F) ** 2
    E1 = geomlib.denoising_experiment(V, F, 0.02, tau, 3, seed=4)[0]
    E2 = geomlib.denoising_experiment(7 * V, F, 0.02, 49 * tau, 3, seed=4)[0]
    assert E1 == pytest.approx(E2, rel=1e-9) and E1 < E


def test_the_noise_grid_tells_the_diagonal_from_the_largest_corner_and_the_edge():
    from geomlib.teaching.check.denoising import _NOISE_F, _NOISE_V

    d, corner = bounding_box_diagonal(_NOISE_V), np.linalg.norm(_NOISE_V.max(axis=0))
    assert d == pytest.approx(357.1, abs=0.05) and geomlib.mean_edge_length(_NOISE_V, _NOISE_F) == pytest.approx(
        5.72, abs=0.005
    )
    assert corner > 3 * d  # away from the origin: a noise scaled by |max(V)| is four times too large


def test_the_experiment_tells_n_iterations_from_n_minus_one_exactly():
    """Without noise the error is the shrinkage of N steps: N - 1 and N + 1 differ from it by far more than
    the exact comparison allows, whatever the noise draw of the other runs."""
    from geomlib.teaching.check.denoising import _EXACT, _e, _experiment_cases

    (quiet,) = [c for c in _experiment_cases() if c.sigma == 0]
    right = _e(quiet)
    for n in (quiet.iterations - 1, quiet.iterations + 1):
        assert abs(_e(quiet, iterations=n) - right) > 1000 * _EXACT * right


# --- the sweep: the error of implicit smoothing after every count, for every step ---------------


def sweep(variant=None):
    """The sweep written fresh with numpy and scipy, right (None) or with one typical mistake."""
    import scipy.sparse.linalg

    def fn(W, F, V_clean, taus, iterations):
        M, C = geomlib.laplacian(W, F, "uniform" if variant == "uniform" else "cotan")
        truth = W if variant == "noisy" else V_clean
        E, P = np.empty((len(taus), iterations + 1)), W
        for i, tau in enumerate(taus):
            solve = scipy.sparse.linalg.splu((M + (1 if variant == "plus" else -1) * tau * C).tocsc()).solve
            P = P if variant == "carry" else W
            E[i, 0] = rms_reference(P, truth)
            for k in range(1, iterations + 1):
                if variant == "rebuild":
                    M, C = geomlib.laplacian(P, F)
                    solve = scipy.sparse.linalg.splu((M - tau * C).tocsc()).solve
                P = (
                    P + tau * (C @ P) / M.diagonal()[:, None]
                    if variant == "explicit"
                    else solve(P if variant == "rhs" else M @ P)
                )
                E[i, k] = rms_reference(P, truth)
        E = E[:, 1:] if variant == "no zero column" else E
        i, k = np.unravel_index((np.argmax if variant == "argmax" else np.argmin)(E), E.shape)
        E = E.T if variant == "transposed" else E
        if variant == "index":
            return i, int(k), E
        return (
            taus[i],
            int(k) + (variant in ("one too many", "no zero column")),
            E.tolist() if variant == "lists" else E,
        )

    return fn


WRONG_SWEEPS = {
    "noisy": "against the noisy mesh W",
    "carry": "previous step's ended",
    "rebuild": "rebuilt from the smoothed mesh",
    "explicit": "explicit steps",
    "rhs": "the right-hand side is P",
    "uniform": "uniform weights",
    "no zero column": "no column for 0 iterations",
    "argmax": "largest error",
    "one too many": "N_best is one too many",
    "index": "the index of the best step",
    "plus": "the sign of tau C is flipped",
    "transposed": "the table is transposed",
}


@pytest.mark.parametrize("variant", [None, "lists"])
def test_right_sweeps_pass(variant):
    result = check.denoising_sweep(sweep(variant))
    assert result.passed, result.message


@pytest.mark.parametrize("variant", sorted(WRONG_SWEEPS))
def test_wrong_sweeps_are_named_and_earn_partial_credit(variant):
    result = check.denoising_sweep.evaluate(sweep(variant))
    assert_diagnosed(result, WRONG_SWEEPS[variant], "Reread section 5 · The sweep, yours")
    assert result.partial


def test_geomlibs_own_sweep_is_refused_and_a_stub_is_not_written():
    refused = check.denoising_sweep.evaluate(lambda W, F, V, taus, n: geomlib.denoising_sweep(W, F, V, taus, n))
    assert_diagnosed(refused, "denoising_sweep")
    assert not refused.partial

    def stub(*args):
        raise NotImplementedError("Your turn")

    assert_diagnosed(check.denoising_sweep(stub), "not written yet")
    assert_diagnosed(check.denoising_sweep(lambda *a: 0.5), "triple")


# --- Taubin's pairs: shrink, inflate, boundary held, the uniform operator ---------------


def taubin_reference(V, F, tau_shrink, tau_inflate, pairs):
    M, C = geomlib.laplacian(V, F, "uniform")
    moving = np.setdiff1d(np.arange(len(V)), geomlib.boundary_vertices(F, len(V)))
    P = V.copy()
    for _ in range(pairs):
        for tau in (tau_shrink, tau_inflate):
            P[moving] += tau * (C @ P)[moving] / M.diagonal()[moving, None]
    return P


def test_reference_taubin_passes_and_a_stub_is_not_written():
    assert check.taubin_smoothing(taubin_reference).passed
    assert_diagnosed(check.taubin_smoothing(lambda *args: (_ for _ in ()).throw(NotImplementedError())), "not written")


def test_every_taubin_mistake_is_named_when_handed_in():
    from diagnoses import replaying

    from geomlib.teaching.check.denoising import TAUBIN_MISTAKES, _taubin_cases
    from geomlib.teaching.check.result import _SEED

    for seed in (1, 2):
        _SEED.update(asked=seed, used=None)
        cases = _taubin_cases()
        for entry in (w for w in TAUBIN_MISTAKES if w.build is not None):
            result = check.taubin_smoothing(replaying(cases, entry.build), seed=seed)
            assert_diagnosed(result, entry.diagnosis, "Reread section 6 · Taubin's filter, yours")
            assert result.partial


def test_taubin_of_the_wrong_shape_or_a_nan_earns_nothing():
    for out in (np.zeros((3, 3)), np.full((16, 3), np.nan)):
        result = check.taubin_smoothing(
            lambda V, F, a, b, k, out=out: np.resize(out, V.shape) if out.shape[0] == 16 else out
        )
        assert not result.passed and not result.partial
