"""The checks of notebook 01's exercises, tried two ways: every wrong answer of the checks' own catalogues,
handed in, gets its own diagnosis; and answers written fresh as learners write them (numpy and scipy only: the
ground rules refuse geomlib's own routines), an oracle independent of the catalogues: correct variants pass
whatever the cases' seed, each typical mistake gets its diagnosis, and a catch-all never hides a mistake the
check can name."""

import numpy as np
import pytest
import scipy.sparse as sparse
from diagnoses import assert_diagnosed, replaying

from geomlib import check
from geomlib.teaching.check import CheckFailed
from geomlib.teaching.check import uniform as catalogues

SEEDS = (0, 1, 2, 3, 4182)


@pytest.fixture(autouse=True)
def lenient(monkeypatch):
    # a learner's session: a failed check returns its diagnosis instead of raising
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")


def stub(V, F):
    raise NotImplementedError("Your turn")


# ---------------------------------------------------------------- uniform_laplacian, written fresh
def directed(V, F):
    """(n, n) dense: how many triangles list i -> j as one of their edges."""
    D = np.zeros((len(V), len(V)))
    for a, b in ((0, 1), (1, 2), (2, 0)):
        np.add.at(D, (F[:, a], F[:, b]), 1.0)
    return D


def adjacency(V, F):
    return ((directed(V, F) + directed(V, F).T) > 0).astype(float)


def triangles_at(V, F):
    return np.bincount(F.ravel(), minlength=len(V)).astype(float)


def uniform_pair(V, F, A=None, diagonal=None, M=None):
    A = adjacency(V, F) if A is None else A
    valence = adjacency(V, F).sum(axis=1)
    C = A - np.diag(valence if diagonal is None else diagonal)
    return (np.diag(valence) if M is None else M), C


def uniform_sparse(V, F):
    """A learner's sparse solution: coo with duplicates summed, then clipped to 1."""
    n = len(V)
    I, J = F.ravel(), F[:, [1, 2, 0]].ravel()
    W = sparse.coo_matrix((np.ones(len(I)), (I, J)), shape=(n, n)).tocsr()
    A = ((W + W.T) > 0).astype(float)
    valence = np.asarray(A.sum(axis=1)).ravel()
    return sparse.diags(valence), (A - sparse.diags(valence)).tocsr()


def uniform_edge_loop(V, F):
    """Another correct answer: a set of undirected edges, dense matrices, float32."""
    n = len(V)
    edges = {tuple(sorted((int(f[a]), int(f[b])))) for f in F for a, b in ((0, 1), (1, 2), (2, 0))}
    C = np.zeros((n, n), np.float32)
    for i, j in edges:
        C[i, j] = C[j, i] = 1
    valence = C.sum(axis=1)
    return np.diag(valence), C - np.diag(valence)


def cotangent_pair(V, F):
    """The cotangent (M, C) of notebook 03, written out."""
    n = len(V)
    C, M = np.zeros((n, n)), np.zeros(n)
    for k in range(3):
        i, j, o = F[:, (k + 1) % 3], F[:, (k + 2) % 3], F[:, k]
        a, b = V[i] - V[o], V[j] - V[o]
        cross = np.linalg.norm(np.cross(a, b), axis=1)
        w = 0.5 * np.einsum("ij,ij->i", a, b) / cross
        np.add.at(C, (i, j), w)
        np.add.at(C, (j, i), w)
        np.add.at(M, o, cross / 6)
    return np.diag(M), C - np.diag(C.sum(axis=1))


