"""Checks of the exercises of notebook 02: the ellipsoid's fundamental forms and its normal curvature.

The learner's expressions are compared by value, at a few points of the
parameter domain and a few semi-axes, so an unsimplified but correct
expression passes: simplification is a matter of taste, not a mistake.

sympy is imported inside the checks that use it: it takes about a second to
import, and every notebook imports ``geomlib.check``, most of them without a
symbolic exercise.
"""

import numpy as np

from .result import Mistake, call, exercise

__all__ = ["fundamental_forms", "normal_curvature"]

# (a, b, c, u, v): generic points (F != 0 at each, 0 < v < pi) on three different ellipsoids
_POINTS = np.array([[1.0, 0.7, 0.5, 0.3, 1.1], [2.0, 1.3, 0.6, 2.1, 0.4], [0.8, 1.5, 1.1, 4.0, 2.5]])
_NAMES = ("E", "F", "G", "e", "f", "g")


def _expressions(out):
    """The six expressions (E, F, G, e, f, g) from a 6-tuple or from the pair of 2x2 matrices (I, II)."""
    import sympy as sp

    if isinstance(out, (tuple, list)) and len(out) == 6:
        return [sp.sympify(x) for x in out]
    if isinstance(out, (tuple, list)) and len(out) == 2:
        I, II = (sp.Matrix(x) if not isinstance(x, sp.MatrixBase) else x for x in out)
        if I.shape != (2, 2) or II.shape != (2, 2):
            raise Mistake(
                f"the forms have shapes {I.shape} and {II.shape}, expected two 2 x 2 matrices",
                "return (I, II) with I = Matrix([[E, F], [F, G]]) and II = Matrix([[e, f], [f, g]])",
                typical=False,
            )
        for name, A in (("I", I), ("II", II)):
            if sp.simplify(A[0, 1] - A[1, 0]) != 0:
                raise Mistake(
                    f"{name} is not symmetric", f"both off-diagonal entries of {name} are the same dot product"
                )
        return [I[0, 0], I[0, 1], I[1, 1], II[0, 0], II[0, 1], II[1, 1]]
    raise Mistake(
        f"the function returned {type(out).__name__}, not (E, F, G, e, f, g) or (I, II)",
        "end with `return E, F, G, e, f, g` (sympy expressions in a, b, c, u, v)",
        typical=False,
    )


def _values(exprs, symbols, points):
    """(6, len(points)) float array of the expressions at the points (a, b, c, u, v)."""
    import sympy as sp

    extra = set().union(*(x.free_symbols for x in exprs)) - set(symbols)
    if extra:
        raise Mistake(
            f"the expressions contain symbols other than a, b, c, u, v: {sorted(map(str, extra))}",
            "build p(u, v) from the symbols the function receives as arguments, not new ones",
        )
    f = sp.lambdify(symbols, exprs, modules="numpy")
    with np.errstate(all="ignore"):
        vals = np.array([np.asarray(f(*pt), dtype=complex) for pt in points]).T
    if not np.all(np.isfinite(vals)) or np.abs(vals.imag).max() > 1e-9 * (1 + np.abs(vals.real).max()):
        raise Mistake(
            "the expressions are not real numbers at points inside the domain",
            "check square roots and divisions: 0 < v < pi, a, b, c > 0",
            typical=False,
        )
    return vals.real


def _reference(points):
    """(E, F, G, e, f, g) at the points, from p's derivatives written out (independent of sympy), and |p_u x p_v|."""
    a, b, c, u, v = points.T
    cu, su, cv, sv = np.cos(u), np.sin(u), np.cos(v), np.sin(v)
    p_u = np.stack([-a * su * sv, b * cu * sv, 0 * u], axis=1)
    p_v = np.stack([a * cu * cv, b * su * cv, -c * sv], axis=1)
    p_uu = np.stack([-a * cu * sv, -b * su * sv, 0 * u], axis=1)
    p_uv = np.stack([-a * su * cv, b * cu * cv, 0 * u], axis=1)
    p_vv = np.stack([-a * cu * sv, -b * su * sv, -c * cv], axis=1)
    m = np.cross(p_u, p_v)
    cross = np.linalg.norm(m, axis=1)
    minus_n = m / cross[:, None]  # the inward normal -n on this parameterisation: the workbook's II
    dot = lambda x, y: np.einsum("ij,ij->i", x, y)
    ref = np.array(
        [dot(p_u, p_u), dot(p_u, p_v), dot(p_v, p_v), dot(p_uu, minus_n), dot(p_uv, minus_n), dot(p_vv, minus_n)]
    )
    return ref, cross


