"""Tests of geomlib.lessons.symbolic against independent checks.

Closed forms (sphere 1/r, torus equators, saddle, the ellipsoid's K and H in
Cartesian form), finite differences of p written out here in numpy, the
normal section cut by a plane and measured by root finding, and laws
(scaling, rigid motion, Euler's theorem).
"""

import numpy as np
import pytest
import sympy as sp
from partials import central_partials
from scipy.optimize import brentq

from geomlib import symbolic
from geomlib.lessons.symbolic import (
    ellipsoid,
    ellipsoid_forms,
    ellipsoid_normal_curvature,
    helicoid,
    monge,
    saddle,
    sphere,
    torus,
)

RNG_SEED = 20240611


# ----------------------------------------------------------------- numpy models
# Written independently of geomlib.lessons.symbolic: plain numpy formulas of p(u, v).
def p_ellipsoid(a, b, c):
    return lambda u, v: np.stack([a * np.cos(u) * np.sin(v), b * np.sin(u) * np.sin(v), c * np.cos(v) + 0 * u], axis=-1)


def p_torus(R, r):
    return lambda u, v: np.stack(
        [(R + r * np.cos(v)) * np.cos(u), (R + r * np.cos(v)) * np.sin(u), r * np.sin(v) + 0 * u], axis=-1
    )


def p_helicoid(c):
    return lambda u, v: np.stack([u * np.cos(v), u * np.sin(v), c * v + 0 * u], axis=-1)


def p_saddle(u, v):
    return np.stack([u, v, u * u - v * v], axis=-1)


def fd_forms(p, u, v, h=1e-4):
    """E, F, G, e, f, g and the unit normal m = p_u x p_v/|.| by central differences."""
    pu, pv, puu, puv, pvv = central_partials(p, u, v, h)
    m = np.cross(pu, pv)
    m /= np.linalg.norm(m)
    first = (pu @ pu, pu @ pv, pv @ pv)
    second = (puu @ m, puv @ m, pvv @ m)
    return first, second, m, pu, pv


# --------------------------------------------------------------- sphere: 1/r
@pytest.mark.parametrize("r", [1, 2.5, sp.Rational(3, 7)])
def test_sphere_every_normal_curvature_is_one_over_r(r):
    phi = sp.Symbol("phi", real=True)
    S = sphere(r)
    r = sp.sympify(r) if not isinstance(r, float) else sp.Rational(repr(r))
    assert sp.simplify(S.normal_curvature(phi) - 1 / r) == 0
    assert sp.simplify(S.mean_curvature() - 1 / r) == 0
    assert sp.simplify(S.gaussian_curvature() - 1 / r**2) == 0
    rng = np.random.default_rng(RNG_SEED)
    u, v, ph = rng.uniform(0, 2 * np.pi, 50), rng.uniform(0.05, np.pi - 0.05, 50), rng.uniform(0, 2 * np.pi, 50)
    np.testing.assert_allclose(S.lambdify("normal_curvature")(u, v, ph), 1 / float(r), rtol=1e-12)
    k1, k2 = S.lambdify("principal_curvatures")(u, v)
    np.testing.assert_allclose(k1, 1 / float(r), rtol=1e-12)
    np.testing.assert_allclose(k2, 1 / float(r), rtol=1e-12)


def test_sphere_with_symbolic_radius_and_ellipsoid_with_equal_axes():
    r, phi = sp.Symbol("r", positive=True), sp.Symbol("phi", real=True)
    for S in (sphere(r), ellipsoid(r, r, r)):
        assert sp.simplify(S.normal_curvature(phi) - 1 / r) == 0
        assert sp.simplify(S.mean_curvature() - 1 / r) == 0
        assert sp.simplify(S.gaussian_curvature() - r**-2) == 0
        assert sp.simplify(S.second_fundamental_form() - S.first_fundamental_form() / r) == sp.zeros(2, 2)


# ------------------------------------------------ finite differences of p(u, v)
CASES = [
    ("ellipsoid", lambda: ellipsoid(1.3, 0.8, 2.1), p_ellipsoid(1.3, 0.8, 2.1), (0, 2 * np.pi), (0.1, np.pi - 0.1)),
    ("ellipsoid2", lambda: ellipsoid(3, 1, 0.5), p_ellipsoid(3, 1, 0.5), (0, 2 * np.pi), (0.1, np.pi - 0.1)),
    ("torus", lambda: torus(2, 0.6), p_torus(2, 0.6), (0, 2 * np.pi), (0, 2 * np.pi)),
    ("helicoid", lambda: helicoid(0.7), p_helicoid(0.7), (-1, 1), (0, 2 * np.pi)),
    ("saddle", saddle, p_saddle, (-1, 1), (-1, 1)),
]


