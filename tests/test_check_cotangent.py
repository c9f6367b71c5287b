"""The checks of notebook 03's exercises, tried two ways: answers written fresh the way a learner writes them
(numpy and scipy only; right variants pass whatever the cases' seed, each typical mistake gets its own
diagnosis), and every wrong C of the check's own catalogue, handed in, gets its own diagnosis."""

import types

import numpy as np
import pytest
import scipy.sparse as sp
from diagnoses import assert_diagnosed, replaying

from geomlib import check
from geomlib.lessons.curvature import signed_mean_curvature
from geomlib.lessons.laplace import edge_lengths, intrinsic_cotangent_matrix
from geomlib.teaching.check import cotangent as catalogues

SEEDS = (0, 1, 2, 4182)


@pytest.fixture(autouse=True)
def lenient(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")


def stub(*args):
    raise NotImplementedError("Your turn")


# ---------------------------------------------------------------- cotangent_matrix(l, F), written fresh
def heron(l, perimeter=False, quarter=0.25):
    s = l.sum(axis=1) / (1 if perimeter else 2)
    if perimeter:
        return np.sqrt(s * (s - l[:, 0]) * (s - l[:, 1]) * (s - l[:, 2]))
    return quarter * 4 * np.sqrt(s * (s - l[:, 0]) * (s - l[:, 1]) * (s - l[:, 2]))


def learner_C(l, F, A=None, squares=True, of=lambda cot: cot, shift=0, half=0.5, both=True, diagonal=True, cos=False):
    """C from the lengths, with the mistakes as switches: a loop over the three corners, sparse triplets."""
    n = F.max() + 1
    A = heron(l) if A is None else A
    m = l**2 if squares else l
    rows, cols, vals = [], [], []
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        c = (i + shift) % 3  # the corner whose angle this edge gets (shift 0: the opposite one)
        cot = (m[:, (c + 1) % 3] + m[:, (c + 2) % 3] - m[:, c]) / (4 * A)
        if cos:  # the law of cosines left as it is
            cot = (m[:, (c + 1) % 3] + m[:, (c + 2) % 3] - m[:, c]) / (2 * l[:, (c + 1) % 3] * l[:, (c + 2) % 3])
        w = half * of(cot)
        rows += [F[:, j], F[:, k]] if both else [F[:, j]]
        cols += [F[:, k], F[:, j]] if both else [F[:, k]]
        vals += [w, w] if both else [w]
    C = sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)).tocsr()
    return C - sp.diags(np.asarray(C.sum(axis=1)).ravel()) if diagonal else C


def learner_C_dense_loop(l, F):
    """Another right answer: a Python loop over faces, the angles by arccos, a dense matrix."""
    n = F.max() + 1
    C = np.zeros((n, n))
    for f, lf in zip(F, l):
        for i in range(3):
            j, k = (i + 1) % 3, (i + 2) % 3
            theta = np.arccos((lf[j] ** 2 + lf[k] ** 2 - lf[i] ** 2) / (2 * lf[j] * lf[k]))
            C[f[j], f[k]] += 0.5 / np.tan(theta)
            C[f[k], f[j]] += 0.5 / np.tan(theta)
    return C - np.diag(C.sum(axis=1))


def boundary_rule(l, F, factor):
    C = learner_C(l, F).toarray()
    count = {}
    for f in F:
        for a, b in ((0, 1), (1, 2), (2, 0)):
            count[frozenset((f[a], f[b]))] = count.get(frozenset((f[a], f[b])), 0) + 1
    off = C - np.diag(np.diag(C))
    for e, k in count.items():
        if k == 1:
            i, j = tuple(e)
            off[i, j] *= factor
            off[j, i] *= factor
    return off - np.diag(off.sum(axis=1))


