"""The checks of notebook 01's exercises: the reference passes, typical mistakes get their diagnosis."""

import numpy as np
import pytest
from diagnoses import assert_diagnosed

from geomlib import check
from geomlib.lessons.curvature import angle_deficit, gaussian_curvature
from geomlib.lessons.laplace import barycentric_areas, laplacian, mixed_areas
from geomlib.teaching.check import CheckFailed


@pytest.fixture(autouse=True)
def lenient(monkeypatch):
    # a learner's session: a failed check returns its diagnosis instead of raising
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")


def stub(V, F):
    raise NotImplementedError("Your turn")


# ---------------------------------------------------------------- uniform_laplacian
def uniform(V, F):
    return laplacian(V, F, weights="uniform")


UNIFORM_MISTAKES = {
    "flipped sign": (lambda V, F: (uniform(V, F)[0], -uniform(V, F)[1]), "sign of C is flipped"),
    "no diagonal": (
        lambda V, F: (uniform(V, F)[0], uniform(V, F)[1] - np.diag(uniform(V, F)[1].diagonal())),
        "diagonal of C is missing",
    ),
    "M^-1 C": (
        lambda V, F: (uniform(V, F)[0], uniform(V, F)[1] / uniform(V, F)[0].diagonal()[:, None]),
        "M^-1 C, not C",
    ),
    "identity M": (lambda V, F: (np.eye(len(V)), uniform(V, F)[1]), "M is the identity"),
    "only C": (lambda V, F: uniform(V, F)[1], "not the pair (M, C)"),
}


def test_uniform_accepts_reference():
    result = check.uniform_laplacian(uniform)
    assert result.passed and "tetrahedron" in result.message


@pytest.mark.parametrize("name", UNIFORM_MISTAKES)
def test_uniform_diagnoses(name):
    fn, phrase = UNIFORM_MISTAKES[name]
    assert_diagnosed(check.uniform_laplacian(fn), phrase, "Reread section 2")


def test_uniform_stub_is_not_written_yet():
    assert_diagnosed(check.uniform_laplacian(stub), "not written yet")


# ---------------------------------------------------------------- gaussian_curvature (angle deficit)
def pointwise_K(V, F):
    """The exercise written out as a learner would: angles by arccos, barycentric areas, NaN on the boundary."""
    theta = np.zeros(len(V))
    area = np.zeros(len(V))
    for k in range(3):
        i, j, l = F[:, k], F[:, (k + 1) % 3], F[:, (k + 2) % 3]
        a, b = V[j] - V[i], V[l] - V[i]
        cos = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
        np.add.at(theta, i, np.arccos(np.clip(cos, -1, 1)))
        np.add.at(area, i, np.linalg.norm(np.cross(a, b), axis=1) / 6)
    K = (2 * np.pi - theta) / area
    edges = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    e, count = np.unique(edges, axis=0, return_counts=True)
    K[np.unique(e[count == 1])] = np.nan
    return K


K_MISTAKES = {
    "sign": (lambda V, F: -gaussian_curvature(V, F), "sign of the deficit is flipped"),
    "area not / 3": (lambda V, F: gaussian_curvature(V, F) / 3, "not divided by 3"),
    "degrees": (lambda V, F: np.degrees(gaussian_curvature(V, F)), "in degrees"),
    "integrated": (lambda V, F: gaussian_curvature(V, F, integrated=True), "not divided by the vertex area"),
    "mixed area": (lambda V, F: gaussian_curvature(V, F, area="mixed"), "mixed Voronoi area"),
    "interior rule on the boundary": (
        lambda V, F: angle_deficit(V, F) / barycentric_areas(V, F),
        "interior formula is applied at boundary vertices",
    ),
    "zero on the boundary": (lambda V, F: gaussian_curvature(V, F, boundary="zero"), "boundary vertices have a value"),
    "a matrix": (lambda V, F: np.diag(gaussian_curvature(V, F)), "expected (4,)"),
}


def test_K_accepts_reference_and_written_solution():
    for fn in (gaussian_curvature, pointwise_K):
        result = check.gaussian_curvature(fn)
        assert result.passed and "bump" in result.message, result.message


def test_mixed_and_barycentric_differ_on_the_check_mesh():
    # otherwise the "mixed area" diagnosis could not be told apart from a correct answer
    from geomlib.teaching.check.uniform import _TET_F, _TET_V

    assert not np.allclose(mixed_areas(_TET_V, _TET_F), barycentric_areas(_TET_V, _TET_F))


@pytest.mark.parametrize("name", K_MISTAKES)
def test_K_diagnoses(name):
    fn, phrase = K_MISTAKES[name]
    assert_diagnosed(check.gaussian_curvature(fn), phrase, "Reread section 3")


def test_K_stub_and_strict_mode(monkeypatch):
    assert_diagnosed(check.gaussian_curvature(stub), "not written yet")
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "1")
    assert not check.gaussian_curvature(stub).passed  # a stub never raises
    with pytest.raises(CheckFailed, match="sign of the deficit"):
        check.gaussian_curvature(K_MISTAKES["sign"][0])
