"""geomlib.teaching.display.site_states: the slider states the website replays.

A recorded state must be what the notebook's callback draws for that value: the
test builds 01's tessellation slider (the same geomlib calls as its callback) on
a small saddle, records it, decodes the stored state the way tools/site_states.js
does, and compares it with a view updated directly by the callback's calls.
"""

import base64
import gzip
import json

import ipywidgets
import numpy as np
import pytest

from geomlib import gaussian_curvature as gaussian_K
from geomlib import mean_curvature, surfaces
from geomlib.teaching.display.site_states import MAX_VALUES, record, slider_values
from geomlib.teaching.display.viewer import MeshView, side_by_side

N, JITTER_MAX, SEED = 6, 0.4, 3


def _curvatures(jitter):
    s = surfaces.saddle(n=N, jitter=jitter, seed=SEED)
    return s, mean_curvature(s.V, s.F, weights="uniform", signed=True, boundary="nan"), gaussian_K(s.V, s.F)


def _tessellation_cell():
    """01's jitter slider: two views and a callback that recomputes both curvatures."""
    base, H0, K0 = _curvatures(0.0)
    hview = MeshView(base.V, base.F, H0, symmetric=True, title="uniform H", label="H uniform (length)")
    kview = MeshView(base.V, base.F, K0, symmetric=True, vmin=-5.0, vmax=5.0, title="K", label="K (1/length^2)")
    jitter = ipywidgets.FloatSlider(value=0.0, min=0.0, max=JITTER_MAX, step=JITTER_MAX / 8, description="jitter")

    def on_jitter(change):
        s, H, K = _curvatures(change["new"])
        hview.update(V=s.V, values=H)
        kview.update(V=s.V, values=K)

    jitter.observe(on_jitter, "value")
    return ipywidgets.VBox([jitter, side_by_side(hview, kview).widget]), jitter, hview, kview


def _decode(original, trait, j):
    """The array of state ``j`` as tools/site_states.js rebuilds it from the page's own array."""
    out = np.array(original, dtype=np.float32).reshape(len(original), -1)
    state = trait["states"][j]
    q = np.frombuffer(gzip.decompress(base64.b64decode(state["q"])), dtype="<u2").reshape(len(out), -1)
    for c, col in enumerate(trait["array"]["columns"]):
        lo, hi = state["lo"][c], state["hi"][c]
        out[:, col] = lo + q[:, c] * ((hi - lo) / 65535)
    return out


def test_a_recorded_state_is_what_the_callback_draws(tmp_path):
    box, jitter, hview, kview = _tessellation_cell()
    buffer = {v: v.geometry.attributes["position"].data for v in (hview, kview)}  # the interleaved buffer
    shown_before = buffer[hview].array.copy()
    record([box.model_id], str(tmp_path / "states.json"))
    (slider,) = json.loads((tmp_path / "states.json").read_text())["sliders"]
    assert slider["model_id"] == jitter.model_id and slider["values"] == slider_values(jitter)
    assert slider["values"][slider["default"]] == 0.0 and len(slider["values"]) == 9
    # the slider is back at its default and so is the picture
    assert jitter.value == 0.0 and np.array_equal(buffer[hview].array, shown_before)

    j = slider["values"].index(0.25)
    s, H, K = _curvatures(0.25)
    base = surfaces.saddle(n=N)
    for view, values, bound in ((hview, H, None), (kview, K, 5.0)):
        # positions are drawn relative to the first mesh's centre: frame the expected view on it
        low = None if bound is None else -bound
        expected = MeshView(s.V, s.F, values, symmetric=True, vmin=low, vmax=bound, frame=base.V)
        (trait,) = [t for t in slider["traits"] if t["model_id"] == buffer[view].model_id]
        assert trait["states"][slider["default"]] is None  # the page's own array
        state = _decode(buffer[view].array, trait, j)
        np.testing.assert_allclose(state[:, 0:3], expected.positions, atol=2e-4)
        np.testing.assert_allclose(state[:, 3:6], expected.normals, atol=2e-4)
        np.testing.assert_allclose(state[:, 6:9], expected.colors, atol=2e-4)
    # the colour bar of H (its range follows the values) is recorded as text
    colorbar = hview.widget.children[2]
    (bar,) = [t for t in slider["traits"] if t["model_id"] == colorbar.model_id]
    hview.update(V=s.V, values=H)
    assert bar["states"][j] == colorbar.value and bar["states"][0] != colorbar.value


