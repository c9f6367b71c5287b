"""The checks of notebook 03's exercises: they accept correct variants and name each typical mistake.

Each wrong implementation below is written the way a learner writes it (a loop over the faces, the
angles from the edge vectors), with numpy and scipy only, with one mistake; the check must name
that mistake with the exact phrase listed. Correct variants (a loop or vectorised, dense or sparse,
angles from arccos or from the law of cosines, faces in any order) must pass.
"""

import numpy as np
import pytest
import scipy.sparse as sp
from diagnoses import assert_diagnosed

from geomlib import check
from geomlib.teaching.check import CheckFailed


@pytest.fixture(autouse=True)
def lenient(monkeypatch):
    """Checks of wrong functions return their diagnosis instead of raising (as for a reader)."""
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")


def cot_at(V, a, b, c):
    """cot of the angle at corner a of the triangle (a, b, c)."""
    u, v = V[b] - V[a], V[c] - V[a]
    return u @ v / np.linalg.norm(np.cross(u, v))


def tan_at(V, a, b, c):
    return 1.0 / cot_at(V, a, b, c)


def cot_by_arccos(V, a, b, c):
    u, v = V[b] - V[a], V[c] - V[a]
    return 1.0 / np.tan(np.arccos(u @ v / np.linalg.norm(u) / np.linalg.norm(v)))


def triangle_area(V, f, halve=True):
    a = np.linalg.norm(np.cross(V[f[1]] - V[f[0]], V[f[2]] - V[f[0]]))
    return a / 2 if halve else a


def boundary_vertices(F, n):
    count = {}
    for f in F:
        for c in range(3):
            e = tuple(sorted((f[c], f[(c + 1) % 3])))
            count[e] = count.get(e, 0) + 1
    on = np.zeros(n, bool)
    for (i, j), k in count.items():
        if k == 1:
            on[[i, j]] = True
    return on, {e for e, k in count.items() if k == 1}


def voronoi_area_of_corner(V, f, c, rule):
    i, j, k = f[c], f[(c + 1) % 3], f[(c + 2) % 3]
    cots = {v: cot_at(V, v, *[w for w in f if w != v]) for v in f}
    voronoi = (np.sum((V[i] - V[j]) ** 2) * cots[k] + np.sum((V[i] - V[k]) ** 2) * cots[j]) / 8
    if rule == "voronoi" or min(cots.values()) >= 0:
        return voronoi
    area = triangle_area(V, f)
    return area / 2 if cots[i] < 0 else area / 4


def learner_laplacian(
    V,
    F,
    angle="opposite",
    factor=0.5,
    diagonal=True,
    cot=cot_at,
    sign=1.0,
    boundary="natural",
    M_rule="barycentric",
    dense=False,
    weights="cotan",
    divide_by_areas=False,
):
    n = len(V)
    C = np.zeros((n, n)) if dense else sp.lil_matrix((n, n))
    A = np.zeros(n)
    on, bedges = boundary_vertices(F, n)
    for f in F:
        for c in range(3):
            i, j, k = f[c], f[(c + 1) % 3], f[(c + 2) % 3]
            at = {"opposite": (k, i, j), "at i": (i, j, k), "at j": (j, k, i)}[angle]
            w = sign * factor * cot(V, *at) if weights == "cotan" else 0.5
            if tuple(sorted((i, j))) in bedges:
                w *= {"natural": 1.0, "left out": 0.0, "no half": 2.0}.get(boundary, 1.0)
            C[i, j] += w
            C[j, i] += w
        area = triangle_area(V, f, halve=M_rule != "cross not halved")
        for c in range(3):
            A[f[c]] += {
                "barycentric": area / 3,
                "cross not halved": area / 3,
                "full": area,
                "ninth": area / 9,
                "mean": area / 3,
                "faces twice": 2 * area / 3,
            }.get(M_rule) or voronoi_area_of_corner(V, f, c, M_rule)
    if M_rule == "mean":
        A /= np.bincount(F.ravel(), minlength=n)
    C = np.asarray(C) if dense else C.tocsr()
    if diagonal:
        C = C - (np.diag(C.sum(axis=1)) if dense else sp.diags(np.asarray(C.sum(axis=1)).ravel()))
    if boundary == "rows zeroed":  # a fixed-boundary pipeline's matrix
        C = sp.csr_matrix(sp.diags((~on).astype(float)) @ C)
    if divide_by_areas:  # the operator Delta = M^-1 C handed in as C
        C = sp.diags(1 / A) @ C
    M = np.eye(n) if M_rule == "identity" else (np.diag(A) if dense else sp.diags(A))
    return M, C


