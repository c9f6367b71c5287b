"""The diagrams of notebook 03, drawn from geomlib's own geometry.

* :func:`hat_figure`: the piecewise-linear hat function psi_i on a one-ring of a jittered flat
  grid, its gradient (constant on each triangle, perpendicular to the edge opposite i, of length
  1 / height; one triangle shows that edge and the height), and an edge ij with the two angles alpha_ij, beta_ij opposite it;
* :func:`voronoi_figure`: the mixed (Voronoi) region of a vertex, circumcentres and edge
  midpoints, and an obtuse triangle, whose circumcentre lies outside it, with the plain Voronoi
  pieces and the mixed rule's split A/2, A/4, A/4.

Each returns ``(fig, alt)``: the matplotlib figure and its alt text, built from the numbers drawn.
The quantities drawn (gradients, circumcentres, regions) are functions here, tested against
``geomlib.lessons.laplace``: the integral of grad psi_i . grad psi_j is -C_ij, and the regions'
areas are the mixed areas.
"""

import numpy as np

from ...lessons.laplace import barycentric_areas, face_geometry, voronoi_pieces
from ...mesh.errors import MeshError
from ...mesh.topology import boundary_vertices, one_ring
from ...mesh.validate import as_mesh
from ..shapes import surfaces

__all__ = [
    "hat_gradients",
    "circumcentres",
    "mixed_region",
    "polygon_area",
    "ring_mesh",
    "hat_figure",
    "voronoi_figure",
]


def hat_gradients(V, F):
    """(m, 3, 3) gradient of each corner's hat function on each triangle: ``n x e_c / (2 A)``.

    ``e_c`` is the edge opposite corner c, counter-clockwise, ``n`` the unit normal: the
    gradient is perpendicular to that edge, points towards c, and has length 1 / h_c (h_c the
    height of c over the edge). Units 1/length.
    """
    V, F = as_mesh(V, F)
    P = V[F]  # (m, 3 corners, 3)
    N = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])  # 2 A n
    dblA = np.linalg.norm(N, axis=1)
    if np.any(dblA == 0):
        raise MeshError(f"hat_gradients: zero-area faces {np.flatnonzero(dblA == 0)[:10].tolist()} have no gradient")
    n = N / dblA[:, None]
    e = np.stack([P[:, 2] - P[:, 1], P[:, 0] - P[:, 2], P[:, 1] - P[:, 0]], axis=1)
    return np.cross(n[:, None, :], e) / dblA[:, None, None]


def circumcentres(V, F):
    """(m, 3) circumcentre of each triangle: the point equidistant from its three corners."""
    V, F = as_mesh(V, F)
    a, b, c = (V[F[:, k]] for k in range(3))
    u, w = b - a, c - a
    n = np.cross(u, w)
    num = np.einsum("fd,fd->f", u, u)[:, None] * np.cross(w, n) + np.einsum("fd,fd->f", w, w)[:, None] * np.cross(n, u)
    return a + num / (2 * np.einsum("fd,fd->f", n, n))[:, None]


def mixed_region(V, F, f, c):
    """(k, 3) polygon of corner ``c`` of face ``f`` in the mixed area (Meyer et al. 2003), corner first.

    No obtuse angle: corner, midpoint of the next edge, circumcentre, midpoint of the previous
    edge (the Voronoi piece). Obtuse at c: corner and the three edge midpoints (A/2). Obtuse at
    another corner: corner and the midpoints of its two edges (A/4).
    """
    V, F = as_mesh(V, F)
    p = V[F[f]]
    i, j, k = c, (c + 1) % 3, (c + 2) % 3
    mid_ij, mid_ik, mid_jk = (p[i] + p[j]) / 2, (p[i] + p[k]) / 2, (p[j] + p[k]) / 2
    cot = face_geometry(V, F[[f]])[2][0]
    if not (cot < 0).any():
        return np.array([p[i], mid_ij, circumcentres(V, F[[f]])[0], mid_ik])
    if cot[c] < 0:
        return np.array([p[i], mid_ij, mid_jk, mid_ik])
    return np.array([p[i], mid_ij, mid_ik])


def polygon_area(P, normal=(0.0, 0.0, 1.0)):
    """Signed area of the planar polygon P (k, 3), positive when counter-clockwise about ``normal``."""
    P = np.asarray(P, float)
    return 0.5 * float(np.dot(np.cross(P, np.roll(P, -1, axis=0)).sum(axis=0), normal))


