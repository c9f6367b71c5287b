"""Machinery: validation of meshes at the door of every geomlib function.

* :func:`as_mesh` (and :func:`as_faces`, :func:`as_vertices`) validate arrays
  handed to any geomlib function. They coerce ``V`` to a C-contiguous (n, 3) float64 array and ``F``
  to a C-contiguous (m, 3) int64 array and raise :class:`~geomlib.MeshError`
  for input nothing can be computed on: wrong shapes, non-numeric or
  non-integral indices, NaN or infinite coordinates, indices out of range and
  faces that repeat a vertex. The message names the problem and the offending
  vertex or face indices. They cost O(n + m) vectorised work and never copy
  arrays that already have the right dtype and layout.
* :func:`is_zero_area` is the package's one test for a zero-area triangle
  (:func:`geomlib.mesh.geometry.zero_area_faces` lists them).
* :func:`check_choice` is the package's one check of an option that takes one
  of a few named values (``weights=``, ``area=``, ``scheme=``, ...);
  :func:`real_number` and :func:`whole_number` are its checks of a scalar argument
  (a step, a noise level, a count, a resolution).

The report of mesh properties that do not stop a computation (boundaries,
non-manifold parts, components, ...) is :func:`geomlib.mesh.report.check_mesh`.
"""

from __future__ import annotations

import numbers

import numpy as np

from .errors import MeshError, count_text, format_indices

__all__ = [
    "as_mesh",
    "as_faces",
    "as_vertices",
    "repeated_vertex_faces",
    "is_zero_area",
    "check_choice",
    "real_number",
    "whole_number",
    "ZERO_AREA_RTOL",
]

# A face counts as zero-area when twice its area is at most this fraction of
# its longest edge squared, i.e. its height over the longest edge is below
# ZERO_AREA_RTOL times that edge: scale-free, and loose enough to catch the
# collinear triangles that rounding leaves with a tiny non-zero area.
ZERO_AREA_RTOL = 1e-12


def _prefix(where):
    return f"{where}: " if where else ""


def _as_int_array(F, label, where):
    """Coerce to int64, refusing non-numeric input and non-integral floats."""
    F = np.asarray(F)
    kind = F.dtype.kind
    if kind in "iu":
        if kind == "u" and F.dtype.itemsize == 8 and F.size and F.max() > np.iinfo(np.int64).max:
            raise MeshError(f"{_prefix(where)}{label} has indices too large for int64")
        return np.ascontiguousarray(F, dtype=np.int64)
    if kind == "f":
        finite = np.isfinite(F)
        integral = finite & (F == np.round(F)) if F.size else finite
        if not integral.all():
            rows = np.flatnonzero(~integral.reshape(len(F), -1).all(axis=1)) if F.ndim == 2 else []
            where_rows = f" in faces {format_indices(rows)}" if len(rows) else ""
            raise MeshError(
                f"{_prefix(where)}{label} holds non-integral or non-finite values{where_rows}; "
                "face indices must be integers"
            )
        return np.ascontiguousarray(F, dtype=np.int64)
    if kind == "b":
        raise MeshError(f"{_prefix(where)}{label} is a boolean array; face indices must be integers")
    raise MeshError(f"{_prefix(where)}{label} has dtype {F.dtype}; face indices must be integers")


def as_faces(F, n=None, *, where=None, allow_empty=False, allow_repeated=False):
    """Validate a face array: (m, 3) int64, C-contiguous, 0-based.

    Parameters
    ----------
    F : array_like, (m, 3)
        Triangles as vertex indices. Integer arrays are converted to int64;
        float arrays are accepted only when every entry is integral.
    n : int, optional
        Number of vertices. When given, every index must lie in ``0 .. n-1``;
        otherwise indices need only be non-negative.
    where : str, optional
        Prefix for error messages (a file name, an argument name).
    allow_empty : bool
        Accept ``m = 0``.
    allow_repeated : bool
        Accept faces that repeat a vertex (for a drawing, where such a face is
        simply invisible; every computation refuses them).

    Returns
    -------
    F : (m, 3) int64 ndarray
        The same object when it already is C-contiguous int64.

    Raises
    ------
    MeshError
        Wrong shape or dtype; indices out of range (the faces, the bad index
        and the vertex count are named); faces that repeat a vertex (unless
        ``allow_repeated``).
    """
    F = _as_int_array(F, "F", where)
    if F.ndim != 2 or F.shape[1] != 3:
        raise MeshError(f"{_prefix(where)}F must have shape (m, 3) (triangles), got shape {F.shape}")
    if len(F) == 0:
        if allow_empty:
            return F
        raise MeshError(f"{_prefix(where)}F has no faces")
    lo, hi = F.min(), F.max()
    if lo < 0 or (n is not None and hi >= n):
        bad = (F < 0) if n is None else ((F < 0) | (F >= n))
        rows = np.flatnonzero(bad.any(axis=1))
        detail = ", ".join(f"face {r} has index {F[r][bad[r]][0]}" for r in rows[:5])
        more = f" (and {len(rows) - 5} more faces)" if len(rows) > 5 else ""
        valid = "non-negative" if n is None else f"0..{n - 1} for {n} vertices"
        raise MeshError(
            f"{_prefix(where)}face indices out of range (valid: {valid}): {detail}{more}; faces {format_indices(rows)}"
        )
    rows = [] if allow_repeated else repeated_vertex_faces(F)
    if len(rows):
        detail = ", ".join(f"face {r} = {F[r].tolist()}" for r in rows[:5])
        raise MeshError(
            f"{_prefix(where)}{count_text(rows, 'face repeats', 'faces repeat')} a vertex (no triangle): {detail}; "
            f"faces {format_indices(rows)}"
        )
    return F


