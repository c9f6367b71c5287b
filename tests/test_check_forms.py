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
    "three values": (lambda *x: forms(*x)[:3], "not (E, F, G, e, f, g) or (I, II)"),
}


def test_forms_accept_reference_simplified_or_not():
    for fn in (forms, as_matrices):
        result = check.fundamental_forms(fn)
        assert result.passed, result.message
    from geomlib.lessons.symbolic import ellipsoid

    def library(a, b, c, u, v):
        ell = ellipsoid(a, b, c)
        sub = {ell.u: u, ell.v: v}
        return ell.first_fundamental_form().subs(sub), ell.second_fundamental_form().subs(sub)

    assert check.fundamental_forms(library).passed


def test_forms_check_is_quick():
    t0 = time.perf_counter()
    check.fundamental_forms(forms)
    assert time.perf_counter() - t0 < 3.0  # generous on a busy machine; about 0.5 s when quiet


@pytest.mark.parametrize("name", FORM_MISTAKES)
def test_forms_diagnoses(name):
    fn, phrase = FORM_MISTAKES[name]
    assert_diagnosed(check.fundamental_forms(fn), phrase, "Reread Steps 2 to 4")


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
    "symbolic leftover": (lambda a, b, c, phi: sp.Symbol("phi") * a, "not a number"),
}


def test_kappa_accepts_reference():
    for fn in (kappa, kappa_sympy):
        result = check.normal_curvature(fn)
        assert result.passed, result.message


@pytest.mark.parametrize("name", KAPPA_MISTAKES)
def test_kappa_diagnoses(name):
    fn, phrase = KAPPA_MISTAKES[name]
    assert_diagnosed(check.normal_curvature(fn), phrase, "Reread Step 6")


def test_kappa_stub():
    assert_diagnosed(check.normal_curvature(stub), "not written yet")
