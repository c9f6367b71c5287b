"""Tests of the notebooks' live-cell helpers: the step's unit and one step per mesh
(geomlib.teaching.experiments.steps), sliders wired to views with a read-out (.controls), and
arrows and markers merged into a displayed mesh (.glyphs)."""

import re
import warnings

import ipywidgets
import numpy as np
import pytest

from geomlib import MeshError, MeshWarning
from geomlib.mesh.geometry import enclosed_volume, mean_edge_length
from geomlib.teaching.display.controls import live, live_figure, mesh_warnings
from geomlib.teaching.display.glyphs import Glyphs, arrow_meshes, marker_meshes
from geomlib.teaching.display.viewer import MeshView
from geomlib.teaching.experiments.steps import MeshSteps, absolute_step, log_positions, log_slider
from geomlib.teaching.experiments.sweep import scale_free_step
from geomlib.teaching.shapes import surfaces


@pytest.fixture(scope="module")
def meshes():
    small = surfaces.sphere(1.0, subdivisions=1)
    big = surfaces.sphere(10.0, subdivisions=2)
    return {"plane": (small.V, small.F), "part": (big.V, big.F)}


# --- the step's unit ------------------------------------------------------------


def test_absolute_step_in_both_units(meshes):
    V, F = meshes["part"]
    ell = mean_edge_length(V, F)
    assert absolute_step(0.5, "length^2", V, F) == 0.5
    assert absolute_step(0.5, "ell^2", V, F) == pytest.approx(0.5 * ell**2, rel=1e-15)
    assert absolute_step(0.5, "ell^2", V, F, weights="uniform") == 0.5  # uniform weights: no units
    with pytest.raises(MeshError, match="one of"):
        absolute_step(0.5, "metres", V, F)


def test_the_sweep_uses_the_same_conversion(meshes):
    V, F = meshes["part"]
    assert scale_free_step(V, F, "implicit", "cotan", 1.0) == pytest.approx(mean_edge_length(V, F) ** 2 / 4, rel=1e-14)
    assert scale_free_step(V, F, "implicit", "uniform", 0.3) == 0.3


def test_one_step_for_every_mesh(meshes):
    steps = MeshSteps(0.03, "ell^2", meshes)
    for name, (V, F) in meshes.items():
        assert steps.tau(name) == pytest.approx(0.03 * mean_edge_length(V, F) ** 2, rel=1e-14)
        assert steps.at(name, 0.3) == pytest.approx(10 * steps.tau(name), rel=1e-14)  # the slider shows STEP
    assert str(steps) == "STEP = 0.03 ell^2" and f"{steps:.3f}" == "0.030"


def test_one_step_per_mesh(meshes):
    steps = MeshSteps({"PLANE": 1e-6, "part": 1e-4}, "length^2", meshes)
    assert steps.tau("plane") == 1e-6 and steps.tau("part") == 1e-4
    assert steps.at("plane", 10.0) == pytest.approx(1e-5) and steps.at("part", 10.0) == pytest.approx(1e-3)
    assert str(steps) == "STEP = {PLANE: 1e-06, PART: 0.0001} length^2"
    assert f"{steps:.1e}" == "{PLANE: 1.0e-06, PART: 1.0e-04}"  # as a notebook's text formats STEP
    only_part = MeshSteps({"PART": 1e-4, "PLANE": 1e-3}, "length^2", {**meshes, "cube": meshes["plane"]})
    assert only_part.tau("cube") == 1e-4  # a mesh left out gets the smallest step given


@pytest.mark.parametrize(
    "step, unit, message",
    [
        ({"CUBE": 1e-4}, "length^2", "CUBE, which is not a mesh here"),
        ({"PLANE": -1.0}, "length^2", "a number > 0"),
        (0.0, "ell^2", "a number > 0"),
        ({}, "ell^2", "a number > 0"),
        (1.0, "length", "STEP_UNIT must be one of"),
    ],
)
def test_bad_steps_say_what_is_wrong(meshes, step, unit, message):
    with pytest.raises(MeshError, match=message):
        MeshSteps(step, unit, meshes)


