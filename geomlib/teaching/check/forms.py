"""Checks of notebook 02: the ellipsoid's fundamental forms, and kappa_n from whatever forms it is handed.

``fundamental_forms`` compares the learner's expressions by value (unsimplified passes) at points drawn each run
on three ellipsoids with F != 0; ``normal_curvature`` hands the learner's function the forms of the ellipsoid (at
(a, 0, 0) and a generic point) and of a Monge patch with F, f != 0, so that ignoring the forms is told apart.
"""

import functools

import numpy as np

from .catalogue import Case, Wrong, answer, judge, number
from .result import Mistake, call, case_rng, exercise

__all__ = ["fundamental_forms", "normal_curvature", "principal_curvatures"]

_PAIR = "return the pair (I, II): I = Matrix([[E, F], [F, G]]), II = Matrix([[e, f], [f, g]])"
_SURFACES = ("lessons.symbolic.ParametricSurface", "lessons.symbolic.ellipsoid")  # forbidden in every exercise
_OWN = ("lessons.symbolic.forms_normal_curvature", "lessons.symbolic.unit_tangent")


@functools.lru_cache(maxsize=None)
def _surface(kind):
    """A surface of the check: its forms function (a, b, c, u, v) -> (I, II), symbols or numbers in (II against
    p_u x p_v / |.|), its own symbols a, b, c, u, v, and its E, F, G, e, f, g in them."""
    import sympy as sp

    own = a, b, c, u, v = sp.symbols("a b c u v", real=True)
    if kind == "ellipsoid":
        p = sp.Matrix([a * sp.cos(u) * sp.sin(v), b * sp.sin(u) * sp.sin(v), c * sp.cos(v)])
    else:  # a Monge patch z = h(u, v) with h_u h_v != 0 (so F != 0) and h_uv != 0 (so f != 0)
        p = sp.Matrix([u, v, c * sp.sin(u / a) * sp.cos(v / b) + u * v / (a + b)])
    p_u, p_v = p.diff(u), p.diff(v)
    unit = p_u.cross(p_v).normalized()
    I = sp.Matrix([[p_u.dot(p_u), p_u.dot(p_v)], [p_u.dot(p_v), p_v.dot(p_v)]])
    II = sp.Matrix(2, 2, lambda i, j: p.diff(own[3 + i], own[3 + j]).dot(unit))

    def forms(*at):
        where = dict(zip(own, at))
        return I.subs(where, simultaneous=True), II.subs(where, simultaneous=True)

    forms.__name__ = f"{kind}_forms"
    return forms, own, _coefficients((I, II))


def _coefficients(out):
    """The six expressions (E, F, G, e, f, g) from the pair of 2x2 matrices (I, II), or from six expressions."""
    import sympy as sp

    if isinstance(out, (tuple, list)) and len(out) == 6:
        return [sp.sympify(x) for x in out]
    if isinstance(out, (tuple, list)) and len(out) == 2:
        I, II = (x if isinstance(x, sp.MatrixBase) else sp.Matrix(x) for x in out)
        if I.shape != (2, 2) or II.shape != (2, 2):
            raise Mistake(f"the forms have shapes {I.shape} and {II.shape}, not 2 x 2", _PAIR, typical=False)
        return [I[0, 0], I[0, 1], I[1, 1], II[0, 0], II[0, 1], II[1, 1]]
    raise Mistake(f"the function returned {type(out).__name__}, not the pair (I, II)", _PAIR, typical=False)


def _values(exprs, symbols, points, learner=True):
    """(6, k) float values of the expressions at the k points (a, b, c, u, v); the learner's must be real."""
    import sympy as sp

    extra = set().union(*(x.free_symbols for x in exprs)) - set(symbols)
    if learner and extra:
        raise Mistake(
            f"the expressions contain symbols other than a, b, c, u, v: {sorted(map(str, extra))}",
            "build p(u, v) from the symbols the function receives as arguments, not new ones",
        )
    f = sp.lambdify(symbols, exprs, modules="numpy")
    with np.errstate(all="ignore"):
        vals = np.array([np.broadcast_to(np.asarray(f(*pt), dtype=complex), 6) for pt in points]).T
    real = np.all(np.isfinite(vals)) and np.abs(vals.imag).max() <= 1e-9 * (1 + np.abs(vals.real).max())
    if learner and not real:
        raise Mistake(
            "the expressions are not real numbers at points inside the domain",
            "check square roots and divisions: 0 < v < pi, a, b, c > 0",
            typical=False,
        )
    return vals.real


