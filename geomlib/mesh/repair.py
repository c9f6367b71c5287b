"""Explicit cleaning steps for meshes a lesson cannot use as they are.

``load_mesh`` keeps a file exactly as written; cleaning is always a named call
that a reader can see and repeat:

* ``remove_unreferenced_vertices(V, F)``: drop vertices no face uses (they have
  no area, so M would have zeros on its diagonal);
* ``largest_component(V, F)``: keep the component with the most faces;
* ``remove_zero_area_faces(V, F)``: drop faces with no area (their angles and
  cotangents are undefined);
* ``prepare(V, F, ...)``: what a notebook calls on a reader's mesh. It applies
  the steps the lesson needs, and for each one it applies it displays one
  sentence (``geomlib.teaching.notebook.note``): what was wrong, what the notebook does
  about it, and the call that does it.

Each step returns the kept indices too, so per-vertex results can be mapped
back to the file's vertices (``values_in_file = full(n); values_in_file[kept] = values``).
"""

import numpy as np

from .geometry import zero_area_faces
from .topology import connected_components
from .validate import as_mesh

__all__ = ["remove_unreferenced_vertices", "largest_component", "remove_zero_area_faces"]


def _reindex(V, F, keep):
    """Vertices ``keep`` (sorted indices) and the faces renumbered to them."""
    new = np.full(len(V), -1, dtype=np.int64)
    new[keep] = np.arange(len(keep))
    return V[keep], new[F]


def remove_unreferenced_vertices(V, F):
    """Drop the vertices that no face uses.

    Returns
    -------
    V2 : (n2, 3) float64, F2 : (m, 3) int64 renumbered, kept : (n2,) int64
        indices into the original V of the vertices kept (ascending).
    """
    V, F = as_mesh(V, F)
    kept = np.unique(F)
    V2, F2 = _reindex(V, F, kept)
    return V2, F2, kept


def largest_component(V, F):
    """Keep the connected component with the most faces (ties: the lowest label).

    Returns (V2, F2, kept) as ``remove_unreferenced_vertices`` does.
    """
    V, F = as_mesh(V, F)
    labels = connected_components(F, len(V))
    face_label = labels[F[:, 0]]
    biggest = np.argmax(np.bincount(face_label))
    F_kept = F[face_label == biggest]
    kept = np.unique(F_kept)
    V2, F2 = _reindex(V, F_kept, kept)
    return V2, F2, kept


def remove_zero_area_faces(V, F):
    """Drop faces whose area is zero up to rounding (``geometry.zero_area_faces``).

    Returns (V, F2, kept_faces): the vertices unchanged, the faces kept and their indices.
    """
    V, F = as_mesh(V, F)
    kept_faces = np.setdiff1d(np.arange(len(F)), zero_area_faces(V, F))
    return V, F[kept_faces], kept_faces