def test_the_slider_reaches_every_limit_and_has_step_on_it(meshes):
    steps = MeshSteps(0.03, "ell^2", meshes)
    limits = {"plane": 0.5 * steps.tau("plane"), "part": 40 * steps.tau("part")}
    slider = steps.slider(limits)
    positions = log_positions(slider)
    assert np.isclose(positions, 0.03, rtol=1e-12).any()
    assert positions[0] <= 0.03 * 0.5 / 20 and positions[-1] >= 0.03 * 40 * 1.5
    per_mesh = MeshSteps({"PLANE": 1e-6, "PART": 1e-4}, "length^2", meshes).slider({"plane": 2e-6, "part": 2e-4})
    assert per_mesh.value == 1.0 and per_mesh.description == "× STEP"


def test_log_slider_positions_are_the_value_times_powers_of_ten():
    slider = log_slider(3e-5, 1e-7, 1e-2, "τ", grid=0.25)
    positions = log_positions(slider)
    np.testing.assert_allclose(positions / 3e-5, 10 ** (0.25 * np.arange(-10, 12)), rtol=1e-12)
    with pytest.raises(MeshError, match="positive"):
        log_slider(0.0, 1e-3, 1.0, "τ")


# --- live cells -----------------------------------------------------------------


def test_live_runs_the_update_now_and_after_every_move(meshes):
    V, F = meshes["plane"]
    view = MeshView(V, F, values=np.zeros(len(V)), vmin=0, vmax=1)
    s = ipywidgets.FloatSlider(value=0.0, min=0.0, max=1.0)
    n = ipywidgets.IntSlider(value=2, min=0, max=5)
    calls = []

    def update(scale, count):
        calls.append((scale, count))
        view.update(V=V * (1 + scale))
        if scale > 0.5:
            warnings.warn(MeshWarning("the run diverged at iteration 3"), stacklevel=1)
        return [f"scale {scale:g}", f"count {count}"]

    knobs = live(update, {"scale": s, "count": n}, view)
    assert calls == [(0.0, 2)]
    s.value = 0.8
    assert calls[-1] == (0.8, 2) and len(knobs.timings) == 2
    np.testing.assert_allclose(view.V, 1.8 * V)
    bundle, metadata = knobs._repr_mimebundle_()
    text = bundle["text/plain"]
    assert text.startswith("scale 0.8\ncount 2\n⚠ the run diverged at iteration 3 (") and text.endswith(" ms)")
    # controls, read-out and view in one box: the browser tests move the slider next to a view
    box = knobs.widget
    assert s in box.children[0].children and view.widget in box.children
    assert "image/png" in bundle
    assert metadata == {"image/png": {"alt": view.alt_text()}}  # the still's alt is the view's text


def test_mesh_warnings_collects_the_messages():
    def run(x):
        warnings.warn(MeshWarning(f"stopped at {x}"), stacklevel=1)
        return 2 * x

    assert mesh_warnings(run, 4) == (8, ["stopped at 4"])


# --- arrows and markers ---------------------------------------------------------


def test_arrows_point_along_their_directions_and_are_closed_outward():
    X = np.array([[0.0, 0, 0], [1.0, 2.0, 3.0]])
    D = np.array([[0.0, 0, 2.0], [1.0, 0, 0]])
    V, F = arrow_meshes(X, D, length=0.5, radius=0.01)
    per = len(V) // 2
    np.testing.assert_allclose(V[per - 2], [0, 0, 0.5])  # the tip of the first, half a unit along z
    np.testing.assert_allclose(V[2 * per - 2], [1.5, 2.0, 3.0])
    for k in range(2):  # each arrow encloses a positive volume: closed, faces counter-clockwise from outside
        Fk = F[(F >= k * per).all(axis=1) & (F < (k + 1) * per).all(axis=1)] - k * per
        assert len(Fk) == len(F) // 2 and enclosed_volume(V[k * per : (k + 1) * per], Fk) > 0
    Vm, Fm = marker_meshes([[1.0, 1.0, 1.0]], 0.1)
    assert enclosed_volume(Vm, Fm) == pytest.approx(4 / 3 * 0.1**3)  # the octahedron's volume
    with pytest.raises(MeshError, match="non-zero"):
        arrow_meshes(X, np.zeros((2, 3)), 1.0, 0.1)


