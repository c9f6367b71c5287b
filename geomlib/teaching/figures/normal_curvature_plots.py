"""The pictures of notebook 02: a normal section of the ellipsoid, and kappa_n(phi) plotted three ways.

``normal_section_figure`` is the diagram of the derivation. At a point p(u, v) of ``ellipsoid(a, b, c)``: the tangent plane with the coordinate tangents
p_u and p_v, the unit tangent t(phi) at angle phi from p_u (towards p_v, as in
``geomlib.lessons.symbolic``), the outward unit normal n, and the plane through n and t,
which cuts the surface in a plane curve, the normal section, whose curvature at the point is
the normal curvature kappa_n(phi). Every vector and the curve come from the library's
compiled formulas and the implicit equation x^2/a^2 + y^2/b^2 + z^2/c^2 = 1.
"""

import numpy as np

from ...lessons.symbolic import ellipsoid

__all__ = [
    "normal_section",
    "normal_section_figure",
    "place_labels",
    "screen_points",
    "polar_and_dupin_figure",
    "kappa_turn_figure",
]


def normal_section(a, b, c, phi, u=0.0, v=np.pi / 2, samples=241):
    """The geometry of the normal section at angle ``phi`` (radians) at p(u, v): a dict of float64 arrays.

    Keys: ``P`` the point, ``p_u``, ``p_v`` the tangents, ``n`` the outward unit normal,
    ``t`` the unit tangent at angle phi, ``w`` the unit tangent perpendicular to p_u towards p_v,
    ``curve`` (samples, 3) the section (a closed curve starting and ending at P), and
    ``kappa_n`` its curvature at P (1/length).

    The section is found without the fundamental forms: each line through P in the plane of
    t and n, in direction d(psi) = cos psi t + sin psi n, meets the ellipsoid once more, at
    P + r d with r = -2 <P, d>_A / <d, d>_A in the metric A = diag(1/a^2, 1/b^2, 1/c^2).
    """
    ell = ellipsoid(a, b, c)
    P, p_u, p_v = (ell.lambdify(name)(u, v) for name in ("position", "p_u", "p_v"))
    n = ell.lambdify("unit_normal")(u, v)
    t_u = p_u / np.linalg.norm(p_u)
    w = np.cross(-n, t_u)  # p_u turned by +90 degrees about p_u x p_v, which is -n on this ellipsoid
    t = np.cos(phi) * t_u + np.sin(phi) * w
    A = 1 / np.array([a, b, c], dtype=float) ** 2
    psi = np.linspace(0, np.pi, samples)[:, None]
    d = np.cos(psi) * t + np.sin(psi) * n
    r = -2 * (d * P * A).sum(axis=1) / (d * d * A).sum(axis=1)
    curve = P + r[:, None] * d
    kappa_n = float(ell.lambdify("normal_curvature")(u, v, phi))
    return {"P": P, "p_u": p_u, "p_v": p_v, "n": n, "t": t, "w": w, "curve": curve, "kappa_n": kappa_n}


def _arrow(ax, start, vector, style="-"):
    ax.quiver(*start, *vector, color="black", linestyle=style, arrow_length_ratio=0.12, linewidth=1.3)


def screen_points(ax, lines, step=1.5):
    """(k, 2) display coordinates of points every ``step`` pixels along the drawn ``lines`` (Line3D and
    Line3DCollection artists of the 3D axes ``ax``, after a draw)."""
    from mpl_toolkits.mplot3d import proj3d

    polylines = []
    for artist in lines:
        if hasattr(artist, "get_data_3d"):
            polylines.append(np.column_stack(artist.get_data_3d()))
        else:
            polylines += [np.asarray(segment, dtype=float) for segment in artist._segments3d]
    points = []
    for xyz in polylines:
        x, y, _ = proj3d.proj_transform(*xyz.T, ax.get_proj())
        screen = ax.transData.transform(np.column_stack([x, y]))
        for p, q in zip(screen[:-1], screen[1:]):
            count = int(np.ceil(np.linalg.norm(q - p) / step)) + 1
            points.append(p + np.linspace(0, 1, count)[:, None] * (q - p))
    return np.vstack(points) if points else np.zeros((0, 2))