@pytest.mark.parametrize("name,make,p,urange,vrange", CASES, ids=[c[0] for c in CASES])
def test_forms_match_finite_differences(name, make, p, urange, vrange):
    S = make()
    I = S.lambdify("first_fundamental_form")
    II = S.lambdify("second_fundamental_form")
    n_of = S.lambdify("unit_normal")
    pos = S.lambdify("position")
    rng = np.random.default_rng(RNG_SEED)
    for _ in range(12):
        u, v = rng.uniform(*urange), rng.uniform(*vrange)
        (E, F, G), (e, f, g), m, _, _ = fd_forms(p, u, v)
        np.testing.assert_allclose(pos(u, v), p(u, v), atol=1e-12)
        np.testing.assert_allclose(I(u, v), [[E, F], [F, G]], atol=1e-6)
        n = n_of(u, v)
        np.testing.assert_allclose(np.linalg.norm(n), 1, atol=1e-12)
        np.testing.assert_allclose(abs(n @ m), 1, atol=1e-8)
        # the second form is taken with -n; the finite differences used m = +-n
        sign = -float(np.sign(n @ m))
        np.testing.assert_allclose(II(u, v), sign * np.array([[e, f], [f, g]]), atol=1e-6)
    # the symbolic matrices, evaluated, agree with the lambdified ones
    u0, v0 = sp.Rational(7, 10), sp.Rational(11, 10)
    sym = S.first_fundamental_form().subs({S.u: u0, S.v: v0}).evalf()
    np.testing.assert_allclose(np.array(sym, dtype=float), I(0.7, 1.1), atol=1e-12)
    sym = S.second_fundamental_form().subs({S.u: u0, S.v: v0}).evalf()
    np.testing.assert_allclose(np.array(sym, dtype=float), II(0.7, 1.1), atol=1e-12)


@pytest.mark.parametrize("abc", [(1.0, 2.0, 3.0), (2.5, 1.2, 0.4), (1.0, 1.0, 1.7)])
def test_ellipsoid_normal_is_outward(abc):
    a, b, c = abc
    S = ellipsoid(*abc)
    rng = np.random.default_rng(RNG_SEED)
    u, v = rng.uniform(0, 2 * np.pi, 200), rng.uniform(0.01, np.pi - 0.01, 200)
    x = S.lambdify("position")(u, v)
    n = S.lambdify("unit_normal")(u, v)
    grad = x / np.array([a * a, b * b, c * c])  # gradient of x^2/a^2 + y^2/b^2 + z^2/c^2, outward
    np.testing.assert_allclose(n, grad / np.linalg.norm(grad, axis=1, keepdims=True), atol=1e-12)
    # ... while p_u x p_v points inward for this parameterisation
    m = np.cross(S.lambdify("p_u")(u, v), S.lambdify("p_v")(u, v))
    assert np.all(np.einsum("ij,ij->i", m, n) < 0)


# ------------------------------------------------- ellipsoid closed forms
def ellipsoid_points(abc, count, seed=RNG_SEED):
    rng = np.random.default_rng(seed)
    u, v = rng.uniform(0, 2 * np.pi, count), rng.uniform(0.02, np.pi - 0.02, count)
    return u, v, p_ellipsoid(*abc)(u, v)


@pytest.mark.parametrize("abc", [(1.0, 2.0, 3.0), (2.5, 1.2, 0.4), (0.9, 0.9, 2.0), (5.0, 0.3, 1.1)])
def test_ellipsoid_gaussian_curvature_closed_form(abc):
    a, b, c = abc
    u, v, X = ellipsoid_points(abc, 500)
    x, y, z = X.T
    K_exact = 1 / (a * b * c) ** 2 / (x**2 / a**4 + y**2 / b**4 + z**2 / c**4) ** 2
    np.testing.assert_allclose(ellipsoid(a, b, c).lambdify("gaussian_curvature")(u, v), K_exact, rtol=1e-11)


@pytest.mark.parametrize("abc", [(1.0, 2.0, 3.0), (2.5, 1.2, 0.4), (0.9, 0.9, 2.0), (5.0, 0.3, 1.1)])
def test_ellipsoid_mean_curvature_closed_form(abc):
    a, b, c = abc
    u, v, X = ellipsoid_points(abc, 500)
    x, y, z = X.T
    h = np.sqrt(x**2 / a**4 + y**2 / b**4 + z**2 / c**4)
    H_exact = np.abs(x**2 + y**2 + z**2 - a**2 - b**2 - c**2) / (2 * (a * b * c) ** 2 * h**3)
    S = ellipsoid(a, b, c)
    H = S.lambdify("mean_curvature")(u, v)
    np.testing.assert_allclose(H, H_exact, rtol=1e-11)
    assert np.all(H > 0)
    k1, k2 = S.lambdify("principal_curvatures")(u, v)
    assert np.all(k1 >= k2) and np.all(k2 > 0)
    np.testing.assert_allclose((k1 + k2) / 2, H, rtol=1e-11)
    np.testing.assert_allclose(k1 * k2, S.lambdify("gaussian_curvature")(u, v), rtol=1e-9)