def _at(kind, points, label, **inputs):
    """A case at k points (a, b, c, u, v): right (6, k) E..g there, at_swapped at (v, u), cross = sqrt(EG - F^2)."""
    _, own, exprs = _surface(kind)
    uv, vu = (_values(exprs, own, at, learner=False) for at in (points, points[:, [0, 1, 2, 4, 3]]))
    return Case(label, **inputs).but(points=points, right=uv, at_swapped=vu, cross=np.sqrt(uv[0] * uv[2] - uv[1] ** 2))


def _times(X, first=1.0, second=1.0):
    """X (6, k) with E, F, G multiplied by ``first`` and e, f, g by ``second``."""
    return np.vstack([X[:3] * first, X[3:] * second])


def _same_factor(got, right):
    """Whether ``got`` is ``right`` times one factor other than 1 (where ``right`` is clearly non-zero)."""
    usable = np.abs(right) > 1e-9 * np.abs(right).max()
    ratio = got[usable] / right[usable]
    return bool(usable.any() and np.allclose(ratio, ratio[0], rtol=1e-7) and not np.isclose(ratio[0], 1.0))


_UV = [2, 1, 0, 5, 4, 3]  # E, F, G, e, f, g with the roles of u and v exchanged
# fmt: off
FORMS_MISTAKES = [
    # the learner's p(u, v) is the true p(v, u): its p_u is the true p_v, and p_u x p_v turns round
    Wrong("u and v are swapped: u is taken as the polar angle and v as the longitude", "p(u, v) = (a cos u sin v, b sin u sin v, c cos v): u turns around the z axis, v runs from the north pole (v = 0) to the south pole (v = pi)", build=lambda c: _times(c.at_swapped[_UV], second=-1)),
    Wrong("u and v are exchanged: the forms come out at the point (v, u) (the parameters taken in the wrong order)", "the function receives a, b, c, u, v in this order; p(u, v) = (a cos u sin v, b sin u sin v, c cos v)", build=lambda c: c.at_swapped),
    Wrong("E and G are exchanged (and e and g): the derivatives in u and v are swapped", "E = p_u . p_u and e = -p_uu . n, with p_u = dp/du; u is the longitude, v the polar angle", build=lambda c: c.right[_UV]),
    Wrong("E and G are exchanged", "E = p_u . p_u with p_u = dp/du, G = p_v . p_v", build=lambda c: c.right[[2, 1, 0, 3, 4, 5]]),
    Wrong("F has the wrong sign", "F = p_u . p_v, the dot product of the two tangents as they are", build=lambda c: _times(c.right, first=[[1], [-1], [1]])),
    Wrong("E and G are the lengths |p_u|, |p_v|, not their squares", "E = p_u . p_u = |p_u|^2, G = p_v . p_v = |p_v|^2", build=lambda c: c.right ** [[0.5], [1], [0.5], [1], [1], [1]]),
    Wrong("the sign of the normal is flipped: e, f, g are all negated", "the workbook's II uses the inward normal -n = p_u x p_v / |p_u x p_v| on this ellipsoid, so that every curvature of a convex surface is positive", build=lambda c: _times(c.right, second=-1)),
    Wrong("the normal is not normalised: e, f, g are multiplied by |p_u x p_v|", "divide p_u x p_v by its length before dotting it with p_uu, p_uv, p_vv", build=lambda c: _times(c.right, second=c.cross)),
    Wrong("the normal is not normalised and its sign is flipped: e, f, g are multiplied by -|p_u x p_v|", "-n = p_u x p_v / |p_u x p_v|: a unit vector, pointing inwards on this ellipsoid", build=lambda c: _times(c.right, second=-c.cross)),
    Wrong("the normal is divided by |p_u x p_v| twice: e, f, g are divided by |p_u x p_v|", "-n = p_u x p_v / |p_u x p_v|, divided once", build=lambda c: _times(c.right, second=1 / c.cross)),
    Wrong("e, f, g are all off by the same factor: the normal is not a unit vector", "-n = p_u x p_v / |p_u x p_v|, a unit vector", when=lambda answer, right, c: _same_factor(answer[3:], right[3:])),
    Wrong("e and g are exchanged: the second derivatives in u and v are swapped", "e = -p_uu . n, f = -p_uv . n, g = -p_vv . n", build=lambda c: c.right[[0, 1, 2, 5, 4, 3]]),
    Wrong("F is left out (taken as 0): p_u and p_v are perpendicular only on the coordinate planes", "F = p_u . p_v, which is not 0 at a generic point of an ellipsoid with a != b", build=lambda c: _times(c.right, first=[[1], [0], [1]])),
]
# fmt: on