def place_labels(ax, labels, lines, fontsize=12, pad=4):
    """Put each label near its 3D anchor where its box, ``pad`` pixels wider all round, touches none of
    ``lines`` and no other label.

    ``labels``: (3D anchor, text, font size or None, 3D direction or None). Candidates ring the anchor's
    screen point in 16 directions, those nearest the given direction's (as drawn) first, the box's near
    edge 3 to 60 pixels from it; the first free one is kept (the nearest free place), else the least
    crowded one. The texts are ``ax.text2D`` in axes
    coordinates, placed after a draw, so they stay where they were checked as long as the view is not
    turned. Returns the texts.
    """
    from mpl_toolkits.mplot3d import proj3d

    fig = ax.figure
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    points = screen_points(ax, lines)
    taken, texts = [], []
    angles = np.radians(np.arange(0, 360, 22.5))
    for anchor, label, size, toward in labels:
        size = size or fontsize
        x, y, _ = proj3d.proj_transform(*anchor, ax.get_proj())
        home = ax.transData.transform((x, y))
        order = angles
        if toward is not None:
            x, y, _ = proj3d.proj_transform(*(anchor + 1e-3 * np.asarray(toward)), ax.get_proj())
            ahead = ax.transData.transform((x, y)) - home
            order = angles[np.argsort(np.abs(np.angle(np.exp(1j * (angles - np.arctan2(ahead[1], ahead[0]))))))]
        text = ax.text2D(0, 0, label, fontsize=size, ha="center", va="center", transform=ax.transAxes)
        extent = text.get_window_extent(renderer)
        half = np.array([extent.width, extent.height]) / 2 + pad
        best = None
        for gap in (3, 8, 15, 25, 40, 60):
            for angle in order:
                way = np.array([np.cos(angle), np.sin(angle)])
                centre = home + (np.abs(way) @ half + gap) * way
                text.set_position(ax.transAxes.inverted().transform(centre))
                box = text.get_window_extent(renderer).padded(pad)
                crossed = int(((points >= box.p0) & (points <= box.p1)).all(axis=1).sum())
                crossed += 1000 * sum(box.overlaps(other) for other in taken)
                if best is None or crossed < best[0]:
                    best = crossed, text.get_position(), box
                if best[0] == 0:
                    break
            if best[0] == 0:
                break
        text.set_position(best[1])
        taken.append(best[2])
        texts.append(text)
    return texts


def normal_section_figure(a, b, c, phi, u=0.0, v=np.pi / 2):
    """(fig, alt): a matplotlib 3D figure of the normal section at angle ``phi`` and its alt text.

    Drawn: the ellipsoid as a light wire mesh, the tangent plane (a grey patch), p_u and p_v at
    their true lengths, t(phi) and n (unit vectors), right-angle marks between n and the tangent
    patch, the point itself labelled with its coordinates, the normal plane (a light patch), the
    section (thick line) and its osculating circle at P (dashed, radius 1/kappa_n). Series are
    told apart by line style and labels, not by colour; every label sits clear of every drawn line
    but the wire mesh (:func:`place_labels`).
    """
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    s = normal_section(a, b, c, phi, u, v)
    P, n, t, w = s["P"], s["n"], s["t"], s["w"]
    fig = plt.figure(figsize=(6.4, 5.6))
    ax = fig.add_subplot(projection="3d")
    uu, vv = np.meshgrid(np.linspace(0, 2 * np.pi, 25), np.linspace(0, np.pi, 13))
    X = np.stack([a * np.cos(uu) * np.sin(vv), b * np.sin(uu) * np.sin(vv), c * np.cos(vv)])
    mesh = ax.plot_wireframe(*X, color="0.75", linewidth=0.4)
    size = 0.55 * max(a, b, c)
    t_u = s["p_u"] / np.linalg.norm(s["p_u"])
    corners = np.array([(-1, -1), (1, -1), (1, 1), (-1, 1), (-1, -1)]) * size
    tangent_patch = P + corners[:, :1] * t_u + corners[:, 1:] * w
    ax.add_collection3d(Poly3DCollection([tangent_patch[:4]], facecolor="0.55", alpha=0.25))
    # the normal plane reaches from outside the surface to deep inside, so the section is seen to lie in it;
    # its dash-dot outline keeps it visible where its face, drawn light, is hidden by the wire mesh
    normal_patch = P + corners[:, :1] * t + (corners[:, 1:] - 0.4 * size) * n * 0.7
    ax.add_collection3d(Poly3DCollection([normal_patch[:4]], facecolor="0.85", alpha=0.3))
    drawn = ax.plot(*normal_patch.T, color="black", linestyle="-.", linewidth=0.8)
    drawn += ax.plot(*s["curve"].T, color="black", linewidth=2.6)
    k = s["kappa_n"]
    angle = np.linspace(0, 2 * np.pi, 181)[:, None]
    circle = P - n / k + (np.cos(angle) * n + np.sin(angle) * t) / k
    drawn += ax.plot(*circle.T, color="black", linestyle="--", linewidth=1.0)
    # n is perpendicular to the tangent patch: a right-angle mark against each of its two directions
    mark = 0.2 * size
    for side in (t_u, w):
        corner = np.array([P + mark * side, P + mark * (side + n), P + mark * n])
        drawn += ax.plot(*corner.T, color="black", linewidth=0.9, gid="right-angle")
    arrows = [(s["p_u"], "$p_u$"), (s["p_v"], "$p_v$"), (t, r"$t(\varphi)$"), (0.8 * n, "$n$")]
    for vec, _ in arrows:
        _arrow(ax, P, vec)
    arc = np.linspace(0, phi, 30)[:, None]
    drawn += ax.plot(*(P + 0.55 * (np.cos(arc) * t_u + np.sin(arc) * w)).T, color="black", linewidth=1.0)
    drawn += ax.plot(*P[:, None], "o", color="black", markersize=4)
    ax.set_box_aspect((a, b, c))
    ax.view_init(elev=28, azim=35)  # both planes seen from their face for most phi (edge-on near 145 degrees)
    ax.set_axis_off()
    ax.set_title(r"the normal section at angle $\varphi$ (thick); dashed: circle of radius $1/\kappa_n$", fontsize=10)
    point = "$(a, 0, 0)$" if np.allclose(P, (a, 0.0, 0.0)) else f"$({P[0]:.2f}, {P[1]:.2f}, {P[2]:.2f})$"
    labels = [(P + vec, label, None, vec) for vec, label in arrows]  # beyond the tips
    half = np.cos(phi / 2) * t_u + np.sin(phi / 2) * w
    labels += [
        (P + 0.55 * half, r"$\varphi$", None, half),
        (P, point, None, -half),
    ]  # in the angle; the point's opposite
    labels.append((normal_patch[0], r"plane of $t$ and $n$", 9, None))
    arrow_lines = [c for c in ax.collections if c is not mesh and hasattr(c, "_segments3d")]
    place_labels(ax, labels, drawn + arrow_lines)  # clear of every line but the light wire mesh
    degrees = np.degrees(phi)
    alt = (
        f"A 3D sketch of the ellipsoid with semi-axes a = {a:g}, b = {b:g}, c = {c:g}, drawn as a light wire mesh. "
        f"At the point ({P[0]:.2f}, {P[1]:.2f}, {P[2]:.2f}) a grey patch of the tangent plane carries the arrows "
        f"p_u (length {np.linalg.norm(s['p_u']):.2f}) and p_v (length {np.linalg.norm(s['p_v']):.2f}) and the unit "
        f"tangent t at phi = {degrees:.0f} degrees from p_u; the arrow n is the outward normal, right-angle marks "
        f"showing it perpendicular to the patch. The plane of n and t "
        f"(a light patch with a dash-dot outline) cuts the ellipsoid in the thick curve, the normal section; the dashed circle touching it at the point has "
        f"radius 1/kappa_n = {1 / k:.3f}, the curvature of the section there being kappa_n = {k:.3f} per length unit."
    )
    return fig, alt