C_MISTAKES = {
    "sign": (lambda l, F: -learner_C(l, F), "the sign of C is flipped"),
    "no 1/2": (lambda l, F: learner_C(l, F, half=1.0), "the factor 1/2 is missing"),
    "Heron with 1/2": (lambda l, F: learner_C(l, F, A=heron(l, quarter=0.5)), "half the right one"),
    "Heron without 1/4": (lambda l, F: learner_C(l, F, A=heron(l, quarter=1.0)), "Heron's formula without its 1/4"),
    "Heron with the perimeter": (lambda l, F: learner_C(l, F, A=heron(l, perimeter=True)), "with the perimeter"),
    "no diagonal": (lambda l, F: learner_C(l, F, diagonal=False), "the diagonal of C is missing"),
    "angle at an end (1)": (lambda l, F: learner_C(l, F, shift=1), "an angle at one of its own ends"),
    "angle at an end (2)": (lambda l, F: learner_C(l, F, shift=2), "an angle at one of its own ends"),
    "no squares": (lambda l, F: learner_C(l, F, squares=False), "with the lengths, not their squares"),
    "cos": (lambda l, F: learner_C(l, F, cos=True), "cos theta is used, not cot theta"),
    "tan": (lambda l, F: learner_C(l, F, of=lambda cot: 1 / cot), "tan is used instead of cot"),
    "boundary left out": (lambda l, F: boundary_rule(l, F, 0.0), "boundary edges are left out"),
    "boundary without 1/2": (lambda l, F: boundary_rule(l, F, 2.0), "without the 1/2"),
    "uniform": (lambda l, F: learner_C(l, F, of=np.ones_like), "the uniform weights"),
    "one direction": (lambda l, F: learner_C(l, F, both=False), "entered at C_jk only"),
    "the pair (M, C)": (lambda l, F: (sp.eye(F.max() + 1), learner_C(l, F)), "not the matrix C"),
}


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("fn", [learner_C, learner_C_dense_loop, lambda l, F: learner_C(l, F).tocsc()])
def test_cotangent_matrix_accepts_correct_variants(fn, seed):
    result = check.cotangent_matrix(fn, seed=seed)
    assert result.passed and "4 x 4 grid" in result.message, result.message


@pytest.mark.parametrize("name", C_MISTAKES)
def test_cotangent_matrix_diagnoses(name):
    fn, phrase = C_MISTAKES[name]
    result = check.cotangent_matrix(fn, seed=7)
    assert_diagnosed(result, phrase, "Reread section 1")
    assert result.partial == (name != "the pair (M, C)"), result.message


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("entry", [e for e in catalogues.C_MISTAKES if e.build is not None], ids=repr)
def test_every_wrong_C_of_the_catalogue_gets_its_own_diagnosis(entry, seed):
    cases = catalogues.cotangent_cases(np.random.default_rng(seed))
    result = check.cotangent_matrix(replaying(cases, entry.build), seed=seed)
    assert_diagnosed(result, entry.diagnosis, f"Cases seed {seed}.")
    assert result.partial


def test_cotangent_matrix_stub_and_the_shortcuts():
    assert_diagnosed(check.cotangent_matrix(stub), "not written yet")
    result = check.cotangent_matrix(lambda l, F: intrinsic_cotangent_matrix(l, F))
    assert_diagnosed(result, "`intrinsic_cotangent_matrix`")
    assert not result.partial


def test_the_cases_hand_in_lengths_that_fit_the_faces():
    for c in catalogues.cotangent_cases(np.random.default_rng(3)):
        assert c.l.shape == c.F.shape and c.F.max() + 1 == c.n
        assert np.allclose(intrinsic_cotangent_matrix(c.l, c.F).toarray(), c.C, atol=1e-12)


# ---------------------------------------------------------------- mixed_areas(V, F), written fresh
def learner_mixed(V, F, rule="mixed", from_lengths=False):
    """Meyer's mixed areas from the law of cosines (rule: "mixed", "plain", "swapped", "barycentric")."""
    l = edge_lengths(V, F) if from_lengths else np.linalg.norm(V[F[:, [2, 0, 1]]] - V[F[:, [1, 2, 0]]], axis=2)
    s = l.sum(axis=1) / 2
    A = np.sqrt(s * (s - l[:, 0]) * (s - l[:, 1]) * (s - l[:, 2]))
    l2 = l**2
    cot = (np.roll(l2, -1, 1) + np.roll(l2, -2, 1) - l2) / (4 * A[:, None])
    piece = (np.roll(l2 * cot, -1, 1) + np.roll(l2 * cot, -2, 1)) / 8  # corner i: edges e_j, e_k at i
    obtuse = cot < 0
    big, small = (A / 4, A / 2) if rule == "swapped" else (A / 2, A / 4)
    per = np.where(obtuse.any(axis=1, keepdims=True), np.where(obtuse, big[:, None], small[:, None]), piece)
    if rule == "plain":
        per = piece
    if rule == "barycentric":
        per = np.repeat(A[:, None] / 3, 3, axis=1)
    out = np.zeros(len(V))
    np.add.at(out, F, per)
    return out


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("from_lengths", [False, True])
def test_mixed_areas_accept_correct_variants(seed, from_lengths):
    result = check.mixed_areas(lambda V, F: learner_mixed(V, F, from_lengths=from_lengths), seed=seed)
    assert result.passed, result.message


