"""Arrows and point markers merged into a displayed mesh (as meshplot's ``add_lines`` / ``add_points``).

The glyphs are small closed triangle meshes (an arrow: a prism shaft and a cone
tip; a marker: an octahedron) appended to the surface, each with one value for
the colour map (NaN draws it bright violet). One merged mesh is one :class:`MeshView`:
the still picture shows the glyphs too, and ``view.update`` moves them with the
surface as long as their number stays the same.

    glyphs = Glyphs(V, F, H, size=diagonal)
    glyphs.add_arrows(X, D, values=H_max)        # (k, 3) origins and directions
    glyphs.add_points(X)
    MeshView(*glyphs.mesh(), symmetric=True)
"""

import numpy as np

from ...mesh.errors import MeshError

__all__ = ["arrow_meshes", "marker_meshes", "Glyphs"]


def arrow_meshes(origins, directions, length, radius, sides=8):
    """(V, F) of k arrows from ``origins`` along ``directions``: a prism shaft (3/4) and a cone tip.

    Faces counter-clockwise from outside; each arrow has ``3 sides + 2`` vertices.
    """
    X = np.asarray(origins, dtype=np.float64).reshape(-1, 3)
    D = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    norm = np.linalg.norm(D, axis=1, keepdims=True)
    if len(X) != len(D) or (norm == 0).any():
        raise MeshError("arrows need as many non-zero directions as origins")
    D = D / norm
    helper = np.where(np.abs(D[:, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]])  # not parallel to D
    e1 = np.cross(D, helper)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(D, e1)
    angle = 2 * np.pi * np.arange(sides) / sides
    ring = np.cos(angle)[None, :, None] * e1[:, None] + np.sin(angle)[None, :, None] * e2[:, None]  # (k, s, 3)
    neck = X[:, None] + 0.75 * length * D[:, None]
    tip, base = X + length * D, X
    V = np.concatenate([X[:, None] + radius * ring, neck + radius * ring, neck + 2.5 * radius * ring,
                        tip[:, None], base[:, None]], axis=1)  # fmt: skip
    i, j = np.arange(sides), (np.arange(sides) + 1) % sides
    top, bottom = np.full(sides, 3 * sides), np.full(sides, 3 * sides + 1)
    F = np.concatenate([np.stack([i, j, sides + j], 1), np.stack([i, sides + j, sides + i], 1),
                        np.stack([2 * sides + i, 2 * sides + j, top], 1), np.stack([bottom, j, i], 1)])  # fmt: skip
    n = V.shape[1]
    return V.reshape(-1, 3), (F[None] + n * np.arange(len(X))[:, None, None]).reshape(-1, 3)


def marker_meshes(points, radius):
    """(V, F) of an octahedron of ``radius`` around each point (6 vertices, 8 faces each)."""
    X = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    corners = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1.0]])
    F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    V = X[:, None] + radius * corners[None]
    return V.reshape(-1, 3), (F[None] + 6 * np.arange(len(X))[:, None, None]).reshape(-1, 3)


class Glyphs:
    """A surface (V, F, values) with arrows and markers appended; :meth:`mesh` gives the merged mesh.

    Parameters
    ----------
    V, F : the surface.
    values : (n,) per-vertex values of the surface, or None (NaN: bright violet).
    size : float
        The scene's size (e.g. its largest semi-axis or half diagonal): arrows
        are ``size / 2`` long and ``0.015 size`` thick, markers ``2.5`` times that.
    """

    def __init__(self, V, F, values=None, size=1.0):
        V = np.asarray(V, dtype=np.float64)
        values = np.full(len(V), np.nan) if values is None else np.asarray(values, dtype=np.float64)
        self.parts = [(V, np.asarray(F, dtype=np.int64), values)]
        self.length, self.radius = 0.5 * size, 0.015 * size

    def _add(self, V, F, values, per_glyph):
        values = np.broadcast_to(np.asarray(values, dtype=np.float64), (len(V) // per_glyph,))
        self.parts.append((V, F, np.repeat(values, per_glyph)))

    def add_arrows(self, origins, directions, values=np.nan, length=None, radius=None):
        """Arrows from each origin along its direction (normalised), one value each (NaN: bright violet)."""
        V, F = arrow_meshes(origins, directions, length or self.length, radius or self.radius)
        self._add(V, F, values, 3 * 8 + 2)

    def add_points(self, points, values=np.nan, radius=None):
        """A marker (octahedron) at each point, one value each (NaN: bright violet)."""
        V, F = marker_meshes(points, radius or 2.5 * self.radius)
        self._add(V, F, values, 6)

    def mesh(self):
        """(V, F, values) of the surface and every glyph, in the order they were added."""
        offsets = np.cumsum([0] + [len(V) for V, _, _ in self.parts])
        V = np.concatenate([V for V, _, _ in self.parts])
        F = np.concatenate([F + k for (_, F, _), k in zip(self.parts, offsets)])
        return V, F, np.concatenate([v for _, _, v in self.parts])
