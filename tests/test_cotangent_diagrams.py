"""Notebook 03's diagrams draw geomlib's own geometry: the hat gradients give the cotangent C,
the drawn regions have the mixed areas, and the alt texts carry the numbers drawn."""

import re

import matplotlib
import numpy as np
import pytest

from geomlib.lessons.laplace import barycentric_areas, cotangent_matrix, mixed_areas
from geomlib.mesh.errors import MeshError
from geomlib.teaching.figures import cotangent_diagrams as d
from geomlib.teaching.shapes import surfaces

matplotlib.use("Agg")


def test_hat_gradients_are_the_linear_hats():
    s = surfaces.sphere(1.0, subdivisions=2, jitter=0.3, seed=1)
    G = d.hat_gradients(s.V, s.F)
    P = s.V[s.F]
    for c in range(3):  # psi_c is 1 at corner c and 0 at the other two
        for o in range(3):
            if o != c:
                assert np.allclose(np.einsum("fd,fd->f", G[:, c], P[:, c] - P[:, o]), 1.0)
    assert np.allclose(G.sum(axis=1), 0.0)  # the hats sum to 1, a constant


def test_the_integral_of_grad_psi_i_dot_grad_psi_j_is_minus_C_ij():
    s = surfaces.sphere(1.0, subdivisions=2, jitter=0.45, seed=3)  # obtuse triangles, negative weights
    G = d.hat_gradients(s.V, s.F)
    A = np.linalg.norm(np.cross(s.V[s.F[:, 1]] - s.V[s.F[:, 0]], s.V[s.F[:, 2]] - s.V[s.F[:, 0]]), axis=1) / 2
    n = len(s.V)
    K = np.zeros((n, n))
    for a in range(3):
        for b in range(3):
            np.add.at(K, (s.F[:, a], s.F[:, b]), A * np.einsum("fd,fd->f", G[:, a], G[:, b]))
    C = cotangent_matrix(s.V, s.F).toarray()
    assert (C[~np.eye(n, dtype=bool)] < 0).any()
    assert np.allclose(K, -C, atol=1e-12)


def test_circumcentres_are_equidistant_and_regions_sum_to_the_mixed_areas():
    p = surfaces.plane(n=6, jitter=0.35, seed=5)
    O = d.circumcentres(p.V, p.F)
    r = np.linalg.norm(p.V[p.F] - O[:, None], axis=2)
    assert np.allclose(r, r[:, :1])
    A = np.zeros(len(p.V))
    for f in range(len(p.F)):
        for c in range(3):
            A[p.F[f, c]] += d.polygon_area(d.mixed_region(p.V, p.F, f, c))
    assert np.allclose(A, mixed_areas(p.V, p.F))


def test_the_figures_say_what_they_draw():
    fig, alt = d.hat_figure()
    assert "6 neighbours" in alt and "C_ij = (cot alpha + cot beta)/2 = " in alt
    h, L = map(float, re.search(r"h_i = ([\d.]+) over it dotted, so its arrow has length (\d+\.\d+)", alt).groups())
    assert abs(L * h - 1) < 0.02  # both printed to two decimals
    edges = [line for line in fig.axes[1].lines + fig.axes[2].lines if line.get_color() == "0.35"]
    assert edges and all(line.get_linestyle() == "-" for line in edges)  # no edge dashed by the style's cycle
    V, F, i = d.ring_mesh(0.3, 2)
    _, alt = d.voronoi_figure()
    assert f"its area {mixed_areas(V, F)[i]:.3f} is the mixed area" in alt
    assert f"against {barycentric_areas(V, F)[i]:.3f} for the barycentric" in alt
    assert "angles 45, 18, 117 degrees" in alt and "-0.250" in alt


def test_a_zero_area_triangle_has_no_gradient():
    with pytest.raises(MeshError, match="zero-area"):
        d.hat_gradients(np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]]), np.array([[0, 1, 2]]))


def test_the_convergence_figure_shows_every_slope_once_and_says_them():
    from geomlib.teaching.figures.convergence import error_figure

    ell = [0.2, 0.1, 0.05]
    rows = {
        "regular": [
            {"n": 10 * 4**s, "ell": e, ("H", "a"): (e**2, 0.1), ("K", "b"): (e, 0.2)} for s, e in enumerate(ell)
        ],
        "jittered": [
            {"n": 10 * 4**s, "ell": e, ("H", "a"): (0.03, 0.3), ("K", "b"): (0.04, 0.4)} for s, e in enumerate(ell)
        ],
    }
    slopes = {
        (f, k, st): (2.0 if f == "regular" and st == "median" and k[0] == "H" else -0.001)
        for f in rows
        for k in (("H", "a"), ("K", "b"))
        for st in ("median", "max")
    }
    fig, alt = error_figure(rows, slopes)
    styles = {
        t.get_label().split(",")[0]: (t.get_marker(), t.get_color())
        for ax in fig.axes
        for t in ax.lines
        if "," in t.get_label()
    }
    assert styles["a"] != styles["b"]
    labels = [t.get_text() for ax in fig.axes for t in ax.get_legend().get_texts()]
    assert "a, median: slope 2.00" in labels and "a, max: slope 0.00" in labels
    assert "H a 2.00 / 0.00" in alt and "regular and jittered meshes" in alt and "10 to 160 vertices" in alt


def test_an_area_rule_keeps_its_marker_in_the_H_and_the_K_panels():
    from geomlib.teaching.figures.convergence import error_figure

    keys = [("H", "uniform"), ("H", "cotan, barycentric"), ("H", "cotan, mixed"), ("K", "barycentric"), ("K", "mixed")]
    rows = {"regular": [{"n": 10 * 4**s, "ell": e, **{k: (e**2, 0.1) for k in keys}} for s, e in enumerate([0.2, 0.1])]}
    slopes = {("regular", k, st): 2.0 for k in keys for st in ("median", "max")}
    fig, _ = error_figure(rows, slopes)
    seen = {}
    for ax in fig.axes:
        for line in ax.lines:
            if ", median" in line.get_label():
                rule = line.get_label().split(", median")[0].split(", ")[-1]
                seen.setdefault(rule, set()).add((line.get_marker(), line.get_color()))
    assert set(seen) == {"uniform", "barycentric", "mixed"}
    assert all(len(v) == 1 for v in seen.values())  # the same marker and colour in both panels
    assert len({next(iter(v)) for v in seen.values()}) == 3