def test_ellipsoid_symbolic_forms_with_symbols():
    E = ellipsoid(*sp.symbols("a b c", positive=True))
    a, b, c = E.params
    u, v = E.u, E.v
    I = E.first_fundamental_form()
    assert sp.simplify(I[0, 0] - sp.sin(v) ** 2 * (a**2 * sp.sin(u) ** 2 + b**2 * sp.cos(u) ** 2)) == 0
    assert sp.simplify(I[0, 1] - (b**2 - a**2) * sp.sin(u) * sp.cos(u) * sp.sin(v) * sp.cos(v)) == 0
    II = E.second_fundamental_form()
    assert II[0, 1] == 0
    W = sp.sqrt(
        b**2 * c**2 * sp.cos(u) ** 2 * sp.sin(v) ** 2
        + a**2 * c**2 * sp.sin(u) ** 2 * sp.sin(v) ** 2
        + a**2 * b**2 * sp.cos(v) ** 2
    )
    assert sp.simplify(II[0, 0] - a * b * c * sp.sin(v) ** 2 / W) == 0
    assert sp.simplify(II[1, 1] - a * b * c / W) == 0
    assert sp.simplify(E.gaussian_curvature() - (a * b * c) ** 2 / W**4) == 0


def test_ellipsoid_at_a00_closed_forms():
    a, b, c = sp.symbols("a b c", positive=True)
    phi = sp.Symbol("phi", real=True)
    E = ellipsoid(a, b, c)
    u0, v0 = 0, sp.pi / 2
    assert list(E.position(u0, v0)) == [a, 0, 0]
    assert E.first_fundamental_form().subs({E.u: u0, E.v: v0}) == sp.diag(b**2, c**2)
    assert sp.simplify(E.second_fundamental_form().subs({E.u: u0, E.v: v0}) - sp.diag(a, a)) == sp.zeros(2, 2)
    kn = E.normal_curvature(phi, u0, v0)
    assert sp.simplify(kn - (a / b**2 * sp.cos(phi) ** 2 + a / c**2 * sp.sin(phi) ** 2)) == 0
    assert list(E.unit_normal().subs({E.u: u0, E.v: v0})) == [1, 0, 0]


# ------------------------------------------------------------ scaling law
def test_curvatures_scale_as_one_over_length():
    rng = np.random.default_rng(RNG_SEED)
    u, v = rng.uniform(0, 2 * np.pi, 100), rng.uniform(0.05, np.pi - 0.05, 100)
    ph = rng.uniform(0, np.pi, 100)
    base = ellipsoid(1.1, 0.7, 1.9)
    for s in (0.25, 3.0, 17.0):
        scaled = ellipsoid(1.1 * s, 0.7 * s, 1.9 * s)
        for name, power in (("mean_curvature", 1), ("gaussian_curvature", 2)):
            np.testing.assert_allclose(scaled.lambdify(name)(u, v), base.lambdify(name)(u, v) / s**power, rtol=1e-11)
        np.testing.assert_allclose(
            scaled.lambdify("normal_curvature")(u, v, ph), base.lambdify("normal_curvature")(u, v, ph) / s, rtol=1e-11
        )
        for k_s, k_b in zip(scaled.lambdify("principal_curvatures")(u, v), base.lambdify("principal_curvatures")(u, v)):
            np.testing.assert_allclose(k_s, k_b / s, rtol=1e-11)
    # and symbolically, with a scale symbol s
    a, b, c, s = sp.symbols("a b c s", positive=True)
    phi = sp.Symbol("phi", real=True)
    k = ellipsoid(a, b, c).normal_curvature(phi, 0, sp.pi / 2)
    ks = ellipsoid(s * a, s * b, s * c).normal_curvature(phi, 0, sp.pi / 2)
    assert sp.simplify(ks - k / s) == 0


# ------------------------------------------- the normal section, numerically
def section_curvature(F, P, t, n, h=2e-3):
    """Curvature, signed towards -n, of the curve cut from {F = 0} by the plane P + span(t, n).

    The curve is the graph sigma(tau) over the tangent line: F(P + tau t + sigma n) = 0,
    solved by root finding; sigma''(0) by a fourth-order central difference.
    """

    def sigma(tau):
        g = lambda s: F(P + tau * t + s * n)
        return brentq(g, -0.2, 0.2, xtol=1e-15, maxiter=200)

    taus = np.array([-2, -1, 0, 1, 2]) * h
    s = np.array([sigma(x) for x in taus])
    d2 = (-s[0] + 16 * s[1] - 30 * s[2] + 16 * s[3] - s[4]) / (12 * h * h)
    return -d2  # the curve bends towards -n: positive normal curvature


