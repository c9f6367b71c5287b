"""The check of notebook 04's exercise (reconstruction from k eigenvectors) names each typical mistake."""

import numpy as np
import pytest
from diagnoses import assert_diagnosed

from geomlib import check, eigenbasis, laplacian, spectral_reconstruction
from geomlib.teaching.check import CheckFailed


@pytest.fixture(autouse=True)
def lenient(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")


def learner(V, F, k, inner="M", columns=lambda k: slice(0, k), k_solve=lambda k: k, out=lambda X, c: X):
    """A learner's reconstruction with one chosen mistake: the inner product, the columns kept, the output."""
    M, C = laplacian(V, F)
    _, E = eigenbasis(V, F, min(k_solve(k), len(V)))
    W = {"M": M @ V, "plain": V, "C": C @ V, "M^-1": V / M.diagonal()[:, None]}[inner]
    Ek = E[:, columns(k)]
    c = Ek.T @ W
    return out(Ek @ c, c)


WRONG = [
    (dict(inner="plain"), "plain dot product"),
    (dict(inner="C"), "C (or M^-1 C) is used where M belongs"),
    (dict(inner="M^-1"), "divided by the vertex areas"),
    (dict(columns=lambda k: slice(1, k)), "constant eigenvector e_0"),
    (dict(columns=lambda k: slice(0, k - 1)), "k is off by one"),
    (dict(columns=lambda k: slice(1, k + 1), k_solve=lambda k: k + 1), "k is off by one"),
    (dict(out=lambda X, c: X.T), "transposed"),
    (dict(out=lambda X, c: c), "coefficients"),
    (dict(out=lambda X, c: X[:, 0]), "expected ("),
]


def test_reference_passes():
    result = check.spectral_reconstruction(spectral_reconstruction)
    assert result.passed, result.message
    assert check.spectral_reconstruction(learner).passed
    assert "k = 42 (gives V back)" in result.message


@pytest.mark.parametrize("mistake, phrase", WRONG, ids=[p for _, p in WRONG])
def test_wrong_reconstruction_is_diagnosed(mistake, phrase):
    assert_diagnosed(
        check.spectral_reconstruction(lambda V, F, k: learner(V, F, k, **mistake)),
        phrase,
        "Reread section 4 · Reconstruction from the first k eigenvectors",
    )


def test_stub_is_not_written_yet():
    def stub(V, F, k):
        raise NotImplementedError("Your turn")

    assert_diagnosed(check.spectral_reconstruction(stub), "not written yet")


def test_exception_is_named():
    assert_diagnosed(check.spectral_reconstruction(lambda V, F, k: np.linalg.inv(laplacian(V, F)[0]) @ V), "raised")


def test_strict_mode_raises_for_a_written_wrong_function(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "1")
    with pytest.raises(CheckFailed, match="plain dot product"):
        check.spectral_reconstruction(lambda V, F, k: learner(V, F, k, inner="plain"))