UNIFORM_MISTAKES = {
    "flipped sign": (lambda V, F: (uniform_pair(V, F)[0], -uniform_pair(V, F)[1]), "sign of C is flipped"),
    "no diagonal": (lambda V, F: uniform_pair(V, F, diagonal=np.zeros(len(V))), "diagonal of C is missing"),
    "+valence on the diagonal": (
        lambda V, F: uniform_pair(V, F, diagonal=-adjacency(V, F).sum(axis=1)),
        "diagonal of C has the wrong sign",
    ),
    "M^-1 C as C": (
        lambda V, F: (uniform_pair(V, F)[0], uniform_pair(V, F)[1] / adjacency(V, F).sum(axis=1)[:, None]),
        "M^-1 C, not C",
    ),
    "diag(1/valence) @ A - I as C, M = I": (
        lambda V, F: (np.eye(len(V)), np.diag(1 / adjacency(V, F).sum(axis=1)) @ adjacency(V, F) - np.eye(len(V))),
        "M^-1 C, not C",
    ),
    "one per triangle": (
        lambda V, F: uniform_pair(
            V, F, A=directed(V, F) + directed(V, F).T, diagonal=(directed(V, F) + directed(V, F).T).sum(axis=1)
        ),
        "an edge counts once per triangle",
    ),
    "triangles on the diagonal": (
        lambda V, F: uniform_pair(V, F, diagonal=triangles_at(V, F)),
        "the diagonal counts the triangles",
    ),
    "one direction per edge": (
        lambda V, F: uniform_pair(V, F, A=directed(V, F), diagonal=directed(V, F).sum(axis=1)),
        "only in the direction the triangles list it",
    ),
    "a cotangent C": (cotangent_pair, "C holds the cotangent weights"),
    "identity M": (lambda V, F: uniform_pair(V, F, M=np.eye(len(V))), "M is the identity"),
    "negative M": (lambda V, F: uniform_pair(V, F, M=-np.diag(adjacency(V, F).sum(axis=1))), "M has the wrong sign"),
    "diag(1/valence) as M": (
        lambda V, F: uniform_pair(V, F, M=np.diag(1 / adjacency(V, F).sum(axis=1))),
        "M holds 1/valence: that is M^-1",
    ),
    "triangles in M": (lambda V, F: uniform_pair(V, F, M=np.diag(triangles_at(V, F))), "M counts the triangles"),
    "areas in M": (lambda V, F: (cotangent_pair(V, F)[0], uniform_pair(V, F)[1]), "M holds vertex areas"),
    "M as a vector": (lambda V, F: (adjacency(V, F).sum(axis=1), uniform_pair(V, F)[1]), "M is a vector"),
    "only C": (lambda V, F: uniform_pair(V, F)[1], "not the pair (M, C)"),
}


# ---------------------------------------------------------------- the catalogues, handed in
def built(catalogue):
    return [entry for entry in catalogue if entry.build is not None]


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("entry", built(catalogues.C_MISTAKES), ids=repr)
def test_every_wrong_C_of_the_catalogue_gets_its_own_diagnosis(entry, seed):
    cases = catalogues.uniform_cases(np.random.default_rng(seed))
    result = check.uniform_laplacian(replaying(cases, lambda c: (c.M, entry.build(c))), seed=seed)
    assert_diagnosed(result, entry.diagnosis, f"Cases seed {seed}.")
    assert result.partial


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("entry", built(catalogues.M_MISTAKES), ids=repr)
def test_every_wrong_M_of_the_catalogue_gets_its_own_diagnosis(entry, seed):
    cases = catalogues.uniform_cases(np.random.default_rng(seed))
    result = check.uniform_laplacian(replaying(cases, lambda c: (entry.build(c), c.C)), seed=seed)
    assert_diagnosed(result, entry.diagnosis)
    assert result.partial


@pytest.mark.parametrize("seed", SEEDS)
def test_the_catalogues_right_answers_pass_and_the_seed_is_reported(seed):
    cases = catalogues.uniform_cases(np.random.default_rng(seed))
    result = check.uniform_laplacian(replaying(cases, lambda c: (c.M, c.C)), seed=seed)
    assert result.passed and result.message.endswith(f"Cases seed {seed}."), result.message


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("fn", [uniform_pair, uniform_sparse, uniform_edge_loop])
def test_uniform_accepts_correct_variants(fn, seed):
    result = check.uniform_laplacian(fn, seed=seed)
    assert result.passed and "tetrahedron" in result.message and "icosphere" in result.message, result.message


def test_the_cases_vary_from_run_to_run_unless_the_seed_is_fixed(monkeypatch):
    seen = set()

    def record(V, F):
        seen.add(V.tobytes())
        return uniform_pair(V, F)

    for _ in range(3):
        assert check.uniform_laplacian(record).passed
    assert len(seen) == 9  # three meshes, placed anew each run
    seen.clear()
    monkeypatch.setenv("GEOMLIB_CHECK_SEED", "17")
    for _ in range(2):
        assert check.uniform_laplacian(record).message.endswith("Cases seed 17.")
    assert len(seen) == 3


def test_uniform_accepts_any_vertex_order_of_the_faces():
    def rotated(V, F):
        return uniform_sparse(V, np.roll(F, 1, axis=1))

    assert check.uniform_laplacian(rotated).passed


@pytest.mark.parametrize("name", UNIFORM_MISTAKES)
def test_uniform_diagnoses(name):
    fn, phrase = UNIFORM_MISTAKES[name]
    result = check.uniform_laplacian(fn)
    assert_diagnosed(result, phrase, "Reread section 2")
    named = name not in ("only C", "M as a vector")  # a wrong shape earns nothing (docs/grading.md)
    assert result.partial == named, result.message