@pytest.mark.parametrize("seed", range(4))
def test_normal_curvature_at_a00_equals_normal_section(seed):
    rng = np.random.default_rng(RNG_SEED + seed)
    a, b, c = rng.uniform(0.5, 3.0, 3)
    phi = rng.uniform(0, 2 * np.pi)
    F = lambda X: X[0] ** 2 / a**2 + X[1] ** 2 / b**2 + X[2] ** 2 / c**2 - 1
    P = np.array([a, 0.0, 0.0])
    n = np.array([1.0, 0.0, 0.0])  # outward normal at (a, 0, 0)
    # phi from p_u = (0, b, 0) towards w; w is the unit tangent perpendicular to
    # p_u on the side of p_v = (0, 0, -c)
    t = np.cos(phi) * np.array([0.0, 1.0, 0.0]) + np.sin(phi) * np.array([0.0, 0.0, -1.0])
    expected = section_curvature(F, P, t, n)
    E = ellipsoid(a, b, c)
    got = E.lambdify("normal_curvature")(0.0, np.pi / 2, phi)
    np.testing.assert_allclose(got, expected, rtol=1e-6)
    # the exact sympy expression evaluated at the same numbers
    kn = E.normal_curvature(sp.Symbol("phi"), 0, sp.pi / 2)
    np.testing.assert_allclose(float(kn.subs("phi", phi)), expected, rtol=1e-6)


@pytest.mark.parametrize("seed", range(3))
def test_normal_curvature_at_random_points_equals_normal_section(seed):
    rng = np.random.default_rng(RNG_SEED + 100 + seed)
    a, b, c = rng.uniform(0.6, 2.5, 3)
    u, v, phi = rng.uniform(0, 2 * np.pi), rng.uniform(0.3, np.pi - 0.3), rng.uniform(0, 2 * np.pi)
    F = lambda X: X[0] ** 2 / a**2 + X[1] ** 2 / b**2 + X[2] ** 2 / c**2 - 1
    p = p_ellipsoid(a, b, c)
    P = p(u, v)
    grad = P / np.array([a * a, b * b, c * c])
    n = grad / np.linalg.norm(grad)
    _, _, m, pu, pv = fd_forms(p, u, v, h=1e-6)
    t_u = pu / np.linalg.norm(pu)
    w = np.cross(m, t_u)  # +90 degrees about m = p_u x p_v / |p_u x p_v|
    assert w @ pv > 0
    t = np.cos(phi) * t_u + np.sin(phi) * w
    expected = section_curvature(F, P, t, n)
    got = ellipsoid(a, b, c).lambdify("normal_curvature")(u, v, phi)
    np.testing.assert_allclose(got, expected, rtol=1e-6)


# ------------------------------------- Euler's theorem, principal directions
@pytest.mark.parametrize(
    "make,urange,vrange",
    [
        (lambda: ellipsoid(1.0, 2.0, 3.0), (0, 2 * np.pi), (0.1, np.pi - 0.1)),
        (lambda: torus(2, 0.6), (0, 2 * np.pi), (0, 2 * np.pi)),
        (saddle, (-1, 1), (-1, 1)),
    ],
)
def test_euler_theorem_and_principal_directions(make, urange, vrange):
    S = make()
    rng = np.random.default_rng(RNG_SEED)
    u, v = rng.uniform(*urange, 64), rng.uniform(*vrange, 64)
    k1, k2 = S.lambdify("principal_curvatures")(u, v)
    d1, d2 = S.lambdify("principal_directions")(u, v)
    n = S.lambdify("unit_normal")(u, v)
    pu = S.lambdify("p_u")(u, v)
    t_u = pu / np.linalg.norm(pu, axis=1, keepdims=True)
    dot = lambda x, y: np.einsum("ij,ij->i", x, y)
    np.testing.assert_allclose(dot(d1, d1), 1, atol=1e-12)
    np.testing.assert_allclose(dot(d1, d2), 0, atol=1e-12)
    np.testing.assert_allclose(dot(d1, n), 0, atol=1e-12)
    np.testing.assert_allclose(dot(d2, n), 0, atol=1e-12)
    # phi1: angle of d1 from p_u, measured towards w = m x t_u
    m = np.cross(pu, S.lambdify("p_v")(u, v))
    m /= np.linalg.norm(m, axis=1, keepdims=True)
    w = np.cross(m, t_u)
    phi1 = np.arctan2(dot(d1, w), dot(d1, t_u))
    kn = S.lambdify("normal_curvature")
    np.testing.assert_allclose(kn(u, v, phi1), k1, atol=1e-12)
    np.testing.assert_allclose(kn(u, v, phi1 + np.pi / 2), k2, atol=1e-12)
    for phi in rng.uniform(0, 2 * np.pi, 5):
        euler = k1 * np.cos(phi - phi1) ** 2 + k2 * np.sin(phi - phi1) ** 2
        np.testing.assert_allclose(kn(u, v, phi), euler, atol=1e-12)
        assert np.all(kn(u, v, phi) <= k1 + 1e-12) and np.all(kn(u, v, phi) >= k2 - 1e-12)
    # the shape operator has eigenvalues k1, k2
    Sop = S.lambdify("shape_operator")(u, v)
    np.testing.assert_allclose(np.trace(Sop, axis1=1, axis2=2), k1 + k2, atol=1e-10)
    np.testing.assert_allclose(np.linalg.det(Sop), k1 * k2, atol=1e-10)


