"""Checks on meshes: validation at the door and a report of properties.

Two kinds of checks, kept apart on purpose:

* :func:`as_mesh` (and :func:`as_faces`) validate arrays handed to any geomlib
  function. They coerce ``V`` to a C-contiguous (n, 3) float64 array and ``F``
  to a C-contiguous (m, 3) int64 array and raise :class:`~geomlib.MeshError`
  for input nothing can be computed on: wrong shapes, non-numeric or
  non-integral indices, NaN or infinite coordinates, indices out of range and
  faces that repeat a vertex. The message names the problem and the offending
  vertex or face indices. They cost O(n + m) vectorised work and never copy
  arrays that already have the right dtype and layout.
* :func:`check_mesh` returns a :class:`MeshReport` of properties that results
  depend on but that do not stop a computation: zero-area faces, non-manifold
  edges and vertices, inconsistent orientation, connected components,
  boundary loops, unreferenced vertices, duplicate faces, Euler characteristic
  and genus. Nothing is raised and nothing is altered; the report says what
  still works.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .errors import MeshError, format_indices

__all__ = ["as_mesh", "as_faces", "check_mesh", "MeshReport"]

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


def as_faces(F, n=None, *, where=None, allow_empty=False):
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

    Returns
    -------
    F : (m, 3) int64 ndarray
        The same object when it already is C-contiguous int64.

    Raises
    ------
    MeshError
        Wrong shape or dtype; indices out of range (the faces, the bad index
        and the vertex count are named); faces that repeat a vertex.
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
            f"{_prefix(where)}face indices out of range (valid: {valid}): {detail}{more}; "
            f"faces {format_indices(rows)}"
        )
    rep = (F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 2] == F[:, 0])
    if rep.any():
        rows = np.flatnonzero(rep)
        detail = ", ".join(f"face {r} = {F[r].tolist()}" for r in rows[:5])
        raise MeshError(
            f"{_prefix(where)}{_count(rows, 'face repeats', 'faces repeat')} a vertex (no triangle): {detail}; "
            f"faces {format_indices(rows)}"
        )
    return F


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
                f"{_prefix(where)}{_count(bad, 'vertex has', 'vertices have')} NaN or infinite coordinates: "
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


# --------------------------------------------------------------------------
# the report


@dataclass(repr=False)
class MeshReport:
    """Properties of a mesh that results depend on; returned by :func:`check_mesh`.

    Index arrays are 0-based and sorted. Edges are (k, 2) arrays of vertex
    indices with the smaller index first. ``problems`` lists, in words, what
    departs from a clean closed or open 2-manifold, with what still works;
    ``ok`` is True when it is empty. Boundaries are a property, not a problem
    (an open surface is a valid input everywhere in geomlib): they appear in
    ``notes``.
    """

    n_vertices: int
    n_faces: int
    n_edges: int
    zero_area_faces: np.ndarray
    non_manifold_edges: np.ndarray
    non_manifold_vertices: np.ndarray
    inconsistent_edges: np.ndarray
    n_components: int
    component_sizes: np.ndarray
    boundary_edges: np.ndarray
    boundary_loops: list
    unreferenced_vertices: np.ndarray
    duplicate_faces: np.ndarray
    euler_characteristic: int
    genus: int | None
    problems: list = field(default_factory=list)
    notes: list = field(default_factory=list)

    # derived properties -------------------------------------------------
    @property
    def ok(self):
        """True when no problem was found (boundaries are not problems)."""
        return not self.problems

    @property
    def is_closed(self):
        """No boundary edges."""
        return len(self.boundary_edges) == 0

    @property
    def is_manifold(self):
        """No non-manifold edges or vertices."""
        return len(self.non_manifold_edges) == 0 and len(self.non_manifold_vertices) == 0

    @property
    def is_oriented(self):
        """Every interior edge is traversed in opposite directions by its two faces."""
        return len(self.inconsistent_edges) == 0

    @property
    def n_boundary_loops(self):
        return len(self.boundary_loops)

    @property
    def boundary_loop_lengths(self):
        """Number of edges of each boundary loop, in the order of ``boundary_loops``."""
        return [len(loop) for loop in self.boundary_loops]

    def summary(self):
        """One paragraph: the problems found, or that there are none."""
        if self.ok:
            return "no problems found"
        return "; ".join(self.problems)

    def _rows(self):
        yes = {True: "yes", False: "no"}
        loops = self.boundary_loop_lengths
        return [
            ("vertices", f"{self.n_vertices}"),
            ("faces", f"{self.n_faces}"),
            ("edges", f"{self.n_edges}"),
            ("Euler characteristic V - E + F", f"{self.euler_characteristic}"),
            ("genus", "n/a (needs a connected, oriented manifold)" if self.genus is None else f"{self.genus}"),
            ("connected components", f"{self.n_components}"
             + (f" (faces per component: {format_indices(self.component_sizes)})" if self.n_components > 1 else "")),
            ("closed", yes[self.is_closed]),
            ("boundary", f"{_count(self.boundary_edges, 'edge')} in {_count(loops, 'loop')}"
             + (f" of {format_indices(loops)} edges" if loops else "")),
            ("manifold", yes[self.is_manifold]),
            ("consistently oriented", yes[self.is_oriented]),
            ("zero-area faces", _listing(self.zero_area_faces)),
            ("non-manifold edges", _listing_edges(self.non_manifold_edges)),
            ("non-manifold vertices", _listing(self.non_manifold_vertices)),
            ("inconsistently oriented edges", _listing_edges(self.inconsistent_edges)),
            ("unreferenced vertices", _listing(self.unreferenced_vertices)),
            ("duplicate faces", _listing(self.duplicate_faces)),
        ]

    def __str__(self):
        rows = self._rows()
        width = max(len(k) for k, _ in rows)
        lines = ["MeshReport"] + [f"  {k:<{width}}  {v}" for k, v in rows]
        if self.problems:
            lines.append("Problems (and what still works):")
            lines += [f"  - {p}" for p in self.problems]
        else:
            lines.append("No problems found.")
        lines += [f"Note: {note}" for note in self.notes]
        return "\n".join(lines)

    def __repr__(self):
        return (f"MeshReport(n_vertices={self.n_vertices}, n_faces={self.n_faces}, "
                f"euler_characteristic={self.euler_characteristic}, problems={len(self.problems)})")

    def _repr_html_(self):
        import html

        rows = "".join(
            f"<tr><th style='text-align:left'>{html.escape(k)}</th><td style='text-align:left'>{html.escape(v)}</td></tr>"
            for k, v in self._rows()
        )
        if self.problems:
            items = "".join(f"<li>{html.escape(p)}</li>" for p in self.problems)
            tail = f"<p><b>Problems (and what still works):</b></p><ul>{items}</ul>"
        else:
            tail = "<p>No problems found.</p>"
        tail += "".join(f"<p>Note: {html.escape(note)}</p>" for note in self.notes)
        return f"<div><b>MeshReport</b><table>{rows}</table>{tail}</div>"


def _count(items, singular, plural=None):
    """'1 edge', '3 edges': a count with its noun in the right number."""
    k = len(items)
    return f"{k} {singular if k == 1 else (plural or singular + 's')}"


def _listing(idx):
    return "none" if len(idx) == 0 else f"{len(idx)}: {format_indices(idx)}"


def _edges_text(E, limit=5):
    head = ", ".join(f"({a}, {b})" for a, b in np.asarray(E)[:limit].tolist())
    return head + (f" (and {len(E) - limit} more)" if len(E) > limit else "")


def _listing_edges(E):
    return "none" if len(E) == 0 else f"{len(E)}: {_edges_text(E)}"


def zero_area_faces(V, F, rtol=ZERO_AREA_RTOL):
    """Indices of faces whose area is zero up to rounding.

    A face is zero-area when ``2 * area <= rtol * (longest edge)^2``
    (scale-free). Faces with a repeated vertex never reach here
    (:func:`as_mesh` refuses them).
    """
    X, Y, Z = (np.ascontiguousarray(V[:, k]) for k in range(3))
    i, j, k = (np.ascontiguousarray(F[:, c]) for c in range(3))
    # edge vectors a = P1 - P0 and b = P2 - P0, coordinate by coordinate
    ax, ay, az = X[j] - X[i], Y[j] - Y[i], Z[j] - Z[i]
    bx, by, bz = X[k] - X[i], Y[k] - Y[i], Z[k] - Z[i]
    cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    twice_area2 = cx * cx + cy * cy + cz * cz
    la, lb = ax * ax + ay * ay + az * az, bx * bx + by * by + bz * bz
    dx, dy, dz = bx - ax, by - ay, bz - az
    longest2 = np.maximum(np.maximum(la, lb), dx * dx + dy * dy + dz * dz)
    return np.flatnonzero(twice_area2 <= (rtol * longest2) ** 2)


def check_mesh(V, F):
    """Report the properties of a triangle mesh that results depend on.

    Nothing is raised for these properties and nothing is altered; input
    that cannot be a mesh at all (see :func:`as_mesh`) still raises
    :class:`~geomlib.MeshError`.

    Definitions (all indices 0-based):

    * zero-area face: ``2 * area <= 1e-12 * (longest edge)^2``;
    * non-manifold edge: used by more than two faces;
    * non-manifold vertex: its faces form more than one fan (faces linked
      through shared edges around the vertex), e.g. two cones touching at a
      tip; vertices only on non-manifold edges are counted there;
    * inconsistent edge: an edge of exactly two faces that both traverse it
      in the same direction;
    * components: faces connected through shared vertices;
    * boundary edges: used by exactly one face, directed as that face
      traverses them; loops as in :func:`geomlib.topology.boundary_loops`;
    * unreferenced vertex: used by no face;
    * duplicate face: the same three vertices as an earlier face (in any
      order); the later copies are listed;
    * Euler characteristic ``chi = V - E + F`` over the vertices used by
      faces; genus ``g = (2 - chi - b) / 2`` with ``b`` boundary loops, given
      only for a connected, manifold, consistently oriented mesh.

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64

    Returns
    -------
    MeshReport
    """
    from . import topology

    V, F = as_mesh(V, F)
    n, m = len(V), len(F)
    T = topology._Topology(F, n)

    zero = zero_area_faces(V, F)
    nm_edges = T.E[T.edge_face_count > 2]
    inconsistent = T.inconsistent_edges()
    nm_vertices = T.non_manifold_vertices()
    labels = T.vertex_components()
    n_comp = int(labels.max()) + 1 if len(labels) else 0
    comp_sizes = np.bincount(labels[F[:, 0]], minlength=n_comp)
    bedges = T.boundary_edges()
    loops = topology._loops_from_edges(bedges) if len(bedges) else []
    unref = np.flatnonzero(T.vertex_face_count == 0)
    dups = T.duplicate_faces()
    chi = int(n - len(unref) - len(T.E) + m)
    genus = None
    if n_comp == 1 and len(nm_edges) == 0 and len(nm_vertices) == 0 and len(inconsistent) == 0:
        g2 = 2 - chi - len(loops)
        genus = g2 // 2 if g2 % 2 == 0 else None

    problems = []
    if len(zero):
        problems.append(
            f"{_count(zero, 'zero-area face')} ({format_indices(zero)}): their cotangent weights and normals are "
            "undefined; the uniform Laplacian, valence and topology still work")
    if len(nm_edges):
        problems.append(
            f"{_count(nm_edges, 'non-manifold edge')} used by more than two faces ({_edges_text(nm_edges)}): "
            "Laplacians still assemble, but one_ring fails at their vertices and boundary loops can be ambiguous")
    if len(nm_vertices):
        problems.append(
            f"{_count(nm_vertices, 'non-manifold vertex', 'non-manifold vertices')} whose faces form more than one fan ({format_indices(nm_vertices)}): "
            "Laplacians and curvature still compute, but one_ring fails there and the angle deficit "
            "mixes the fans; Euler characteristic and genus do not describe a surface")
    if len(inconsistent):
        problems.append(
            f"{_count(inconsistent, 'edge')} traversed in the same direction by both faces (inconsistent orientation, "
            f"{_edges_text(inconsistent)}): signed mean curvature and normals flip "
            "between the two sides; unsigned H, K and the Laplacians still work")
    if n_comp > 1:
        problems.append(
            f"{n_comp} connected components: the Laplacian has one zero eigenvalue per component; "
            "curvature and smoothing work per component")
    if len(unref):
        problems.append(
            f"{_count(unref, 'unreferenced vertex', 'unreferenced vertices')} ({format_indices(unref)}): no area and no neighbours, "
            "so their Laplacian rows are zero and M is singular there; they are kept so that indices match the file")
    if len(dups):
        problems.append(
            f"{_count(dups, 'duplicate face')} ({format_indices(dups)}): areas and cotangent weights count them twice")
    notes = []
    if len(bedges):
        notes.append(
            f"open surface, {_count(bedges, 'boundary edge')} in {_count(loops, 'loop')}: every geomlib function "
            "works; each curvature function states its rule at boundary vertices, and Gauss-Bonnet needs the "
            "boundary (geodesic curvature) term")
    return MeshReport(
        n_vertices=n,
        n_faces=m,
        n_edges=len(T.E),
        zero_area_faces=zero,
        non_manifold_edges=nm_edges,
        non_manifold_vertices=nm_vertices,
        inconsistent_edges=inconsistent,
        n_components=n_comp,
        component_sizes=comp_sizes,
        boundary_edges=bedges,
        boundary_loops=loops,
        unreferenced_vertices=unref,
        duplicate_faces=dups,
        euler_characteristic=chi,
        genus=genus,
        problems=problems,
        notes=notes,
    )
