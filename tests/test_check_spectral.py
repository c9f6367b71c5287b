"""The check of notebook 04's exercise (reconstruction from k eigenvectors) names each typical mistake."""

import numpy as np
import pytest

from geomlib import check
from geomlib.check import CheckFailed


@pytest.fixture(autouse=True)
def lenient(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")


def reference(V, M, E, k):
    Ek = E[:, :k]
    return Ek @ (Ek.T @ (M @ V))


WRONG = [
    (lambda V, M, E, k: E[:, :k] @ (E[:, :k].T @ V), "plain dot product"),
    (lambda V, M, E, k: E[:, :k] @ (E[:, :k].T @ (V / M.diagonal()[:, None])), "divided by the vertex areas"),
    (lambda V, M, E, k: M @ (E[:, :k] @ (E[:, :k].T @ V)), "M multiplies the result"),
    (lambda V, M, E, k: E[:, 1:k] @ (E[:, 1:k].T @ (M @ V)), "constant eigenvector e_0"),
    (lambda V, M, E, k: E[:, :k - 1] @ (E[:, :k - 1].T @ (M @ V)), "k is off by one"),
    (lambda V, M, E, k: E[:, 1:k + 1] @ (E[:, 1:k + 1].T @ (M @ V)), "k is off by one"),
    (lambda V, M, E, k: E[:, -k:] @ (E[:, -k:].T @ (M @ V)), "last k eigenvectors"),
    (lambda V, M, E, k: reference(V, M, E, k).T, "transposed"),
    (lambda V, M, E, k: E[:, :k].T @ (M @ V), "coefficients"),
    (lambda V, M, E, k: reference(V, M, E, k)[:, 0], "expected ("),
]


def test_reference_passes():
    result = check.spectral_reconstruction(reference)
    assert result.passed, result.message
    assert "k = 42 (gives V back)" in result.message


def test_diagonal_vector_form_passes():
    assert check.spectral_reconstruction(
        lambda V, M, E, k: E[:, :k] @ (E[:, :k].T @ (M.diagonal()[:, None] * V))).passed


@pytest.mark.parametrize("fn, phrase", WRONG, ids=[p for _, p in WRONG])
def test_wrong_reconstruction_is_diagnosed(fn, phrase):
    result = check.spectral_reconstruction(fn)
    assert not result.passed
    assert phrase in result.message, result.message
    assert "Reread section 4 · Reconstruction from the first k eigenvectors" in result.message


def test_stub_is_not_written_yet():
    def stub(V, M, E, k):
        raise NotImplementedError("Your turn")

    result = check.spectral_reconstruction(stub)
    assert not result.passed and "not written yet" in result.message


def test_exception_is_named():
    result = check.spectral_reconstruction(lambda V, M, E, k: np.linalg.inv(M) @ V)
    assert not result.passed and "raised" in result.message


def test_strict_mode_raises_for_a_written_wrong_function(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "1")
    with pytest.raises(CheckFailed, match="plain dot product"):
        check.spectral_reconstruction(WRONG[0][0])