def test_euler_theorem_symbolic_at_a00():
    a, b, c = sp.symbols("a b c", positive=True)
    phi = sp.Symbol("phi", real=True)
    E = ellipsoid(a, b, c)
    kn = E.normal_curvature(phi, 0, sp.pi / 2)
    k_u, k_v = kn.subs(phi, 0), kn.subs(phi, sp.pi / 2)
    assert sp.simplify(kn - (k_u * sp.cos(phi) ** 2 + k_v * sp.sin(phi) ** 2)) == 0
    k1, k2 = E.principal_curvatures(0, sp.pi / 2)
    assert sp.simplify(k1 + k2 - (k_u + k_v)) == 0 and sp.simplify(k1 * k2 - k_u * k_v) == 0
    (phi1, d1), (phi2, d2) = ellipsoid(1, 2, 3).principal_directions(0, sp.pi / 2)
    # a/b^2 = 1/4 along p_u > a/c^2 = 1/9 along p_v
    assert phi1 == 0 and list(d1) == [0, 1, 0] and list(d2) == [0, 0, -1]


def test_ellipsoid_poles_are_finite_and_exact():
    # p_u = 0 at v = 0, pi; curvature there is c/a^2 along x and c/b^2 along y
    a, b, c = 1.0, 2.0, 3.0
    E = ellipsoid(a, b, c)
    u = np.array([0.0, 0.7, 2.0, 0.0, 1.1])
    v = np.array([0.0, 0.0, 0.0, np.pi, np.pi])
    k1, k2 = E.lambdify("principal_curvatures")(u, v)
    np.testing.assert_allclose(k1, c / a**2, rtol=1e-12)
    np.testing.assert_allclose(k2, c / b**2, rtol=1e-12)
    np.testing.assert_allclose(E.lambdify("mean_curvature")(u, v), (c / a**2 + c / b**2) / 2, rtol=1e-12)
    np.testing.assert_allclose(E.lambdify("gaussian_curvature")(u, v), c**2 / (a * b) ** 2, rtol=1e-12)
    np.testing.assert_allclose(np.abs(E.lambdify("unit_normal")(u, v)[:, 2]), 1, atol=1e-12)
    d1, d2 = E.lambdify("principal_directions")(u, v)
    np.testing.assert_allclose(np.abs(d1), np.tile([1.0, 0, 0], (5, 1)), atol=1e-6)
    np.testing.assert_allclose(np.abs(d2), np.tile([0, 1.0, 0], (5, 1)), atol=1e-6)


# ------------------------------------------------- torus, saddle, helicoid
def test_torus_equators():
    R, r = sp.symbols("R r", positive=True)
    T = torus(R, r)
    K = T.gaussian_curvature()
    assert sp.simplify(K.subs(T.v, 0) - 1 / (r * (R + r))) == 0
    assert sp.simplify(K.subs(T.v, sp.pi) + 1 / (r * (R - r))) == 0
    H = T.mean_curvature()
    assert sp.simplify(H.subs(T.v, 0) - (1 / r + 1 / (R + r)) / 2) == 0
    Tn = torus(3, 1)
    np.testing.assert_allclose(Tn.lambdify("gaussian_curvature")([0.3, 1.0], [0.0, np.pi]), [1 / 4, -1 / 2], rtol=1e-13)
    k1, k2 = Tn.lambdify("principal_curvatures")(0.0, 0.0)
    np.testing.assert_allclose([k1, k2], [1.0, 1 / 4], rtol=1e-13)


def test_saddle_at_origin():
    S = saddle()
    x, y = S.u, S.v
    assert S.gaussian_curvature().subs({x: 0, y: 0}) == -4
    assert S.mean_curvature().subs({x: 0, y: 0}) == 0
    assert S.lambdify("gaussian_curvature")(0.0, 0.0) == -4
    assert S.lambdify("mean_curvature")(0.0, 0.0) == 0
    k1, k2 = S.lambdify("principal_curvatures")(0.0, 0.0)
    assert (k1, k2) == (2.0, -2.0)
    assert list(S.unit_normal().subs({x: 0, y: 0})) == [0, 0, 1]  # upward