def repeated_vertex_faces(F):
    """Indices (k,) int64 of the faces that repeat a vertex (no triangle); ``F`` an (m, 3) integer array."""
    return np.flatnonzero((F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 2] == F[:, 0]))


def as_vertices(V, *, where=None):
    """Validate vertex positions: (n, 3) float64, C-contiguous, all finite.

    Raises MeshError naming the vertices with NaN or infinite coordinates.
    """
    V = np.asarray(V)
    if V.dtype.kind not in "fiu":
        raise MeshError(f"{_prefix(where)}V has dtype {V.dtype}; vertex positions must be real numbers")
    if V.ndim != 2 or V.shape[1] != 3:
        raise MeshError(f"{_prefix(where)}V must have shape (n, 3), got shape {V.shape}")
    if len(V) == 0:
        raise MeshError(f"{_prefix(where)}V has no vertices")
    V = np.ascontiguousarray(V, dtype=np.float64)
    # one reduction first: the sum is finite whenever all entries are (barring overflow)
    if not np.isfinite(V.sum()):
        bad = np.flatnonzero(~np.isfinite(V).all(axis=1))
        if len(bad):
            raise MeshError(
                f"{_prefix(where)}{count_text(bad, 'vertex has', 'vertices have')} NaN or infinite coordinates: "
                f"vertices {format_indices(bad)}"
            )
    return V


def as_mesh(V, F, *, where=None, allow_empty=False):
    """Validate a triangle mesh at the door; return ``(V, F)`` as geomlib uses them.

    ``V`` becomes a C-contiguous (n, 3) float64 array, ``F`` a C-contiguous
    (m, 3) int64 array of 0-based indices. Arrays already in that form are
    returned as they are (no copy); nothing is ever reordered or merged.
    Vectorised, O(n + m).

    Parameters
    ----------
    V : array_like, (n, 3)
        Vertex positions, real numbers.
    F : array_like, (m, 3)
        Triangles, integer indices (integral floats are accepted).
    where : str, optional
        Prefix for error messages, e.g. a file name.
    allow_empty : bool
        Accept a mesh with no faces.

    Returns
    -------
    V : (n, 3) float64 ndarray
    F : (m, 3) int64 ndarray

    Raises
    ------
    MeshError
        Wrong shape or dtype; NaN or infinite coordinates (vertex indices
        named); non-integral face indices; indices out of range (faces, bad
        index and vertex count named); faces repeating a vertex (faces named).

    Examples
    --------
    >>> V, F = as_mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    >>> V.dtype, F.dtype
    (dtype('float64'), dtype('int64'))
    """
    V = as_vertices(V, where=where)
    F = as_faces(F, len(V), where=where, allow_empty=allow_empty)
    return V, F


def is_zero_area(dblA, longest2, rtol=ZERO_AREA_RTOL):
    """The zero-area test used everywhere in geomlib: ``2 A <= rtol * (longest edge)^2``.

    Scale-free: the triangle's height over its longest edge is below ``rtol``
    times that edge. ``dblA`` is twice the area, ``longest2`` the longest edge
    squared (arrays of the same shape); returns a boolean array.
    """
    return dblA <= rtol * longest2


def check_choice(name, value, choices):
    """Return ``value`` if it is one of ``choices``; otherwise raise MeshError naming the option, the value and the choices.

    >>> check_choice("weights", "cotan", ("cotan", "uniform"))
    'cotan'
    """
    if isinstance(value, str) and value in choices:  # `in` on a non-string (an array) would compare elementwise
        return value
    listed = ", ".join(repr(c) for c in choices)
    raise MeshError(f"{name} must be one of {listed}, not {value!r}")


def real_number(name, value, minimum=None, *, strict=False, below=None, why=""):
    """``value`` as a float, after checking that it is a finite real number (not a bool), at least
    ``minimum`` (above it, when ``strict``) and below ``below``; otherwise MeshError naming the
    argument, the rule (with ``why``, its reason) and the value.

    >>> real_number("tau", 0.5, 0)
    0.5
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise MeshError(f"{name} must be a real number{why}, not {type(value).__name__} {value!r}")
    x = float(value)
    if not np.isfinite(x):
        raise MeshError(f"{name} must be finite{why}, not {value!r}")
    if minimum is not None and (x <= minimum if strict else x < minimum):
        raise MeshError(f"{name} must be {'>' if strict else '>='} {minimum:g}{why}, not {value!r}")
    if below is not None and not x < below:
        raise MeshError(f"{name} must be below {below:g}{why}, not {value!r}")
    return x


def whole_number(name, value, minimum=0, maximum=None, *, why=""):
    """``value`` as an int, after checking that it is an integer (not a bool) from ``minimum`` to
    ``maximum``; otherwise MeshError naming the argument, the rule (with ``why``, its reason) and the value.

    >>> whole_number("iterations", 3)
    3
    """
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise MeshError(f"{name} must be an integer (a whole number){why}, not {type(value).__name__} {value!r}")
    if value < minimum:
        raise MeshError(f"{name} must be at least {minimum}{why}, not {value}")
    if maximum is not None and value > maximum:
        raise MeshError(f"{name} = {value} is more than {maximum}{why}")
    return int(value)