def forms_cases(rng):
    """Three ellipsoids with different semi-axes (a != b, so F != 0), two points each, drawn with ``rng``."""
    cases = []
    for k in range(3):
        axes = np.zeros(3)
        while np.min(np.abs(np.diff(np.sort(axes)))) < 0.15:  # three clearly different semi-axes
            axes = np.sort(rng.uniform(0.4, 2.5, size=3))[rng.permutation(3)]
        u = rng.uniform(0.2, 1.3, size=2) + rng.integers(0, 4, size=2) * np.pi / 2  # away from sin 2u = 0
        v = rng.uniform(0.25, 1.3, size=2) + rng.integers(0, 2, size=2) * (np.pi / 2 - 0.1)
        points = np.column_stack([np.tile(axes, (2, 1)), u, v])
        cases.append(_at("ellipsoid", points, f"the ellipsoid with semi-axes {', '.join(f'{x:.2f}' for x in axes)}"))
    return cases


@exercise(
    "fundamental_forms",
    reread="The definitions and Steps 1-2 · the tangents p_u, p_v and the inward normal p_u x p_v / |p_u x p_v| = -n",
    forbid=("lessons.symbolic.ellipsoid_forms", *_SURFACES),
    tools=("sympy", "numpy", "scipy"),
)
def fundamental_forms(fn):
    """Check ``fn(a, b, c, u, v) -> (I, II)`` (or the six E, F, G, e, f, g) for the ellipsoid, by value."""
    import sympy as sp

    symbols = sp.symbols("a b c", positive=True) + sp.symbols("u v", real=True)
    exprs, cases = _coefficients(call(fn, *symbols)), forms_cases(case_rng())
    answers = [_values(exprs, symbols, c.points) for c in cases]
    judge(FORMS_MISTAKES, cases, answers, right=lambda c: c.right)
    return ["E, F, G, e, f, g at two generic points (F != 0) of three ellipsoids"]


def _kappa(k, du, dv, two=2.0, divide=True):
    """II(t, t) / I(t, t) (or II(t, t) alone) for the forms k = (E, F, G, e, f, g) and t = (du, dv)."""
    form = lambda X, Y, Z: X * du**2 + two * Y * du * dv + Z * dv**2  # t^T [[X, Y], [Y, Z]] t
    return form(*k[3:]) / form(*k[:3]) if divide else form(*k[3:])


def _tangent(k, phi):
    """(du, dv) of t(phi) = cos phi p_u / |p_u| + sin phi w, w the unit tangent perpendicular to p_u."""
    root_E, area = np.sqrt(k[0]), np.sqrt(k[0] * k[2] - k[1] ** 2)
    return np.cos(phi) / root_E - np.sin(phi) * k[1] / (root_E * area), np.sin(phi) * root_E / area


def _right(k, phi):
    with np.errstate(all="ignore"):  # the forms evaluated at (v, u) may sit at a pole (E = 0)
        return _kappa(k, *_tangent(k, phi))


def _on(rule, k="right"):
    """The wrong answer ``rule(forms k of the case, phi)`` at every angle of a case."""
    return lambda c: np.array([rule(getattr(c, k)[:, 0], phi) for phi in c.phis])