def vectorised_laplacian(V, F):
    """A right answer written at once: law of cosines, Heron-free areas, faces in reverse order."""
    F = F[::-1]
    n = len(V)
    l2 = np.stack([np.sum((V[F[:, (c + 1) % 3]] - V[F[:, (c + 2) % 3]]) ** 2, axis=1) for c in range(3)], axis=1)
    A_f = np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1) / 2
    cot = (l2.sum(axis=1, keepdims=True) - 2 * l2) / (4 * A_f[:, None])
    rows = np.concatenate([F[:, (c + 1) % 3] for c in range(3)])
    cols = np.concatenate([F[:, (c + 2) % 3] for c in range(3)])
    W = sp.coo_matrix((cot.T.ravel() / 2, (rows, cols)), shape=(n, n))
    W = (W + W.T).tocsr()
    C = W - sp.diags(np.asarray(W.sum(axis=1)).ravel())
    return sp.diags(np.bincount(F.ravel(), np.repeat(A_f / 3, 3), minlength=n)), C


CORRECT_LAPLACIANS = {
    "a loop, sparse": lambda V, F: learner_laplacian(V, F),
    "a loop, dense": lambda V, F: learner_laplacian(V, F, dense=True),
    "angles from arccos": lambda V, F: learner_laplacian(V, F, cot=cot_by_arccos),
    "vectorised, faces reversed": vectorised_laplacian,
    "corners rotated": lambda V, F: learner_laplacian(V, F[:, [1, 2, 0]]),
}

WRONG_LAPLACIANS = [
    (dict(sign=-1.0), "sign of C is flipped"),
    (dict(factor=1.0), "factor 1/2 is missing"),
    (dict(diagonal=False), "diagonal of C is missing"),
    (dict(angle="at i"), "cotangent of the wrong angle"),
    (dict(angle="at j"), "cotangent of the wrong angle"),
    (dict(cot=tan_at), "tan is used instead of cot"),
    (dict(weights="uniform"), "these are the uniform weights (1 for every edge)"),
    (dict(divide_by_areas=True), "C is already divided by the vertex areas"),
    (dict(divide_by_areas=True, M_rule="meyer"), "C is already divided by the vertex areas"),
    # issue 29, class 6: a zeroed boundary row is the boundary rule, not a symmetry slip
    (dict(boundary="rows zeroed"), "rows of the boundary vertices are zeroed"),
    (dict(boundary="left out"), "boundary edges are left out"),
    (dict(boundary="no half"), "boundary edges get cot of their one opposite angle, without the 1/2"),
    (dict(M_rule="identity"), "M is the identity"),
    (dict(M_rule="full"), "full area of its incident triangles"),
    (dict(M_rule="ninth"), "a ninth of its incident triangle areas"),
    # issue 29, class 5: the mean of the incident A_f/3 is named as such, not as "a ninth"
    (dict(M_rule="mean"), "the mean of its triangles' pieces (A_f/3 each) instead of their sum"),
    # issue 29, class 7: counted twice with the cross product halved; both causes named
    (dict(M_rule="faces twice"), "a triangle counted twice, or its area taken as the length of the cross"),
    (dict(M_rule="cross not halved"), "a triangle counted twice, or its area taken as the length of the cross"),
    # issue 29, class 8: the mixed M where the barycentric one is asked
    (dict(M_rule="meyer"), "mixed (Voronoi) areas, not the barycentric ones"),
    (dict(M_rule="voronoi"), "plain Voronoi areas"),
]


@pytest.mark.parametrize("name", CORRECT_LAPLACIANS)
def test_correct_laplacians_pass(name):
    result = check.cotangent_laplacian(CORRECT_LAPLACIANS[name])
    assert result.passed, result.message
    assert "tetrahedron" in result.message and "bipyramid" in result.message and "grid" in result.message


@pytest.mark.parametrize("mistake, phrase", WRONG_LAPLACIANS, ids=[p for _, p in WRONG_LAPLACIANS])
def test_wrong_laplacian_is_diagnosed(mistake, phrase):
    result = check.cotangent_laplacian(lambda V, F: learner_laplacian(V, F, **mistake))
    assert_diagnosed(result, phrase, "Reread section 1 · Cotangent weights, derived")
    assert result.partial, "a named mistake earns partial credit"


def test_laplacian_shapes_are_diagnosed():
    assert_diagnosed(check.cotangent_laplacian(lambda V, F: learner_laplacian(V, F)[1]), "not the pair (M, C)")
    assert_diagnosed(
        check.cotangent_laplacian(lambda V, F: (learner_laplacian(V, F)[0].diagonal(), learner_laplacian(V, F)[1])),
        "M is a vector",
    )


def learner_areas(V, F, divide=3.0, double=False, per_face=False, twice=False, mean=False):
    A = np.zeros(len(V))
    areas = []
    for f in F:
        a = triangle_area(V, f, halve=not double)
        areas.append(a)
        A[f] += (2 if twice else 1) * a / divide
    if mean:
        A /= np.bincount(F.ravel(), minlength=len(V))
    return np.array(areas) if per_face else A


