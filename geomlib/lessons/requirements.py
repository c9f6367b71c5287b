"""What the Laplacian lessons need of a mesh, checked once with a message that says how to fix it."""

import numpy as np

from ..mesh.errors import MeshError, format_indices

__all__ = ["positive_vertex_areas"]


def positive_vertex_areas(M, F, what):
    """The diagonal m (n,) of the mass matrix M, after checking that every entry is positive.

    A vertex in no triangle of non-zero area has ``M_ii = 0``: ``M^-1`` and
    ``M^-1/2`` do not exist there, and dividing by it would put NaN into every
    result. Raises MeshError naming those vertices, telling apart the
    unreferenced ones (used by no face) from those used only by zero-area
    faces, and the call that fixes it. ``what`` names the caller (for example
    ``"eigenbasis"``); F may be None when only M is known.
    """
    m = np.asarray(M.diagonal(), dtype=np.float64)
    bad = np.flatnonzero(~(m > 0))
    if len(bad) == 0:
        return m
    if F is None:  # only M is known: the two cases cannot be told apart
        raise MeshError(
            f"{what}: the vertex area M_ii is zero at {len(bad)} of {len(m)} vertices "
            f"({format_indices(bad)}), so M^-1 does not exist there; vertices used by no "
            f"face are removed by V, F = geomlib.mesh.repair.remove_unreferenced_vertices(V, F)"
        )
    used = np.zeros(len(m), dtype=bool)
    used[np.asarray(F).ravel()] = True
    unused, degenerate = bad[~used[bad]], bad[used[bad]]
    parts = []
    if len(unused):
        parts.append(
            f"{len(unused)} vertices are used by no face ({format_indices(unused)}); "
            f"remove them with V, F = geomlib.mesh.repair.remove_unreferenced_vertices(V, F)"
        )
    if len(degenerate):
        parts.append(
            f"{len(degenerate)} vertices are used only by zero-area faces "
            f"({format_indices(degenerate)}); geomlib.check_mesh(V, F) lists those faces"
        )
    raise MeshError(
        f"{what}: the vertex area M_ii is zero at {len(bad)} of {len(m)} vertices, so "
        f"M^-1 does not exist there: " + "; ".join(parts)
    )
