"""The exercise checks of notebook 07: they accept the reference, and name each typical mistake."""

import time

import numpy as np
import pytest
from diagnoses import assert_diagnosed

import geomlib
from geomlib import check
from geomlib.mesh.geometry import bounding_box_diagonal, mean_edge_length


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
        "modified in place",
    ),
    "in place, copy returned": (
        lambda V, F, sigma, seed: np.copy(V.__iadd__(sigma * bounding_box_diagonal(V) * _normals(V, sigma, seed))),
        "modified in place",
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
    "one coordinate": (
        lambda V, F, sigma, seed: V + sigma * bounding_box_diagonal(V) * _normals(V, sigma, seed) * [1, 1, 0],
        "not equally noisy",
    ),
}


def rms_reference(V, V_clean):
    return float(np.sqrt(np.mean(np.sum((V - V_clean) ** 2, axis=1)))) / bounding_box_diagonal(V_clean)


def _e2(V, V_clean):
    return np.sum((V - V_clean) ** 2, axis=1)


WRONG_RMS = {
    "not relative": (lambda V, W: float(np.sqrt(_e2(V, W).mean())), "not relative"),
    "mean of norms": (
        lambda V, W: float(np.sqrt(_e2(V, W)).mean()) / bounding_box_diagonal(W),
        "mean of the distances",
    ),
    "not rooted": (lambda V, W: float(_e2(V, W).mean()) / bounding_box_diagonal(W), "not rooted"),
    "squared ratio": (lambda V, W: float(_e2(V, W).mean()) / bounding_box_diagonal(W) ** 2, "not rooted"),
    "summed": (lambda V, W: float(np.sqrt(_e2(V, W).sum())) / bounding_box_diagonal(W), "summed"),
    "noisy diagonal": (
        lambda V, W: float(np.sqrt(_e2(V, W).mean())) / bounding_box_diagonal(V),
        "noisy mesh's diagonal",
    ),
    "over coordinates": (
        lambda V, W: float(np.sqrt(np.mean((V - W) ** 2))) / bounding_box_diagonal(W),
        "3n coordinates",
    ),
    "per vertex": (lambda V, W: np.sqrt(_e2(V, W)) / bounding_box_diagonal(W), "not one number"),
}


def test_reference_noise_passes_quickly():
    start = time.perf_counter()
    result = check.add_noise(noise_reference)
    assert result.passed, result.message
    assert "grid" in result.message
    assert time.perf_counter() - start < 1.0


def test_geomlib_add_noise_passes():
    assert check.add_noise(lambda V, F, sigma, seed: geomlib.add_noise(V, F, sigma, seed)).passed


@pytest.mark.parametrize("name", sorted(WRONG_NOISE))
def test_wrong_noise_is_diagnosed(name):
    fn, phrase = WRONG_NOISE[name]
    assert_diagnosed(check.add_noise(fn), phrase, "Reread section 2 · The noise model")


def test_reference_rms_passes():
    result = check.vertex_rms(rms_reference)
    assert result.passed, result.message
    assert check.vertex_rms(lambda V, W: geomlib.vertex_rms(V, W)).passed


def test_rms_has_exact_answer_on_the_tetrahedron():
    V_clean = np.array([[0.0, 0, 0], [2, 0, 0], [0, 1, 0], [0, 0, 4]])
    V = V_clean.copy()
    V[1, 0] += 3.0
    assert rms_reference(V, V_clean) == pytest.approx(1.5 / np.sqrt(21))


@pytest.mark.parametrize("name", sorted(WRONG_RMS))
def test_wrong_rms_is_diagnosed(name):
    fn, phrase = WRONG_RMS[name]
    assert_diagnosed(check.vertex_rms(fn), phrase, "Reread section 3 · The metrics")


@pytest.mark.parametrize("exercise", [check.add_noise, check.vertex_rms])
def test_stub_is_not_written_yet(exercise):
    def stub(*args):
        raise NotImplementedError("Your turn")

    assert_diagnosed(exercise(stub), "not written yet")


def test_strict_mode_raises_for_written_wrong_function(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "1")
    with pytest.raises(check.CheckFailed, match="not relative"):
        check.vertex_rms(WRONG_RMS["not relative"][0])
