"""geomlib.lessons.filters: the per-mode factor of each smoothing step, against its formula and the
inequalities the notebooks quote (1/(1 + x) > exp(-x) > 1 - x for x > 0)."""

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest

from geomlib import MeshError
from geomlib.lessons.filters import SCHEMES, mode_factor
from geomlib.teaching.figures.filter_plots import plot_mode_factors


def test_factors_at_known_points():
    lam = np.array([0.0, 1.0, 2.0, 4.0])
    tau = 0.5
    np.testing.assert_allclose(mode_factor(lam, tau, "explicit"), [1.0, 0.5, 0.0, -1.0])
    np.testing.assert_allclose(mode_factor(lam, tau, "implicit"), [1.0, 2 / 3, 0.5, 1 / 3])
    np.testing.assert_allclose(mode_factor(lam, tau, "crank-nicolson"), [1.0, 0.6, 1 / 3, 0.0])
    np.testing.assert_allclose(mode_factor(lam, tau, "diffusion"), np.exp(-tau * lam))
    np.testing.assert_allclose(mode_factor(lam, tau, "taubin", tau_inflate=-0.6), (1 - 0.5 * lam) * (1 + 0.6 * lam))


def test_implicit_is_weaker_than_diffusion_and_explicit_stronger():
    x = np.geomspace(1e-3, 1e3, 200)
    implicit, diffusion, explicit = (mode_factor(x, 1.0, s) for s in ("implicit", "diffusion", "explicit"))
    assert (implicit > diffusion).all() and (diffusion > explicit).all()
    # the explicit step stays in [-1, 1] exactly up to tau lam = 2; the implicit and CN ones always
    assert (np.abs(explicit[x <= 2]) <= 1).all() and (np.abs(explicit[x > 2]) > 1).all()
    assert (np.abs(mode_factor(x, 1.0, "crank-nicolson")) <= 1).all() and (implicit > 0).all()


def test_taubin_keeps_low_frequencies_and_needs_its_signs():
    lam = np.array([0.0, 1e-3])
    f = mode_factor(lam, 0.5, "taubin", tau_inflate=-0.53)
    assert f[0] == 1.0 and f[1] > 1.0 - 1e-4  # the pass band is (nearly) untouched
    with pytest.raises(MeshError, match="tau_inflate < 0"):
        mode_factor(lam, 0.5, "taubin", tau_inflate=0.5)
    with pytest.raises(MeshError, match="scheme must be one of"):
        mode_factor(lam, 0.5, "heun")


def test_plot_draws_every_scheme_and_the_eigenvalue_band():
    ax = plot_mode_factors(2.0, 50.0, 0.01, taubin=(0.01, -0.0105))
    labels = [line.get_label() for line in ax.get_lines()]
    for scheme in SCHEMES[:-1]:
        assert scheme in labels
    assert any(label.startswith("Taubin") for label in labels)
    assert len(ax.patches) == 1 and ax.patches[0].get_label() == "this mesh's eigenvalues"


def test_a_taubin_pair_that_rises_above_1_gets_a_zoom_where_the_rise_is_seen():
    # 05's pair (tau, -1.05 tau): the factor exceeds 1 by at most 0.05^2 / (4 * 1.05) = 0.000595, invisible
    # on axes from -2.2 to 1.2; the zoom's y range is 1.8 times the rise, so the rise fills most of it
    tau = 0.01
    ax = plot_mode_factors(2.0, 50.0, tau, taubin=(tau, -1.05 * tau))
    zoom = [other for other in ax.figure.axes if other is not ax]
    assert len(zoom) == 1
    lo, hi = zoom[0].get_ylim()
    top = 1 + 0.05**2 / (4 * 1.05)
    assert lo < 1 < top < hi and (top - 1) / (hi - lo) > 0.5
    (curve,) = [line for line in zoom[0].get_lines() if line.get_label().startswith("_") and len(line.get_xdata()) > 2]
    assert np.isclose(curve.get_ydata().max(), top, atol=1e-7)
    label = next(line.get_label() for line in ax.get_lines() if line.get_label().startswith("Taubin"))
    assert "(0.01, -0.0105)" in label and r"$|\tau_{inflate}| > \tau_{shrink}$" in label
    # a pair with |tau_inflate| <= tau_shrink (07's (tau, -tau)) never exceeds 1: no zoom, and the label says so
    ax = plot_mode_factors(2.0, 50.0, tau, taubin=(tau, -tau))
    assert ax.figure.axes == [ax]
    label = next(line.get_label() for line in ax.get_lines() if line.get_label().startswith("Taubin"))
    assert "at most 1" in label and mode_factor(np.linspace(0, 60, 100), tau, "taubin", -tau).max() <= 1


def test_explicit_damps_more_than_diffusion_in_magnitude_only_below_x_1_2785():
    # the module docstring: the signed chain holds for every x > 0, the magnitudes cross at x = 1.2785
    x = np.linspace(1e-3, 1.999, 4000)
    explicit, diffusion, implicit = (mode_factor(x, 1.0, s) for s in ("explicit", "diffusion", "implicit"))
    assert (implicit > diffusion).all() and (diffusion > explicit).all()
    crossing = x[np.argmax(np.abs(explicit) > diffusion)]
    assert abs(crossing - 1.2785) < 1e-3
    assert (np.abs(explicit[x < 1.278]) < diffusion[x < 1.278]).all()
    assert np.isclose(abs(mode_factor(1.8, 1.0, "explicit")), 0.8)
    assert np.isclose(mode_factor(1.8, 1.0, "diffusion"), 0.1653, atol=1e-4)


def test_no_curve_is_told_apart_by_colour_alone():
    ax = plot_mode_factors(2.0, 50.0, 0.01, taubin=(0.01, -0.0105), past=0.05)
    looks = [
        (line.get_linestyle(), line.get_marker()) for line in ax.get_lines() if not line.get_label().startswith("_")
    ]
    assert len(looks) == len(set(looks)) == 7


def test_a_step_past_the_limit_is_drawn_with_the_point_where_it_leaves_the_band():
    ax = plot_mode_factors(2.0, 50.0, 0.01, past=1.1 * 2 / 50.0)
    marks = [line for line in ax.get_lines() if line.get_label().startswith("leaves")]
    assert len(marks) == 1
    (lam,), (factor,) = marks[0].get_data()
    assert np.isclose(lam, 50.0 / 1.1) and factor == -1.0 and lam < 50.0  # inside the band: it diverges
    assert np.isclose(mode_factor(lam, 1.1 * 2 / 50.0, "explicit"), -1.0)