def test_uniform_unnamed_mistake_is_the_catch_all_without_partial_credit():
    def noisy(V, F):
        M, C = uniform_pair(V, F)
        C = C.copy()
        C[0, 1] = C[1, 0] = 0.5
        return M, C

    result = check.uniform_laplacian(noisy)
    assert_diagnosed(result, "C differs from the uniform Laplacian")
    assert not result.partial


def test_uniform_stub_is_not_written_yet():
    assert_diagnosed(check.uniform_laplacian(stub), "not written yet")


# ---------------------------------------------------------------- gaussian_curvature, written fresh
def corner_angles(V, F, pi=np.pi, dtype=float):
    """(m, 3) angles by arccos, in radians (``pi`` only for the degrees variant)."""
    theta = np.zeros(F.shape, dtype)
    for k in range(3):
        a, b = V[F[:, (k + 1) % 3]] - V[F[:, k]], V[F[:, (k + 2) % 3]] - V[F[:, k]]
        cos = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
        theta[:, k] = np.arccos(np.clip(cos, -1, 1)) * (pi / np.pi)
    return theta


def face_area(V, F):
    return np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1) / 2


def boundary(V, F):
    edges = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    e, count = np.unique(edges, axis=0, return_counts=True)
    mask = np.zeros(len(V), bool)
    mask[np.unique(e[count == 1])] = True
    return mask


def vertex_area(V, F, how="third"):
    n, Af = len(V), face_area(V, F)
    summed = np.bincount(F.ravel(), weights=np.repeat(Af, 3), minlength=n)
    if how == "third":
        return summed / 3
    if how == "full":
        return summed
    if how == "ninth":
        return summed / 9
    if how == "mean":  # the mean of the incident A_f / 3, not their sum
        return summed / 3 / np.bincount(F.ravel(), minlength=n)
    if how == "twice":  # the cross product's length taken as the area
        return 2 * summed / 3
    if how in ("mixed", "voronoi"):
        A = np.zeros(n)
        theta = corner_angles(V, F)
        cot = 1 / np.tan(theta)
        for k in range(3):
            i, j, o = F[:, k], F[:, (k + 1) % 3], F[:, (k + 2) % 3]
            lj, lo = np.sum((V[o] - V[i]) ** 2, axis=1), np.sum((V[j] - V[i]) ** 2, axis=1)
            piece = (lo * cot[:, (k + 2) % 3] + lj * cot[:, (k + 1) % 3]) / 8
            if how == "mixed":
                obtuse = (theta > np.pi / 2).any(axis=1)
                piece = np.where(obtuse, np.where(theta[:, k] > np.pi / 2, Af / 2, Af / 4), piece)
            np.add.at(A, i, piece)
        return A
    raise ValueError(how)


def learner_K(V, F, two_pi=2 * np.pi, area="third", rule="nan", sign=1.0, pi=np.pi, divide=True, dtype=float):
    theta_sum = np.bincount(F.ravel(), weights=corner_angles(V, F, pi, dtype).ravel(), minlength=len(V))
    deficit = sign * (two_pi - theta_sum) if pi == np.pi else (360.0 - theta_sum)
    K = deficit / vertex_area(V, F, area) if divide else deficit
    if rule == "nan":
        K[boundary(V, F)] = np.nan
    elif rule == "zero":
        K[boundary(V, F)] = 0.0
    return K


K_CORRECT = {
    "written out": learner_K,
    "pi to 7 digits": lambda V, F: learner_K(V, F, two_pi=2 * 3.141593),
    "pi to 7 digits, 2 pi as 6.283185": lambda V, F: learner_K(V, F, two_pi=6.283185),
    "single-precision angles": lambda V, F: learner_K(V, F, dtype=np.float32),
    "rotated faces": lambda V, F: learner_K(V, np.roll(F, 2, axis=1)),
}

