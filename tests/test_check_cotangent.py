"""The checks of notebook 03's exercises: they accept the reference and name each typical mistake.

Each wrong implementation below is written the way a learner writes it (a loop over the faces, the
angles from the edge vectors), with one mistake; the check must name that mistake.
"""

import numpy as np
import pytest
import scipy.sparse as sp
from diagnoses import assert_diagnosed

from geomlib import check
from geomlib.lessons.laplace import barycentric_areas, laplacian, mixed_areas
from geomlib.teaching.check import CheckFailed


@pytest.fixture(autouse=True)
def lenient(monkeypatch):
    """Checks of wrong functions return their diagnosis instead of raising (as for a reader)."""
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")


def cot_at(V, a, b, c):
    """cot of the angle at corner a of the triangle (a, b, c)."""
    u, v = V[b] - V[a], V[c] - V[a]
    return u @ v / np.linalg.norm(np.cross(u, v))


def learner_laplacian(V, F, angle="opposite", factor=0.5, diagonal=True, cot=cot_at, M_div=3.0, M_eye=False, sign=1.0):
    n = len(V)
    C = sp.lil_matrix((n, n))
    A = np.zeros(n)
    for f in F:
        for c in range(3):
            i, j, k = f[c], f[(c + 1) % 3], f[(c + 2) % 3]
            at = {"opposite": (k, i, j), "at i": (i, j, k), "at j": (j, k, i)}[angle]
            w = sign * factor * cot(V, *at)
            C[i, j] += w
            C[j, i] += w
        area = np.linalg.norm(np.cross(V[f[1]] - V[f[0]], V[f[2]] - V[f[0]])) / 2
        A[f] += area / M_div
    C = C.tocsr()
    if diagonal:
        C = C - sp.diags(np.asarray(C.sum(axis=1)).ravel())
    M = sp.identity(n) if M_eye else sp.diags(A)
    return M, C


def tan_at(V, a, b, c):
    return 1.0 / cot_at(V, a, b, c)


WRONG_LAPLACIANS = [
    (dict(sign=-1.0), "sign of C is flipped"),
    (dict(factor=1.0), "factor 1/2 is missing"),
    (dict(diagonal=False), "diagonal of C is missing"),
    (dict(angle="at i"), "cotangent of the wrong angle"),
    (dict(angle="at j"), "cotangent of the wrong angle"),
    (dict(cot=tan_at), "tan is used instead of cot"),
    (dict(M_div=1.0), "M is not divided by 3"),
    (dict(M_eye=True), "M is the identity"),
]


def test_reference_laplacian_passes():
    result = check.cotangent_laplacian(lambda V, F: laplacian(V, F))
    assert result.passed, result.message
    assert "tetrahedron" in result.message and "grid" in result.message


def test_learner_loop_laplacian_passes():
    assert check.cotangent_laplacian(learner_laplacian).passed


@pytest.mark.parametrize("mistake, phrase", WRONG_LAPLACIANS, ids=[p for _, p in WRONG_LAPLACIANS])
def test_wrong_laplacian_is_diagnosed(mistake, phrase):
    assert_diagnosed(
        check.cotangent_laplacian(lambda V, F: learner_laplacian(V, F, **mistake)),
        phrase,
        "Reread section 1 · Cotangent weights, derived",
    )


def test_laplacian_shapes_are_diagnosed():
    assert_diagnosed(check.cotangent_laplacian(lambda V, F: laplacian(V, F)[1]), "not the pair (M, C)")
    assert_diagnosed(
        check.cotangent_laplacian(lambda V, F: (laplacian(V, F)[0].diagonal(), laplacian(V, F)[1])), "M is a vector"
    )


def learner_areas(V, F, divide=3.0, double=False, per_face=False):
    A = np.zeros(len(V))
    areas = []
    for f in F:
        a = np.linalg.norm(np.cross(V[f[1]] - V[f[0]], V[f[2]] - V[f[0]]))
        a = a if double else a / 2
        areas.append(a)
        A[f] += a / divide
    return np.array(areas) if per_face else A


WRONG_AREAS = [
    (dict(divide=1.0), "not divided by 3"),
    (dict(double=True), "twice the triangle area"),
    (dict(per_face=True), "one value per face"),
]


def test_reference_areas_pass():
    assert check.vertex_areas(barycentric_areas).passed
    assert check.vertex_areas(learner_areas).passed


@pytest.mark.parametrize("mistake, phrase", WRONG_AREAS, ids=[p for _, p in WRONG_AREAS])
def test_wrong_areas_are_diagnosed(mistake, phrase):
    assert_diagnosed(
        check.vertex_areas(lambda V, F: learner_areas(V, F, **mistake)),
        phrase,
        "Which area? Barycentric and mixed Voronoi",
    )


def test_mixed_instead_of_barycentric_is_diagnosed():
    assert_diagnosed(check.vertex_areas(mixed_areas), "mixed (Voronoi) areas, not the barycentric")


def learner_mixed(V, F, rule="meyer"):
    A = np.zeros(len(V))
    for f in F:
        area = np.linalg.norm(np.cross(V[f[1]] - V[f[0]], V[f[2]] - V[f[0]])) / 2
        cots = [cot_at(V, f[c], f[(c + 1) % 3], f[(c + 2) % 3]) for c in range(3)]
        obtuse = [c < 0 for c in cots]
        for c in range(3):
            i, j, k = f[c], f[(c + 1) % 3], f[(c + 2) % 3]
            voronoi = (
                np.sum((V[i] - V[j]) ** 2) * cots[(c + 2) % 3] + np.sum((V[i] - V[k]) ** 2) * cots[(c + 1) % 3]
            ) / 8
            if rule == "barycentric":
                A[i] += area / 3
            elif rule == "voronoi" or not any(obtuse):
                A[i] += voronoi
            elif rule == "swapped":
                A[i] += area / 4 if obtuse[c] else area / 2
            elif rule == "only at the obtuse corner":
                A[i] += area / 2 if obtuse[c] else voronoi
            else:
                A[i] += area / 2 if obtuse[c] else area / 4
    return A


WRONG_MIXED = [
    ("voronoi", "obtuse rule is missing"),
    ("swapped", "halves are swapped"),
    ("barycentric", "barycentric areas"),
    ("only at the obtuse corner", "applied only at the obtuse corner"),
]


def test_reference_mixed_passes():
    assert check.mixed_areas(mixed_areas).passed
    assert check.mixed_areas(learner_mixed).passed


@pytest.mark.parametrize("rule, phrase", WRONG_MIXED, ids=[p for _, p in WRONG_MIXED])
def test_wrong_mixed_is_diagnosed(rule, phrase):
    assert_diagnosed(check.mixed_areas(lambda V, F: learner_mixed(V, F, rule)), phrase)


@pytest.mark.parametrize("name", ["cotangent_laplacian", "vertex_areas", "mixed_areas"])
def test_stub_is_not_written_yet(name):
    def stub(V, F):
        raise NotImplementedError("Your turn")

    assert_diagnosed(getattr(check, name)(stub), "not written yet")


def test_strict_mode_raises_for_a_written_wrong_function(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "1")
    with pytest.raises(CheckFailed, match="sign of C is flipped"):
        check.cotangent_laplacian(lambda V, F: learner_laplacian(V, F, sign=-1.0))
