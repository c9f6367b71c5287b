"""Machinery: :func:`check_mesh`, a report of the mesh properties that results depend on.

:func:`check_mesh` returns a :class:`MeshReport` of properties that do not
stop a computation: zero-area faces, non-manifold edges and vertices,
inconsistent orientation, connected components, boundary loops, unreferenced
vertices, duplicate faces, Euler characteristic and genus. Nothing is raised
and nothing is altered; the report says what still works. Input that cannot
be a mesh at all is refused by :func:`geomlib.mesh.validate.as_mesh`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .errors import count_text, format_indices
from .geometry import zero_area_faces
from .topology import Topology, loops_from_edges
from .validate import as_mesh

__all__ = ["check_mesh", "MeshReport"]


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
            (
                "connected components",
                f"{self.n_components}"
                + (f" (faces per component: {format_indices(self.component_sizes)})" if self.n_components > 1 else ""),
            ),
            ("closed", yes[self.is_closed]),
            (
                "boundary",
                f"{count_text(self.boundary_edges, 'edge')} in {count_text(loops, 'loop')}"
                + (f" of {format_indices(loops)} edges" if loops else ""),
            ),
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
        return (
            f"MeshReport(n_vertices={self.n_vertices}, n_faces={self.n_faces}, "
            f"euler_characteristic={self.euler_characteristic}, problems={len(self.problems)})"
        )

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


def _listing(idx):
    return "none" if len(idx) == 0 else f"{len(idx)}: {format_indices(idx)}"


def _edges_text(E, limit=5):
    head = ", ".join(f"({a}, {b})" for a, b in np.asarray(E)[:limit].tolist())
    return head + (f" (and {len(E) - limit} more)" if len(E) > limit else "")


def _listing_edges(E):
    return "none" if len(E) == 0 else f"{len(E)}: {_edges_text(E)}"


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
      traverses them; loops as in :func:`geomlib.mesh.topology.boundary_loops`;
    * unreferenced vertex: used by no face;
    * duplicate face: the same three vertices as an earlier face (in any
      order); the later copies are listed;
    * Euler characteristic ``chi = V - E + F`` over the vertices used by
      faces; genus ``g = (2 - chi - b) / 2`` with ``b`` boundary loops, given
      only for a connected, manifold, consistently oriented mesh.

    V (n, 3) float64 and F (m, 3) int64 are the mesh; returns a :class:`MeshReport`.
    """
    V, F = as_mesh(V, F)
    n, m = len(V), len(F)
    T = Topology(F, n)

    zero = zero_area_faces(V, F)
    nm_edges = T.E[T.edge_face_count > 2]
    inconsistent = T.inconsistent_edges()
    nm_vertices = T.non_manifold_vertices()
    labels = T.vertex_components()
    n_comp = int(labels.max()) + 1 if len(labels) else 0
    comp_sizes = np.bincount(labels[F[:, 0]], minlength=n_comp)
    bedges = T.boundary_edges()
    loops = loops_from_edges(bedges) if len(bedges) else []
    unref = np.flatnonzero(T.vertex_face_count == 0)
    dups = T.duplicate_faces()
    chi = T.euler_characteristic()
    genus = None
    if n_comp == 1 and len(nm_edges) == 0 and len(nm_vertices) == 0 and len(inconsistent) == 0:
        g2 = 2 - chi - len(loops)
        genus = g2 // 2 if g2 % 2 == 0 else None

    problems = []
    if len(zero):
        problems.append(
            f"{count_text(zero, 'zero-area face')} ({format_indices(zero)}): their cotangent weights and normals are "
            "undefined; the uniform Laplacian, valence and topology still work"
        )
    if len(nm_edges):
        problems.append(
            f"{count_text(nm_edges, 'non-manifold edge')} used by more than two faces ({_edges_text(nm_edges)}): "
            "Laplacians still assemble, but one_ring fails at their vertices and boundary loops can be ambiguous"
        )
    if len(nm_vertices):
        problems.append(
            f"{count_text(nm_vertices, 'non-manifold vertex', 'non-manifold vertices')} whose faces form more than one fan ({format_indices(nm_vertices)}): "
            "Laplacians and curvature still compute, but one_ring fails there and the angle deficit "
            "mixes the fans; Euler characteristic and genus do not describe a surface"
        )
    if len(inconsistent):
        problems.append(
            f"{count_text(inconsistent, 'edge')} traversed in the same direction by both faces (inconsistent orientation, "
            f"{_edges_text(inconsistent)}): signed mean curvature and normals flip "
            "between the two sides; unsigned H, K and the Laplacians still work"
        )
    if n_comp > 1:
        problems.append(
            f"{n_comp} connected components: the Laplacian has one zero eigenvalue per component; "
            "curvature and smoothing work per component"
        )
    if len(unref):
        problems.append(
            f"{count_text(unref, 'unreferenced vertex', 'unreferenced vertices')} ({format_indices(unref)}): no area and no neighbours, "
            "so their Laplacian rows are zero and M is singular there; they are kept so that indices match the file"
        )
    if len(dups):
        problems.append(
            f"{count_text(dups, 'duplicate face')} ({format_indices(dups)}): areas and cotangent weights count them twice"
        )
    notes = []
    if len(bedges):
        notes.append(
            f"open surface, {count_text(bedges, 'boundary edge')} in {count_text(loops, 'loop')}: every geomlib function "
            "works; each curvature function states its rule at boundary vertices, and Gauss-Bonnet needs the "
            "boundary (geodesic curvature) term"
        )
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