K_MISTAKES = {
    "sign": (lambda V, F: learner_K(V, F, sign=-1.0), "sign of the deficit is flipped"),
    "degrees": (lambda V, F: learner_K(V, F, pi=180.0), "in degrees"),
    "integrated": (lambda V, F: learner_K(V, F, divide=False), "not divided by the vertex area"),
    "full area": (lambda V, F: learner_K(V, F, area="full"), "full area of its incident triangles"),
    "a ninth": (lambda V, F: learner_K(V, F, area="ninth"), "a ninth"),
    "mean of the A_f / 3": (lambda V, F: learner_K(V, F, area="mean"), "the mean of its triangles' pieces"),
    "mean, pi to 7 digits": (
        lambda V, F: learner_K(V, F, two_pi=2 * 3.141593, area="mean"),
        "the mean of its triangles' pieces",
    ),
    "cross product as area": (lambda V, F: learner_K(V, F, area="twice"), "twice the right one"),
    "mixed area": (lambda V, F: learner_K(V, F, area="mixed"), "mixed (Voronoi) areas"),
    "plain Voronoi area": (lambda V, F: learner_K(V, F, area="voronoi"), "plain Voronoi areas"),
    "no boundary rule": (lambda V, F: learner_K(V, F, rule=None), "interior formula is applied at boundary"),
    "no boundary rule, pi to 7 digits": (
        lambda V, F: learner_K(V, F, two_pi=2 * 3.141593, rule=None),
        "interior formula is applied at boundary",
    ),
    "zero on the boundary": (lambda V, F: learner_K(V, F, rule="zero"), "boundary vertices have a value"),
    "a matrix": (lambda V, F: np.diag(learner_K(V, F, rule="zero")), "expected (4,)"),
}


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("entry", built(catalogues.K_MISTAKES + catalogues.K_BOUNDARY_MISTAKES), ids=repr)
def test_every_wrong_K_of_the_catalogue_gets_its_own_diagnosis(entry, seed):
    cases = catalogues.curvature_cases(np.random.default_rng(seed))
    result = check.gaussian_curvature(replaying(cases, entry.build), seed=seed)
    assert_diagnosed(result, entry.diagnosis)
    assert result.partial


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("name", K_CORRECT)
def test_K_accepts_correct_variants(name, seed):
    result = check.gaussian_curvature(K_CORRECT[name], seed=seed)
    assert result.passed and "bump" in result.message and "icosphere" in result.message, result.message


@pytest.mark.parametrize("name", K_MISTAKES)
def test_K_diagnoses(name):
    fn, phrase = K_MISTAKES[name]
    result = check.gaussian_curvature(fn)
    assert_diagnosed(result, phrase, "Reread section 3")
    assert result.partial == (name != "a matrix"), result.message


def test_the_mean_area_is_told_from_a_ninth_by_the_meshes_whose_valences_differ():
    # on the tetrahedron alone (valence 3 everywhere) the two coincide
    valences = [np.bincount(c.F.ravel()) for c in catalogues.curvature_cases(np.random.default_rng(0))]
    assert set(valences[0]) == {3} and any(len(set(v)) > 1 for v in valences[1:])
    result = check.gaussian_curvature(K_MISTAKES["mean of the A_f / 3"][0])
    assert "ninth" not in result.message, result.message


def test_K_catch_all_still_names_the_missing_boundary_rule():
    def wrong_inside_too(V, F):
        K = learner_K(V, F, rule=None)
        return K + 0.5 * np.sin(np.arange(len(K)))

    result = check.gaussian_curvature(wrong_inside_too)
    assert_diagnosed(result, "K differs", "have values, where K is not defined")
    assert not result.partial


@pytest.mark.parametrize("seed", range(20))
def test_the_checks_meshes_hold_obtuse_triangles_and_a_boundary_whatever_the_seed(seed):
    for cases in (catalogues.curvature_cases, catalogues.uniform_cases):
        placed = cases(np.random.default_rng(seed))
        assert any((corner_angles(c.V, c.F) > np.pi / 2).any() for c in placed)
        assert any(boundary(c.V, c.F).any() for c in placed)
        assert all(np.linalg.norm(c.V, axis=1).min() > 1.0 for c in placed)  # away from the origin


def test_K_stub_and_strict_mode(monkeypatch):
    assert_diagnosed(check.gaussian_curvature(stub), "not written yet")
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "1")
    assert not check.gaussian_curvature(stub).passed  # a stub never raises
    with pytest.raises(CheckFailed, match="sign of the deficit"):
        check.gaussian_curvature(K_MISTAKES["sign"][0])


# ---------------------------------------------------------------- the signed mean curvature H, from (M, C)
def learner_H(V, F, M, C, sign=1.0, half=0.5, inverse=True, normalise=True, weights="area", rule="nan"):
    """A learner's H = -1/2 <M^-1 C x, n>, written independently of the check, with knobs for the mistakes."""
    CX = C @ V
    DX = CX / M.diagonal()[:, None] if inverse else CX
    N = np.zeros_like(V)
    for f in F:
        a, b, c = V[f]
        n = np.cross(b - a, c - a)
        N[f] += n if weights == "area" else n / np.linalg.norm(n)
    if normalise:
        N /= np.linalg.norm(N, axis=1)[:, None]
    H = -sign * half * (DX * N).sum(axis=1)
    if rule == "nan":
        H[boundary(V, F)] = np.nan
    return H


