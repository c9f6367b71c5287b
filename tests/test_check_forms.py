"""The checks of notebook 02's exercises: the reference passes, typical mistakes get their diagnosis."""

import time

import numpy as np
import pytest
import sympy as sp
from diagnoses import assert_diagnosed

from geomlib import check


@pytest.fixture(autouse=True)
def lenient(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")


def stub(*args):
    raise NotImplementedError("Your turn")


def parts(a, b, c, u, v):
    p = sp.Matrix([a * sp.cos(u) * sp.sin(v), b * sp.sin(u) * sp.sin(v), c * sp.cos(v)])
    p_u, p_v = p.diff(u), p.diff(v)
    return p, p_u, p_v, p_u.cross(p_v)


def forms(a, b, c, u, v):
    """The exercise as a learner writes it: unsimplified expressions."""
    p, p_u, p_v, m = parts(a, b, c, u, v)
    N = m / sp.sqrt(m.dot(m))
    return (p_u.dot(p_u), p_u.dot(p_v), p_v.dot(p_v), p.diff(u, 2).dot(N), p.diff(u, v).dot(N), p.diff(v, 2).dot(N))


def as_matrices(a, b, c, u, v):
    E, F, G, e, f, g = forms(a, b, c, u, v)
    return sp.Matrix([[E, F], [F, G]]), sp.Matrix([[e, f], [f, g]])


def unnormalised(a, b, c, u, v):
    p, _, _, m = parts(a, b, c, u, v)
    return forms(a, b, c, u, v)[:3] + (p.diff(u, 2).dot(m), p.diff(u, v).dot(m), p.diff(v, 2).dot(m))


def polar_u(a, b, c, u, v):
    # u taken as the polar angle: p = (a cos v sin u, b sin v sin u, c cos u)
    return forms(a, b, c, v, u)


FORM_MISTAKES = {
    "unnormalised normal": (unnormalised, "normal is not normalised"),
    "outward normal": (lambda *x: forms(*x)[:3] + tuple(-y for y in forms(*x)[3:]), "sign of the normal is flipped"),
    "u and v swapped": (polar_u, "u and v are swapped"),
    "E and G exchanged": (
        lambda *x: (forms(*x)[2], forms(*x)[1], forms(*x)[0]) + forms(*x)[3:],
        "E and G are exchanged",
    ),
    "fresh symbols": (lambda a, b, c, u, v: forms(a, b, c, *sp.symbols("s t")), "other than a, b, c, u, v"),
    "F with its sign flipped": (lambda *x: (forms(*x)[0], -forms(*x)[1]) + forms(*x)[2:], "F has the wrong sign"),
    "normal of length 2": (lambda *x: forms(*x)[:3] + tuple(2 * y for y in forms(*x)[3:]), "off by the same factor 2"),
    "e and g exchanged": (
        lambda *x: forms(*x)[:3] + (forms(*x)[5], forms(*x)[4], forms(*x)[3]),
        "e and g are exchanged",
    ),
    "three values": (lambda *x: forms(*x)[:3], "not (E, F, G, e, f, g) or (I, II)"),
}


def test_forms_accept_reference_simplified_or_not():
    for fn in (forms, as_matrices):
        result = check.fundamental_forms(fn)
        assert result.passed, result.message
    from geomlib.lessons.symbolic import ellipsoid

    # the library's simplified forms, derived before the check (its ground rules refuse a call inside)
    ell = ellipsoid(*sp.symbols("a b c", positive=True))
    simplified = ell.first_fundamental_form(), ell.second_fundamental_form()
    result = check.fundamental_forms(lambda a, b, c, u, v: simplified)
    assert result.passed, result.message


def test_forms_check_is_quick():
    t0 = time.perf_counter()
    check.fundamental_forms(forms)
    assert time.perf_counter() - t0 < 3.0  # generous on a busy machine; about 0.5 s when quiet


@pytest.mark.parametrize("name", FORM_MISTAKES)
def test_forms_diagnoses(name):
    fn, phrase = FORM_MISTAKES[name]
    assert_diagnosed(check.fundamental_forms(fn), phrase, "Reread The definitions and Steps 1-2")


def test_forms_stub():
    assert_diagnosed(check.fundamental_forms(stub), "not written yet")


def kappa(a, b, c, phi):
    return a * np.cos(phi) ** 2 / b**2 + a * np.sin(phi) ** 2 / c**2


def kappa_sympy(a, b, c, phi):
    # the learner's symbolic route: II(t, t) / I(t, t) in sympy, then numbers
    I, II = sp.diag(b**2, c**2), sp.diag(a, a)
    t = sp.Matrix([sp.cos(phi) / b, sp.sin(phi) / c])
    return (t.T * II * t)[0] / (t.T * I * t)[0]


KAPPA_MISTAKES = {
    "phi from p_v": (lambda a, b, c, phi: kappa(a, b, c, phi + np.pi / 2), "measured from p_v instead of p_u"),
    "b and c swapped": (lambda a, b, c, phi: kappa(a, c, b, phi), "b and c are exchanged"),
    "no division by I": (
        lambda a, b, c, phi: a * np.cos(phi) ** 2 + a * np.sin(phi) ** 2,
        "not divided by the first form",
    ),
    "parameter-plane angle": (
        lambda a, b, c, phi: a / (b**2 * np.cos(phi) ** 2 + c**2 * np.sin(phi) ** 2),
        "(u, v) parameter plane",
    ),
    "sign": (lambda a, b, c, phi: -kappa(a, b, c, phi), "sign is flipped"),
    "only E divides": (lambda a, b, c, phi: a / b**2 + 0 * phi, "only E divides"),
    "lengths, not their squares": (
        lambda a, b, c, phi: a * np.cos(phi) ** 2 / b + a * np.sin(phi) ** 2 / c,
        "divided by the length |p_u| = b",
    ),
    "divided twice": (
        lambda a, b, c, phi: a * np.cos(phi) ** 2 / b**4 + a * np.sin(phi) ** 2 / c**4,
        "the first form divides twice",
    ),
    "a cross term": (
        lambda a, b, c, phi: kappa(a, b, c, phi) + np.sin(2 * phi) * a / (b * c),
        "right along p_u and p_v but not between them",
    ),
    "symbolic leftover": (lambda a, b, c, phi: sp.Symbol("phi") * a, "not a number"),
}


def test_kappa_accepts_reference():
    for fn in (kappa, kappa_sympy):
        result = check.normal_curvature(fn)
        assert result.passed, result.message


@pytest.mark.parametrize("name", KAPPA_MISTAKES)
def test_kappa_diagnoses(name):
    fn, phrase = KAPPA_MISTAKES[name]
    assert_diagnosed(check.normal_curvature(fn), phrase, "Reread Step 4")


def test_kappa_stub():
    assert_diagnosed(check.normal_curvature(stub), "not written yet")


def kappa_numpy_rounded(a, b, c, phi):
    # II(t, t) / I(t, t) with numpy matrices, a rounded constant (phi shifted by a period of 3.14159265)
    t = np.array([np.cos(phi + 2 * 3.14159265) / b, np.sin(phi + 2 * 3.14159265) / c])
    return (t @ np.diag([a, a]) @ t) / (t @ np.diag([b * b, c * c]) @ t)


def test_kappa_accepts_a_rounded_constant():
    result = check.normal_curvature(kappa_numpy_rounded)
    assert result.passed, result.message


def following(hint):
    """kappa_n as a learner writes it from a hint's "(du, dv) = (X, Y)" and its kappa_n = II(t, t) / I(t, t)."""
    du, dv = hint.split("(du, dv) = (", 1)[1].split(")", 1)[0].replace(" phi", "(phi)").split(", ")

    def kappa_n(a, b, c, phi):
        names = {"cos": np.cos, "sin": np.sin, "phi": phi, "b": b, "c": c}
        t = np.array([eval(du, names), eval(dv, names)])  # noqa: S307 (the hint's own formula)
        return (t @ np.diag([a, a]) @ t) / (t @ np.diag([b * b, c * c]) @ t)

    return kappa_n


@pytest.mark.parametrize("name", ["no division by I", "parameter-plane angle", "lengths, not their squares"])
def test_a_hint_that_gives_the_unit_tangent_leads_to_the_right_answer(name):
    """W3: the hint names (du, dv) of the unit tangent; a learner who follows it passes (the old hint,
    (du, dv) = (cos phi, sin phi), led to the very mistake the check diagnoses)."""
    message = check.normal_curvature(KAPPA_MISTAKES[name][0]).message
    hint = message.split("Hint:", 1)[1]
    assert "(du, dv) = (" in hint, message
    result = check.normal_curvature(following(hint))
    assert result.passed, (message, result.message)
    # and the old hint's tangent is diagnosed, not passed
    assert_diagnosed(check.normal_curvature(following("(du, dv) = (cos phi, sin phi)")), "(u, v) parameter plane")