# fmt: off
KAPPA_MISTAKES = [
    Wrong("kappa_n is about 0 at every angle: a guard on the denominator swamps I(t, t) (1e10 where 1e-10 was meant?)", "divide by I(t, t) itself; with the unit tangent t(phi) it is 1, so no guard is needed", when=lambda kappa, right, c: np.abs(kappa).max() <= 1e-6 * np.abs(right).max()),
    Wrong("the function does not use the forms it receives: it gives the ellipsoid's kappa_n at (a, 0, 0) everywhere", "call forms(a, b, c, u, v) with sympy symbols, substitute the numbers, and build kappa_n from its I and II", build=lambda c: c.a * np.cos(c.phis) ** 2 / c.b**2 + c.a * np.sin(c.phis) ** 2 / c.c**2),
    Wrong("the sign is flipped", "kappa_n = II(t, t) / I(t, t) with II as the forms give it, no minus sign", build=_on(lambda k, p: -_right(k, p))),
    Wrong("F is ignored in the tangent: (du, dv) = (cos phi / sqrt(E), sin phi / sqrt(G)) treats p_u and p_v as perpendicular", "where F != 0, p_v is not perpendicular to p_u: w, the unit tangent perpendicular to p_u, is a combination of p_u and p_v with w . p_u = 0", build=_on(lambda k, p: _kappa(k, np.cos(p) / np.sqrt(k[0]), np.sin(p) / np.sqrt(k[2])))),
    Wrong("phi is measured in the (u, v) parameter plane: (du, dv) = (cos phi, sin phi)", "phi is an angle on the surface, from p_u: t = cos phi p_u / |p_u| + sin phi w, with |p_u| = sqrt(E)", build=_on(lambda k, p: _kappa(k, np.cos(p), np.sin(p)))),
    Wrong("II(t, t) is not divided by I(t, t), and t = (cos phi, sin phi) in (du, dv) is not a unit vector", "kappa_n = II(t, t) / I(t, t); with the unit tangent t(phi), I(t, t) = 1", build=_on(lambda k, p: _kappa(k, np.cos(p), np.sin(p), divide=False))),
    Wrong("the angle turns the other way: w points away from p_v (kappa_n(phi) came out kappa_n(-phi))", "w is the unit tangent perpendicular to p_u on the side of p_v: w . p_v > 0", build=_on(lambda k, p: _right(k, -p))),
    Wrong("phi is measured from p_v instead of p_u (the roles of u and v exchanged)", "phi = 0 is the direction of p_u: t(0) = p_u / sqrt(E)", build=_on(lambda k, p: _right(k[_UV], p))),
    Wrong("the mixed terms lack their factor 2: I(t, t) = E du^2 + 2 F du dv + G dv^2, and II(t, t) likewise", "t^T I t = E du^2 + 2 F du dv + G dv^2: F stands twice in the matrix I", build=_on(lambda k, p: _kappa(k, *_tangent(k, p), two=1.0))),
    Wrong("phi is converted from degrees, but it is already in radians", "phi is in radians: use np.cos(phi), np.sin(phi) as they are", build=_on(lambda k, p: _right(k, np.radians(p)))),
    Wrong("the forms are evaluated at (v, u) instead of (u, v)", "substitute u for the symbol u and v for the symbol v", build=_on(_right, "at_swapped")),
]
# fmt: on


def kappa_cases(rng):
    phis = np.concatenate([[0.0, np.pi / 2], rng.uniform(0.2, 1.3, size=2), rng.uniform(1.8, 3.0, size=1)])
    a, b, c = rng.uniform(0.6, 1.0), rng.uniform(1.1, 1.5), rng.uniform(1.6, 2.2)
    u, v = rng.uniform(0.3, 1.2), rng.uniform(0.4, 1.2)
    return [
        _at(kind, np.array([x]), label, forms=_surface(kind)[0], **dict(zip("abcuv", x))).but(phis=phis)
        for label, kind, x in (
            ("the ellipsoid at (a, 0, 0)", "ellipsoid", (a, b, c, 0.0, np.pi / 2)),
            (f"the ellipsoid at (u, v) = ({u:.2f}, {v:.2f}), where F != 0", "ellipsoid", (a, b, c, u, v)),
            (f"a Monge patch at (u, v) = ({v:.2f}, {u:.2f}), where F and f != 0", "monge", (c, b, 0.7, v, u)),
        )
    ]