@pytest.mark.parametrize(
    "rule, phrase",
    [
        ("plain", "the obtuse rule is missing"),
        ("swapped", "the halves are swapped"),
        ("barycentric", "these are the barycentric areas"),
    ],
)
def test_mixed_areas_diagnoses(rule, phrase):
    result = check.mixed_areas(lambda V, F: learner_mixed(V, F, rule), seed=5)
    assert_diagnosed(result, phrase, "Reread section 2")
    assert result.partial


def test_mixed_areas_per_face_values_and_the_shortcut():
    assert_diagnosed(check.mixed_areas(lambda V, F: np.ones(len(F) + 1)), "not one per vertex")
    result = check.mixed_areas(lambda V, F: __import__("geomlib").vertex_areas(V, F, area="mixed"))
    assert_diagnosed(result, "`vertex_areas`")
    assert not result.partial


# ---------------------------------------------------------------- discrete_principal_curvatures(V, F, deficit)
# the learner's routines of sections 1 and 2, right, in the namespace the answers below are written in
my_cotangent_matrix, my_mixed_areas = learner_C, learner_mixed


def learner_kappas(V, F, deficit, areas=None, sign=1.0, per_area=True, clamp=np.maximum, order=1, absolute=False):
    """kappa_1,2 from the learner's C and mixed areas, H of signed_mean_curvature, K = deficit / A; mistakes as
    switches (``areas``: what M holds, from the mixed areas A)."""
    C = my_cotangent_matrix(edge_lengths(V, F), F)
    A = my_mixed_areas(V, F)
    H = sign * signed_mean_curvature(V, F, sp.diags(A if areas is None else areas(A)), C)
    H = np.abs(H) if absolute else H
    K = deficit / A if per_area else deficit
    with np.errstate(invalid="ignore"):
        root = np.sqrt(clamp(H * H - K, 0.0))
    return (H + root, H - root)[::order]


def learner_kappas_loop(V, F, deficit):
    """Another right answer: dense matrices, a loop over the vertices, the clamp by np.where."""
    M = np.diag(my_mixed_areas(V, F))
    C = np.asarray(my_cotangent_matrix(edge_lengths(V, F), F).todense())
    H = signed_mean_curvature(V, F, M, C)
    k1, k2 = np.empty(len(V)), np.empty(len(V))
    for i in range(len(V)):
        d = H[i] ** 2 - deficit[i] / M[i, i]
        s = np.sqrt(np.where(d < 0, 0.0, d))  # NaN < 0 is False: the boundary's NaN goes through
        k1[i], k2[i] = H[i] + s, H[i] - s
    return [k1, k2]


def beside(fn, **yours):
    """``fn`` written in a notebook whose earlier routines are ``yours`` (my_cotangent_matrix=..., ...)."""
    return types.FunctionType(fn.__code__, {**fn.__globals__, **yours}, fn.__name__, fn.__defaults__)


KAPPA_MISTAKES = {
    "swapped": (lambda *a: learner_kappas(*a, order=-1), "kappa_1 and kappa_2 are swapped"),
    "integrated K": (lambda *a: learner_kappas(*a, per_area=False), "not divided by the area"),
    "no clamp": (lambda *a: learner_kappas(*a, clamp=lambda d, _: d), "is not clamped"),
    "|H^2 - K|": (lambda *a: learner_kappas(*a, clamp=lambda d, _: np.abs(d)), "|H^2 - K| is used"),
    "no root": (lambda *a: learner_kappas(*a, clamp=lambda d, _: np.maximum(d, 0) ** 2), "the square root is missing"),
    "|H|": (lambda *a: learner_kappas(*a, absolute=True), "the sign of H is lost"),
    "-H": (lambda *a: learner_kappas(*a, sign=-1.0), "H has the wrong sign"),
    "M = I in H": (lambda *a: learner_kappas(*a, areas=np.ones_like), "M is the identity in H"),
    "M^-1": (lambda *a: learner_kappas(*a, areas=lambda A: 1 / A), "M^-1 is handed to signed_mean_curvature"),
    "boundary filled": (lambda *a: np.nan_to_num(learner_kappas(*a)), "have values at boundary vertices"),
    "one array (n, 2)": (lambda *a: np.stack(learner_kappas(*a), axis=1), "not the pair (kappa_1, kappa_2)"),
}


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("fn", [learner_kappas, learner_kappas_loop, lambda *a: np.stack(learner_kappas(*a))])
def test_discrete_principal_curvatures_accept_correct_variants(fn, seed):
    result = check.discrete_principal_curvatures(fn, seed=seed)
    assert result.passed and "an irregular bipyramid" in result.message, result.message


