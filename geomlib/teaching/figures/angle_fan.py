"""The angle-deficit fan of a vertex, unfolded into the plane: notebook 01's diagram.

The triangles around an interior vertex i keep their true edge lengths and their angles
theta_j at i and are laid side by side around i in the plane. They close up exactly when
sum_j theta_j = 2 pi; what is left, 2 pi - sum_j theta_j, is the angle deficit: a gap when
positive (the vertex of a bowl or a sphere), an overlap when negative (a saddle-like vertex).
"""

import numpy as np

from ...mesh.errors import MeshError
from ...mesh.topology import boundary_vertices, one_ring
from ...mesh.validate import as_mesh

__all__ = ["unfolded_fan", "angle_fan_figure"]


def unfolded_fan(V, F, i):
    """The fan of interior vertex ``i`` laid flat, vertex i at the origin.

    Parameters
    ----------
    V : (n, 3) float64, F : (m, 3) int64 (counter-clockwise from outside)
    i : int, an interior vertex

    Returns
    -------
    points : (k + 1, 2) float64
        Neighbour j of the one-ring at its true distance from vertex i, at the angle
        theta_0 + ... + theta_{j-1}; the last point is the first neighbour again, turned by
        the whole angle sum (so it meets the first point only when the deficit is zero).
    theta : (k,) float64, the angles at i of the k triangles, radians, in ring order.
    deficit : float, 2 pi - sum(theta), radians.

    Raises
    ------
    MeshError
        ``i`` is a boundary vertex (its fan is open: no deficit) or no face uses it.
    """
    V, F = as_mesh(V, F)
    i = int(i)
    if i in set(boundary_vertices(F, len(V)).tolist()):
        raise MeshError(f"unfolded_fan: vertex {i} is on the boundary; its fan is open and has no angle deficit")
    ring = one_ring(F, i)
    if len(ring) == 0:
        raise MeshError(f"unfolded_fan: no face uses vertex {i}")
    a, b = V[ring] - V[i], V[np.roll(ring, -1)] - V[i]
    # the angle between two edges by atan2(|a x b|, a . b): accurate also for very thin triangles
    theta = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b))
    phi = np.concatenate([[0.0], np.cumsum(theta)])
    r = np.linalg.norm(np.vstack([a, a[:1]]), axis=1)
    return r[:, None] * np.column_stack([np.cos(phi), np.sin(phi)]), theta, float(2 * np.pi - theta.sum())


def _draw(ax, points, theta, deficit, title):
    from matplotlib.patches import Polygon, Wedge

    reach = np.linalg.norm(points, axis=1)
    arc = 0.3 * reach.min()
    phi = np.degrees(np.concatenate([[0.0], np.cumsum(theta)]))
    for j in range(len(theta)):
        tri = Polygon([(0, 0), points[j], points[j + 1]], closed=True, facecolor="0.88" if j % 2 else "0.97")
        ax.add_patch(tri)
        tri.set_edgecolor("black")
        mid = np.radians(phi[j] + phi[j + 1]) / 2
        at = 0.55 * min(reach[j], reach[j + 1])  # inside the triangle, clear of the arcs
        ax.text(
            at * np.cos(mid),
            at * np.sin(mid),
            f"{np.degrees(theta[j]):.1f}°",
            ha="center",
            va="center",
            fontsize=8,
            bbox={"facecolor": "white", "edgecolor": "none", "pad": 1},
        )
        ax.add_patch(Wedge((0, 0), arc, phi[j], phi[j + 1], fill=False, linewidth=0.8))
    lo, hi = sorted((phi[-1], 360.0))
    word = "gap" if deficit > 0 else "overlap"
    ax.add_patch(Wedge((0, 0), 0.9 * reach.max(), lo, hi, fill=False, hatch="///", linestyle="--", linewidth=1.2))
    mid = np.radians(lo + hi) / 2
    ax.annotate(
        f"{word}: 2π − Σθ = {np.degrees(deficit):.1f}°",
        (0.6 * reach.max() * np.cos(mid), 0.6 * reach.max() * np.sin(mid)),
        xytext=(0.5, -0.12),
        textcoords="axes fraction",
        ha="center",
        arrowprops={"arrowstyle": "->"},
    )
    ax.plot(0, 0, "ko", ms=4)
    ax.set_title(f"{title}\nΣθ = {np.degrees(theta.sum()):.1f}° around vertex i", fontsize=10)
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.axis("off")


def angle_fan_figure(fans):
    """A figure with one panel per fan, and its alt text built from the angles drawn.

    Parameters
    ----------
    fans : list of (title, V, F, i)

    Returns
    -------
    fig : matplotlib Figure, alt : str, deficits : list of float (radians, one per fan)
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(fans), figsize=(4.6 * len(fans), 4.4), squeeze=False)
    said, deficits = [], []
    for ax, (title, V, F, i) in zip(axes[0], fans):
        points, theta, deficit = unfolded_fan(V, F, i)
        _draw(ax, points, theta, deficit, title)
        deficits.append(deficit)
        kind = (
            f"leaving a gap of {np.degrees(deficit):.1f}°, a positive deficit (K > 0)"
            if deficit > 0
            else f"overlapping by {-np.degrees(deficit):.1f}°, a negative deficit (K < 0)"
        )
        said.append(
            f"{title}: {len(theta)} triangles whose angles at the vertex sum to {np.degrees(theta.sum()):.1f}°, {kind}"
        )
    fig.tight_layout()
    alt = "The triangles around a mesh vertex, unfolded flat with their true edge lengths and angles. " + "; ".join(
        said
    )
    return fig, alt + ".", deficits
