"""Parametric surfaces p(u, v) in sympy: fundamental forms and curvature, exact.

Sign convention (the same as the discrete one in the rest of geomlib, where
``Delta x = -2 H n`` with ``n`` the outward unit normal):

* ``unit_normal()`` returns ``n``: the *outward* normal on closed surfaces
  (sphere, ellipsoid, torus); on open surfaces the normal each constructor
  documents (``n = p_u x p_v / |p_u x p_v|`` unless stated, so the upward
  normal ``(-h_x, -h_y, 1) / sqrt(1 + h_x^2 + h_y^2)`` of a Monge patch
  ``z = h(x, y)``).
* The second fundamental form uses the opposite normal ``-n``:
  ``e = -p_uu . n``, ``f = -p_uv . n``, ``g = -p_vv . n``. A surface that bends
  away from ``n`` (a sphere seen from outside) therefore has positive normal
  curvature: a sphere of radius r has every normal curvature ``+1/r``,
  ``H = 1/r`` and ``K = 1/r^2``. For the ellipsoid and sphere parameterised as
  ``(a cos u sin v, b sin u sin v, c cos v)`` the vector ``p_u x p_v`` points
  inward, so there ``-n = p_u x p_v / |p_u x p_v|``, the normal of do Carmo
  (1976, section 3-2), and his formulas hold unchanged.

Definitions (all pointwise, in 1/length for curvatures, 1/length^2 for K)::

    I  = [[E, F], [F, G]],   E = p_u.p_u, F = p_u.p_v, G = p_v.p_v
    II = [[e, f], [f, g]]    (with the normal -n, as above)
    L  = I^-1 II             shape operator on coordinate vectors (du, dv)
    K  = det II / det I = k1 k2,      H = tr L / 2 = (k1 + k2) / 2
    k1 >= k2                 principal curvatures, eigenvalues of L

Tangent directions are given by an angle ``phi`` measured from ``p_u`` in the
tangent plane: the unit direction is

    t(phi) = cos(phi) p_u / |p_u| + sin(phi) w,

where ``w`` is the unit tangent perpendicular to ``p_u`` obtained by turning
``p_u / |p_u|`` by +90 degrees counter-clockwise about ``m = p_u x p_v / |p_u x p_v|``
(``w = m x p_u / |p_u|``); equivalently ``w`` is the unit tangent with
``w . p_u = 0`` and ``w . p_v > 0``. So ``phi = pi/2`` is the direction of
``p_v`` where ``F = 0``. (On the ellipsoid ``m`` is the inward normal, so
seen from outside ``phi`` turns clockwise.) The normal curvature is
``kappa_n(phi) = II(t, t)`` (``I(t, t) = 1``).

At singular points of a parameterisation (the ellipsoid's poles, where
``p_u = 0``) H, K, the principal curvatures and the normal are still finite
and exact (the vanishing factor is cancelled symbolically); the frame and the
principal directions are taken 1e-8 inside the domain there.

Every symbolic result is simplified once and cached per surface. Surfaces with
numeric parameters (``ellipsoid(1, 2, 3)``) are computed once per family with
positive parameter symbols and then substituted, and ``lambdify(name)`` compiles
the family's expression once, so building many ellipsoids is cheap and the
numpy functions take ~10 ms for 10^5 points.

References: M. P. do Carmo, Differential Geometry of Curves and Surfaces
(1976), chapter 3; A. Pressley, Elementary Differential Geometry (2nd ed. 2010),
chapters 6-8.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import sympy as sp
from sympy.simplify.fu import TR5, TR6

__all__ = [
    "ParametricSurface",
    "ellipsoid",
    "ellipsoid_forms",
    "ellipsoid_normal_curvature",
    "forms_normal_curvature",
    "forms_principal_curvatures",
    "unit_tangent",
    "sphere",
    "torus",
    "helicoid",
    "monge",
    "saddle",
    "LAMBDIFY_NAMES",
]

# The names lambdify() knows, with what the compiled function returns.
LAMBDIFY_NAMES = {
    "position": "(..., 3) float64 point p(u, v)",
    "p_u": "(..., 3) tangent dp/du",
    "p_v": "(..., 3) tangent dp/dv",
    "unit_normal": "(..., 3) unit normal n (outward on closed surfaces)",
    "first_fundamental_form": "(..., 2, 2) [[E, F], [F, G]]",
    "second_fundamental_form": "(..., 2, 2) [[e, f], [f, g]] with normal -n",
    "shape_operator": "(..., 2, 2) L = I^-1 II",
    "area_element": "(...,) sqrt(EG - F^2)",
    "gaussian_curvature": "(...,) K in 1/length^2",
    "mean_curvature": "(...,) H in 1/length (H = 1/r on a sphere)",
    "principal_curvatures": "tuple (k1, k2), each (...,), k1 >= k2",
    "principal_directions": "tuple (d1, d2), each (..., 3) unit vectors for k1, k2",
    "normal_curvature": "f(u, v, phi) -> (...,) kappa_n(phi)",
}


def _exact(x):
    """A number as an exact sympy number (floats via their shortest decimal repr)."""
    if isinstance(x, sp.Basic):
        return x
    if isinstance(x, (bool, np.bool_)):
        raise TypeError("a surface parameter must be a number or a sympy expression, not a bool")
    if isinstance(x, (int, np.integer)):
        return sp.Integer(int(x))
    if isinstance(x, (float, np.floating)):
        if not math.isfinite(float(x)):
            raise ValueError(f"surface parameter must be finite, got {x!r}")
        return sp.Rational(repr(float(x)))
    return sp.sympify(x)


def _tidy(expr):
    """Simplify a scalar expression, keeping the form with the fewest operations.

    Candidates: the expression, ``factor``, ``cancel`` + ``factor`` and, for
    small expressions, either the two Pythagorean rewrites
    (below) where sines or cosines of the variables occur, or ``simplify``.
    Full ``simplify`` on the large expressions of a general ellipsoid takes
    tens of seconds and seldom wins, so it is skipped there.

    On polynomials in sin and cos what ``simplify`` finds is sin^2 + cos^2 = 1:
    writing sin^2 as 1 - cos^2 (sympy's ``TR5``) or cos^2 as 1 - sin^2
    (``TR6``) and factoring finds it too. Over the 24 expressions the
    ellipsoid of notebook 02 passes through here, that took 0.56 s against
    1.58 s with ``simplify`` (one process, 2 cores, load average 2.5), with
    the same forms everywhere the notebook shows one; the tangent frame comes
    out shorter (a b^2 sin v cos u cos v instead of
    a b^2 (sin(u + 2v) - sin(u - 2v)) / 4).
    """
    expr = sp.sympify(expr)
    if expr.is_number:
        return sp.simplify(expr)
    rewrites = [sp.factor, lambda x: sp.factor(sp.cancel(x))]
    if sp.count_ops(expr) <= 60:
        if any(f.free_symbols for f in expr.atoms(sp.sin, sp.cos)):
            rewrites += [lambda x: sp.factor(TR5(x)), lambda x: sp.factor(TR6(x))]
        else:
            rewrites.append(sp.simplify)
    cands = [expr]
    for fn in rewrites:
        try:
            cands.append(fn(expr))
        except (sp.PolynomialError, NotImplementedError, TypeError):  # pragma: no cover
            pass
    return min(cands, key=sp.count_ops)


def _subs_tidy(val, sub):
    """Substitute into an expression, matrix or tuple of them and simplify each entry."""
    if isinstance(val, tuple):
        return tuple(_subs_tidy(x, sub) for x in val)
    if isinstance(val, sp.MatrixBase):
        return val.subs(sub).applyfunc(_tidy)
    return _tidy(sp.sympify(val).subs(sub))


def _dot(a, b):
    return sum(a[i] * b[i] for i in range(3))


class ParametricSurface:
    """A parametric surface p(u, v) with exact fundamental forms and curvature.

    Convention: ``unit_normal()`` is ``n = orientation * (p_u x p_v) / |p_u x p_v|``
    (outward on closed surfaces); the second fundamental form uses ``-n`` so
    that a sphere of radius r has every normal curvature ``+1/r`` (see the
    module docstring).

    Parameters
    ----------
    p : sequence of 3 sympy expressions in ``u``, ``v`` and ``params``.
    u, v : sympy Symbol
        The parameters (declare them ``real=True``).
    params : tuple of sympy Symbol, optional
        Shape parameters (e.g. the semi-axes a, b, c), declared ``positive=True``
        so that simplification can use it.
    values : dict, optional
        Values for (some of) ``params``: numbers or sympy expressions. The
        exact results are computed once for the family (``values`` empty) and
        substituted; ``lambdify`` binds numeric values.
    normal_direction : sequence of 3 expressions, optional
        A vector ``D`` pointing along ``n`` (a positive multiple of it) with
        the factors that vanish or change sign on the domain removed, such that
        ``p_u x p_v = orientation * area_factor * D`` with ``area_factor >= 0``
        on the domain. Supplying it keeps ``|D| = sqrt(D . D)`` free of
        ``Abs`` and the results short. Default: ``D = orientation * p_u x p_v``,
        ``area_factor = 1``. Checked numerically at random points.
    area_factor : expression, optional
        See ``normal_direction``; ``sqrt(EG - F^2) = area_factor * |D|``.
    orientation : +1 or -1
        -1 when ``p_u x p_v`` points against the wanted normal ``n`` (the
        ellipsoid: ``p_u x p_v`` points inward, ``n`` outward).
    domain : ((u0, u1), (v0, v1)), optional
        The parameter domain, for documentation and plotting.
    name : str
    closed : bool
        Whether the surface is closed (``n`` is then the outward normal).
    check_values : dict, optional
        Admissible numbers for ``params`` used to check the normal hint at
        random points (torus: R > r).
    simplify : bool
        False: derive without simplifying each step (the cancellations that
        keep the poles finite still happen). The expressions are longer but
        their values the same, to rounding: for surfaces that are only
        evaluated (``lambdify``), as the test meshes' exact curvature is; the
        derivation then takes a fifth of the time or less.
    """

    def __init__(
        self,
        p,
        u,
        v,
        *,
        params=(),
        values=None,
        normal_direction=None,
        area_factor=1,
        orientation=1,
        domain=None,
        name="surface",
        closed=False,
        check_values=None,
        simplify=True,
        _family=None,
    ):
        if orientation not in (1, -1):
            raise ValueError(f"orientation must be +1 or -1, got {orientation!r}")
        self.u, self.v = u, v
        self.params = tuple(params)
        self.values = {k: _exact(x) for k, x in (values or {}).items()}
        unknown = set(self.values) - set(self.params)
        if unknown:
            raise ValueError(f"values given for names that are not parameters: {sorted(map(str, unknown))}")
        self.name = name
        self.closed = closed
        self.orientation = orientation
        self._cache = {}
        self._lambdified = {}
        self.simplify = simplify if _family is None else _family.simplify
        if _family is not None:
            # A member of a family: symbolic results come from the family by substitution.
            self._family = _family
            self.p = sp.Matrix(_family.p).subs(self.values)
            self.domain = (
                None
                if _family.domain is None
                else tuple(tuple(sp.sympify(x).subs(self.values) for x in rng) for rng in _family.domain)
            )
            return
        self._family = None
        self.p = sp.Matrix(p)
        if self.p.shape != (3, 1):
            raise ValueError(f"p must have three components, got shape {self.p.shape}")
        self.domain = None if domain is None else tuple(tuple(sp.sympify(x) for x in rng) for rng in domain)
        self._D = None if normal_direction is None else sp.Matrix(normal_direction)
        self._area_factor = sp.sympify(area_factor)
        if self._D is not None:
            self._check_normal_hint(check_values or {})

    # ------------------------------------------------------------------ helpers
    def __repr__(self):
        vals = ", ".join(f"{k}={x}" for k, x in self.values.items())
        return f"<ParametricSurface {self.name}{'(' + vals + ')' if vals else ''}: p = {list(self.p)}>"

    def with_values(self, **values):
        """The same family with some parameters set, e.g. ``E.with_values(a=1, b=2, c=3)``."""
        fam = self._family or self
        by_name = {str(s): s for s in fam.params}
        bad = [k for k in values if k not in by_name]
        if bad:
            raise ValueError(f"unknown parameter(s) {bad}; this surface has {sorted(by_name)}")
        merged = dict(self.values)
        merged.update({by_name[k]: x for k, x in values.items()})
        return _specialised(fam, merged)

    def _check_normal_hint(self, check_values):
        """Check p_u x p_v = orientation * area_factor * D numerically at random points."""
        rng = np.random.default_rng(0)
        cross = self.p.diff(self.u).cross(self.p.diff(self.v))
        free = [s for s in self.params if s not in check_values]
        for _ in range(3):
            sub = {s: float(x) for s, x in check_values.items()}
            sub.update({s: float(rng.uniform(0.6, 1.9)) for s in free})
            sub[self.u] = float(rng.uniform(0.1, 1.4))
            sub[self.v] = float(rng.uniform(0.1, 1.4))
            af = complex(self._area_factor.evalf(subs=sub)).real
            if af < 0:
                raise ValueError(
                    f"area_factor = {self._area_factor} is negative at {sub}; it must be >= 0 "
                    "on the domain (put the sign into orientation)"
                )
            lhs = np.array([complex(x.evalf(subs=sub)) for x in cross])
            rhs = np.array([complex((self._area_factor * d).evalf(subs=sub)) for d in self._D]) * self.orientation
            if not np.allclose(lhs, rhs, atol=1e-9 * (1 + np.abs(lhs).max())):
                raise ValueError(
                    f"normal_direction/area_factor/orientation do not reproduce p_u x p_v at {sub}: "
                    f"p_u x p_v = {lhs.real}, orientation*area_factor*D = {rhs.real}"
                )

    def _get(self, key, compute):
        """Cache; for family members take the family's result and substitute."""
        if key not in self._cache:
            if self._family is not None:
                val = self._family._get(key, getattr(self._family, "derive_" + key))
                self._cache[key] = self._substitute(val)
            else:
                self._cache[key] = compute()
        return self._cache[key]

    def _simplified(self, expr):
        """``_tidy(expr)``, or expr as it is on a surface made with ``simplify=False``."""
        return _tidy(expr) if self.simplify else sp.sympify(expr)

    def _substitute(self, val):
        return _subs_tidy(val, self.values)

    # ------------------------------------------------- the derivations (derive_*)
    # Each derive_X computes X from p(u, v) without the cache; the method X below
    # returns it cached (and, for a family member, substituted from the family's).
    # Everything is kept in the structured form
    #   p_u x p_v = orientation * area_factor * D,   W = |D| = sqrt(D.D),
    #   e = e_n / W  with e_n = -p_uu . D  (likewise f, g),
    #   EG - F^2 = area_factor^2 W^2,
    # so that only polynomials in sin/cos are simplified and sqrt(W^2) never
    # needs an Abs.
    def derive_tangents(self):
        return (self.p.diff(self.u), self.p.diff(self.v))

    def derive_first_fundamental_form(self):
        pu, pv = self.tangents()
        E, F, G = (self._simplified(x) for x in (pu.dot(pu), pu.dot(pv), pv.dot(pv)))
        return sp.Matrix([[E, F], [F, G]])

    def derive_normal_parts(self):
        """(D, D.D, area_factor): n = D/|D|, p_u x p_v = orientation * area_factor * D."""
        if self._D is None:
            pu, pv = self.tangents()
            D = (self.orientation * pu.cross(pv)).applyfunc(self._simplified)
            return D, self._simplified(D.dot(D)), sp.Integer(1)
        D = self._D.applyfunc(self._simplified)
        return D, self._simplified(D.dot(D)), self._area_factor

    def derive_unit_normal(self):
        D, DD, _ = self._normal_parts()
        return D / sp.sqrt(DD)

    def derive_second_numerators(self):
        """(e_n, f_n, g_n) = -(p_uu, p_uv, p_vv) . D: the second form times |D| (normal -n)."""
        D, _, _ = self._normal_parts()
        p, u, v = self.p, self.u, self.v
        return tuple(self._simplified(-_dot(p.diff(x, y), D)) for x, y in ((u, u), (u, v), (v, v)))

    def derive_second_fundamental_form(self):
        en, fn, gn = self._second_numerators()
        _, DD, _ = self._normal_parts()
        W = sp.sqrt(DD)
        return sp.Matrix([[en / W, fn / W], [fn / W, gn / W]])

    def derive_curvature_numerators(self):
        """(k_num, h_num): K = k_num / W^4, H = h_num / (2 W^3)."""
        en, fn, gn = self._second_numerators()
        _, DD, af = self._normal_parts()
        I = self.first_fundamental_form()
        E, F, G = I[0, 0], I[0, 1], I[1, 1]
        k_num = self._simplified(sp.cancel((en * gn - fn**2) / af**2))
        h_num = self._simplified(sp.cancel((en * G - 2 * fn * F + gn * E) / af**2))
        return (k_num, h_num)

    def derive_gaussian_curvature(self):
        k_num, _ = self._get("curvature_numerators", self.derive_curvature_numerators)
        _, DD, _ = self._normal_parts()
        return k_num / DD**2

    def derive_mean_curvature(self):
        _, h_num = self._get("curvature_numerators", self.derive_curvature_numerators)
        _, DD, _ = self._normal_parts()
        return h_num / (2 * DD ** sp.Rational(3, 2))

    def derive_principal_curvatures(self):
        # k = H +- sqrt(H^2 - K) = (h_num +- sqrt(h_num^2 - 4 k_num W^2)) / (2 W^3)
        k_num, h_num = self._get("curvature_numerators", self.derive_curvature_numerators)
        _, DD, _ = self._normal_parts()
        root = sp.sqrt(self._simplified(h_num**2 - 4 * k_num * DD))
        den = 2 * DD ** sp.Rational(3, 2)
        return ((h_num + root) / den, (h_num - root) / den)

    def derive_shape_operator(self):
        en, fn, gn = self._second_numerators()
        _, DD, af = self._normal_parts()
        I = self.first_fundamental_form()
        num = I.adjugate() * sp.Matrix([[en, fn], [fn, gn]])
        return num.applyfunc(lambda x: self._simplified(sp.cancel(x / af**2))) / DD ** sp.Rational(3, 2)

    def derive_area_element(self):
        _, DD, af = self._normal_parts()
        return af * sp.sqrt(DD)

    def derive_frame(self):
        """(t_u, w) = (p_u/|p_u|, (E p_v - F p_u) / (sqrt(E) sqrt(EG - F^2)))."""
        pu, pv = self.tangents()
        I = self.first_fundamental_form()
        E, F = I[0, 0], I[0, 1]
        _, DD, af = self._normal_parts()
        t_u = pu / sp.sqrt(E)
        wn = (E * pv - F * pu).applyfunc(lambda x: self._simplified(sp.cancel(x / af)))
        return (t_u, wn / (sp.sqrt(E) * sp.sqrt(DD)))

    def derive_frame_coefficients(self):
        """(L11, L12, L22): the shape operator L (= II) in the orthonormal frame (p_u/|p_u|, w).

        kappa_n(phi) = L11 cos^2 phi + 2 L12 sin phi cos phi + L22 sin^2 phi, with
        L11 = e/E, L12 = (fE - eF)/(E sqrt(EG - F^2)), L22 = (eF^2 - 2fFE + gE^2)/(E (EG - F^2)).
        """
        en, fn, gn = self._second_numerators()
        _, DD, af = self._normal_parts()
        I = self.first_fundamental_form()
        E, F = I[0, 0], I[0, 1]
        W = sp.sqrt(DD)
        L11 = self._simplified(sp.cancel(en / E)) / W
        L12 = self._simplified(sp.cancel((fn * E - en * F) / (E * af))) / DD
        L22 = self._simplified(sp.cancel((en * F**2 - 2 * fn * F * E + gn * E**2) / (E * af**2))) / W**3
        return (L11, L12, L22)

    # ------------------------------------------------------ public, symbolic
    def tangents(self):
        """(p_u, p_v): the coordinate tangents as 3x1 sympy matrices (length units)."""
        return self._get("tangents", self.derive_tangents)

    def first_fundamental_form(self):
        """I = [[E, F], [F, G]], E = p_u.p_u, F = p_u.p_v, G = p_v.p_v (length^2), 2x2 sympy Matrix."""
        return self._get("first_fundamental_form", self.derive_first_fundamental_form)

    def _normal_parts(self):
        return self._get("normal_parts", self.derive_normal_parts)

    def _second_numerators(self):
        return self._get("second_numerators", self.derive_second_numerators)

    def unit_normal(self):
        """n: unit normal, outward on closed surfaces (3x1 sympy Matrix, dimensionless).

        The second fundamental form uses -n (see the module docstring).
        """
        return self._get("unit_normal", self.derive_unit_normal)

    def second_fundamental_form(self):
        """II = [[e, f], [f, g]] with e = -p_uu . n, n = unit_normal() (length), 2x2 sympy Matrix.

        Positive on a sphere / ellipsoid: a sphere of radius r has II = I / r.
        """
        return self._get("second_fundamental_form", self.derive_second_fundamental_form)

    def shape_operator(self):
        """L = I^-1 II (1/length), acting on coordinate vectors (du, dv); eigenvalues k1, k2."""
        return self._get("shape_operator", self.derive_shape_operator)

    def area_element(self):
        """sqrt(EG - F^2) = |p_u x p_v| (length^2 per unit parameter area)."""
        return self._get("area_element", self.derive_area_element)

    def gaussian_curvature(self):
        """K = (eg - f^2) / (EG - F^2) = k1 k2, pointwise, 1/length^2 (1/r^2 on a sphere)."""
        return self._get("gaussian_curvature", self.derive_gaussian_curvature)

    def mean_curvature(self):
        """H = (eG - 2fF + gE) / (2 (EG - F^2)) = (k1 + k2)/2, pointwise, 1/length (+1/r on a sphere)."""
        return self._get("mean_curvature", self.derive_mean_curvature)

    def frame_coefficients(self):
        """(L11, L12, L22) with kappa_n(phi) = L11 cos^2 phi + 2 L12 sin phi cos phi + L22 sin^2 phi (1/length).

        L11 = kappa_n(0) (direction p_u), L22 = kappa_n(pi/2), L12 the twist; the
        second fundamental form written in the orthonormal frame (p_u/|p_u|, w).
        """
        return self._get("frame_coefficients", self.derive_frame_coefficients)

    def _at(self, expr, u, v):
        """expr (this surface's, or a tuple/matrix of them) at (u, v), simplified."""
        if u is None and v is None:
            return expr
        sub = {}
        if u is not None:
            sub[self.u] = sp.sympify(u)
        if v is not None:
            sub[self.v] = sp.sympify(v)
        return _subs_tidy(expr, sub)

    def _point(self, key, u, v):
        """A cached family result at (u, v) with this surface's values, substituted once."""
        if u is None and v is None:
            return self._get(key, getattr(self, "derive_" + key))
        ckey = ("at", key, sp.sympify(u) if u is not None else None, sp.sympify(v) if v is not None else None)
        if ckey not in self._cache:
            src = self._family or self
            sub = dict(self.values)
            if u is not None:
                sub[self.u] = sp.sympify(u)
            if v is not None:
                sub[self.v] = sp.sympify(v)
            self._cache[ckey] = _subs_tidy(src._get(key, getattr(src, "derive_" + key)), sub)
        return self._cache[ckey]

    def normal_curvature(self, phi, u=None, v=None):
        """kappa_n(phi) = II(t, t) at (u, v), t = cos phi p_u/|p_u| + sin phi w (1/length).

        ``phi`` (radians, a number or sympy expression) is measured from p_u,
        towards p_v: w is p_u/|p_u| turned by +90 degrees about
        m = p_u x p_v / |p_u x p_v| (module docstring). ``u``, ``v`` default to
        the surface's symbols. Positive where the surface bends away from the
        unit normal n (a sphere of radius r: 1/r for every phi).
        """
        L11, L12, L22 = self._point("frame_coefficients", u, v)
        phi = sp.sympify(phi)
        expr = L11 * sp.cos(phi) ** 2 + 2 * L12 * sp.sin(phi) * sp.cos(phi) + L22 * sp.sin(phi) ** 2
        if u is None and v is None:
            return expr
        return _tidy(expr)

    def principal_curvatures(self, u=None, v=None):
        """(k1, k2), k1 >= k2: H +- sqrt(H^2 - K) (1/length), at (u, v) or as functions of u, v.

        At a point the values are computed from the frame coefficients:
        H = (L11 + L22)/2, sqrt(H^2 - K) = sqrt(((L11 - L22)/2)^2 + L12^2).
        """
        if u is None and v is None:
            return self._get("principal_curvatures", self.derive_principal_curvatures)
        L11, L12, L22 = self._point("frame_coefficients", u, v)
        H = _tidy((L11 + L22) / 2)
        R = _tidy(sp.sqrt(((L11 - L22) / 2) ** 2 + L12**2))
        return (_tidy(H + R), _tidy(H - R))

    def principal_directions(self, u, v):
        """Principal directions at (u, v): ((phi1, d1), (phi2, d2)) for k1 >= k2.

        phi1 = atan2(2 L12, L11 - L22) / 2 in the frame (p_u/|p_u|, w), phi2 = phi1 -+ pi/2
        (both angles in (-pi/2, pi/2]);
        d1, d2 are unit 3-vectors (3x1 sympy matrices). At an umbilic
        (L11 = L22, L12 = 0) every direction is principal and phi1 = 0 is returned.
        """
        L11, L12, L22 = self._point("frame_coefficients", u, v)
        diff = _tidy(L11 - L22)
        if _tidy(L12) == 0:
            # the frame is principal; which of t_u, w has the larger curvature?
            if diff.is_nonnegative:
                phi1 = sp.Integer(0)
            elif diff.is_negative:
                phi1 = sp.pi / 2
            else:
                phi1 = sp.Piecewise((sp.Integer(0), diff >= 0), (sp.pi / 2, True))
        else:
            phi1 = _tidy(sp.atan2(2 * L12, diff) / 2)
        # the second direction at phi1 -+ pi/2, whichever lies in (-pi/2, pi/2]
        if isinstance(phi1, sp.Piecewise):
            phi2 = sp.Piecewise((sp.pi / 2, diff >= 0), (sp.Integer(0), True))
        else:
            nonpositive = sp.simplify(phi1) <= 0
            if nonpositive in (sp.true, sp.false):
                phi2 = phi1 + sp.pi / 2 if nonpositive == sp.true else phi1 - sp.pi / 2
            else:
                phi2 = sp.Piecewise((phi1 + sp.pi / 2, nonpositive), (phi1 - sp.pi / 2, True))
        t_u, w = self.frame(u, v)
        out = []
        for phi in (phi1, phi2):
            d = (sp.cos(phi) * t_u + sp.sin(phi) * w).applyfunc(_tidy)
            out.append((_tidy(phi), d))
        return tuple(out)

    def frame(self, u=None, v=None):
        """(t_u, w): the orthonormal tangent frame phi is measured in (3x1 sympy matrices).

        t_u = p_u/|p_u|; w = m x t_u with m = p_u x p_v / |p_u x p_v|, i.e. the unit
        tangent perpendicular to p_u on the side of p_v.
        """
        return self._point("frame", u, v)

    def position(self, u=None, v=None):
        """p(u, v) as a 3x1 sympy Matrix."""
        return self._at(self.p, u, v)

    # ------------------------------------------------------------- numerics
    def _family_symbolic(self, name):
        fam = self._family or self
        if name == "position":
            return list(fam.p)
        if name == "p_u":
            return list(fam.tangents()[0])
        if name == "p_v":
            return list(fam.tangents()[1])
        if name in ("unit_normal",):
            return list(fam.unit_normal())
        if name in ("first_fundamental_form", "second_fundamental_form", "shape_operator"):
            return list(getattr(fam, name)())
        if name in ("gaussian_curvature", "mean_curvature", "area_element"):
            return [getattr(fam, name)()]
        if name == "frame_coefficients":
            return list(fam.frame_coefficients())
        if name == "frame":
            t_u, w = fam.frame()
            return list(t_u) + list(w)
        raise ValueError(f"unknown quantity {name!r}; lambdify knows {sorted(LAMBDIFY_NAMES)}")

    def _compiled(self, name):
        """numpy function of (u, v, *params) returning a list of component arrays (family-wide)."""
        fam = self._family or self
        if name not in fam._lambdified:
            exprs = self._family_symbolic(name)
            f = sp.lambdify((fam.u, fam.v, *fam.params), exprs, modules="numpy", cse=True)
            fam._lambdified[name] = f
        return fam._lambdified[name]

    def lambdify(self, name):
        """A vectorised numpy function of (u, v) for one of LAMBDIFY_NAMES.

        Arguments broadcast like numpy arrays (radians); results are float64 of
        the broadcast shape ``s``: scalars ``s``, vectors ``s + (3,)``, 2x2 forms
        ``s + (2, 2)``; "principal_curvatures" returns ``(k1, k2)`` with
        ``k1 >= k2``; "principal_directions" ``(d1, d2)`` unit vectors;
        "normal_curvature" takes ``(u, v, phi)``. Parameters that have no
        value are extra trailing arguments in the order of ``self.params``.
        """
        if name not in LAMBDIFY_NAMES:
            raise ValueError(f"unknown quantity {name!r}; lambdify knows {sorted(LAMBDIFY_NAMES)}")
        fam = self._family or self
        bound = []
        for s in fam.params:
            if s in self.values:
                val = self.values[s]
                if not val.is_number:
                    raise ValueError(f"parameter {s} = {val} is not a number; give numbers to lambdify")
                bound.append(float(val))
            else:
                bound.append(None)
        nfree = sum(b is None for b in bound)

        def args(rest):
            if len(rest) != nfree:
                free = [str(s) for s, b in zip(fam.params, bound) if b is None]
                raise TypeError(f"{name}: expected u, v" + "".join(", " + f for f in free))
            it = iter(rest)
            return [next(it) if b is None else b for b in bound]

        def evaluate(qname, u, v, rest):
            u = np.asarray(u, dtype=float)
            v = np.asarray(v, dtype=float)
            prm = args(rest)
            shape = np.broadcast_shapes(u.shape, v.shape, *(np.shape(x) for x in prm))
            comps = self._compiled(qname)(u, v, *prm)
            return [np.broadcast_to(np.asarray(c, dtype=float), shape) for c in comps], shape

        if name in ("position", "p_u", "p_v", "unit_normal"):

            def f(u, v, *rest):
                comps, shape = evaluate(name, u, v, rest)
                return np.stack(comps, axis=-1)
        elif name in ("first_fundamental_form", "second_fundamental_form", "shape_operator"):

            def f(u, v, *rest):
                comps, shape = evaluate(name, u, v, rest)
                return np.stack(comps, axis=-1).reshape(shape + (2, 2))
        elif name in ("gaussian_curvature", "mean_curvature", "area_element"):

            def f(u, v, *rest):
                comps, shape = evaluate(name, u, v, rest)
                return np.array(comps[0])
        elif name == "principal_curvatures":

            def f(u, v, *rest):
                (L11, L12, L22), _ = evaluate("frame_coefficients", u, v, rest)
                H = 0.5 * (L11 + L22)
                R = np.hypot(0.5 * (L11 - L22), L12)
                return H + R, H - R
        elif name == "principal_directions":

            def f(u, v, *rest):
                u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
                # Where the parameterisation is singular (p_u or p_v = 0, e.g. the
                # ellipsoid's poles) the frame p_u/|p_u| is undefined: evaluate at v
                # moved by 1e-8 into the domain. Principal directions are continuous
                # away from umbilics, so this is their value at the point to ~1e-8.
                pu = np.stack(evaluate("p_u", u, v, rest)[0], axis=-1)
                pv = np.stack(evaluate("p_v", u, v, rest)[0], axis=-1)
                E = np.einsum("...i,...i->...", pu, pu)
                G = np.einsum("...i,...i->...", pv, pv)
                bad = (E <= 1e-20 * (E + G)) | (G <= 1e-20 * (E + G))
                if np.any(bad):
                    v = v.copy()
                    step = 1e-8 * np.maximum(1.0, np.abs(v[bad]))
                    up = evaluate("area_element", u[bad], v[bad] + step, rest)[0][0]
                    down = evaluate("area_element", u[bad], v[bad] - step, rest)[0][0]
                    v[bad] = np.where(np.abs(up) >= np.abs(down), v[bad] + step, v[bad] - step)
                (L11, L12, L22), _ = evaluate("frame_coefficients", u, v, rest)
                comps, _ = evaluate("frame", u, v, rest)
                t_u = np.stack(comps[:3], axis=-1)
                w = np.stack(comps[3:], axis=-1)
                phi1 = 0.5 * np.arctan2(2 * L12, L11 - L22)[..., None]
                d1 = np.cos(phi1) * t_u + np.sin(phi1) * w
                d2 = -np.sin(phi1) * t_u + np.cos(phi1) * w
                return d1, d2
        else:  # normal_curvature

            def f(u, v, phi, *rest):
                (L11, L12, L22), _ = evaluate("frame_coefficients", u, v, rest)
                phi = np.asarray(phi, dtype=float)
                c, s = np.cos(phi), np.sin(phi)
                return L11 * c * c + 2 * L12 * s * c + L22 * s * s

        f.__name__ = name
        f.__doc__ = f"{name} of {self!r}: {LAMBDIFY_NAMES[name]}"
        return f


# ---------------------------------------------------------------- constructors
_U, _V = sp.symbols("u v", real=True)


@functools.lru_cache(maxsize=None)
def _ellipsoid_family(simplify=True):
    a, b, c = sp.symbols("a b c", positive=True)
    u, v = _U, _V
    p = (a * sp.cos(u) * sp.sin(v), b * sp.sin(u) * sp.sin(v), c * sp.cos(v))
    # p_u x p_v = -sin(v) * (bc cos u sin v, ac sin u sin v, ab cos v): inward for 0 < v < pi
    D = (b * c * sp.cos(u) * sp.sin(v), a * c * sp.sin(u) * sp.sin(v), a * b * sp.cos(v))
    return ParametricSurface(
        p,
        u,
        v,
        params=(a, b, c),
        normal_direction=D,
        area_factor=sp.sin(v),
        orientation=-1,
        domain=((0, 2 * sp.pi), (0, sp.pi)),
        name="ellipsoid",
        closed=True,
        simplify=simplify,
    )


def _member(family, args):
    vals = dict(zip(family.params, (_exact(x) for x in args)))
    for s, x in vals.items():
        if x.is_number and not (x.is_positive):
            raise ValueError(f"{family.name}: parameter {s} must be positive, got {x}")
    if all(vals[s] == s for s in family.params):
        return family
    return _specialised(family, vals)


def _specialised(family, values):
    """The member of ``family`` with its parameters set to ``values`` (shares the family's cache)."""
    return ParametricSurface(
        None,
        family.u,
        family.v,
        params=family.params,
        values=values,
        orientation=family.orientation,
        name=family.name,
        closed=family.closed,
        _family=family,
    )


def ellipsoid(a, b, c, simplify=True):
    """Ellipsoid p(u, v) = (a cos u sin v, b sin u sin v, c cos v), u in [0, 2 pi), v in [0, pi].

    ``a, b, c`` > 0 are numbers or sympy expressions (assumed positive). The
    unit normal is the outward one, ``(x/a^2, y/b^2, z/c^2)`` normalised; note
    that ``p_u x p_v = -sin v (bc cos u sin v, ac sin u sin v, ab cos v)``
    points inward, and the second fundamental form uses exactly that inward
    direction, so every curvature is positive. ``v`` is the polar angle from
    the +z axis (v = 0 north pole, where p_u = 0: the parameterisation is
    singular at v = 0 and v = pi).
    """
    return _member(_ellipsoid_family(simplify), (a, b, c))


def ellipsoid_forms(a, b, c, u, v):
    """(I, II) of the ellipsoid p(u, v) = (a cos u sin v, b sin u sin v, c cos v): two 2x2 sympy matrices.

    The derivation of notebook 02 written out, as a learner writes it (the
    reference of its exercise): I = [[E, F], [F, G]] in length^2 from the
    tangents, II = [[e, f], [f, g]] in length from the second derivatives and
    the unit normal p_u x p_v / |p_u x p_v|, which on this parameterisation is
    the inward normal -n (module docstring). ``a, b, c, u, v`` are numbers or
    sympy symbols; nothing is simplified. ``ellipsoid(a, b, c)`` derives the
    same forms, kept short for the general ellipsoid.
    """
    s, t = sp.symbols("u v", real=True)  # differentiate in symbols, then put (u, v) in: they may be numbers
    p = sp.Matrix([a * sp.cos(s) * sp.sin(t), b * sp.sin(s) * sp.sin(t), c * sp.cos(t)])
    p_u, p_v = p.diff(s), p.diff(t)
    m = p_u.cross(p_v)
    minus_n = m / sp.sqrt(m.dot(m))
    I = sp.Matrix([[p_u.dot(p_u), p_u.dot(p_v)], [p_v.dot(p_u), p_v.dot(p_v)]])
    p_uu, p_uv, p_vv = p.diff(s, s), p.diff(s, t), p.diff(t, t)
    II = sp.Matrix([[p_uu.dot(minus_n), p_uv.dot(minus_n)], [p_uv.dot(minus_n), p_vv.dot(minus_n)]])
    at = {s: sp.sympify(u), t: sp.sympify(v)}
    return I.subs(at, simultaneous=True), II.subs(at, simultaneous=True)


def forms_principal_curvatures(I, II):
    """(kappa_1, kappa_2), kappa_1 >= kappa_2: the eigenvalues of the shape operator L = I^-1 II, in 1/length.

    ``I``, ``II``: 2x2 sympy matrices (expressions in any symbols, or numbers), II with the normal
    the curvatures are signed by. L is similar to the symmetric I^-1/2 II I^-1/2 (I is positive
    definite), so its eigenvalues are real: with H = tr(L) / 2 and K = det L = det II / det I they are
    H +- sqrt(H^2 - K), and H^2 - K = (kappa_1 - kappa_2)^2 / 4 >= 0. Equal at an umbilic. sympy
    expressions, simplified.
    """
    I, II = sp.Matrix(I), sp.Matrix(II)
    L = I.adjugate() * II / I.det()  # I^-1 II without a division inside the inverse
    H = sp.simplify(L.trace() / 2)
    K = sp.simplify(II.det() / I.det())
    root = sp.sqrt(sp.simplify(H**2 - K))
    return H + root, H - root


def unit_tangent(E, F, G, phi):
    """(du, dv): the unit tangent t = du p_u + dv p_v at angle ``phi`` (radians) from p_u, towards p_v.

    ``t = cos phi p_u / |p_u| + sin phi w`` with ``w`` the unit tangent perpendicular to p_u on the side
    of p_v (module docstring). From I alone: ``|p_u| = sqrt(E)``, ``|p_u x p_v| = sqrt(EG - F^2)`` and
    ``w = (E p_v - F p_u) / (sqrt(E) sqrt(EG - F^2))`` (then ``w . p_u = 0``, ``w . p_v > 0``, ``|w| = 1``).
    Numbers or numpy arrays; where F = 0 it is (cos phi / sqrt(E), sin phi / sqrt(G)).
    """
    root_E, area = np.sqrt(E), np.sqrt(E * G - F**2)
    return np.cos(phi) / root_E - np.sin(phi) * F / (root_E * area), np.sin(phi) * root_E / area


def ellipsoid_normal_curvature(a, b, c, phi, u=0.0, v=math.pi / 2):
    """kappa_n(phi) = II(t, t) of ``ellipsoid(a, b, c)`` at (u, v), by default the point (a, 0, 0), in 1/length.

    ``t`` is the unit tangent at angle ``phi`` (radians) from p_u, towards p_v
    (:func:`unit_tangent`), written in coordinates (du, dv): t = du p_u + dv p_v with
    I(t, t) = 1. At (a, 0, 0), I = diag(b^2, c^2), II = diag(a, a) and
    (du, dv) = (cos phi / b, sin phi / c), so kappa_n = a cos^2 phi / b^2 + a sin^2 phi / c^2.
    Numbers or numpy arrays in, float64 out (the forms are compiled once per family).
    """
    ell = ellipsoid(a, b, c)
    I, II = ell.lambdify("first_fundamental_form")(u, v), ell.lambdify("second_fundamental_form")(u, v)
    du, dv = unit_tangent(I[..., 0, 0], I[..., 0, 1], I[..., 1, 1], phi)
    return II[..., 0, 0] * du**2 + 2 * II[..., 0, 1] * du * dv + II[..., 1, 1] * dv**2


def forms_normal_curvature(forms, a, b, c, u, v, phi):
    """kappa_n(phi) = II(t, t) / I(t, t) at p(u, v), from the fundamental forms ``forms`` derives, in 1/length.

    ``forms(a, b, c, u, v)`` returns ``E, F, G, e, f, g`` (or the pair of 2x2 matrices ``I, II``) as
    sympy expressions in the symbols it is given, like notebook 02's exercise and :func:`ellipsoid_forms`:
    the surface's forms, with ``e, f, g`` taken against -n (module docstring). They are evaluated at the
    numbers ``a, b, c, u, v``; ``t`` is the unit tangent at angle ``phi`` (radians, a number or an
    array) from p_u towards p_v (:func:`unit_tangent`). Notebook 02 feeds it the learner's own forms.
    """
    E, F, G, e, f, g = (float(x) for x in _forms_at(forms, (a, b, c, u, v)))
    du, dv = unit_tangent(E, F, G, phi)
    II_tt = e * du**2 + 2 * f * du * dv + g * dv**2
    I_tt = E * du**2 + 2 * F * du * dv + G * dv**2  # 1 up to rounding: t is a unit vector
    return II_tt / I_tt


def _forms_at(forms, values):
    """The six coefficients E, F, G, e, f, g of ``forms`` (6 expressions, or the matrices I, II) at ``values``."""
    symbols = sp.symbols("a b c u v", real=True)
    out = forms(*symbols)
    if len(out) == 2:
        I, II = (sp.Matrix(X) for X in out)
        out = (I[0, 0], I[0, 1], I[1, 1], II[0, 0], II[0, 1], II[1, 1])
    at = dict(zip(symbols, (sp.Float(x) for x in values)))
    return [sp.sympify(x).evalf(subs=at) for x in out]


@functools.lru_cache(maxsize=None)
def _sphere_family():
    r = sp.symbols("r", positive=True)
    u, v = _U, _V
    p = (r * sp.cos(u) * sp.sin(v), r * sp.sin(u) * sp.sin(v), r * sp.cos(v))
    D = (sp.cos(u) * sp.sin(v), sp.sin(u) * sp.sin(v), sp.cos(v))
    return ParametricSurface(
        p,
        u,
        v,
        params=(r,),
        normal_direction=D,
        area_factor=r**2 * sp.sin(v),
        orientation=-1,
        domain=((0, 2 * sp.pi), (0, sp.pi)),
        name="sphere",
        closed=True,
    )


def sphere(r=1):
    """Sphere of radius r, parameterised as the ellipsoid with a = b = c = r.

    Outward unit normal; every normal curvature 1/r, H = 1/r, K = 1/r^2.
    """
    return _member(_sphere_family(), (r,))


@functools.lru_cache(maxsize=None)
def _torus_family(simplify=True):
    R, r = sp.symbols("R r", positive=True)
    u, v = _U, _V
    rho = R + r * sp.cos(v)
    p = (rho * sp.cos(u), rho * sp.sin(u), r * sp.sin(v))
    D = (sp.cos(u) * sp.cos(v), sp.sin(u) * sp.cos(v), sp.sin(v))
    return ParametricSurface(
        p,
        u,
        v,
        params=(R, r),
        normal_direction=D,
        area_factor=r * rho,
        orientation=1,
        domain=((0, 2 * sp.pi), (0, 2 * sp.pi)),
        name="torus",
        closed=True,
        check_values={R: 2.0, r: 0.7},
        simplify=simplify,
    )


def torus(R=2, r=sp.Rational(1, 2), simplify=True):
    """Torus ((R + r cos v) cos u, (R + r cos v) sin u, r sin v), R > r > 0, u, v in [0, 2 pi).

    p_u x p_v = r (R + r cos v) (cos u cos v, sin u cos v, sin v) is outward.
    K = cos v / (r (R + r cos v)): 1/(r (R + r)) on the outer equator (v = 0),
    -1/(r (R - r)) on the inner one (v = pi).
    """
    Rv, rv = _exact(R), _exact(r)
    if Rv.is_number and rv.is_number and not (Rv > rv):
        raise ValueError(f"torus needs R > r (a ring torus), got R={R}, r={r}")
    return _member(_torus_family(simplify), (Rv, rv))


@functools.lru_cache(maxsize=None)
def _helicoid_family():
    c = sp.symbols("c", positive=True)
    u, v = _U, _V
    p = (u * sp.cos(v), u * sp.sin(v), c * v)
    return ParametricSurface(p, u, v, params=(c,), domain=((-1, 1), (0, 2 * sp.pi)), name="helicoid", closed=False)


def helicoid(c=1):
    """Helicoid (u cos v, u sin v, c v), a minimal surface: H = 0, K = -c^2/(c^2 + u^2)^2.

    Open; the unit normal is n = p_u x p_v / |p_u x p_v| = (c sin v, -c cos v, u)/sqrt(c^2+u^2).
    """
    return _member(_helicoid_family(), (c,))


def monge(h, x=None, y=None, domain=((-1, 1), (-1, 1)), name="monge patch", simplify=True):
    """Monge patch p(x, y) = (x, y, h(x, y)) (the graph of h; x, y are the parameters u, v).

    Open; the unit normal is the upward one, n = (-h_x, -h_y, 1)/sqrt(1 + h_x^2 + h_y^2)
    (= p_u x p_v / |p_u x p_v|), and with the sign convention of this module
    (second form with -n) a cup z = (x^2 + y^2)/2 has H = -1 at the origin,
    as the discrete ``Delta x = -2 H n`` gives with upward mesh normals.
    Use ``monge(-h)`` mirrored, or flip the mesh, for the other side.
    ``h`` is a sympy expression in the symbols ``x`` and ``y`` (default: the
    symbols named "x" and "y" found in h, declared real).
    """
    h = sp.sympify(h)
    if x is None or y is None:
        names = {s.name: s for s in h.free_symbols}
        x = x if x is not None else names.get("x", sp.Symbol("x", real=True))
        y = y if y is not None else names.get("y", sp.Symbol("y", real=True))
    return ParametricSurface((x, y, h), x, y, domain=domain, name=name, closed=False, simplify=simplify)


def saddle(k=1):
    """The saddle z = k (x^2 - y^2): at the origin K = -4 k^2, H = 0."""
    x, y = sp.symbols("x y", real=True)
    return monge(_exact(k) * (x**2 - y**2), x, y, name="saddle")
