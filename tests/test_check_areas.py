"""The shared diagnosis of vertex-area mistakes (geomlib.teaching.check.area_mistakes).

Every wrong answer of the catalogue, handed in, gets its own diagnosis; and each wrong area
written fresh below with numpy, the way a learner writes it (an oracle independent of the
catalogue), is named from the areas alone, the same words whichever check asks. The meshes are
the checks' own: every two typical mistakes must differ on the meshes a check hands in, or one
of them could be named for the other (a tetrahedron alone cannot tell "a ninth" from "the
mean of A_f/3": all its vertices have three triangles).
"""

import itertools

import numpy as np
import pytest

from geomlib.lessons.laplace import barycentric_areas, mixed_areas
from geomlib.teaching.check import area_mistakes as areas
from geomlib.teaching.check import cotangent, meshes
from geomlib.teaching.check.catalogue import Case


def face_areas(V, F, halve=True):
    A = np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    return A / 2 if halve else A


def angles(V, F):
    """(m, 3) angle at each corner, from the edge vectors."""
    out = np.empty(F.shape)
    for c in range(3):
        u = V[F[:, (c + 1) % 3]] - V[F[:, c]]
        v = V[F[:, (c + 2) % 3]] - V[F[:, c]]
        out[:, c] = np.arccos(np.einsum("fd,fd->f", u, v) / np.linalg.norm(u, axis=1) / np.linalg.norm(v, axis=1))
    return out


def learner(V, F, mistake=None):
    """Barycentric areas with one learner's mistake (None: right)."""
    n = len(V)
    A_f = face_areas(V, F, halve=mistake not in ("cross not halved", "cross only"))
    third = A_f if mistake in ("full", "cross only") else A_f / (9 if mistake == "ninth" else 3)
    A = np.zeros(n)
    for _ in range(2 if mistake == "faces twice" else 1):
        np.add.at(A, F, third[:, None])
    if mistake == "mean":
        A /= np.bincount(F.ravel(), minlength=n)
    return A


def learner_voronoi(V, F, obtuse_rule=True):
    """Meyer's mixed areas from the angles (obtuse_rule=False: plain Voronoi)."""
    theta = angles(V, F)
    A_f = face_areas(V, F)
    A = np.zeros(len(V))
    for c in range(3):
        j, k = (c + 1) % 3, (c + 2) % 3
        l_ij2 = np.sum((V[F[:, c]] - V[F[:, j]]) ** 2, axis=1)
        l_ik2 = np.sum((V[F[:, c]] - V[F[:, k]]) ** 2, axis=1)
        piece = (l_ij2 / np.tan(theta[:, k]) + l_ik2 / np.tan(theta[:, j])) / 8
        if obtuse_rule:
            obtuse = theta.max(axis=1) > np.pi / 2
            piece = np.where(obtuse, np.where(theta[:, c] > np.pi / 2, A_f / 2, A_f / 4), piece)
        np.add.at(A, F[:, c], piece)
    return A


BARYCENTRIC = [
    ("full", "full area of its incident triangles"),
    ("ninth", "a ninth of its incident triangle areas"),
    ("mean", "the mean of its triangles' pieces (A_f/3 each) instead of their sum"),
    ("faces twice", "a triangle counted twice, or its area taken as the length of the cross product"),
    ("cross not halved", "a triangle counted twice, or its area taken as the length of the cross product"),
    ("cross only", "neither halved nor divided by 3"),
]
MESHES = [(c.V, c.F) for c in cotangent.areas_cases(np.random.default_rng(0))]
CATALOGUE = [(asked, entry) for asked, entries in areas.AREA_MISTAKES.items() for entry in entries]


@pytest.mark.parametrize("asked, entry", CATALOGUE, ids=[f"{a}: {e.diagnosis[:40]}" for a, e in CATALOGUE])
def test_every_wrong_area_of_the_catalogue_gets_its_own_diagnosis(asked, entry):
    wrong = [(entry.build(Case("", V=V, F=F)), V, F) for V, F in MESHES]
    assert areas.area_mistake_over(wrong, asked) == (entry.diagnosis, entry.hint)