def learner_mixed(V, F, rule="meyer"):
    A = np.zeros(len(V))
    for f in F:
        area = triangle_area(V, f)
        cots = [cot_at(V, f[c], f[(c + 1) % 3], f[(c + 2) % 3]) for c in range(3)]
        obtuse = [c < 0 for c in cots]
        for c in range(3):
            voronoi = voronoi_area_of_corner(V, f, c, "voronoi")
            if rule == "barycentric":
                A[f[c]] += area / 3
            elif rule == "voronoi" or not any(obtuse):
                A[f[c]] += voronoi
            elif rule == "swapped":
                A[f[c]] += area / 4 if obtuse[c] else area / 2
            elif rule == "only at the obtuse corner":
                A[f[c]] += area / 2 if obtuse[c] else voronoi
            else:
                A[f[c]] += area / 2 if obtuse[c] else area / 4
    return A


WRONG_AREAS = [
    (dict(divide=1.0), "full area of its incident triangles"),
    (dict(divide=9.0), "a ninth of its incident triangle areas"),
    (dict(mean=True), "the mean of its triangles' pieces (A_f/3 each) instead of their sum"),
    (dict(double=True), "a triangle counted twice, or its area taken as the length of the cross product"),
    (dict(twice=True), "a triangle counted twice, or its area taken as the length of the cross product"),
    (dict(double=True, divide=1.0), "neither halved nor divided by 3"),
    (dict(per_face=True), "one value per face"),
]


def test_correct_areas_pass():
    assert check.vertex_areas(learner_areas).passed
    assert check.vertex_areas(lambda V, F: learner_areas(V, F[:, [2, 0, 1]])).passed
    assert check.mixed_areas(learner_mixed).passed
    assert check.mixed_areas(lambda V, F: learner_mixed(V, F[::-1])).passed


@pytest.mark.parametrize("mistake, phrase", WRONG_AREAS, ids=[p for _, p in WRONG_AREAS])
def test_wrong_areas_are_diagnosed(mistake, phrase):
    assert_diagnosed(
        check.vertex_areas(lambda V, F: learner_areas(V, F, **mistake)),
        phrase,
        "Which area? Barycentric and mixed Voronoi",
    )


@pytest.mark.parametrize(
    "rule, phrase",
    [("meyer", "mixed (Voronoi) areas, not the barycentric"), ("voronoi", "plain Voronoi areas")],
)
def test_voronoi_kinds_instead_of_barycentric_are_diagnosed(rule, phrase):
    assert_diagnosed(check.vertex_areas(lambda V, F: learner_mixed(V, F, rule)), phrase)


WRONG_MIXED = [
    ("voronoi", "obtuse rule is missing"),
    ("swapped", "halves are swapped"),
    ("barycentric", "barycentric areas"),
    ("only at the obtuse corner", "applied only at the obtuse corner"),
]


@pytest.mark.parametrize("rule, phrase", WRONG_MIXED, ids=[p for _, p in WRONG_MIXED])
def test_wrong_mixed_is_diagnosed(rule, phrase):
    assert_diagnosed(check.mixed_areas(lambda V, F: learner_mixed(V, F, rule)), phrase)


def test_plain_voronoi_hint_says_what_is_true_of_the_pieces():
    # issue 29 class 9 / issue 31 L13: a plain Voronoi piece is not negative at every obtuse corner
    message = check.mixed_areas(lambda V, F: learner_mixed(V, F, "voronoi")).message
    assert "negative at corners of obtuse triangles" not in message
    assert "negative where the other two angles differ by more than 90 degrees" in message


def test_the_three_area_checks_name_the_mean_in_the_same_words():
    phrase = "the mean of its triangles' pieces"
    assert_diagnosed(check.vertex_areas(lambda V, F: learner_areas(V, F, mean=True)), phrase)
    assert_diagnosed(check.cotangent_laplacian(lambda V, F: learner_laplacian(V, F, M_rule="mean")), phrase)
    assert_diagnosed(
        check.mixed_areas(lambda V, F: learner_mixed(V, F) / np.bincount(F.ravel(), minlength=len(V))), phrase
    )


@pytest.mark.parametrize("name", ["cotangent_laplacian", "vertex_areas", "mixed_areas"])
def test_stub_is_not_written_yet(name):
    def stub(V, F):
        raise NotImplementedError("Your turn")

    assert_diagnosed(getattr(check, name)(stub), "not written yet")


def test_strict_mode_raises_for_a_written_wrong_function(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "1")
    with pytest.raises(CheckFailed, match="sign of C is flipped"):
        check.cotangent_laplacian(lambda V, F: learner_laplacian(V, F, sign=-1.0))
