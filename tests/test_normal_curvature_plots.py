"""The diagram of notebook 02: the normal section is drawn from the ellipsoid's own geometry."""

import matplotlib
import numpy as np
import pytest

from geomlib.teaching.figures.normal_curvature_plots import (
    kappa_turn_figure,
    normal_section,
    normal_section_figure,
    polar_and_dupin_figure,
)

matplotlib.use("Agg")


@pytest.mark.parametrize("abc,phi,uv", [((1.0, 0.7, 0.5), 0.7, (0.0, np.pi / 2)), ((2.0, 1.3, 0.6), 2.2, (0.7, 1.0))])
def test_the_section_lies_on_the_surface_and_in_the_normal_plane(abc, phi, uv):
    s = normal_section(*abc, phi, *uv)
    C, P, t, n = s["curve"], s["P"], s["t"], s["n"]
    assert np.abs((C**2 / np.square(abc)).sum(axis=1) - 1).max() < 1e-12
    assert np.abs((C - P) @ np.cross(t, n)).max() < 1e-12
    assert np.allclose(C[0], P) and np.allclose(C[-1], P)
    assert abs(t @ n) < 1e-12 and abs(np.linalg.norm(t) - 1) < 1e-12
    # t is at angle phi from p_u, turning towards p_v
    t_u = s["p_u"] / np.linalg.norm(s["p_u"])
    assert np.isclose(t @ t_u, np.cos(phi)) and s["w"] @ s["p_v"] > 0


def test_the_curvature_of_the_drawn_curve_at_the_point_is_kappa_n():
    a, b, c, phi = 1.0, 0.7, 0.5, np.radians(40)
    s = normal_section(a, b, c, phi, samples=20001)
    # the curve near P as a height h(q) over the tangent t, towards -n: h ~ kappa_n q^2 / 2
    near = s["curve"][1:40] - s["P"]
    q, h = near @ s["t"], -(near @ s["n"])
    kappa = np.polyfit(q, h, 4)[-3] * 2
    assert abs(kappa - s["kappa_n"]) < 1e-6 * s["kappa_n"]
    assert np.isclose(s["kappa_n"], a * np.cos(phi) ** 2 / b**2 + a * np.sin(phi) ** 2 / c**2)


def test_the_figure_says_what_it_shows():
    fig, alt = normal_section_figure(1.0, 0.7, 0.5, np.radians(40))
    texts = {t.get_text() for t in fig.axes[0].texts}
    assert {"$p_u$", "$p_v$", r"$t(\varphi)$", "$n$", r"$\varphi$", "$(a, 0, 0)$"} <= texts  # the point named
    assert "phi = 40 degrees" in alt and "kappa_n = 2.850" in alt and "1/kappa_n = 0.351" in alt
    assert "perpendicular to the patch" in alt


@pytest.mark.parametrize("degrees", [10, 40, 90, 150])
def test_no_label_of_the_diagram_sits_on_a_line_or_on_another_label(degrees):
    from geomlib.teaching.figures.normal_curvature_plots import screen_points

    fig, _ = normal_section_figure(1.0, 0.7, 0.5, np.radians(degrees))
    ax = fig.axes[0]
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    mesh = ax.collections[0]  # the light wire mesh of the ellipsoid, under everything
    lines = list(ax.lines) + [c for c in ax.collections if hasattr(c, "_segments3d") and c is not mesh]
    points = screen_points(ax, lines, step=0.5)
    boxes = {t.get_text(): t.get_window_extent(renderer) for t in ax.texts}
    assert len(boxes) == 7
    crossed = {label: int(((points >= b.p0) & (points <= b.p1)).all(axis=1).sum()) for label, b in boxes.items()}
    assert crossed == dict.fromkeys(boxes, 0)
    overlapping = [(a, b) for a in boxes for b in boxes if a < b and boxes[a].overlaps(boxes[b])]
    assert overlapping == []


def test_the_diagram_marks_n_perpendicular_to_the_tangent_patch():
    fig, _ = normal_section_figure(1.0, 0.7, 0.5, np.radians(40))
    s = normal_section(1.0, 0.7, 0.5, np.radians(40))
    marks = [np.column_stack(line.get_data_3d()) for line in fig.axes[0].lines if line.get_gid() == "right-angle"]
    assert len(marks) == 2
    sides = []
    for corner in marks:
        first, second = corner[1] - corner[0], corner[2] - corner[1]
        assert np.allclose(np.cross(first, s["n"]), 0, atol=1e-12)  # one leg along n
        assert abs(second @ s["n"]) < 1e-12 and np.allclose(corner[2] - s["P"], first)  # the other in the patch
        sides.append(second / np.linalg.norm(second))
    assert abs(sides[0] @ sides[1]) < 1e-12  # against two directions of the patch: n is normal to it


@pytest.mark.parametrize("b, c, labels", [(0.7, 0.5, 2), (0.5, 0.5, 1), (0.5, 0.505, 1)])
def test_the_two_principal_labels_never_print_over_each_other(b, c, labels):
    fig, _ = kappa_turn_figure(1.0, b, c)
    assert len(fig.axes[0].texts) == labels


def test_the_indicatrix_alt_reads_the_plotted_radii():
    phis = np.linspace(0, 2 * np.pi, 361)
    kappa = 4 * (np.cos(phis) ** 2 / 0.49 + np.sin(phis) ** 2 / 0.25)  # four times a = 1, b = 0.7, c = 0.5
    _, alt = polar_and_dupin_figure(phis, kappa, 1.0, 0.7, 0.5)
    assert "semi-axes 0.350 along p_u and 0.250 along p_v" in alt