def polar_and_dupin_figure(phis, kappa, a, b, c):
    """(fig, alt): kappa_n(phi) at (a, 0, 0) as a polar curve, and Dupin's indicatrix beside it.

    ``kappa`` (values at the angles ``phis``, radians from p_u) is drawn as a radius in
    direction phi (left) and as the radius 1/sqrt(|kappa_n|) (right, solid), over the ellipse
    kappa_u xi^2 + kappa_v eta^2 = 1 of the exact principal curvatures kappa_u = a/b^2,
    kappa_v = a/c^2 (dotted). The alt text reports the plotted extremes and where they are.
    """
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    phis, kappa = np.asarray(phis, dtype=float), np.asarray(kappa, dtype=float)
    k_u, k_v = a / b**2, a / c**2
    fig = plt.figure(figsize=(9, 4.3))
    ax1 = fig.add_subplot(1, 2, 1, projection="polar")
    ax1.plot(phis, kappa, color="black")
    ax1.yaxis.set_major_locator(MaxNLocator(3))  # three radial labels, apart from each other
    ax1.set_rlabel_position(112.5)
    ax1.set_xticks(np.radians([0, 90, 180, 270]), [r"$0$ ($p_u$)", r"$\pi/2$ ($p_v$)", r"$\pi$", r"$3\pi/2$"])
    ax1.set_title(r"$\kappa_n(\varphi)$ at $(a, 0, 0)$ (1/length)", fontsize=10, pad=14)
    r = 1 / np.sqrt(np.abs(kappa))
    ax2 = fig.add_subplot(1, 2, 2)
    ax2.plot(r * np.cos(phis), r * np.sin(phis), color="0.6", linewidth=3, label=r"$1/\sqrt{|\kappa_n|}$")
    ellipse = np.cos(phis) / np.sqrt(k_u), np.sin(phis) / np.sqrt(k_v)
    ax2.plot(*ellipse, "k:", linewidth=1.5, label=r"$\kappa_u \xi^2 + \kappa_v \eta^2 = 1$")
    ax2.set_aspect("equal")
    ax2.set_xlabel(r"$\xi$, along $p_u$ (length$^{1/2}$)")
    ax2.set_ylabel(r"$\eta$, along $p_v$")
    ax2.set_title("Dupin's indicatrix", fontsize=10)
    ax2.legend(loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=2, fontsize=9, frameon=False)
    fig.tight_layout()
    top, low = int(np.argmax(kappa)), int(np.argmin(kappa))
    # the indicatrix's semi-axes as plotted: its radius in the directions of p_u (phi = 0) and p_v (phi = pi/2)
    r_u, r_v = (float(r[np.argmin(np.abs(np.angle(np.exp(1j * (phis - x)))))]) for x in (0, np.pi / 2))
    alt = (
        f"Left, a polar plot of the normal curvature at (a, 0, 0) of the ellipsoid a = {a:g}, b = {b:g}, c = {c:g}: "
        f"the radius is largest, {kappa[top]:.3f}, at phi = {np.degrees(phis[top]):.0f} degrees and smallest, "
        f"{kappa[low]:.3f}, at phi = {np.degrees(phis[low]):.0f} degrees from p_u, repeating every 180 degrees. "
        f"Right, Dupin's indicatrix: the radius 1/sqrt(kappa_n) traces an ellipse with semi-axes "
        f"{r_u:.3f} along p_u and {r_v:.3f} along p_v, on top of the dotted ellipse "
        f"drawn from the principal curvatures a/b^2 = {k_u:.3f} and a/c^2 = {k_v:.3f}."
    )
    return fig, alt


