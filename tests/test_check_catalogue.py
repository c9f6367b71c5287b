"""The form checks are written in (geomlib.teaching.check.catalogue): the one matcher's rules, the coercion
helpers' refusals, the cases' seed, tried on the module docstring's own example check."""

import numpy as np
import pytest
from diagnoses import assert_diagnosed, replaying

from geomlib import check
from geomlib.lessons.laplace import barycentric_areas
from geomlib.teaching.check.catalogue import (
    Case,
    Wrong,
    agree,
    eigenpairs,
    first_mistake,
    judge,
    matrix_pair,
    mesh_cases,
    number,
    positions,
    run,
    vector,
)
from geomlib.teaching.check.meshes import grid_3x3, irregular_tetrahedron
from geomlib.teaching.check.result import Mistake, call, case_rng, exercise

# ---------------------------------------------------------------- the module docstring's example, as written there
AREA_MISTAKES = [
    Wrong(
        "each vertex gets the full area of its triangles (not divided by 3)",
        "a triangle gives a third of its area to each corner",
        build=lambda c: 3 * c.A,
    ),
    Wrong("the areas are negative", "A_f = |cross| / 2 >= 0", when=lambda A, right, c: (A < 0).any()),
    Wrong(
        "the areas differ from the barycentric areas on {label}",
        "A_i = 1/3 of the areas of the triangles around i",
        typical=False,
    ),
]


def example_cases(rng):
    meshes = (("an irregular tetrahedron", irregular_tetrahedron()), ("a 3 x 3 grid", grid_3x3()))
    return mesh_cases(meshes, rng, lambda V, F: {"A": barycentric_areas(V, F)})


@exercise("vertex_areas", reread="section 2 · Which area?", forbid=("lessons.laplace.barycentric_areas",))
def vertex_areas(fn):
    cases = example_cases(case_rng())
    answers = run(fn, cases, vector)
    judge(AREA_MISTAKES, cases, answers, right=lambda c: c.A)
    return [c.label for c in cases]


def third(V, F):
    A_f = np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1) / 2
    return np.bincount(F.ravel(), weights=np.repeat(A_f / 3, 3), minlength=len(V))