@pytest.mark.parametrize("name", KAPPA_MISTAKES)
def test_discrete_principal_curvatures_diagnoses(name):
    fn, phrase = KAPPA_MISTAKES[name]
    result = check.discrete_principal_curvatures(fn, seed=7)
    assert_diagnosed(result, phrase, "Reread section 5")
    assert result.partial == (name != "one array (n, 2)"), result.message


@pytest.mark.parametrize(
    "yours, phrase",
    [
        (dict(my_cotangent_matrix=lambda l, F: 2 * learner_C(l, F)), "your my_cotangent_matrix (section 1)"),
        (dict(my_cotangent_matrix=lambda l, F: learner_C(l, F, diagonal=False)), "check.cotangent_matrix("),
        (dict(my_mixed_areas=lambda V, F: learner_mixed(V, F, "plain")), "your my_mixed_areas (section 2)"),
        (dict(my_mixed_areas=lambda V, F: learner_mixed(V, F, "barycentric")), "fix section 2 first"),
    ],
)
@pytest.mark.parametrize("fn", [learner_kappas, lambda *a: learner_kappas(*a, order=-1)], ids=["right", "swapped"])
def test_a_wrong_earlier_routine_is_named_as_the_exercise_to_fix(yours, phrase, fn):
    result = check.discrete_principal_curvatures(beside(fn, **yours), seed=3)
    assert_diagnosed(result, phrase, "names its mistake")
    assert result.partial


def test_earlier_routines_that_are_stubs_or_missing_leave_the_new_part_judged():
    swapped = KAPPA_MISTAKES["swapped"][0]
    result = check.discrete_principal_curvatures(beside(swapped, my_mixed_areas=None, my_cotangent_matrix=stub), seed=3)
    assert not result.passed and "section 1" not in result.message and "section 2" not in result.message


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("entry", [e for e in catalogues.KAPPA_MISTAKES if e.build is not None], ids=repr)
def test_every_wrong_pair_of_the_catalogue_gets_its_own_diagnosis(entry, seed):
    cases = catalogues.principal_cases(np.random.default_rng(seed))
    result = check.discrete_principal_curvatures(replaying(cases, entry.build), seed=seed)
    assert_diagnosed(result, entry.diagnosis, f"Cases seed {seed}.")
    assert result.partial


def test_the_principal_cases_clamp_split_and_bend_both_ways():
    for seed in SEEDS:
        cases = {c.label: c for c in catalogues.principal_cases(np.random.default_rng(seed))}
        ico, saddle, bump = (
            cases["a jittered icosphere"],
            cases["a saddle on a 4 x 4 grid"],
            cases["a bump on a 4 x 4 grid"],
        )
        assert (ico.H**2 < ico.K).all()  # the clamp at every vertex
        inside = ~saddle.boundary
        assert (saddle.H[inside] < 0).any() and (saddle.H[inside] > 0).any() and (saddle.K[inside] < 0).all()
        assert bump.boundary.any() and np.isnan(bump.kappas[:, bump.boundary]).all()
        bipyramid = cases["an irregular bipyramid"]  # obtuse: the mixed areas are not the barycentric ones
        assert not np.allclose(bipyramid.A, bipyramid.bary)


def test_discrete_principal_curvatures_stub_and_the_shortcuts():
    assert_diagnosed(check.discrete_principal_curvatures(stub), "not written yet")
    from geomlib import discrete_principal_curvatures, laplacian, principal_curvatures
    from geomlib.lessons.curvature import mixed_principal_curvatures

    result = check.discrete_principal_curvatures(mixed_principal_curvatures)
    assert_diagnosed(result, "`mixed_principal_curvatures`", "asks you to write")
    assert not result.partial

    def with_geomlib_pair(V, F, deficit):
        M, C = laplacian(V, F, area="mixed")
        return discrete_principal_curvatures(V, F, M, C, deficit)

    def with_geomlib_kappas(V, F, deficit):
        A = my_mixed_areas(V, F)
        return principal_curvatures(
            signed_mean_curvature(V, F, sp.diags(A), learner_C(edge_lengths(V, F), F)), deficit / A
        )

    for fn, named in ((with_geomlib_pair, "`laplacian`"), (with_geomlib_kappas, "`principal_curvatures`")):
        result = check.discrete_principal_curvatures(fn)
        assert_diagnosed(result, named, "earns no points")
        assert not result.partial


def test_the_rules_name_the_routines_handed_out_and_the_learners_own():
    rules = check.discrete_principal_curvatures.rules
    assert "`edge_lengths` and `signed_mean_curvature`" in rules
    assert "your own `my_cotangent_matrix` and `my_mixed_areas`" in rules