def test_monge_cup_sign_follows_the_upward_normal():
    x, y = sp.symbols("x y", real=True)
    cup = monge((x**2 + y**2) / 2, x, y)
    # the cup bends towards its upward normal n: H < 0 with Delta x = -2 H n
    assert cup.mean_curvature().subs({x: 0, y: 0}) == -1
    assert cup.gaussian_curvature().subs({x: 0, y: 0}) == 1


def test_helicoid_is_minimal():
    c = sp.Symbol("c", positive=True)
    Hc = helicoid(c)
    assert sp.simplify(Hc.mean_curvature()) == 0
    assert sp.simplify(Hc.gaussian_curvature() + c**2 / (c**2 + Hc.u**2) ** 2) == 0


# ------------------------------------------------ rigid motion invariance
def test_rigid_motion_leaves_curvature_unchanged():
    u, v = sp.symbols("u v", real=True)
    a, b, c = 1, 2, sp.Rational(3, 2)
    p = sp.Matrix([a * sp.cos(u) * sp.sin(v), b * sp.sin(u) * sp.sin(v), c * sp.cos(v)])
    Q = sp.Matrix([[sp.Rational(3, 5), -sp.Rational(4, 5), 0], [sp.Rational(4, 5), sp.Rational(3, 5), 0], [0, 0, 1]])
    Q = Q * sp.Matrix(
        [[1, 0, 0], [0, sp.Rational(5, 13), -sp.Rational(12, 13)], [0, sp.Rational(12, 13), sp.Rational(5, 13)]]
    )
    moved = symbolic.ParametricSurface(Q * p + sp.Matrix([1, -2, 3]), u, v, orientation=-1, closed=True)
    ref = ellipsoid(a, b, c)
    rng = np.random.default_rng(RNG_SEED)
    uu, vv = rng.uniform(0, 2 * np.pi, 100), rng.uniform(0.05, np.pi - 0.05, 100)
    for name in ("mean_curvature", "gaussian_curvature"):
        np.testing.assert_allclose(moved.lambdify(name)(uu, vv), ref.lambdify(name)(uu, vv), rtol=1e-10)
    Qn = np.array(Q, dtype=float)
    np.testing.assert_allclose(
        moved.lambdify("unit_normal")(uu, vv), ref.lambdify("unit_normal")(uu, vv) @ Qn.T, atol=1e-12
    )


# ------------------------------------------------------- numpy interface
def test_lambdify_shapes_and_broadcasting():
    E = ellipsoid(1, 2, 3)
    u = np.linspace(0, 2 * np.pi, 12).reshape(3, 4)
    v = np.full((3, 4), 0.7)
    assert E.lambdify("position")(u, v).shape == (3, 4, 3)
    assert E.lambdify("first_fundamental_form")(u, v).shape == (3, 4, 2, 2)
    assert E.lambdify("mean_curvature")(u, 0.7).shape == (3, 4)
    assert E.lambdify("gaussian_curvature")(0.1, 0.7).shape == ()
    assert E.lambdify("normal_curvature")(u, v, 0.5).shape == (3, 4)
    # a constant component (z of p_u) is broadcast, not a scalar
    assert E.lambdify("p_u")(u, v).shape == (3, 4, 3)
    # the family with free parameters takes them as trailing arguments
    fam = ellipsoid(*sp.symbols("a b c", positive=True))
    np.testing.assert_allclose(
        fam.lambdify("mean_curvature")(u, v, 1, 2, 3), E.lambdify("mean_curvature")(u, v), rtol=1e-13
    )
    with pytest.raises(TypeError):
        fam.lambdify("mean_curvature")(u, v)


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="positive"):
        ellipsoid(1, -2, 3)
    with pytest.raises(ValueError, match="R > r"):
        torus(1, 2)
    with pytest.raises(ValueError, match="unknown quantity"):
        ellipsoid(1, 2, 3).lambdify("curvature")
    u, v = sp.symbols("u v", real=True)
    with pytest.raises(ValueError, match="p_u x p_v"):
        symbolic.ParametricSurface(
            (sp.cos(u) * sp.sin(v), sp.sin(u) * sp.sin(v), sp.cos(v)),
            u,
            v,
            normal_direction=(sp.cos(u), sp.sin(u), 0),
            area_factor=1,
        )


def test_results_are_cached_and_families_shared():
    E1, E2 = ellipsoid(1, 2, 3), ellipsoid(2, 2, 5)
    assert E1._family is E2._family
    assert E1.first_fundamental_form() is E1.first_fundamental_form()
    assert E1.lambdify("mean_curvature")  # compiled once per family
    assert "mean_curvature" in E1._family._lambdified


