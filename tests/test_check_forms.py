"""The checks of notebook 02's exercises, tried two ways: learners' answers written fresh (right variants pass
whatever the cases' seed, each typical mistake gets its own diagnosis), and, for the normal curvature, every
wrong answer of the check's own catalogue handed in gets its own diagnosis."""

import numpy as np
import pytest
import sympy as sp
from diagnoses import assert_diagnosed

from geomlib import check
from geomlib.lessons import symbolic
from geomlib.teaching.check import forms as catalogues
from geomlib.teaching.check.catalogue import first_mistake

SEEDS = (0, 1, 2, 4182)


@pytest.fixture(autouse=True)
def lenient(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")


def stub(*args):
    raise NotImplementedError("Your turn")


# ---------------------------------------------------------------- fundamental_forms, written fresh
def parts(a, b, c, u, v):
    p = sp.Matrix([a * sp.cos(u) * sp.sin(v), b * sp.sin(u) * sp.sin(v), c * sp.cos(v)])
    p_u, p_v = p.diff(u), p.diff(v)
    return p, p_u, p_v, p_u.cross(p_v)


def six(a, b, c, u, v):
    """The exercise as a learner writes it: unsimplified expressions, the six coefficients."""
    p, p_u, p_v, m = parts(a, b, c, u, v)
    N = m / sp.sqrt(m.dot(m))
    return (p_u.dot(p_u), p_u.dot(p_v), p_v.dot(p_v), p.diff(u, 2).dot(N), p.diff(u, v).dot(N), p.diff(v, 2).dot(N))


def polar_u(a, b, c, u, v):
    """p written with u as the polar angle and v as the longitude, differentiated correctly."""
    p = sp.Matrix([a * sp.cos(v) * sp.sin(u), b * sp.sin(v) * sp.sin(u), c * sp.cos(u)])
    p_u, p_v = p.diff(u), p.diff(v)
    m = p_u.cross(p_v)
    N = m / sp.sqrt(m.dot(m))
    return (p_u.dot(p_u), p_u.dot(p_v), p_v.dot(p_v), p.diff(u, 2).dot(N), p.diff(u, v).dot(N), p.diff(v, 2).dot(N))


def pair(a, b, c, u, v):
    E, F, G, e, f, g = six(a, b, c, u, v)
    return sp.Matrix([[E, F], [F, G]]), sp.Matrix([[e, f], [f, g]])


def nested_lists(a, b, c, u, v):
    return [list(row) for row in pair(a, b, c, u, v)[0].tolist()], pair(a, b, c, u, v)[1].tolist()


def with_second(fn, scale):
    def wrong(a, b, c, u, v):
        out = six(a, b, c, u, v)
        _, _, _, m = parts(a, b, c, u, v)
        k = scale(m)
        return out[:3] + tuple(k * y for y in out[3:])

    return wrong


FORM_MISTAKES = {
    "u as the polar angle": (polar_u, "u and v are swapped: u is taken as the polar"),
    "parameters in the wrong order": (
        lambda a, b, c, u, v: six(a, b, c, v, u),
        "the forms come out at the point (v, u)",
    ),
    "both forms with u and v exchanged": (
        lambda *x: tuple(six(*x)[k] for k in (2, 1, 0, 5, 4, 3)),
        "E and G are exchanged (and e and g)",
    ),
    "E and G exchanged": (lambda *x: (six(*x)[2], six(*x)[1], six(*x)[0]) + six(*x)[3:], "E and G are exchanged"),
    "F with its sign flipped": (lambda *x: (six(*x)[0], -six(*x)[1]) + six(*x)[2:], "F has the wrong sign"),
    "lengths for E and G": (
        lambda *x: (sp.sqrt(six(*x)[0]), six(*x)[1], sp.sqrt(six(*x)[2])) + six(*x)[3:],
        "lengths |p_u|, |p_v|, not their squares",
    ),
    "F left out": (lambda *x: (six(*x)[0], 0, six(*x)[2]) + six(*x)[3:], "F is left out"),
    "outward normal": (with_second(six, lambda m: -1), "sign of the normal is flipped"),
    "unnormalised normal": (with_second(six, lambda m: sp.sqrt(m.dot(m))), "the normal is not normalised: e, f, g"),
    "unnormalised outward normal": (
        with_second(six, lambda m: -sp.sqrt(m.dot(m))),
        "not normalised and its sign is flipped",
    ),
    "divided twice": (with_second(six, lambda m: 1 / sp.sqrt(m.dot(m))), "divided by |p_u x p_v| twice"),
    "normal of length 2": (with_second(six, lambda m: 2), "off by the same factor"),
    "e and g exchanged": (lambda *x: six(*x)[:3] + (six(*x)[5], six(*x)[4], six(*x)[3]), "e and g are exchanged"),
    "fresh symbols": (lambda a, b, c, u, v: six(a, b, c, *sp.symbols("s t")), "other than a, b, c, u, v"),
    "three values": (lambda *x: six(*x)[:3], "not the pair (I, II)"),
}


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("fn", [pair, six, nested_lists])
def test_forms_accept_correct_variants(fn, seed):
    result = check.fundamental_forms(fn, seed=seed)
    assert result.passed and result.message.endswith(f"Cases seed {seed}."), result.message


def test_forms_accept_the_library_simplified_forms():
    # the library's simplified forms, derived before the check (its ground rules refuse a call inside)
    ell = symbolic.ellipsoid(*sp.symbols("a b c", positive=True))
    simplified = ell.first_fundamental_form(), ell.second_fundamental_form()
    u, v = ell.u, ell.v

    def renamed(a, b, c, s, t):
        return tuple(X.subs({u: s, v: t}, simultaneous=True) for X in simplified)

    assert check.fundamental_forms(renamed).passed


@pytest.mark.parametrize("seed", SEEDS[:2])
@pytest.mark.parametrize("name", FORM_MISTAKES)
def test_forms_diagnoses(name, seed):
    fn, phrase = FORM_MISTAKES[name]
    result = check.fundamental_forms(fn, seed=seed)
    assert_diagnosed(result, phrase, "Reread The definitions and Steps 1-2")
    assert result.partial == (name not in ("three values",)), result.message


def test_every_forms_mistake_of_the_catalogue_is_reached_by_a_learner_answer():
    reached = {check.fundamental_forms(fn, seed=0).message.split(".")[0] for fn, _ in FORM_MISTAKES.values()}
    for entry in catalogues.FORMS_MISTAKES:
        assert entry.diagnosis.split(".")[0] in reached, entry


def test_forms_stub_and_the_shortcut():
    assert_diagnosed(check.fundamental_forms(stub), "not written yet")
    result = check.fundamental_forms(symbolic.ellipsoid_forms)
    assert_diagnosed(result, "calls geomlib's `ellipsoid_forms`")
    assert not result.partial


# ---------------------------------------------------------------- normal_curvature, written fresh
def substituted(forms, a, b, c, u, v):
    sym = sp.symbols("a b c u v", real=True)
    at = dict(zip(sym, (a, b, c, u, v)))
    return [np.array(sp.Matrix(X).subs(at).evalf(), dtype=float) for X in forms(*sym)]


def kappa(forms, a, b, c, u, v, phi):
    """The exercise as a learner writes it: w from I, t in (du, dv), II(t, t) / I(t, t)."""
    I, II = substituted(forms, a, b, c, u, v)
    E, F, G = I[0, 0], I[0, 1], I[1, 1]
    w = np.array([-F, E]) / np.sqrt(E * (E * G - F**2))
    t = np.cos(phi) * np.array([1 / np.sqrt(E), 0.0]) + np.sin(phi) * w
    return (t @ II @ t) / (t @ I @ t)


def kappa_sympy(forms, a, b, c, u, v, phi):
    """Another right answer: all in sympy, with numbers put in for a, b, c before the forms are called."""
    s, t = sp.symbols("s t", real=True)
    I, II = (sp.Matrix(X).subs({s: u, t: v}).evalf() for X in forms(a, b, c, s, t))
    E, F, G = I[0, 0], I[0, 1], I[1, 1]
    d = sp.Matrix([sp.cos(phi) / sp.sqrt(E) - sp.sin(phi) * F / sp.sqrt(E * (E * G - F**2)), 0])
    d[1] = sp.sin(phi) * sp.sqrt(E) / sp.sqrt(E * G - F**2)
    return float((d.T * II * d)[0] / (d.T * I * d)[0])


def kappa_gram_schmidt(forms, a, b, c, u, v, phi):
    """Another right answer: Gram-Schmidt on (1, 0), (0, 1) in the metric I, without dividing by I(t, t)."""
    I, II = substituted(forms, a, b, c, u, v)
    e1 = np.array([1.0, 0.0]) / np.sqrt(I[0, 0])
    w = np.array([0.0, 1.0]) - (e1 @ I @ np.array([0.0, 1.0])) * e1
    w = w / np.sqrt(w @ I @ w)
    t = np.cos(phi) * e1 + np.sin(phi) * w
    return t @ II @ t


def tangent(forms, a, b, c, u, v, phi, rule):
    I, II = substituted(forms, a, b, c, u, v)
    t = rule(I, phi)
    return (t @ II @ t) / (t @ I @ t)


KAPPA_MISTAKES = {
    "the ellipsoid at (a, 0, 0) written in": (
        lambda forms, a, b, c, u, v, phi: a * np.cos(phi) ** 2 / b**2 + a * np.sin(phi) ** 2 / c**2,
        "does not use the forms it receives",
    ),
    "sign": (lambda *x: -kappa(*x), "the sign is flipped"),
    "F ignored": (
        lambda *x: tangent(
            *x, rule=lambda I, p: np.array([np.cos(p) / np.sqrt(I[0, 0]), np.sin(p) / np.sqrt(I[1, 1])])
        ),
        "F is ignored in the tangent",
    ),
    "parameter-plane angle": (
        lambda *x: tangent(*x, rule=lambda I, p: np.array([np.cos(p), np.sin(p)])),
        "(u, v) parameter plane",
    ),
    "no division": (
        lambda forms, a, b, c, u, v, phi: (lambda I, II, t: t @ II @ t)(
            *substituted(forms, a, b, c, u, v), np.array([np.cos(phi), np.sin(phi)])
        ),
        "is not divided by I(t, t)",
    ),
    "the other side": (
        lambda forms, a, b, c, u, v, phi: kappa(forms, a, b, c, u, v, -phi),
        "the angle turns the other way",
    ),
    "from p_v": (
        lambda forms, a, b, c, u, v, phi: kappa(
            lambda *s: [sp.Matrix(X)[::-1, ::-1] for X in forms(*s)], a, b, c, u, v, phi
        ),
        "measured from p_v",
    ),
    "degrees": (lambda forms, a, b, c, u, v, phi: kappa(forms, a, b, c, u, v, np.radians(phi)), "from degrees"),
    "(v, u)": (lambda forms, a, b, c, u, v, phi: kappa(forms, a, b, c, v, u, phi), "evaluated at (v, u)"),
    "a symbol left": (lambda forms, a, b, c, u, v, phi: sp.Symbol("phi") * a, "not a number"),
}


def single_mixed_terms(forms, a, b, c, u, v, phi):
    I, II = substituted(forms, a, b, c, u, v)
    E, F, G = I[0, 0], I[0, 1], I[1, 1]
    du = (np.cos(phi) - np.sin(phi) * F / np.sqrt(E * G - F**2)) / np.sqrt(E)
    dv = np.sin(phi) * np.sqrt(E) / np.sqrt(E * G - F**2)
    q = lambda X: X[0, 0] * du**2 + X[0, 1] * du * dv + X[1, 1] * dv**2  # noqa: E731
    return q(II) / q(I)


@pytest.mark.parametrize(
    "fn, seed", [(kappa, s) for s in SEEDS] + [(kappa_gram_schmidt, s) for s in SEEDS] + [(kappa_sympy, 0)]
)
def test_kappa_accepts_correct_variants(fn, seed):
    result = check.normal_curvature(fn, seed=seed)
    assert result.passed and "Monge patch" in result.message, result.message


@pytest.mark.parametrize("name", KAPPA_MISTAKES)
def test_kappa_diagnoses(name):
    fn, phrase = KAPPA_MISTAKES[name]
    result = check.normal_curvature(fn, seed=3)
    assert_diagnosed(result, phrase, "Reread Step 5")
    assert result.partial == (name != "a symbol left"), result.message


def test_kappa_stub_and_the_shortcuts():
    assert_diagnosed(check.normal_curvature(stub), "not written yet")
    for shortcut, name in (
        (symbolic.forms_normal_curvature, "forms_normal_curvature"),
        (lambda forms, a, b, c, u, v, phi: symbolic.ellipsoid_normal_curvature(a, b, c, phi, u, v), "ellipsoid_normal"),
    ):
        result = check.normal_curvature(shortcut)
        assert_diagnosed(result, f"calls geomlib's `{name}")
        assert not result.partial


def replayed(cases, answer):
    """A learner's function handing back ``answer(case)[k]`` for the k-th angle of the case met (by a, u, phi)."""
    table = {}
    for c in cases:
        for phi, value in zip(c.phis, answer(c)):
            table[(c.a, c.u, float(phi))] = value
    return lambda forms, a, b, c, u, v, phi: table[(a, u, phi)]


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("entry", [e for e in catalogues.KAPPA_MISTAKES if e.build is not None], ids=repr)
def test_every_wrong_kappa_of_the_catalogue_gets_its_own_diagnosis(entry, seed):
    cases = catalogues.kappa_cases(np.random.default_rng(seed))
    result = check.normal_curvature(replayed(cases, entry.build), seed=seed)
    assert_diagnosed(result, entry.diagnosis, f"Cases seed {seed}.")
    assert result.partial


def test_the_mixed_terms_without_their_factor_2_are_named():
    assert_diagnosed(check.normal_curvature(single_mixed_terms, seed=5), "lack their factor 2")


# ---------------------------------------------------------------- principal curvatures from (I, II)
def learner_k(I, II, order=1, ignore_I=False, inverse="I", half=True, swap=False, K_sign=1, det_I=True):
    """A learner's kappa_1, kappa_2 = H +- sqrt(H^2 - K), written apart from the check, with knobs for the mistakes."""
    I, II = sp.Matrix(I), sp.Matrix(II)
    if ignore_I:
        I = sp.eye(2)
    L = I.inv() * II if inverse == "I" else II.inv() * I
    H = L.trace() / (2 if half else 1)
    K = L.det() if det_I else II.det()
    if swap:
        H, K = K, H
    root = sp.sqrt(H**2 - K_sign * K)
    return (H + root, H - root)[::order]


PRINCIPAL_CORRECT = {
    "closed form": learner_k,
    "II I^-1, same eigenvalues": lambda I, II: _right_left(I, II),
    "roots of det(II - k I) = 0": lambda I, II: _quadratic(I, II),
    "simplified": lambda I, II: tuple(sp.simplify(k) for k in learner_k(I, II)),
    "a list": lambda I, II: list(learner_k(I, II)),
}


def _right_left(I, II):
    L = II * I.inv()  # similar to I^-1 II: I (I^-1 II) I^-1
    H, K = L.trace() / 2, L.det()
    return H + sp.sqrt(H**2 - K), H - sp.sqrt(H**2 - K)


def _quadratic(I, II):
    k = sp.Symbol("k")
    A, B, C = sp.Poly((II - k * I).det(), k).all_coeffs()  # det I k^2 + B k + det II
    return (-B + sp.sqrt(B**2 - 4 * A * C)) / (2 * A), (-B - sp.sqrt(B**2 - 4 * A * C)) / (2 * A)


PRINCIPAL_WRONG = {
    "ascending": (dict(order=-1), "the pair is in the wrong order"),
    "II alone": (dict(ignore_I=True), "the eigenvalues of II alone"),
    "II^-1 I": (dict(inverse="II"), "radii 1/kappa"),
    "trace, not half": (dict(half=False), "H is the trace of L"),
    "H and K swapped": (dict(swap=True), "H and K are swapped"),
    "H^2 + K": (dict(K_sign=-1), "the sign of K under the root"),
    "det II": (dict(det_I=False), "K is det II"),
}


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("name", PRINCIPAL_CORRECT)
def test_principal_curvatures_accept_correct_variants(name, seed):
    result = check.principal_curvatures(PRINCIPAL_CORRECT[name], seed=seed)
    assert result.passed and "sphere" in result.message and "Monge" in result.message, result.message


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("name", PRINCIPAL_WRONG)
def test_principal_curvatures_name_the_mistakes_written_by_hand(name, seed):
    knobs, phrase = PRINCIPAL_WRONG[name]
    result = check.principal_curvatures(lambda I, II: learner_k(I, II, **knobs), seed=seed)
    assert_diagnosed(result, phrase)
    assert result.partial


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("entry", [e for e in catalogues.PRINCIPAL_MISTAKES if e.build], ids=repr)
def test_every_wrong_pair_of_the_catalogue_gets_its_own_diagnosis(entry, seed):
    cases = catalogues.principal_cases(np.random.default_rng(seed))
    right = [catalogues._eig(c.I_at, c.II_at) for c in cases]
    mistake = first_mistake(
        catalogues.PRINCIPAL_MISTAKES, cases, [entry.build(c) for c in cases], lambda c: right[cases.index(c)]
    )
    assert mistake is not None and mistake.diagnosis.startswith(entry.diagnosis.split("{")[0]) and mistake.typical


def test_principal_curvatures_refuse_a_dict_and_name_a_scaled_answer_without_credit():
    eigenvals = check.principal_curvatures(lambda I, II: (I.inv() * II).eigenvals())
    assert_diagnosed(eigenvals, "returned a dict")
    scaled = check.principal_curvatures(lambda I, II: tuple(1.5 * k for k in learner_k(I, II)))
    assert_diagnosed(scaled, "differ from the eigenvalues of I^-1 II")
    assert not eigenvals.partial and not scaled.partial