def H_dense(V, F, M, C):
    """Correct variant: dense matrices and a solve instead of a division."""
    DX = np.linalg.solve(M.toarray(), C.toarray() @ V)
    N = np.zeros_like(V)
    for k in range(3):
        np.add.at(N, F[:, k], np.cross(V[F[:, (k + 1) % 3]] - V[F[:, k]], V[F[:, (k + 2) % 3]] - V[F[:, k]]))
    H = -0.5 * np.einsum("ij,ij->i", DX, N / np.linalg.norm(N, axis=1, keepdims=True))
    return np.where(boundary(V, F), np.nan, H).tolist()  # a list is read as the vector it holds


def H_sparse_solve(V, F, M, C):
    """Correct variant: scipy.sparse.linalg.spsolve, the normals from the faces' corners in a rotated order."""
    import scipy.sparse.linalg as spla

    DX = spla.spsolve(M.tocsc(), C @ V)
    i, j, k = F[:, 1], F[:, 2], F[:, 0]
    n2 = np.cross(V[j] - V[i], V[k] - V[i])
    N = sum(
        sparse.coo_matrix((n2[:, d], (c, np.full(len(F), d))), shape=(len(V), 3)) for c in (i, j, k) for d in range(3)
    )
    N = N.toarray() / np.linalg.norm(N.toarray(), axis=1)[:, None]
    H = -0.5 * (DX * N).sum(axis=1)
    H[boundary(V, F)] = np.nan
    return H


H_MISTAKES = {
    "inward normals": (lambda V, F, M, C: learner_H(V, F[:, ::-1], M, C), "H has the wrong sign"),
    "no minus sign": (lambda V, F, M, C: learner_H(V, F, M, C, sign=-1.0), "H has the wrong sign"),
    "no 1/2": (lambda V, F, M, C: learner_H(V, F, M, C, half=1.0), "the factor 1/2 is missing"),
    "no M^-1": (lambda V, F, M, C: learner_H(V, F, M, C, inverse=False), "M^-1 is missing"),
    "raw normal sums": (lambda V, F, M, C: learner_H(V, F, M, C, normalise=False), "the normals are not normalised"),
    "unit face normals": (
        lambda V, F, M, C: learner_H(V, F, M, C, weights="unit"),
        "the normals average the unit face normals",
    ),
    "no boundary rule": (lambda V, F, M, C: learner_H(V, F, M, C, rule="formula"), "applied at boundary vertices"),
    "boundary zero": (
        lambda V, F, M, C: np.nan_to_num(learner_H(V, F, M, C)),
        "boundary vertices have a value (the wrong boundary rule)",
    ),
}


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("entry", built(catalogues.H_MISTAKES + catalogues.H_BOUNDARY_MISTAKES), ids=repr)
def test_every_wrong_H_of_the_catalogue_gets_its_own_diagnosis(entry, seed):
    cases = catalogues.mean_cases(np.random.default_rng(seed))
    result = check.mean_curvature(replaying(cases, entry.build), seed=seed)
    assert_diagnosed(result, entry.diagnosis)
    assert result.partial


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("fn", [learner_H, H_dense, H_sparse_solve])
def test_H_accepts_correct_variants(fn, seed):
    result = check.mean_curvature(fn, seed=seed)
    assert result.passed and "bump" in result.message and "cotangent (M, C)" in result.message, result.message


@pytest.mark.parametrize("name", H_MISTAKES)
def test_H_diagnoses(name):
    fn, phrase = H_MISTAKES[name]
    result = check.mean_curvature(fn)
    assert_diagnosed(result, phrase)
    assert result.partial


def test_H_unnamed_mistake_and_wrong_shape_earn_no_partial_credit():
    scaled = check.mean_curvature(lambda V, F, M, C: 1.3 * learner_H(V, F, M, C))
    assert_diagnosed(scaled, "H differs from -1/2 <M^-1 C x, n> at interior vertices")
    vectors = check.mean_curvature(lambda V, F, M, C: -0.5 * (C @ V) / M.diagonal()[:, None])
    assert_diagnosed(vectors, "expected (")
    assert not scaled.partial and not vectors.partial