@pytest.mark.parametrize("mistake, phrase", BARYCENTRIC, ids=[m for m, _ in BARYCENTRIC])
def test_barycentric_mistakes_are_named_over_the_meshes(mistake, phrase):
    found = areas.area_mistake_over([(learner(V, F, mistake), V, F) for V, F in MESHES])
    assert found is not None and phrase in found[0], found


def test_the_mean_is_a_ninth_on_a_tetrahedron_alone_and_named_right_with_other_valences():
    V, F = meshes.irregular_tetrahedron()
    assert "a ninth" in areas.area_mistake_over([(learner(V, F, "mean"), V, F)])[0]
    V, F = meshes.irregular_bipyramid()
    assert "the mean" in areas.area_mistake_over([(learner(V, F, "mean"), V, F)])[0]


def test_right_areas_and_unnamed_ones_give_none():
    assert areas.area_mistake_over([(learner(V, F), V, F) for V, F in MESHES]) is None
    assert areas.area_mistake_over([(learner_voronoi(V, F), V, F) for V, F in MESHES], "mixed") is None
    rng = np.random.default_rng(0)
    assert areas.area_mistake_over([(rng.random(len(V)), V, F) for V, F in MESHES]) is None


def test_voronoi_kinds_are_named_against_what_is_asked():
    mixed = [(learner_voronoi(V, F), V, F) for V, F in MESHES]
    plain = [(learner_voronoi(V, F, obtuse_rule=False), V, F) for V, F in MESHES]
    bary = [(learner(V, F), V, F) for V, F in MESHES]
    assert "mixed (Voronoi) areas, not the barycentric" in areas.area_mistake_over(mixed)[0]
    assert "plain Voronoi areas" in areas.area_mistake_over(plain)[0]
    assert "not the mixed ones" in areas.area_mistake_over(bary, "mixed")[0]
    found = areas.area_mistake_over(plain, "mixed")
    assert "obtuse rule is missing" in found[0]
    # what is true of the plain pieces (issue 31, L13): not negative at every obtuse corner
    assert "negative where the other two angles differ by more than 90 degrees" in found[1]


def test_a_mistake_is_named_only_where_it_differs_from_the_right_areas():
    V, F = meshes.irregular_tetrahedron()  # no obtuse triangle: plain Voronoi areas are the mixed ones
    assert np.allclose(learner_voronoi(V, F, obtuse_rule=False), mixed_areas(V, F))
    assert areas.area_mistake_over([(learner_voronoi(V, F, obtuse_rule=False), V, F)], "mixed") is None


def test_where_restricts_the_comparison_and_a_rounded_pi_still_matches():
    V, F = meshes.jittered_grid_4x4()
    A = 3 * barycentric_areas(V, F) * (1 + 3e-7)  # read back from a deficit with pi = 3.141593
    where = np.zeros(len(V), bool)
    where[[5, 6, 9, 10]] = True
    A[~where] = np.nan
    assert "full area" in areas.area_mistake_over([(A, V, F, where)])[0]


@pytest.mark.parametrize("asked", areas.AREA_MISTAKES)
def test_every_two_mistakes_differ_on_the_meshes_of_each_check(asked):
    for made in (cotangent.areas_cases(np.random.default_rng(seed)) for seed in (0, 1)):
        per_mesh = [(areas.RIGHT_AREAS[asked](c), [e.build(c) for e in areas.AREA_MISTAKES[asked]]) for c in made]
        count = len(areas.AREA_MISTAKES[asked])
        for a, b in itertools.combinations(range(count), 2):
            assert any(not np.allclose(vs[a], vs[b]) for _, vs in per_mesh), (asked, a, b)
        for a in range(count):
            assert any(not np.allclose(vs[a], right) for right, vs in per_mesh), (asked, a)


def test_unknown_choice_is_refused():
    with pytest.raises(ValueError, match="asked"):
        areas.area_mistake_over([], "voronoi")
