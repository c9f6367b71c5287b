"""Analytic surfaces as triangle meshes with exact per-vertex truth.

Convention: every mesh is returned as an :class:`AnalyticMesh` with ``V``
(n, 3) float64 and ``F`` (m, 3) int64, triangles counter-clockwise seen from
outside (closed surfaces) or from +z (height fields), and the exact differential
geometry of the smooth surface at every vertex: unit normal ``N`` (outward,
or upward for height fields), mean curvature ``H``, Gaussian curvature ``K`` and
principal curvatures ``k1 >= k2``, with the workbook's sign: ``H > 0`` and
``k1, k2 > 0`` on a sphere with outward normals, ``H = (k1 + k2) / 2``,
``K = k1 k2``. So the discrete ``Delta x = -2 H n`` of geomlib.laplacian is
compared with these values directly. Curvatures are pointwise (1/length for
``H``, ``k1``, ``k2``, 1/length^2 for ``K``), not integrated over vertex areas.

Every vertex lies on the exact surface (to rounding): a jittered (irregular)
tessellation moves points along the surface, by jittering in the parameter
domain and evaluating the parametrisation again (grids), or by moving in the
tangent plane of the unit sphere and projecting back before the map
``(x, y, z) -> (a x, b y, c z)`` (icosphere-based meshes). Jitter is seeded
(``seed``, numpy ``default_rng``), so the same arguments give the same mesh.

Resolution: ``subdivisions`` (icosphere) halves the edge length per step; the
grid sizes ``n`` of the grid-based surfaces can be doubled (``n`` counts
intervals, so ``2 n`` halves every edge). This is what a convergence study needs.

Where the truth comes from: one source, :mod:`geomlib.lessons.symbolic`. For the
ellipsoid, torus and saddle, ``N``, ``H``, ``K``, ``k1``, ``k2`` are the sympy
expressions of ``geomlib.lessons.symbolic.ellipsoid(a, b, c)``, ``torus(R, r)`` and
``monge(h, x, y)``, compiled with their ``lambdify`` and evaluated at each
vertex's parameters ``uv`` (the ellipsoid's expressions stay finite at the
poles). The sphere and the plane are the trivial cases ``H = 1/r`` and
``H = K = 0``. The truth is computed on first access to ``N``, ``H``, ...:
compiling a surface family takes a few seconds once per process, and a mesh
that is only written to a file does not pay for it. The tests check the
values against closed forms derived independently.

Functions: :func:`plane`, :func:`saddle`, :func:`sphere` (icosphere),
:func:`uv_sphere`, :func:`ellipsoid` (mapped icosphere), :func:`uv_ellipsoid`,
:func:`torus`, and :func:`attach_truth` for vertices read from a file (for
instance ``geomlib/meshes/ellipsoid.obj``).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Callable, Mapping

import numpy as np

from ...mesh.errors import MeshError, format_indices
from ...mesh.geometry import face_cross, zero_area_faces
from ...mesh.validate import check_choice, real_number, whole_number

__all__ = [
    "AnalyticMesh",
    "plane",
    "saddle",
    "saddle_height",
    "sphere",
    "uv_sphere",
    "ellipsoid",
    "uv_ellipsoid",
    "torus",
    "attach_truth",
    "icosphere",
    "grid_faces",
]


# ----------------------------------------------------------------------------
# the result object
# ----------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class AnalyticMesh:
    """A triangle mesh of an analytic surface with exact per-vertex truth.

    Convention: faces counter-clockwise seen from outside (from +z for height
    fields); ``N`` outward (upward); ``H > 0``, ``k1, k2 > 0`` on a sphere;
    ``H = (k1 + k2) / 2``, ``K = k1 k2``, ``k1 >= k2``; pointwise values.

    Attributes
    ----------
    name : str
        Surface name ("plane", "saddle", "sphere", "ellipsoid", "torus").
    params : mapping
        The arguments that made the mesh (radii, resolution, jitter, seed).
    V : (n, 3) float64
        Vertex positions, on the exact surface to rounding.
    F : (m, 3) int64
        Triangles, 0-based, CCW seen from outside / from +z.
    N : (n, 3) float64
        Exact unit normal at each vertex (outward, or upward for a height field).
    H, K : (n,) float64
        Exact mean (1/length) and Gaussian (1/length^2) curvature.
    k1, k2 : (n,) float64
        Exact principal curvatures, ``k1 >= k2``.
    uv : (n, 2) float64 or None
        Parameter values of each vertex (see the surface's function for the
        parametrisation), None where the surface has no global parametrisation.
    closed : bool
        True when every edge is shared by exactly two faces.
    area, volume : float or None
        Exact area and enclosed volume of the smooth surface (None if not known
        in closed form or not enclosed).
    truth : callable
        Returns (N, H, K, k1, k2); called once, on the first access to any of
        them (so a mesh that is only written to a file never compiles the
        symbolic expressions). The values are kept.

    The arrays belong to the object: copy them before changing them in place.
    """

    name: str
    params: Mapping[str, object]
    V: np.ndarray
    F: np.ndarray
    uv: np.ndarray | None
    closed: bool
    area: float | None = None
    volume: float | None = None
    truth: Callable[[], tuple] | None = field(default=None, repr=False, compare=False)

    @functools.cached_property
    def _values(self):
        n = self.V.shape[0]
        N, H, K, k1, k2 = self.truth()
        out = {}
        for key, val, shape in (("N", N, (n, 3)), ("H", H, (n,)), ("K", K, (n,)), ("k1", k1, (n,)), ("k2", k2, (n,))):
            a = np.ascontiguousarray(np.broadcast_to(np.asarray(val, dtype=np.float64), shape))
            if not np.isfinite(a).all():  # a chart singularity would show up here, never silently
                bad = np.flatnonzero(~np.isfinite(a.reshape(n, -1)).all(axis=1))
                raise MeshError(f"{self.name}: exact {key} is not finite at vertices {format_indices(bad)}")
            out[key] = a
        return out

    # the exact values, computed together on the first access to any of them
    N = property(lambda self: self._values["N"], doc="(n, 3) exact outward (upward) unit normal")
    H = property(lambda self: self._values["H"], doc="(n,) exact mean curvature (1/length)")
    K = property(lambda self: self._values["K"], doc="(n,) exact Gaussian curvature (1/length^2)")
    k1 = property(lambda self: self._values["k1"], doc="(n,) exact larger principal curvature (1/length)")
    k2 = property(lambda self: self._values["k2"], doc="(n,) exact smaller principal curvature (1/length)")

    @property
    def n_vertices(self) -> int:
        return int(self.V.shape[0])

    @property
    def n_faces(self) -> int:
        return int(self.F.shape[0])

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.params.items())
        kind = "closed" if self.closed else "open"
        return f"AnalyticMesh({self.name}({args}): {self.n_vertices} vertices, {self.n_faces} faces, {kind})"


# ----------------------------------------------------------------------------
# argument checks
# ----------------------------------------------------------------------------


def _positive(name, value):
    return real_number(name, value, 0, strict=True, why=" (a positive length)")


def _count(name, value, minimum, maximum=2048):
    """An integer resolution in [minimum, maximum]; the upper bound keeps a
    typo (subdivisions=12: 168 million vertices) from exhausting memory."""
    return whole_number(name, value, minimum, maximum, why=" (a resolution: more would be too many vertices)")


def _jitter(value):
    return real_number("jitter", value, 0, below=0.5, why=" (a fraction of the local edge length, in [0, 0.5))")


def _rng(seed):
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, (int, np.integer))):
        raise MeshError(f"seed must be an integer or None, got {seed!r}")
    return np.random.default_rng(seed)


# ----------------------------------------------------------------------------
# mesh helpers
# ----------------------------------------------------------------------------


def _check_faces(V, F, D, what):
    """Raise MeshError on zero-area faces or faces that disagree with D.

    ``D`` (n, 3) is a direction on the outer (upper) side at each vertex. A
    face is inverted when its normal points against the sum of ``D`` over its
    three vertices; this happens only when the jitter folds the tessellation
    over, and is reported rather than repaired.
    """
    bad = zero_area_faces(V, F)
    if bad.size:
        raise MeshError(f"{what}: zero-area faces {format_indices(bad)}")
    s = np.einsum("ij,ij->i", face_cross(V, F), D[F].sum(axis=1))
    bad = np.flatnonzero(s <= 0)
    if bad.size:
        raise MeshError(f"{what}: inverted faces {format_indices(bad)} (jitter too large for this resolution)")


def grid_faces(nu, nv, periodic_u=False, periodic_v=False, diagonals="right"):
    """Triangles of an nu x nv vertex grid, vertex index i * nv + j.

    Each quad (i, j), (i+1, j), (i+1, j+1), (i, j+1) is counter-clockwise when
    u grows along the first and v along the second axis of a right-handed
    frame; it is split by the diagonal (i, j)-(i+1, j+1) ("right"), or
    alternately by both diagonals in a checkerboard ("alternate").
    """
    iu = np.arange(nu if periodic_u else nu - 1)
    jv = np.arange(nv if periodic_v else nv - 1)
    I, J = np.meshgrid(iu, jv, indexing="ij")
    I, J = I.ravel(), J.ravel()
    I1 = (I + 1) % nu
    J1 = (J + 1) % nv
    a = I * nv + J
    b = I1 * nv + J
    c = I1 * nv + J1
    d = I * nv + J1
    check_choice("diagonals", diagonals, ("right", "alternate"))
    flip = (I + J) % 2 == 1 if diagonals == "alternate" else np.zeros(a.shape, dtype=bool)
    t1 = np.where(flip[:, None], np.stack([a, b, d], 1), np.stack([a, b, c], 1))
    t2 = np.where(flip[:, None], np.stack([b, c, d], 1), np.stack([a, c, d], 1))
    F = np.empty((2 * a.size, 3), dtype=np.int64)
    F[0::2] = t1
    F[1::2] = t2
    return F


def _grid_jitter(rng, shape, jitter, fixed_u=None, fixed_v=None):
    """Offsets in grid steps, uniform in a disc of radius ``jitter``.

    ``fixed_u`` / ``fixed_v``: boolean masks of vertices whose u (v) offset is
    zero (boundary vertices slide along the boundary only, corners stay).
    """
    r = jitter * np.sqrt(rng.random(shape))
    t = 2.0 * np.pi * rng.random(shape)
    du, dv = r * np.cos(t), r * np.sin(t)
    if fixed_u is not None:
        du = np.where(fixed_u, 0.0, du)
    if fixed_v is not None:
        dv = np.where(fixed_v, 0.0, dv)
    return du, dv


def _jittered_grid(count, rows, du, dv, jitter, seed):
    """(u, v) of the grid points (du i, dv j), i in 0..count-1 and j in ``rows``, ravelled i-major,
    each moved by up to ``jitter`` grid steps (:func:`_grid_jitter`)."""
    i, j = np.meshgrid(np.arange(count), rows, indexing="ij")
    u, v = (du * i).ravel(), (dv * j).ravel()
    if jitter > 0:
        ou, ov = _grid_jitter(_rng(seed), u.shape, jitter)
        u, v = u + du * ou, v + dv * ov
    return u, v


def _make(name, params, V, F, uv, closed, truth, area=None, volume=None):
    if uv is not None:
        uv = np.ascontiguousarray(uv, dtype=np.float64)
    return AnalyticMesh(
        name=name,
        params=MappingProxyType(dict(params)),
        V=np.ascontiguousarray(V, dtype=np.float64),
        F=np.ascontiguousarray(F, dtype=np.int64),
        uv=uv,
        closed=closed,
        area=None if area is None else float(area),
        volume=None if volume is None else float(volume),
        truth=truth,
    )


def _constant_truth(n, normal, H, K):
    """Truth of a plane (normal fixed, H = K = 0) or a sphere (normal given, H = 1/r)."""

    def truth():
        N = np.broadcast_to(normal, (n, 3))
        return N, np.full(n, H), np.full(n, K), np.full(n, H), np.full(n, H)

    return truth


# ----------------------------------------------------------------------------
# the one source of exact curvature: geomlib.lessons.symbolic
# ----------------------------------------------------------------------------


def _exact_number(x):
    """A float as the exact rational of its shortest decimal (0.7 -> 7/10)."""
    import sympy as sp

    return sp.Rational(repr(float(x)))


@functools.lru_cache(maxsize=32)
def _symbolic_surface(kind, params):
    """The geomlib.lessons.symbolic surface for ("ellipsoid", (a, b, c)), ("torus", (R, r))
    or ("saddle", (A, B)), made once per parameter set and process. Only evaluated, never shown:
    derived without simplifying (the same values, a fraction of the time)."""
    import sympy as sp

    from ...lessons import symbolic

    if kind == "ellipsoid":
        return symbolic.ellipsoid(*params, simplify=False)
    if kind == "torus":
        return symbolic.torus(*params, simplify=False)
    if kind == "saddle":
        A, B = (_exact_number(t) for t in params)
        x, y = sp.symbols("x y", real=True)
        # a polynomial, so its curvature needs no simplification to stay finite
        h = A * sp.Rational(27, 4) * x * (1 - x**2) * y * (1 - y**2) + B * (x**3 - 3 * x * y**2)
        return symbolic.monge(h, x, y, name="saddle", simplify=False)
    raise MeshError(f"no symbolic surface {kind!r}")  # pragma: no cover


def _symbolic_truth(kind, params, uv):
    """Truth evaluated lazily: unit normal, H, K from geomlib.lessons.symbolic at the
    parameters uv, and k1, k2 = H +- sqrt(H^2 - K) from them.

    (H^2 - K >= 0 holds exactly; a negative value is rounding at an umbilic
    point and is clamped to 0. Deriving k1, k2 from H and K spares compiling
    a third family of expressions; the tests compare them with
    ``lambdify("principal_curvatures")``.)
    """

    def truth():
        s = _symbolic_surface(kind, tuple(float(t) for t in params))
        u, v = uv[:, 0], uv[:, 1]
        N = s.lambdify("unit_normal")(u, v)
        H = s.lambdify("mean_curvature")(u, v)
        K = s.lambdify("gaussian_curvature")(u, v)
        d = np.sqrt(np.maximum(H * H - K, 0.0))
        return N, H, K, H + d, H - d

    return truth


# ----------------------------------------------------------------------------
# plane and saddle (height fields over a square)
# ----------------------------------------------------------------------------


def _square_grid(n, size, jitter, seed):
    """(n+1)^2 points of the square [-size/2, size/2]^2, jittered inside.

    Boundary points move along their side only; the four corners stay.
    """
    h = size / n
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    i, j = i.ravel(), j.ravel()
    x = -0.5 * size + h * i
    y = -0.5 * size + h * j
    if jitter > 0:
        rng = _rng(seed)
        on_x_side = (i == 0) | (i == n)  # x fixed there
        on_y_side = (j == 0) | (j == n)
        du, dv = _grid_jitter(rng, x.shape, jitter, fixed_u=on_x_side, fixed_v=on_y_side)
        x = x + h * du
        y = y + h * dv
    return x, y


def plane(n=20, size=2.0, jitter=0.0, seed=0, diagonals="right"):
    """Flat square ``z = 0`` of side ``size`` centred at the origin; exact H = K = 0.

    Convention: triangles counter-clockwise seen from +z, normal ``N = +z``.

    Parameters
    ----------
    n : int >= 1
        Grid intervals per side: (n + 1)^2 vertices, 2 n^2 triangles, edge
        length ``size / n`` (double ``n`` to halve it).
    size : float > 0
        Side length of the square (length units).
    jitter : float in [0, 0.5)
        Irregular tessellation: every vertex moves by up to ``jitter`` grid steps
        in the plane (uniform in a disc), boundary vertices along their side only.
    seed : int or None
        Seed of ``numpy.random.default_rng`` for the jitter.
    diagonals : "right" or "alternate"
        Quad split: all by the same diagonal (valence 6 inside) or alternating
        (valences 4 and 8).

    Returns
    -------
    AnalyticMesh
        ``uv`` holds (x, y); ``area = size^2``; open (one boundary loop).
    """
    n = _count("n", n, 1)
    size = _positive("size", size)
    jitter = _jitter(jitter)
    x, y = _square_grid(n, size, jitter, seed)
    V = np.stack([x, y, np.zeros_like(x)], axis=1)
    F = grid_faces(n + 1, n + 1, diagonals=diagonals)
    up = np.array([0.0, 0.0, 1.0])
    _check_faces(V, F, np.broadcast_to(up, V.shape), "plane")
    params = dict(n=n, size=size, jitter=jitter, seed=seed, diagonals=diagonals)
    truth = _constant_truth(V.shape[0], up, 0.0, 0.0)
    return _make("plane", params, V, F, np.stack([x, y], 1), False, truth, area=size * size)


def saddle_height(x, y, amplitude=0.2, monkey=0.1):
    """Height of the saddle surface: ``z = A (27/4) x (1 - x^2) y (1 - y^2) + B (x^3 - 3 x y^2)``.

    ``A = amplitude`` (the height of the bumps: ``x (1 - x^2)`` peaks at
    ``2 / (3 sqrt 3)``, hence the factor 27/4), ``B = monkey``. On the square
    [-1, 1]^2 (``size = 2``) the first term has two bumps, two dips, a saddle
    at the origin and eight more on the boundary (the four edge midpoints and
    the four corners), like ``sin(pi x) sin(pi y)``; the monkey-saddle term
    breaks the symmetry.
    A polynomial, so that its exact curvature is a rational expression.
    x, y, z in the same length units.
    """
    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    return amplitude * 6.75 * x * (1.0 - x * x) * y * (1.0 - y * y) + monkey * (x**3 - 3.0 * x * y**2)


def saddle(n=48, size=2.0, amplitude=0.2, monkey=0.1, jitter=0.0, seed=0, diagonals="right"):
    """Open height field with saddles: ``z = A (27/4) x (1 - x^2) y (1 - y^2) + B (x^3 - 3 x y^2)``.

    Convention: triangles counter-clockwise seen from +z, ``N`` the upward
    unit normal, ``H > 0`` where the surface bends down (away from ``N``).
    Exact truth: ``geomlib.lessons.symbolic.monge(h, x, y)`` at the vertices' (x, y).
    Defined over the square [-size/2, size/2]^2 (x, y in length units; the
    height uses x, y directly and is meant for ``size <= 2``).

    Parameters
    ----------
    n : int >= 2
        Grid intervals per side: (n + 1)^2 vertices; double to halve edges.
    size : float > 0
        Side of the square.
    amplitude, monkey : float
        ``A`` and ``B`` of the height function (see :func:`saddle_height`).
    jitter : float in [0, 0.5)
        Irregular tessellation: (x, y) jittered by up to ``jitter`` grid steps
        (boundary vertices along their side), then ``z = h(x, y)`` again, so
        vertices stay on the surface exactly.
    seed : int or None
        Seed of ``numpy.random.default_rng``.
    diagonals : "right" or "alternate"
        Quad split (see :func:`plane`).

    Returns
    -------
    AnalyticMesh
        ``uv`` holds (x, y); open, one boundary loop; area None.
    """
    n = _count("n", n, 2)
    size = _positive("size", size)
    A = real_number("amplitude", amplitude)
    B = real_number("monkey", monkey)
    jitter = _jitter(jitter)
    x, y = _square_grid(n, size, jitter, seed)
    V = np.stack([x, y, saddle_height(x, y, A, B)], axis=1)
    F = grid_faces(n + 1, n + 1, diagonals=diagonals)
    # upward side: +z (the tessellation must not fold over in the (x, y) plane)
    _check_faces(V, F, np.broadcast_to([0.0, 0.0, 1.0], V.shape), "saddle")
    params = dict(n=n, size=size, amplitude=A, monkey=B, jitter=jitter, seed=seed, diagonals=diagonals)
    uv = np.stack([x, y], 1)
    return _make("saddle", params, V, F, uv, False, _symbolic_truth("saddle", (A, B), uv))


# ----------------------------------------------------------------------------
# icosphere, sphere, ellipsoid
# ----------------------------------------------------------------------------


def _canonical_faces(F):
    """Rotate each triangle so its smallest index comes first, then sort rows.

    Orientation is kept; the result does not depend on the order in which a
    construction produced the triangles.
    """
    k = np.argmin(F, axis=1)
    idx = (k[:, None] + np.arange(3)[None, :]) % 3
    F = np.take_along_axis(F, idx, axis=1)
    return F[np.lexsort((F[:, 2], F[:, 1], F[:, 0]))]


def _icosahedron():
    """The 12 unit vectors of a regular icosahedron and its 20 outward triangles.

    Vertices are the cyclic permutations of (0, +-1, +-t), t the golden ratio,
    normalised; the faces are all triples of mutually nearest vertices.
    """
    t = (1.0 + np.sqrt(5.0)) / 2.0
    P = []
    for s1 in (-1.0, 1.0):
        for s2 in (-1.0, 1.0):
            P += [(0.0, s1, s2 * t), (s1, s2 * t, 0.0), (s2 * t, 0.0, s1)]
    P = np.array(P) / np.sqrt(1.0 + t * t)
    D = np.linalg.norm(P[:, None, :] - P[None, :, :], axis=2)
    edge = np.min(D[D > 1e-9])
    adj = np.abs(D - edge) < 1e-9
    F = []
    for i in range(12):
        for j in range(i + 1, 12):
            if not adj[i, j]:
                continue
            for k in range(j + 1, 12):
                if adj[i, k] and adj[j, k]:
                    F.append((i, j, k))
    F = np.array(F, dtype=np.int64)
    flip = np.einsum("ij,ij->i", face_cross(P, F), P[F].sum(axis=1)) < 0
    F[flip] = F[flip][:, [0, 2, 1]]
    return P, _canonical_faces(F)


def icosphere(subdivisions=3):
    """Unit icosphere: (10 * 4^k + 2) unit vectors and 20 * 4^k outward triangles.

    Convention: CCW seen from outside. Each subdivision splits every triangle
    into four at the edge midpoints and projects the new points to the sphere,
    so edge lengths halve (about 1.05 / 2^k for k subdivisions). No duplicate
    vertices: every edge is shared by exactly two triangles.

    Returns
    -------
    P : (n, 3) float64 unit vectors
    F : (m, 3) int64
    """
    k = _count("subdivisions", subdivisions, 0, 9)
    P, F = _icosahedron()
    for _ in range(k):
        E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
        E.sort(axis=1)
        uniq, inv = np.unique(E, axis=0, return_inverse=True)
        inv = inv.ravel()
        mid = P[uniq[:, 0]] + P[uniq[:, 1]]
        mid /= np.linalg.norm(mid, axis=1, keepdims=True)
        m = F.shape[0]
        ab = P.shape[0] + inv[:m]
        bc = P.shape[0] + inv[m : 2 * m]
        ca = P.shape[0] + inv[2 * m :]
        a, b, c = F[:, 0], F[:, 1], F[:, 2]
        F = np.concatenate([np.stack(t, axis=1) for t in ((a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca))])
        P = np.concatenate([P, mid])
        F = _canonical_faces(F)
    return P, F


def _sphere_jitter(P, F, jitter, seed):
    """Move unit vectors in their tangent planes by up to ``jitter`` times the
    mean length of their edges (uniform in a disc), then normalise again."""
    rng = _rng(seed)
    n = P.shape[0]
    E = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    L = np.linalg.norm(P[E[:, 0]] - P[E[:, 1]], axis=1)
    h = np.bincount(E[:, 0], weights=L, minlength=n) / np.bincount(E[:, 0], minlength=n)
    # an orthonormal tangent frame per point
    helper = np.where(np.abs(P[:, [2]]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
    t1 = np.cross(P, helper)
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    t2 = np.cross(P, t1)
    du, dv = _grid_jitter(rng, (n,), jitter)
    Q = P + h[:, None] * (du[:, None] * t1 + dv[:, None] * t2)
    return Q / np.linalg.norm(Q, axis=1, keepdims=True)


def _ellipsoid_uv(X, a, b, c):
    """Parameters (u, v) of points on the ellipsoid
    p(u, v) = (a cos u sin v, b sin u sin v, c cos v), u in (-pi, pi], v in [0, pi].
    At the two poles u is 0 by convention."""
    u = np.arctan2(X[:, 1] / b, X[:, 0] / a)
    v = np.arccos(np.clip(X[:, 2] / c, -1.0, 1.0))
    return np.stack([u, v], axis=1)


def _ellipsoid_area(a, b, c):
    """Exact area of the ellipsoid (Legendre's form with elliptic integrals)."""
    from scipy.special import ellipeinc, ellipkinc

    a, b, c = sorted((a, b, c), reverse=True)
    if a == c:
        return 4.0 * np.pi * a * a
    phi = np.arccos(c / a)
    m = (a * a * (b * b - c * c)) / (b * b * (a * a - c * c))
    s = np.sin(phi)
    return 2.0 * np.pi * c * c + 2.0 * np.pi * a * b / s * (
        ellipeinc(phi, m) * s * s + ellipkinc(phi, m) * (1.0 - s * s)
    )


def sphere(r=1.0, subdivisions=3, jitter=0.0, seed=0):
    """Icosphere of radius ``r`` centred at the origin; exact H = 1/r, K = 1/r^2.

    Convention: CCW seen from outside, ``N = x / r`` outward, H > 0.

    Parameters
    ----------
    r : float > 0
        Radius (length units).
    subdivisions : int >= 0
        10 * 4^k + 2 vertices; each step halves the edge length.
    jitter : float in [0, 0.5)
        Irregular tessellation: each vertex moves in its tangent plane by up to
        ``jitter`` times its mean edge length and is projected back to the sphere.
    seed : int or None
        Seed of ``numpy.random.default_rng``.

    Returns
    -------
    AnalyticMesh
        ``uv`` holds (u, v) of p = r (cos u sin v, sin u sin v, cos v);
        area 4 pi r^2, volume 4/3 pi r^3; closed.
    """
    r = _positive("r", r)
    subdivisions = _count("subdivisions", subdivisions, 0, 9)
    jitter = _jitter(jitter)
    P, F = icosphere(subdivisions)
    if jitter > 0:
        P = _sphere_jitter(P, F, jitter, seed)
    V = r * P
    params = dict(r=r, subdivisions=subdivisions, jitter=jitter, seed=seed)
    return _sphere_mesh(params, V, F, P, _ellipsoid_uv(V, r, r, r), r, "sphere")


def _sphere_mesh(params, V, F, N, uv, r, what):
    """The AnalyticMesh of a sphere of radius r, its exact truth constant: N outward, H = 1/r, K = 1/r^2."""
    _check_faces(V, F, N, what)
    truth = _constant_truth(V.shape[0], N, 1.0 / r, 1.0 / r**2)
    return _make("sphere", params, V, F, uv, True, truth, area=4.0 * np.pi * r * r, volume=4.0 / 3.0 * np.pi * r**3)


def _ellipsoid_mesh(params, V, F, uv):
    """The closed ellipsoid mesh (icosphere or UV-grid built) with its exact values, area and volume."""
    a, b, c = params["a"], params["b"], params["c"]
    truth = _symbolic_truth("ellipsoid", (a, b, c), uv)
    return _make(
        "ellipsoid", params, V, F, uv, True, truth, area=_ellipsoid_area(a, b, c), volume=4 / 3 * np.pi * a * b * c
    )


def ellipsoid(a=1.0, b=0.7, c=0.5, subdivisions=3, jitter=0.0, seed=0):
    """Ellipsoid x^2/a^2 + y^2/b^2 + z^2/c^2 = 1 from a mapped icosphere.

    Convention: CCW seen from outside, ``N`` outward, H > 0 (= 1/r when
    a = b = c = r). The unit icosphere (optionally jittered on the sphere) is
    mapped by (x, y, z) -> (a x, b y, c z), so every vertex is on the exact
    ellipsoid; its parameters (u, v) of p(u, v) = (a cos u sin v, b sin u sin v,
    c cos v) are computed per vertex (u = 0 at the poles).

    Parameters
    ----------
    a, b, c : float > 0
        Semi-axes along x, y, z (length units).
    subdivisions : int >= 0
        10 * 4^k + 2 vertices; each step halves the edge length.
    jitter : float in [0, 0.5)
        Irregular tessellation (jitter on the unit sphere, see :func:`sphere`).
    seed : int or None
        Seed of ``numpy.random.default_rng``.

    Returns
    -------
    AnalyticMesh
        Closed; exact area (elliptic integrals) and volume 4/3 pi a b c.
    """
    a, b, c = _positive("a", a), _positive("b", b), _positive("c", c)
    subdivisions = _count("subdivisions", subdivisions, 0, 9)
    jitter = _jitter(jitter)
    P, F = icosphere(subdivisions)
    if jitter > 0:
        P = _sphere_jitter(P, F, jitter, seed)
    V = P * np.array([a, b, c])
    _check_faces(V, F, V / np.array([a * a, b * b, c * c]), "ellipsoid")  # gradient side = outside
    params = dict(a=a, b=b, c=c, subdivisions=subdivisions, jitter=jitter, seed=seed)
    return _ellipsoid_mesh(params, V, F, _ellipsoid_uv(V, a, b, c))


def _uv_ellipsoid_mesh(a, b, c, n, jitter, seed):
    """Latitude-longitude grid: n latitude intervals, 2n longitudes, one vertex
    per pole (fans of triangles there, no degenerate quads)."""
    nu, nv = 2 * n, n
    du, dv = 2.0 * np.pi / nu, np.pi / nv
    u, v = _jittered_grid(nu, np.arange(1, nv), du, dv, jitter, seed)  # ring j = 1..n-1
    # vertex order: north pole, rings (ring-major by longitude i), south pole
    # grid index of (i, j) is i * (nv - 1) + (j - 1) + 1
    u = np.concatenate([[0.0], u, [0.0]])
    v = np.concatenate([[0.0], v, [np.pi]])
    V = np.stack([a * np.cos(u) * np.sin(v), b * np.sin(u) * np.sin(v), c * np.cos(v)], axis=1)
    V[0] = (0.0, 0.0, c)
    V[-1] = (0.0, 0.0, -c)
    rings = nv - 1
    # body: quads between consecutive rings; grid faces in (i, j) with i periodic
    body = np.empty((0, 3), dtype=np.int64)
    if rings >= 2:
        body = grid_faces(nu, rings, periodic_u=True) + 1
    i = np.arange(nu)
    i1 = (i + 1) % nu
    north = np.stack([np.zeros(nu, dtype=np.int64), i * rings + 1, i1 * rings + 1], axis=1)
    last = V.shape[0] - 1
    south = np.stack([np.full(nu, last, dtype=np.int64), i1 * rings + rings, i * rings + rings], axis=1)
    F = np.concatenate([north, body, south])
    # (u, v) grid order is inward for this parametrisation (p_u x p_v points
    # inwards), so the body quads are flipped to face outwards
    F[nu : nu + body.shape[0]] = F[nu : nu + body.shape[0]][:, [0, 2, 1]]
    return V, F, np.stack([u, v], axis=1)


def uv_ellipsoid(a=1.0, b=0.7, c=0.5, n=16, jitter=0.0, seed=0):
    """Ellipsoid as a latitude-longitude (UV) grid of p(u, v) = (a cos u sin v, b sin u sin v, c cos v).

    Convention: CCW seen from outside, ``N`` outward, H > 0. ``n`` latitude
    intervals and ``2 n`` longitudes: 2 n (n - 1) + 2 vertices, 4 n (n - 1)
    triangles; one vertex per pole with a fan of triangles (no zero-area faces).
    Jitter moves the ring vertices in (u, v) by up to ``jitter`` grid steps
    (poles stay). ``n >= 2``. Doubling ``n`` halves the edges.
    """
    a, b, c = _positive("a", a), _positive("b", b), _positive("c", c)
    n = _count("n", n, 2)
    jitter = _jitter(jitter)
    V, F, uv = _uv_ellipsoid_mesh(a, b, c, n, jitter, seed)
    _check_faces(V, F, V / np.array([a * a, b * b, c * c]), "uv_ellipsoid")
    params = dict(a=a, b=b, c=c, n=n, jitter=jitter, seed=seed)
    return _ellipsoid_mesh(params, V, F, uv)


def uv_sphere(r=1.0, n=16, jitter=0.0, seed=0):
    """Sphere of radius ``r`` as a latitude-longitude grid (see :func:`uv_ellipsoid`).

    Convention: CCW seen from outside, ``N`` outward, H = 1/r, K = 1/r^2.
    """
    r = _positive("r", r)
    n = _count("n", n, 2)
    jitter = _jitter(jitter)
    V, F, uv = _uv_ellipsoid_mesh(r, r, r, n, jitter, seed)
    return _sphere_mesh(dict(r=r, n=n, jitter=jitter, seed=seed), V, F, V / r, uv, r, "uv_sphere")


# ----------------------------------------------------------------------------
# torus
# ----------------------------------------------------------------------------


def _torus_point(u, v, R, r):
    w = R + r * np.cos(v)
    return np.stack([w * np.cos(u), w * np.sin(u), r * np.sin(v)], axis=1)


def torus(R=1.0, r=0.4, n=64, m=None, jitter=0.0, seed=0):
    """Torus p(u, v) = ((R + r cos v) cos u, (R + r cos v) sin u, r sin v) around the z-axis.

    Convention: CCW seen from outside, ``N`` outward; H > 0 on the outer
    equator, K < 0 on the inner half.

    Parameters
    ----------
    R, r : float, R > r > 0
        Distance from the axis to the tube centre, and the tube radius.
    n : int >= 3
        Intervals around the axis (u).
    m : int >= 3 or None
        Intervals around the tube (v); default ``round(n r / R)`` (at least 3),
        which makes the grid cells roughly square on the tube's centre line.
        Doubling ``n`` and ``m`` halves the edges.
    jitter : float in [0, 0.5)
        Irregular tessellation: (u, v) jittered by up to ``jitter`` grid steps.
    seed : int or None
        Seed of ``numpy.random.default_rng``.

    Returns
    -------
    AnalyticMesh
        n m vertices (no seam duplicates), 2 n m triangles, closed;
        area 4 pi^2 R r, volume 2 pi^2 R r^2.
    """
    R, r = _positive("R", R), _positive("r", r)
    if r >= R:
        raise MeshError(f"torus needs r < R (a ring torus), got R={R!r}, r={r!r}")
    n = _count("n", n, 3)
    m = max(3, int(round(n * r / R))) if m is None else _count("m", m, 3)
    jitter = _jitter(jitter)
    du, dv = 2.0 * np.pi / n, 2.0 * np.pi / m
    u, v = _jittered_grid(n, np.arange(m), du, dv, jitter, seed)
    V = _torus_point(u, v, R, r)
    F = grid_faces(n, m, periodic_u=True, periodic_v=True)
    # outside: away from the tube's centre circle
    _check_faces(V, F, V - _torus_point(u, np.full_like(v, np.pi / 2), R, 0.0), "torus")
    params = dict(R=R, r=r, n=n, m=m, jitter=jitter, seed=seed)
    uv = np.stack([u, v], 1)
    return _make(
        "torus",
        params,
        V,
        F,
        uv,
        True,
        _symbolic_truth("torus", (R, r), uv),
        area=4.0 * np.pi**2 * R * r,
        volume=2.0 * np.pi**2 * R * r * r,
    )


# ----------------------------------------------------------------------------
# truth for vertices that come from elsewhere (a file)
# ----------------------------------------------------------------------------


def attach_truth(name, V, F, **params):
    """Exact truth at given vertices of a known analytic surface.

    Convention as :class:`AnalyticMesh` (outward / upward ``N``, H > 0 on a
    sphere). Use it for meshes read from a file, e.g.
    ``attach_truth("ellipsoid", V, F, a=1.0, b=0.7, c=0.5)`` for
    ``geomlib/meshes/ellipsoid.obj``. The truth is evaluated at the parameters of the
    nearest exact point: the vertices are projected to the surface for the
    evaluation (a file stores about 9 significant digits), while ``V`` is
    returned as given.

    Parameters
    ----------
    name : "plane", "saddle", "sphere", "ellipsoid" or "torus"
    V : (n, 3) float64, F : (m, 3) int64
    **params : the surface's shape parameters
        plane: none; saddle: amplitude, monkey (defaults as :func:`saddle`);
        sphere: r; ellipsoid: a, b, c; torus: R, r.

    Raises
    ------
    MeshError
        Unknown name or parameters, bad shapes, or vertices farther than
        1e-6 (relative to the size) from the surface.
    """
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    if V.ndim != 2 or V.shape[1] != 3:
        raise MeshError(f"V must have shape (n, 3), got {V.shape}")
    if F.ndim != 2 or F.shape[1] != 3:
        raise MeshError(f"F must have shape (m, 3), got {F.shape}")
    allowed = {
        "plane": {},
        "saddle": {"amplitude": 0.2, "monkey": 0.1},
        "sphere": {"r": 1.0},
        "ellipsoid": {"a": 1.0, "b": 0.7, "c": 0.5},
        "torus": {"R": 1.0, "r": 0.4},
    }
    if name not in allowed:
        raise MeshError(f"unknown surface {name!r}; known: {', '.join(allowed)}")
    extra = set(params) - set(allowed[name])
    if extra:
        raise MeshError(f"{name} takes parameters {sorted(allowed[name])}, got unknown {sorted(extra)}")
    p = {**allowed[name], **params}
    n = V.shape[0]
    closed = name in ("sphere", "ellipsoid", "torus")
    area = volume = None
    if name == "plane":
        dist = np.abs(V[:, 2])
        scale = 1.0
        uv = V[:, :2].copy()
        truth = _constant_truth(n, np.array([0.0, 0.0, 1.0]), 0.0, 0.0)
    elif name == "saddle":
        A, B = real_number("amplitude", p["amplitude"]), real_number("monkey", p["monkey"])
        x, y = V[:, 0], V[:, 1]
        dist = np.abs(V[:, 2] - saddle_height(x, y, A, B))
        scale = 1.0
        uv = V[:, :2].copy()
        truth = _symbolic_truth("saddle", (A, B), uv)
    elif name in ("sphere", "ellipsoid"):
        if name == "sphere":
            a = b = c = _positive("r", p["r"])
        else:
            a, b, c = _positive("a", p["a"]), _positive("b", p["b"]), _positive("c", p["c"])
        S = V / np.array([a, b, c])
        rho = np.linalg.norm(S, axis=1)
        if np.any(rho == 0):
            raise MeshError(f"vertices {format_indices(np.flatnonzero(rho == 0))} are at the centre")
        dist = np.abs(rho - 1.0)  # relative: the scaled points should be unit vectors
        scale = 1.0
        X = S / rho[:, None] * np.array([a, b, c])  # radial projection in the scaled space
        uv = _ellipsoid_uv(X, a, b, c)
        if name == "sphere":
            truth = _constant_truth(n, X / a, 1.0 / a, 1.0 / a**2)
        else:
            truth = _symbolic_truth("ellipsoid", (a, b, c), uv)
        area, volume = _ellipsoid_area(a, b, c), 4.0 / 3.0 * np.pi * a * b * c
    else:
        R, r = _positive("R", p["R"]), _positive("r", p["r"])
        if r >= R:
            raise MeshError(f"torus needs r < R (a ring torus), got R={R!r}, r={r!r}")
        u = np.arctan2(V[:, 1], V[:, 0])
        w = np.hypot(V[:, 0], V[:, 1]) - R
        v = np.arctan2(V[:, 2], w)
        dist = np.abs(np.hypot(w, V[:, 2]) - r)
        scale = r
        uv = np.stack([u, v], 1)
        truth = _symbolic_truth("torus", (R, r), uv)
        area, volume = 4.0 * np.pi**2 * R * r, 2.0 * np.pi**2 * R * r * r
    far = np.flatnonzero(dist > 1e-6 * scale)
    if far.size:
        raise MeshError(
            f"vertices {format_indices(far)} are not on the {name} with {p} (off by up to {dist.max():.3g})"
        )
    return _make(name, p, V, F, uv, closed, truth, area=area, volume=volume)