def test_ellipsoid_forms_at_a_point_and_kappa_n_at_the_axis_end():
    a, b, c = sp.symbols("a b c", positive=True)
    I, II = symbolic.ellipsoid_forms(a, b, c, 0, sp.pi / 2)
    assert sp.simplify(I - sp.diag(b**2, c**2)) == sp.zeros(2, 2)
    assert sp.simplify(II - sp.diag(a, a)) == sp.zeros(2, 2)
    phi = np.linspace(0, 2 * np.pi, 13)
    expected = 2.0 * np.cos(phi) ** 2 / 1.5**2 + 2.0 * np.sin(phi) ** 2 / 0.7**2  # a cos^2/b^2 + a sin^2/c^2
    assert np.allclose(symbolic.ellipsoid_normal_curvature(2.0, 1.5, 0.7, phi), expected, rtol=1e-12)
    # at a generic point the numbers agree with the library's form of the same ellipsoid
    I_num, II_num = symbolic.ellipsoid_forms(2.0, 1.5, 0.7, 0.7, 1.0)
    ell = symbolic.ellipsoid(2.0, 1.5, 0.7)
    assert np.allclose(np.array(I_num, dtype=float), ell.lambdify("first_fundamental_form")(0.7, 1.0), rtol=1e-12)
    assert np.allclose(np.array(II_num, dtype=float), ell.lambdify("second_fundamental_form")(0.7, 1.0), rtol=1e-12)


# ------------------------------------------- derived without simplification
def test_unsimplified_ellipsoid_matches_the_closed_forms_and_stays_finite_at_the_poles():
    a, b, c = 2.5, 1.2, 0.4
    u, v, X = ellipsoid_points((a, b, c), 300)
    u, v = np.r_[u, 0.0, 1.1], np.r_[v, 0.0, np.pi]  # the poles, where p_u = 0
    x, y, z = np.r_[X[:, 0], 0, 0], np.r_[X[:, 1], 0, 0], np.r_[X[:, 2], c, -c]
    h = np.sqrt(x**2 / a**4 + y**2 / b**4 + z**2 / c**4)
    S = ellipsoid(a, b, c, simplify=False)
    assert not S.simplify
    K_exact = 1 / (a * b * c) ** 2 / h**4
    H_exact = np.abs(x**2 + y**2 + z**2 - a**2 - b**2 - c**2) / (2 * (a * b * c) ** 2 * h**3)
    np.testing.assert_allclose(S.lambdify("gaussian_curvature")(u, v), K_exact, rtol=1e-11)
    np.testing.assert_allclose(S.lambdify("mean_curvature")(u, v), H_exact, rtol=1e-11)
    n_exact = np.stack([x / a**2, y / b**2, z / c**2], axis=1) / h[:, None]
    np.testing.assert_allclose(S.lambdify("unit_normal")(u, v), n_exact, atol=1e-12)


X_, Y_ = sp.symbols("x y", real=True)


@pytest.mark.parametrize(
    "make",
    [
        lambda simplify: torus(2.0, 0.7, simplify=simplify),
        lambda simplify: monge(
            sp.Rational(27, 20) * X_ * (1 - X_**2) * Y_ * (1 - Y_**2) + (X_**3 - 3 * X_ * Y_**2) / 10,
            X_,
            Y_,
            simplify=simplify,
        ),
    ],
)
def test_unsimplified_surfaces_give_the_simplified_values(make):
    rng = np.random.default_rng(RNG_SEED)
    u, v = rng.uniform(-1, 1, 200), rng.uniform(-1, 1, 200)
    plain, simple = make(False), make(True)
    for name in ("unit_normal", "mean_curvature", "gaussian_curvature"):
        np.testing.assert_allclose(plain.lambdify(name)(u, v), simple.lambdify(name)(u, v), rtol=1e-11, atol=1e-13)


# ------------------------- the references of notebook 02's exercises, written out
def test_ellipsoid_forms_written_out_equal_the_structured_derivation():
    """ellipsoid_forms derives I and II as a learner does; ellipsoid() keeps them short: the same values."""
    a, b, c = sp.symbols("a b c", positive=True)
    u, v = sp.symbols("u v", real=True)
    I, II = ellipsoid_forms(a, b, c, u, v)
    ell = ellipsoid(a, b, c)
    args = (a, b, c, ell.u, ell.v)
    mine = sp.lambdify((a, b, c, u, v), list(I) + list(II), "numpy")
    library = sp.lambdify(args, list(ell.first_fundamental_form()) + list(ell.second_fundamental_form()), "numpy")
    rng = np.random.default_rng(RNG_SEED)
    for _ in range(20):
        point = (*rng.uniform(0.4, 2.5, 3), rng.uniform(0, 2 * np.pi), rng.uniform(0.05, np.pi - 0.05))
        np.testing.assert_allclose(mine(*point), library(*point), rtol=1e-12, atol=1e-14)
    # numbers for (u, v) are put in after differentiating: (a, 0, 0) gives I = diag(b^2, c^2), II = diag(a, a)
    I0, II0 = ellipsoid_forms(a, b, c, 0, sp.pi / 2)
    assert I0.applyfunc(sp.simplify) == sp.diag(b**2, c**2) and II0.applyfunc(sp.simplify) == sp.diag(a, a)