def _same(x, y):
    return np.allclose(x, y, rtol=1e-7, atol=1e-9)


@exercise(
    "fundamental_forms",
    reread="The definitions and Steps 1-2 · the tangents p_u, p_v and the inward normal p_u x p_v / |p_u x p_v| = -n",
    forbid=("lessons.symbolic.ellipsoid_forms", "lessons.symbolic.ParametricSurface", "lessons.symbolic.ellipsoid"),
    tools=("sympy", "numpy", "scipy"),
)
def fundamental_forms(fn):
    """Check ``fn(a, b, c, u, v) -> (E, F, G, e, f, g)`` (or ``(I, II)``) for the ellipsoid, by value."""
    import sympy as sp

    a, b, c = sp.symbols("a b c", positive=True)
    u, v = sp.symbols("u v", real=True)
    exprs = _expressions(call(fn, a, b, c, u, v))
    vals = _values(exprs, (a, b, c, u, v), _POINTS)
    ref, cross = _reference(_POINTS)
    first, second = vals[:3], vals[3:]
    swap = [2, 1, 0]
    # u as the polar angle and v as the longitude: the learner's E(u, v) is the true G(v, u)
    at_swapped = _values(exprs, (a, b, c, u, v), _POINTS[:, [0, 1, 2, 4, 3]])
    if not _same(first, ref[:3]) and (_same(at_swapped[:3], ref[:3]) or _same(at_swapped[[2, 1, 0]], ref[:3])):
        raise Mistake(
            "u and v are swapped: u is taken as the polar angle and v as the longitude",
            "p(u, v) = (a cos u sin v, b sin u sin v, c cos v): u turns around the z axis, "
            "v runs from the north pole (v = 0) to the south pole (v = pi)",
        )
    if not _same(first, ref[:3]):
        if _same(first, ref[:3][swap]):
            raise Mistake(
                "u and v are swapped: E and G are exchanged",
                "E = p_u . p_u with p_u = dp/du; u is the longitude, v the polar angle",
            )
        if _same(first[[0, 2]], ref[[0, 2]]) and _same(first[1], -ref[1]):
            raise Mistake("F has the wrong sign", "F = p_u . p_v, the dot product of the two tangents as they are")
        wrong = [n for n, x, y in zip(_NAMES, first, ref[:3]) if not _same(x, y)]
        raise Mistake(
            f"{', '.join(wrong)} of the first fundamental form differ from p_u . p_u, p_u . p_v, p_v . p_v",
            "differentiate p(u, v) = (a cos u sin v, b sin u sin v, c cos v) once in u and once in v",
            typical=False,
        )
    if _same(second, ref[3:]):
        return ["E, F, G, e, f, g at three generic points (F != 0) of three ellipsoids"]
    if _same(second, ref[3:][swap]):
        raise Mistake(
            "u and v are swapped in the second fundamental form: e and g are exchanged", "e = -p_uu . n, g = -p_vv . n"
        )
    if _same(second, -ref[3:]):
        raise Mistake(
            "the sign of the normal is flipped: e, f, g are all negated",
            "the workbook's II uses the inward normal -n = p_u x p_v / |p_u x p_v| on this ellipsoid, "
            "so that every curvature of a convex surface is positive",
        )
    for sign in (1, -1):
        if _same(second, sign * cross * ref[3:]):
            raise Mistake(
                "the normal is not normalised: e, f, g are multiplied by |p_u x p_v| = sin v W",
                "divide p_u x p_v by its length before dotting it with p_uu, p_uv, p_vv",
            )
    with np.errstate(all="ignore"):
        ratio = second / ref[3:]
    usable = np.isfinite(ratio) & (np.abs(ref[3:]) > 1e-9)
    if usable.any() and np.allclose(ratio[usable], ratio[usable][0]) and not np.isclose(abs(ratio[usable][0]), 1):
        raise Mistake(
            f"e, f, g are all off by the same factor {ratio[usable][0]:.4g}: the normal is not a unit vector",
            "-n = p_u x p_v / |p_u x p_v|, a unit vector",
        )
    wrong = [n for n, x, y in zip(_NAMES[3:], second, ref[3:]) if not _same(x, y)]
    raise Mistake(
        f"{', '.join(wrong)} of the second fundamental form differ from -p_uu . n, -p_uv . n, -p_vv . n",
        "take the second derivatives of p and dot them with the unit normal -n = p_u x p_v / |p_u x p_v|",
        typical=False,
    )