def ring_mesh(jitter, seed, n=4):
    """A jittered flat grid and its centre vertex (interior, valence 6)."""
    grid = surfaces.plane(n=n, size=2.0, jitter=jitter, seed=seed)
    i = (n + 1) * (n // 2) + n // 2
    if i in set(boundary_vertices(grid.F, len(grid.V)).tolist()):
        raise MeshError(f"vertex {i} of the grid is on its boundary")
    return grid.V, grid.F, i


def _faces_at(F, i):
    return np.flatnonzero((F == i).any(axis=1))


def _draw_edges(ax, V, F, **style):
    for f in F:
        xy = V[np.r_[f, f[0]], :2]
        # solid whatever the style's line cycle: a dashed edge would look like it meant something
        ax.plot(xy[:, 0], xy[:, 1], **{"color": "0.35", "lw": 0.8, "ls": "-", **style})


def hat_figure(jitter=0.25, seed=1):
    """(fig, alt): the hat psi_i as a tent, its gradient per triangle, and an edge ij with alpha_ij, beta_ij."""
    import matplotlib.pyplot as plt

    V, F, i = ring_mesh(jitter, seed)
    faces = _faces_at(F, i)
    ring = one_ring(F, i)
    G = hat_gradients(V, F[faces])
    grad = G[np.arange(len(faces)), np.argmax(F[faces] == i, axis=1)]  # gradient of psi_i per triangle
    fig = plt.figure(figsize=(11.5, 3.7))
    ax = fig.add_subplot(1, 3, 1, projection="3d")
    psi = np.where(np.arange(len(V)) == i, 1.0, 0.0)
    ax.plot_trisurf(V[:, 0], V[:, 1], psi, triangles=F[faces], color="0.8", edgecolor="0.2", lw=0.6)
    ax.text(*V[i, :2], 1.08, r"$\psi_i = 1$ at $i$", ha="center")
    ax.set(title=r"(a) the hat $\psi_i$: 1 at $i$, 0 at the ring", zticks=[0, 1], xticks=[], yticks=[])
    ax.view_init(elev=28, azim=-60)
    ax = fig.add_subplot(1, 3, 2)
    _draw_edges(ax, V, F[faces])
    centre = V[F[faces]].mean(axis=1)
    scale = 0.18 / np.linalg.norm(grad, axis=1).max()  # the longest arrow shorter than the triangles are apart
    ax.quiver(
        centre[:, 0],
        centre[:, 1],
        grad[:, 0] * scale,
        grad[:, 1] * scale,
        angles="xy",
        scale_units="xy",
        scale=1,
        width=0.012,
        color="k",
    )
    ax.plot(*V[i, :2], "ko")
    ax.annotate("i", V[i, :2], xytext=(6, -12), textcoords="offset points", fontsize=12)
    # in one triangle, the edge opposite i and the height h_i over it: the arrow there has length 1/h_i
    f0 = F[faces[0]]
    a, b = (V[v] for v in f0 if v != i)
    foot = a + (b - a) * np.dot(V[i] - a, b - a) / np.dot(b - a, b - a)
    h_i = float(np.linalg.norm(V[i] - foot))
    ax.plot(*np.c_[a, b][:2], "k-", lw=2.5)
    ax.plot(*np.c_[V[i], foot][:2], "k:", lw=1.2)
    ax.annotate(r"$h_i$", (V[i, :2] + foot[:2]) / 2, xytext=(4, 4), textcoords="offset points", fontsize=11)
    ax.set(title=r"(b) $\nabla\psi_i$: one constant arrow per triangle", aspect="equal")
    ax.axis("off")
    # the first neighbour whose two triangles with i have no obtuse angle (a positive weight), else the first
    acute = (face_geometry(V, F)[2] > 0).all(axis=1)
    j = next((v for v in ring if all(acute[f] for f in faces if v in F[f])), ring[0])
    pair = [f for f in faces if j in F[f]]
    third = [int(np.setdiff1d(F[f], [i, j])[0]) for f in pair]
    ax = fig.add_subplot(1, 3, 3)
    _draw_edges(ax, V, F[pair])
    ax.plot(*V[[i, j], :2].T, "k-", lw=3.5)
    angles = []
    for name, k in zip((r"\alpha_{ij}", r"\beta_{ij}"), third):
        u, w = V[i] - V[k], V[j] - V[k]
        angles.append(np.degrees(np.arctan2(np.linalg.norm(np.cross(u, w)), u @ w)))
        toward = (V[i] + V[j]) / 2 - V[k]
        ax.annotate(f"${name}$", V[k, :2] + 0.28 * toward[:2], fontsize=13, ha="center", va="center")
    middle = V[[i, j] + third, :2].mean(axis=0)
    for name, v in (("i", i), ("j", j), ("k", third[0]), ("l", third[1])):
        away = V[v, :2] - middle  # each label just outside its corner
        away = 12 * away / np.linalg.norm(away)
        ax.annotate(name, V[v, :2], xytext=away, textcoords="offset points", fontsize=12, ha="center", va="center")
    C_ij = 0.5 * sum(1 / np.tan(np.radians(a)) for a in angles)
    ax.set_title(f"(c) edge ij (thick), C_ij = {C_ij:.3f}", pad=16)
    ax.set_aspect("equal")
    ax.axis("off")
    fig.tight_layout()
    lengths = np.linalg.norm(grad, axis=1)
    alt = (
        f"Three panels drawn from a one-ring of a jittered flat grid, vertex i with {len(ring)} neighbours. "
        f"(a) The hat function psi_i as a tent: height 1 at vertex i, 0 at its {len(ring)} neighbours, flat on each "
        f"triangle. (b) Its gradient, one arrow per triangle at the triangle's centre, each perpendicular to the edge "
        f"opposite i and pointing towards i, of length 1/height from {lengths.min():.2f} to {lengths.max():.2f} per "
        f"length; in one triangle the edge opposite i is drawn thick and the height h_i = {h_i:.2f} over it dotted, "
        f"so its arrow has length {1 / h_i:.2f}. (c) The edge ij drawn thick in its two triangles, with the angles opposite it, alpha_ij = "
        f"{angles[0]:.1f} degrees and beta_ij = {angles[1]:.1f} degrees: C_ij = (cot alpha + cot beta)/2 = {C_ij:.3f}."
    )
    return fig, alt


def voronoi_figure(jitter=0.3, seed=2, obtuse=((0.0, 0.0), (4.0, 0.0), (1.0, 1.0))):
    """(fig, alt): a vertex's mixed region on a jittered grid, and one obtuse triangle's pieces and split."""
    import matplotlib.pyplot as plt

    V, F, i = ring_mesh(jitter, seed)
    faces = _faces_at(F, i)
    cot = face_geometry(V, F[faces])[2]
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.4))
    _draw_edges(ax, V, F[faces])
    total = 0.0
    for f in faces:
        region = mixed_region(V, F, f, int(np.argmax(F[f] == i)))
        total += polygon_area(region)
        ax.fill(region[:, 0], region[:, 1], facecolor="0.85", edgecolor="k", hatch="//", lw=0.8)
    O = circumcentres(V, F[faces])
    out = (cot < 0).any(axis=1)
    ax.plot(O[~out, 0], O[~out, 1], "k.", ms=8, label="circumcentre (triangle without obtuse angle)")
    ax.plot(O[out, 0], O[out, 1], "kx", ms=9, mew=2, label="circumcentre outside (obtuse triangle)")
    ax.plot(*V[i, :2], "ko")
    ax.annotate("i", V[i, :2], xytext=(6, -12), textcoords="offset points", fontsize=12)
    bary = barycentric_areas(V, F)[i]
    ax.set(title=f"(a) the mixed region of i: area {total:.3f} (barycentric {bary:.3f})", aspect="equal")
    ax.legend(loc="lower center", bbox_to_anchor=(0.5, -0.2), fontsize=8, ncol=1, frameon=False)
    ax.axis("off")
    T = np.c_[np.asarray(obtuse, float), np.zeros(3)]
    t = np.array([[0, 1, 2]])
    l2, dblA, tcot, _ = face_geometry(T, t)
    theta = np.degrees(np.arctan2(1.0, tcot[0]))
    pieces = voronoi_pieces(T, t)[0]
    O = circumcentres(T, t)[0]
    hatches = {2: "\\\\", 3: ".."}
    for c in range(3):
        region = mixed_region(T, t, 0, c)
        bx.fill(region[:, 0], region[:, 1], facecolor="0.92", edgecolor="k", hatch=hatches[len(region) - 1], lw=0.8)
        share = polygon_area(region) / (dblA[0] / 2)
        below = T[c, 1] <= T[:, 1].mean()
        bx.annotate(
            f"{theta[c]:.0f}°: mixed A/{1 / share:.0f}, Voronoi piece {pieces[c]:+.3f}",
            T[c, :2],
            xytext=(0, -16 if below else 10),
            textcoords="offset points",
            fontsize=9,
            ha="center",
        )
    for a, b in ((0, 1), (1, 2), (2, 0)):
        mid = (T[a] + T[b]) / 2
        bx.plot([mid[0], O[0]], [mid[1], O[1]], "k--", lw=0.8)
    bx.plot(*O[:2], "kx", ms=10, mew=2)
    bx.annotate("circumcentre", O[:2], xytext=(8, -4), textcoords="offset points", fontsize=9)
    bx.margins(0.12)
    bx.set(title=f"(b) an obtuse triangle ({theta.max():.0f}°), area A = {dblA[0] / 2:.2f}", aspect="equal")
    bx.axis("off")
    fig.tight_layout()
    obtuse_corner = int(np.argmax(theta))
    alt = (
        f"Two panels. (a) The one-ring of vertex i on a jittered flat grid with {len(faces)} triangles, "
        f"{int(out.sum())} of them obtuse; vertex i's mixed region hatched: in each triangle without an obtuse angle "
        f"the quadrilateral from i to the two edge midpoints and the circumcentre (dots), in an obtuse triangle "
        f"(circumcentre outside, crosses) a piece cut by the edge midpoints; its area {total:.3f} is the mixed area of "
        f"i, against {bary:.3f} for the barycentric area. (b) A triangle with angles "
        f"{', '.join(f'{a:.0f}' for a in theta)} degrees and area {dblA[0] / 2:.2f}: its circumcentre lies outside, "
        f"beyond the longest edge, with dashed lines to the edge midpoints; the plain Voronoi pieces are "
        f"{', '.join(f'{p:.3f}' for p in pieces)}; the mixed rule gives the obtuse corner ({theta[obtuse_corner]:.0f} "
        f"degrees) half the area, hatched with dots, and the other two a quarter each, hatched with lines."
    )
    return fig, alt