def test_ellipsoid_normal_curvature_is_the_compiled_one_where_F_is_not_zero():
    rng = np.random.default_rng(RNG_SEED + 7)
    a, b, c = 1.3, 0.8, 0.45
    u, v, phi = rng.uniform(0, 2 * np.pi, 200), rng.uniform(0.05, np.pi - 0.05, 200), rng.uniform(0, 2 * np.pi, 200)
    assert np.abs(ellipsoid(a, b, c).lambdify("first_fundamental_form")(u, v)[:, 0, 1]).max() > 0.1
    np.testing.assert_allclose(
        ellipsoid_normal_curvature(a, b, c, phi, u, v),
        ellipsoid(a, b, c).lambdify("normal_curvature")(u, v, phi),
        rtol=1e-12,
    )
    phi = np.linspace(0, 2 * np.pi, 9)
    np.testing.assert_allclose(
        ellipsoid_normal_curvature(a, b, c, phi), a * np.cos(phi) ** 2 / b**2 + a * np.sin(phi) ** 2 / c**2
    )


def test_frame_coefficients_are_the_shape_operator_in_the_orthonormal_frame():
    """(L11, L12, L22): the matrix of L = I^-1 II in the frame (t_u, w) is symmetric with these entries."""
    ell = ellipsoid(1.0, 2.0, 3.0)
    u, v = 0.7, 1.0
    L11, L12, L22 = (float(x.subs({ell.u: u, ell.v: v})) for x in ell.frame_coefficients())
    t_u, w = (np.array(x, dtype=float).ravel() for x in ell.frame(u, v))
    pu, pv = ell.lambdify("p_u")(u, v), ell.lambdify("p_v")(u, v)
    coords = np.linalg.lstsq(np.stack([pu, pv], axis=1), np.stack([t_u, w], axis=1), rcond=None)[0]
    L = ell.lambdify("shape_operator")(u, v)  # acts on coordinate vectors (du, dv)
    in_frame = np.linalg.solve(coords, L @ coords)
    np.testing.assert_allclose(in_frame, [[L11, L12], [L12, L22]], atol=1e-12)
    assert abs(L12) > 1e-3


def test_unit_tangent_is_a_unit_vector_at_angle_phi_from_p_u():
    E, F, G = 2.0, 0.7, 1.5  # I of some parameterisation, F != 0
    I = np.array([[E, F], [F, G]])
    for phi in (0.0, 0.3, 1.2, np.pi / 2, 2.9):
        t = np.array(symbolic.unit_tangent(E, F, G, phi))
        assert t @ I @ t == pytest.approx(1.0, rel=1e-14)
        # cos of the angle to p_u = (1, 0) in the metric I is cos(phi)
        assert t @ I @ np.array([1.0, 0.0]) / np.sqrt(E) == pytest.approx(np.cos(phi), abs=1e-14)


def test_forms_normal_curvature_takes_any_forms_function():
    a, b, c, u, v = 1.0, 0.7, 0.5, 0.7, 1.0
    phis = np.array([0.0, 0.4, 2.0])
    expected = symbolic.ellipsoid_normal_curvature(a, b, c, phis, u, v)
    from_pair = symbolic.forms_normal_curvature(symbolic.ellipsoid_forms, a, b, c, u, v, phis)
    np.testing.assert_allclose(from_pair, expected, rtol=1e-12)

    def six(a, b, c, u, v):  # the same forms as six coefficients
        I, II = symbolic.ellipsoid_forms(a, b, c, u, v)
        return I[0, 0], I[0, 1], I[1, 1], II[0, 0], II[0, 1], II[1, 1]

    np.testing.assert_allclose(symbolic.forms_normal_curvature(six, a, b, c, u, v, phis), expected, rtol=1e-12)

    def sphere_forms(a, b, c, u, v):  # a sphere of radius a: every normal curvature is 1/a
        s, t = sp.symbols("s t", real=True)
        I, II = symbolic.ellipsoid_forms(a, a, a, s, t)
        return I.subs({s: u, t: v}), II.subs({s: u, t: v})

    np.testing.assert_allclose(
        symbolic.forms_normal_curvature(sphere_forms, 2.0, 0, 0, 0.3, 1.1, phis), 0.5, rtol=1e-12
    )