# (a, b, c) triples with b != c (at b = c every direction at (a, 0, 0) is principal) and angles phi
_AXES = np.array([[1.0, 0.7, 0.5], [2.0, 1.5, 0.8], [1.3, 0.6, 1.9]])
_PHIS = np.array([0.0, 0.4, 1.1, np.pi / 2, 2.5, 4.0])


@exercise(
    "normal_curvature",
    reread="Step 4 · The point (a, 0, 0) and its normal sections",
    forbid=(
        "lessons.symbolic.ellipsoid_normal_curvature",
        "lessons.symbolic.ParametricSurface",
        "lessons.symbolic.ellipsoid",
    ),
    tools=("numpy", "scipy", "sympy"),
)
def normal_curvature(fn):
    """Check ``fn(a, b, c, phi) -> kappa_n`` at (a, 0, 0), phi in radians from p_u (numbers or sympy numbers)."""
    got = np.empty((len(_AXES), len(_PHIS)))
    for i, (a, b, c) in enumerate(_AXES):
        for j, phi in enumerate(_PHIS):
            out = call(fn, float(a), float(b), float(c), float(phi))
            try:
                got[i, j] = float(out)
            except (TypeError, ValueError):
                raise Mistake(
                    f"the function returned {type(out).__name__} ({out!s:.60}), not a number",
                    "return kappa_n as one number for the given a, b, c, phi (substitute them "
                    "into a sympy expression, or write it with numpy)",
                    typical=False,
                ) from None
    a, b, c = (_AXES[:, k, None] for k in range(3))
    cos2, sin2 = np.cos(_PHIS) ** 2, np.sin(_PHIS) ** 2
    right = a * cos2 / b**2 + a * sin2 / c**2
    if _same(got, right):
        return ["(a, 0, 0) of three ellipsoids, six directions each"]
    diagnoses = [
        (
            -right,
            "the sign is flipped",
            "at (a, 0, 0) the ellipsoid bends away from its outward normal: kappa_n > 0, as on a sphere",
        ),
        (
            a * sin2 / b**2 + a * cos2 / c**2,
            "kappa_n(0) came out a / c^2: b and c are exchanged, or phi is measured from p_v instead of p_u",
            "phi = 0 is the direction of p_u = (0, b, 0), of length b, so kappa_n(0) = e / E = a / b^2",
        ),
        (
            np.broadcast_to(a, right.shape),
            "kappa_n = a for every phi: II(t, t) is not divided by the first form",
            "kappa_n = II(t, t) / I(t, t); the unit tangent at angle phi from p_u has (du, dv) = "
            "(cos phi / b, sin phi / c), since |p_u| = b and |p_v| = c, and then I(t, t) = 1",
        ),
        (
            np.broadcast_to(a / b**2, right.shape),
            "kappa_n = a / b^2 for every phi: only E divides, for both directions",
            "divide II(t, t) by I(t, t), which mixes E and G as the direction turns",
        ),
        (
            a / (b**2 * cos2 + c**2 * sin2),
            "phi is measured in the (u, v) parameter plane: (du, dv) = (cos phi, sin phi) treats p_u, p_v as unit vectors",
            "the unit tangent at angle phi has (du, dv) = (cos phi / b, sin phi / c), since |p_u| = b and |p_v| = c",
        ),
        (
            a * cos2 / b + a * sin2 / c,
            "kappa_n(0) came out a / b: II is divided by the length |p_u| = b, not by I(p_u, p_u) = b^2",
            "with (du, dv) = (cos phi / b, sin phi / c), II(t, t) = a cos^2 phi / b^2 + a sin^2 phi / c^2",
        ),
        (
            a * cos2 / b**4 + a * sin2 / c**4,
            "the first form divides twice",
            "with (du, dv) = (cos phi / b, sin phi / c) the tangent is already a unit vector: I(t, t) = 1",
        ),
    ]
    for wrong, diagnosis, hint in diagnoses:
        if _same(got, wrong):
            raise Mistake(diagnosis, hint)
    if np.allclose(got[:, 0], right[:, 0]) and np.allclose(got[:, 3], right[:, 3]):
        raise Mistake(
            "kappa_n is right along p_u and p_v but not between them",
            "Euler: kappa_n = kappa_u cos^2 phi + kappa_v sin^2 phi, squares of cos and sin",
        )
    raise Mistake(
        "kappa_n differs from II(t, t) / I(t, t) at (a, 0, 0)",
        "at (a, 0, 0): I = diag(b^2, c^2), II = diag(a, a), (du, dv) = (cos phi / b, sin phi / c)",
        typical=False,
    )