def kappa_turn_figure(a, b, c, swapped=False):
    """(fig, alt): kappa_n(phi) at (a, 0, 0) over a full turn, with a/b^2 and a/c^2 marked.

    Values from ``ellipsoid_normal_curvature``; ``swapped`` adds the curve of the ellipsoid with b
    and c exchanged (dash-dot). Lines are told apart by style and direct labels.
    """
    import matplotlib.pyplot as plt

    from ...lessons.symbolic import ellipsoid_normal_curvature

    phis = np.linspace(0, 2 * np.pi, 361)
    kappa = ellipsoid_normal_curvature(a, b, c, phis)
    fig, ax = plt.subplots(figsize=(7, 3.2))
    ax.plot(phis, kappa, color="black", label=f"$a={a:g}$, $b={b:g}$, $c={c:g}$")
    if swapped:
        ax.plot(phis, ellipsoid_normal_curvature(a, c, b, phis), "-.", color="0.4", label="$b$ and $c$ swapped")
    marks = [(a / b**2, "--", r"$a/b^2$ (along $p_u$)"), (a / c**2, ":", r"$a/c^2$ (along $p_v$)")]
    if abs(marks[0][0] - marks[1][0]) < 0.06 * max(marks[0][0], marks[1][0]):
        # closer than a line of text on this axis: one label, or the two would print over each other
        marks = [(a / b**2, "--", r"$a/b^2 \approx a/c^2$" if b != c else r"$a/b^2 = a/c^2$")]
    for value, style, text in marks:
        ax.axhline(value, color="0.5", linestyle=style, linewidth=0.9)
        ax.annotate(text, (2 * np.pi, value), xytext=(4, 0), textcoords="offset points", va="center", fontsize=9)
    ax.set_xticks(np.pi * np.arange(0, 2.01, 0.5), ["0", r"$\pi/2$", r"$\pi$", r"$3\pi/2$", r"$2\pi$"])
    ax.set_xlabel(r"$\varphi$ (rad, from $p_u$ towards $p_v$)")
    ax.set_ylabel(r"$\kappa_n$ (1/length)")
    ax.set_ylim(0, 1.3 * max(a / b**2, a / c**2))
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.22), ncol=2, frameon=False)
    ax.set_title(r"normal curvature at $(a, 0, 0)$", fontsize=10)
    spread = float(kappa.max() - kappa.min())
    shape = (
        "a flat line: every direction is principal (an umbilic)"
        if spread < 1e-9 * kappa.max()
        else f"a wave of period pi between {kappa.min():.3f} and {kappa.max():.3f}, touching a/b^2 at phi = 0 and "
        "a/c^2 at phi = pi/2"
    )
    alt = (
        f"Line plot of the normal curvature at (a, 0, 0) against phi from 0 to 2 pi for a = {a:g}, b = {b:g}, "
        f"c = {c:g}, with dashed and dotted lines at a/b^2 = {a / b**2:.3f} and a/c^2 = {a / c**2:.3f}: {shape}."
        + (
            " The dash-dot curve of the ellipsoid with b and c swapped is the same wave shifted by pi/2."
            if swapped
            else ""
        )
    )
    return fig, alt