@exercise(
    "normal_curvature",
    reread="Step 5 · the unit tangent t(phi) = cos phi p_u / |p_u| + sin phi w and kappa_n = II(t, t) / I(t, t)",
    forbid=(*_OWN, "lessons.symbolic.ellipsoid_normal_curvature", *_SURFACES),
    own=_OWN,
    tools=("numpy", "scipy", "sympy"),
)
def normal_curvature(fn):
    """Check ``fn(forms, a, b, c, u, v, phi) -> kappa_n``: forms(a, b, c, u, v) -> (I, II) in sympy; numbers in."""
    cases, hint = kappa_cases(case_rng()), "return kappa_n as one number for the given forms, a, b, c, u, v and phi"
    answers = [np.array([number(answer(fn, c, phi=float(phi)), hint=hint) for phi in c.phis]) for c in cases]
    judge(KAPPA_MISTAKES, cases, answers, right=_on(_right))
    return [c.label for c in cases]


_PRINCIPAL = "kappa_1,2 = H +- sqrt(H^2 - K), H = tr(I^-1 II) / 2, K = det II / det I: the eigenvalues of L = I^-1 II"


def principal_cases(rng):
    """(I, II) in sympy, the points (values of their symbols) they are read at, and I, II there: the ellipsoid
    at (a, 0, 0) (an umbilic where b = c), the sphere (all umbilics), a Monge patch z = h(x, y) at a point
    with F, f != 0 and K < 0 (exact), the ellipsoid at a point where F != 0 (floats)."""
    import sympy as sp

    from ...lessons.symbolic import ellipsoid_forms

    a, b, c, r, v = sp.symbols("a b c r v", positive=True)
    abc = [rng.uniform(0.5, 2.5, 3) for _ in range(3)] + [np.array([1.3, 0.8, 0.8])]  # the last: b = c
    hx, hy = (int(rng.choice([-2, -1, 1, 2])) for _ in range(2))
    hxx, hyy, hxy = int(rng.integers(1, 4)), -int(rng.integers(1, 4)), int(rng.integers(1, 3))
    W = sp.sqrt(1 + hx**2 + hy**2)
    A, B, C = rng.uniform(0.6, 2.0, 3)
    u0, v0 = rng.uniform(0.3, 1.2), rng.uniform(0.4, 1.2)
    sphere = (sp.diag(r**2 * sp.sin(v) ** 2, r**2), sp.diag(r * sp.sin(v) ** 2, r))
    monge = (sp.Matrix([[1 + hx**2, hx * hy], [hx * hy, 1 + hy**2]]), sp.Matrix([[hxx, hxy], [hxy, hyy]]) / W)
    at_F = f"the ellipsoid ({A:.2f}, {B:.2f}, {C:.2f}) at (u, v) = ({u0:.2f}, {v0:.2f}), where F != 0"
    pairs = [
        ("the ellipsoid at (a, 0, 0)", sp.diag(b**2, c**2), sp.diag(a, a), (a, b, c), abc),
        ("the sphere of radius r", *sphere, (r, v), [rng.uniform([0.3, 0.2], [3.0, 2.9]) for _ in range(3)]),
        ("a Monge patch at a point where K < 0 and F, f != 0", *monge, (), [()]),
        (at_F, *ellipsoid_forms(*(float(x) for x in (A, B, C, u0, v0))), (), [()]),
    ]
    cases = []
    for label, I, II, symbols, points in pairs:
        at = np.array([np.array(sp.Matrix.vstack(I, II).subs(dict(zip(symbols, p))), dtype=float) for p in points])
        cases.append(Case(label, I=I, II=II).but(symbols=symbols, points=points, I_at=at[:, :2], II_at=at[:, 2:], n=2))
    return cases


def _eig(I, II):
    """(P, 2): the eigenvalues of I^-1 II at each point, largest first (real: L is similar to a symmetric matrix)."""
    return -np.sort(-np.linalg.eigvals(np.linalg.solve(I, II)).real, axis=-1)