def test_glyphs_merge_into_one_mesh_with_one_value_each(meshes):
    V, F = meshes["plane"]
    H = np.linspace(0, 1, len(V))
    glyphs = Glyphs(V, F, H, size=2.0)
    glyphs.add_arrows([[0, 0, 1.0]] * 2, [[0, 0, 1.0], [1.0, 0, 0]], values=[5.0, np.nan])
    glyphs.add_points([[1.0, 0, 0]])
    V2, F2, H2 = glyphs.mesh()
    assert len(V2) == len(V) + 2 * 26 + 6 and F2.max() == len(V2) - 1
    np.testing.assert_array_equal(H2[: len(V)], H)
    assert (H2[len(V) : len(V) + 26] == 5.0).all() and np.isnan(H2[len(V) + 26 :]).all()
    np.testing.assert_allclose(V2[len(V) + 24], [0, 0, 2.0])  # the tip: size / 2 above the origin


# --- a figure redrawn by sliders ------------------------------------------------


def test_live_figure_is_a_still_picture_where_no_widget_front_end_runs_and_its_text_while_graded(monkeypatch):
    import matplotlib.pyplot as plt

    from geomlib.teaching.display.viewer import box_still

    def draw(k):
        fig, ax = plt.subplots(figsize=(3, 2))
        ax.plot([0, 1], [0, k], color="C3", lw=4)
        ax.set_ylim(0, 3)
        return fig, f"a line rising to {k:g}"

    slider = ipywidgets.FloatSlider(value=1.0, min=0.0, max=3.0, description="k")
    shown = live_figure(draw, {"k": slider})
    assert isinstance(shown.widget, ipywidgets.VBox) and slider in shown.widget.children[0].children
    low = shown.still()
    assert low.ndim == 3 and low.shape[2] == 3 and shown.alt_text() == "a line rising to 1"
    slider.value = 3.0  # the still follows the controls
    high = shown.still()
    assert shown.alt_text() == "a line rising to 3" and not np.array_equal(low, high)
    assert np.array_equal(box_still(shown.widget), high)  # the box alone, as display(box) gives it
    # while nbgrader grades: the figure's alt text, no widget, no "VBox(...)" text and nothing drawn
    monkeypatch.setenv("NBGRADER_EXECUTION", "autograde")
    slider.value = 2.0
    bundle = shown._repr_mimebundle_()
    assert bundle == {"text/plain": "Figure: a line rising to 2"}


def test_while_grading_the_implicit_explorer_shows_what_it_shows_a_reader(meshes, monkeypatch):
    from geomlib.teaching.display.smoothing_controls import implicit_explorer

    steps = MeshSteps(1.0, "ell^2", meshes)
    reader = implicit_explorer(*meshes["part"], steps, "part", 5, 1.0)
    monkeypatch.setenv("NBGRADER_EXECUTION", "autograde")
    grader = implicit_explorer(*meshes["part"], steps, "part", 5, 1.0)

    def said(knobs):  # the read-out without its time
        return re.sub(r" \([\d.]+ ms\)", "", knobs.readout.value)

    assert said(grader) == said(reader) and "tau = " in said(reader)  # the starting position, prepared in both
    np.testing.assert_array_equal(grader.view.V, reader.view.V)
    for knobs in (reader, grader):  # a position the graded run did not prepare is factorised when asked
        knobs.controls["step"].value = knobs.positions[0]
    assert said(grader) == said(reader)
    np.testing.assert_array_equal(grader.view.V, reader.view.V)