def test_a_slider_that_changes_nothing_shown_is_left_out(tmp_path):
    lonely = ipywidgets.IntSlider(value=2, min=0, max=5, description="n")
    lonely.observe(lambda change: None, "value")
    record([ipywidgets.VBox([lonely]).model_id], str(tmp_path / "states.json"))
    states = json.loads((tmp_path / "states.json").read_text())
    assert states["sliders"] == []
    assert states["left_out"][0]["reason"] == "moving it changes nothing the cell shows"


def test_values_a_reader_would_try():
    k = ipywidgets.IntSlider(value=15, min=1, max=200)
    assert slider_values(k) == [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 15, 20, 30, 50, 100, 150, 200]
    sigma = ipywidgets.FloatSlider(value=0.005, min=0.0, max=0.05, step=1e-5)
    assert {0.0, 0.001, 0.002, 0.005, 0.01, 0.02, 0.05} <= set(slider_values(sigma))
    # a log grid is thinned from the default, keeping both ends (the top one past a stability limit)
    tau = ipywidgets.FloatLogSlider(value=0.03, base=10, min=np.log10(0.03) - 2.5, max=np.log10(0.03) + 1, step=0.05)
    values = slider_values(tau)
    assert len(values) <= MAX_VALUES + 2 and 0.03 in values
    assert values[0] == pytest.approx(10**tau.min) and values[-1] == pytest.approx(10**tau.max)
    small = ipywidgets.FloatSlider(value=0.1, min=0.0, max=0.4, step=0.05)
    assert slider_values(small) == [0.0, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4]


def test_a_plot_in_an_output_widget_is_not_replayed(tmp_path):
    """The kernel never sees what an Output widget captures: such a slider stays disabled."""
    a = ipywidgets.FloatSlider(value=1.0, min=0.0, max=2.0, step=0.5, description="a")
    out = ipywidgets.interactive_output(lambda a: print(a), {"a": a})
    out.msg_id = ""  # what a kernel's Output does around each capture: it must not count as a change
    out.observe(lambda change: setattr(out, "msg_id", "capturing"), "outputs")
    a.observe(lambda change: setattr(out, "msg_id", f"message {change['new']}"), "value")
    record([ipywidgets.VBox([a, out]).model_id], str(tmp_path / "states.json"))
    states = json.loads((tmp_path / "states.json").read_text())
    assert states["sliders"] == [] and states["left_out"][0]["description"] == "a"


def test_the_text_alternative_of_a_view_moves_with_its_slider(tmp_path):
    # the website replays the caption under a view (its alt_text) with the view: a description
    # the callback sets for a value is the one the page shows, and announces, for that value
    base, H0, _ = _curvatures(0.0)
    view = MeshView(base.V, base.F, H0, symmetric=True, label="H (length)", description="smooth saddle")
    jitter = ipywidgets.FloatSlider(value=0.0, min=0.0, max=JITTER_MAX, step=JITTER_MAX / 8, description="jitter")

    def on_jitter(change):
        s, H, _ = _curvatures(change["new"])
        view.update(V=s.V, values=H, description=f"vertices moved by up to {change['new']:.2f} of an edge")

    jitter.observe(on_jitter, "value")
    box = ipywidgets.VBox([jitter, view.widget])
    record([box.model_id], str(tmp_path / "states.json"))
    (slider,) = json.loads((tmp_path / "states.json").read_text())["sliders"]
    (caption,) = [t for t in slider["traits"] if t["model_id"] == view._caption.model_id]
    j = slider["values"].index(0.25)
    assert "Vertices moved by up to 0.25 of an edge." in caption["states"][j]
    assert "Smooth saddle." in caption["states"][slider["default"]]
    s, H, _ = _curvatures(0.25)
    view.update(V=s.V, values=H, description="vertices moved by up to 0.25 of an edge")
    assert caption["states"][j] == view._caption.value  # what the kernel would show