def _from_HK(H, K):
    """(P, 2): H +- sqrt(H^2 - K), NaN where the root is not real."""
    d = H**2 - K
    root = np.sqrt(np.where(d >= 0, d, np.nan))
    return np.stack([H + root, H - root], axis=-1)


def _HK(c):
    L = np.linalg.solve(c.I_at, c.II_at)
    return np.trace(L, axis1=1, axis2=2) / 2, np.linalg.det(c.II_at) / np.linalg.det(c.I_at)


def _pair(out, case):
    """(P, 2) floats: the two expressions returned, at the case's points; NaN where they are not real."""
    import sympy as sp

    if isinstance(out, dict):
        raise Mistake(
            "the function returned a dict, as sympy's eigenvals() does (a repeated eigenvalue appears once)",
            "return the pair (kappa_1, kappa_2), kappa_1 >= kappa_2",
            typical=False,
        )
    if not isinstance(out, (tuple, list)) or len(out) != 2:
        raise Mistake(
            f"the function returned {type(out).__name__}, not the pair (kappa_1, kappa_2)",
            "end with `return kappa_1, kappa_2`",
            typical=False,
        )
    exprs = [sp.sympify(x) for x in out]
    extra = set().union(*(x.free_symbols for x in exprs)) - set(case.symbols)
    if extra:
        raise Mistake(
            f"the curvatures hold symbols that I and II do not: {sorted(map(str, extra))}",
            "build them from the entries of I and II only",
            typical=False,
        )
    exact = [dict(zip(case.symbols, map(sp.Rational, p))) for p in case.points]  # an umbilic's root is exactly 0
    values = np.array([[complex(x.subs(at).evalf(30)) for x in exprs] for at in exact])
    return np.where(np.abs(values.imag) > 1e-9 * (1 + np.abs(values.real)), np.nan, values.real)


# fmt: off
PRINCIPAL_MISTAKES = [
    Wrong("kappa_1 < kappa_2: the pair is in the wrong order", "kappa_1 = H + sqrt(H^2 - K) is the larger", build=lambda c: _eig(c.I_at, c.II_at)[:, ::-1]),
    Wrong("the curvatures are the eigenvalues of II alone: I is left out", _PRINCIPAL, build=lambda c: _eig(np.eye(2)[None].repeat(len(c.points), 0), c.II_at)),
    Wrong("the curvatures are the eigenvalues of II^-1 I: radii 1/kappa, not curvatures", _PRINCIPAL, build=lambda c: -np.sort(-1 / _eig(c.I_at, c.II_at), axis=1)),
    Wrong("H and K are swapped: K +- sqrt(K^2 - H)", _PRINCIPAL, build=lambda c: _from_HK(*_HK(c)[::-1])),
    Wrong("H is the trace of L, not half of it", _PRINCIPAL, build=lambda c: _from_HK(2 * _HK(c)[0], _HK(c)[1])),
    Wrong("the root is sqrt(H^2 + K): the sign of K under the root", "(kappa_1 - kappa_2)^2 / 4 = H^2 - K", build=lambda c: _from_HK(_HK(c)[0], -_HK(c)[1])),
    Wrong("K is det II, not det II / det I", _PRINCIPAL, build=lambda c: _from_HK(_HK(c)[0], np.linalg.det(c.II_at))),
    Wrong("the principal curvatures differ from the eigenvalues of I^-1 II on {label}", _PRINCIPAL, typical=False),
]
# fmt: on


@exercise(
    "principal_curvatures",
    reread="After the discussion · the shape operator L = I^-1 II and its eigenvalues",
    forbid=("lessons.symbolic.forms_principal_curvatures", *_SURFACES),
    tools=("sympy", "numpy", "scipy"),
)
def principal_curvatures(fn):
    """Check ``fn(I, II) -> (kappa_1, kappa_2)`` (sympy), by value at points drawn each run."""
    cases = principal_cases(case_rng())
    answers = [_pair(call(fn, c.I.copy(), c.II.copy()), c) for c in cases]
    judge(PRINCIPAL_MISTAKES, cases, answers, right=lambda c: _eig(c.I_at, c.II_at))
    return [c.label for c in cases]