@pytest.fixture(autouse=True)
def lenient(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")


def test_the_example_passes_a_right_answer_and_names_its_mistakes():
    assert vertex_areas(third).passed
    assert_diagnosed(vertex_areas(lambda V, F: 3 * third(V, F)), "the full area", "Cases seed")
    assert_diagnosed(vertex_areas(lambda V, F: third(V, F) - 1), "the areas are negative")
    wrong = vertex_areas(lambda V, F: third(V, F) + np.arange(len(V)))
    assert_diagnosed(wrong, "differ from the barycentric areas on an irregular tetrahedron")
    assert not wrong.partial
    assert vertex_areas(lambda V, F: 3 * third(V, F)).partial


def test_float32_is_named_as_a_precision_problem_with_partial_credit():
    result = vertex_areas(lambda V, F: (third(V, F) * (1 + 3e-5)).astype(np.float32))
    assert_diagnosed(result, "right to float32 precision: compute in float64")
    assert result.partial
    for seed in range(10):  # computed in float32 throughout: passes, or is told so; never the catch-all
        result = vertex_areas(lambda V, F: third(V.astype(np.float32), F), seed=seed)
        assert result.passed or "float32 precision" in result.message, result.message


def test_a_mistake_is_named_only_when_it_matches_on_every_case_and_is_wrong_on_one():
    cases = [Case("one", x=np.ones(3)), Case("two", x=np.arange(3.0))]
    doubled = Wrong("doubled", build=lambda c: 2 * c.x)
    same_as_right_on_one = Wrong("zeroed", build=lambda c: np.zeros(3) if c.label == "one" else c.x)
    right = [c.x for c in cases]
    assert first_mistake([doubled], cases, right, lambda c: c.x) is None
    found = first_mistake([doubled], cases, [2 * c.x for c in cases], lambda c: c.x)
    assert found.diagnosis == "doubled" and found.typical
    # doubled on one case only: not named, the catch-all (typical=False) speaks
    half = [2 * cases[0].x, cases[1].x + 1]
    assert not first_mistake([doubled], cases, half, lambda c: c.x).typical
    # a wrong answer that is right on case "two" is named, by the case where it is wrong
    found = first_mistake([same_as_right_on_one], cases, [np.zeros(3), cases[1].x], lambda c: c.x)
    assert found.diagnosis == "zeroed"
    # a "mistake" equal to the right answer on every case is never named
    assert first_mistake([Wrong("same", build=lambda c: c.x)], cases, half, lambda c: c.x).diagnosis != "same"


def test_a_case_counts_its_vertices_from_a_sparse_first_input_or_a_fact():
    import scipy.sparse as sp

    assert Case("sparse", M=sp.identity(7, format="csr"), k=3).n == 7  # len() of a sparse matrix raises
    assert Case("dense", V=np.zeros((5, 3))).n == 5
    assert Case("told", M=sp.identity(7, format="csr")).but(n=4).n == 4


def test_agree_is_relative_to_the_scale_and_reads_where():
    assert agree(1e6 * np.ones(3) + 0.5, 1e6 * np.ones(3))
    assert not agree(np.ones(3) + 1e-3, np.ones(3))
    assert agree(np.array([1.0, 5.0]), np.array([1.0, 9.0]), Case("", x=None).but(where=np.array([True, False])))
    assert agree(np.array([np.nan, 1.0]), np.array([np.nan, 1.0]))
    assert not agree(np.ones(3), np.ones((3, 1)))


@pytest.mark.parametrize(
    "helper, out, phrase",
    [
        (lambda out: matrix_pair(out, 2), np.eye(2), "not the pair (M, C)"),
        (lambda out: matrix_pair(out, 2), (np.ones(2), np.eye(2)), "M is a vector"),
        (lambda out: matrix_pair(out, 2), (np.eye(3), np.eye(2)), "M has shape (3, 3)"),
        (lambda out: vector(out, 3), np.ones(4), "expected (3,)"),
        (lambda out: positions(out, 2), np.ones((3, 2)), "expected (2, 3)"),
        (lambda out: positions(out, 1), np.array([[np.nan, 0, 0]]), "NaN or infinite"),
        (lambda out: eigenpairs(out, 4, 2), (np.ones(2), np.ones((2, 4))), "E is transposed"),
        (lambda out: eigenpairs(out, 4, 2), (np.ones((4, 2)), np.ones(2)), "as (E, lam)"),
        (lambda out: eigenpairs(out, 4, 2), (np.ones(3), np.ones((4, 3))), "3 eigenpairs"),
        (lambda out: number(out), np.ones(2), "not one number"),
        (lambda out: number(out), "one", "not a number"),
    ],
)
def test_a_wrong_shape_or_type_is_never_partial_credit(helper, out, phrase):
    with pytest.raises(Mistake, match=phrase.replace("(", r"\(").replace(")", r"\)")) as caught:
        helper(out)
    assert not caught.value.typical


def test_coercion_reads_what_is_right():
    M, C = matrix_pair((np.eye(2, dtype=int), np.eye(2)), 2)
    assert M.dtype == float and C.shape == (2, 2)
    assert vector(np.ones((1, 3)), 3).shape == (3,)
    lam, E = eigenpairs((np.ones((2, 1)), np.ones((4, 2)) + 0j), 4, 2)
    assert lam.shape == (2,) and E.dtype == float
    assert number(np.array([2.5])) == 2.5


def test_the_seed_fixes_the_cases_and_is_reported():
    seen = []
    for seed in (5, 5, 6):
        result = vertex_areas(replaying(example_cases(np.random.default_rng(seed)), lambda c: c.A), seed=seed)
        assert result.passed and result.message.endswith(f"Cases seed {seed}."), result.message
        seen.append(example_cases(np.random.default_rng(seed))[0].V)
    assert np.array_equal(seen[0], seen[1]) and not np.allclose(seen[0], seen[2])


# ---------------------------------------------------------------- every call confirms the caller's arrays are unchanged
def test_an_input_changed_in_place_is_named_by_the_learners_own_parameter_name():
    def shifted(V, F):
        V -= V.mean(axis=0)  # areas do not care, the caller's V does
        return third(V, F)

    def sorted_faces(points, faces):
        faces.sort(axis=1)  # flips half the faces' orientation: areas do not care
        return third(points, faces)

    result = vertex_areas(shifted)
    assert_diagnosed(result, "the function changed its input V in place", "V = V.copy()")
    assert result.partial
    assert_diagnosed(vertex_areas(sorted_faces), "changed its input faces in place")
    assert vertex_areas(lambda V, F: third(V.copy(), F)).passed


def test_a_smoothing_loop_that_overwrites_the_callers_V_is_named():
    from geomlib.lessons.laplace import laplacian

    def overwrites(V, F, tau, iterations):
        M, C = laplacian(V, F)
        held = np.zeros(len(V), bool)
        edges = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
        e, count = np.unique(edges, axis=0, return_counts=True)
        held[e[count == 1].ravel()] = True
        for _ in range(iterations):
            V[~held] += tau * (C @ V)[~held] / M.diagonal()[~held, None]  # the caller's V, step by step
        return V

    assert_diagnosed(check.smoothing_loop(overwrites), "the function changed its input V in place")


# ---------------------------------------------------------------- every check: a wrong type earns nothing, and never a crash
EXERCISES = sorted(name for name in dir(check) if hasattr(getattr(check, name), "partial_credit"))


@pytest.mark.parametrize("name", EXERCISES)
def test_an_answer_of_the_wrong_type_earns_nothing_in_every_check(name):
    for returned in (None, "text", (np.zeros(2),), object()):
        result = getattr(check, name).evaluate(lambda *args, returned=returned: returned)
        assert not result.passed and not result.partial, (name, returned, result.message)


@exercise("a number", reread="section 0")
def a_number(fn):
    if float(call(fn)) != 2.0:  # float() of what came back may raise: the check must not
        raise Mistake("not two", typical=False)
    return ["two"]


def test_an_answer_the_check_cannot_read_is_a_failed_check_without_points():
    result = a_number.evaluate(lambda: "two")
    assert_diagnosed(result, "could not be read as an answer (ValueError", "Reread section 0")
    assert not result.partial and result.written
    assert a_number.evaluate(lambda: 2).passed


def test_each_check_module_holds_at_most_110_lines_per_exercise():
    """Every line of a check module counts, docstrings and blank lines too: its total over its exercises."""
    from pathlib import Path

    import geomlib.teaching.check as package

    counted = 0
    for path in sorted(Path(package.__file__).parent.glob("*.py")):
        text = path.read_text()
        exercises = text.count("\n@exercise(")
        if exercises:
            counted += 1
            lines = len(text.splitlines())
            assert lines <= 110 * exercises, f"{path.name}: {lines} lines for {exercises} exercises, over 110 each"
    assert counted >= 7  # one module per notebook 01..07
