"""The notebooks' pictures show what their sentences promise: measured on the stills the notebooks draw.

Each test runs a notebook as a reader would (``notebook_runner``) and measures the still picture of a view
(the image/png a page without a widget front-end shows), or moves a view's sliders in the notebook's own
kernel and measures the still at every position.
"""

import base64
import io
import json

import numpy as np
import pytest
from notebook_runner import ran
from PIL import Image

pytestmark = pytest.mark.slow


def _still(run, cell_id):
    """((h, w, 3) uint8, alt text): the still picture the cell ``cell_id`` displayed."""
    cell = next(c for c in run.notebook.cells if c.get("id") == cell_id)
    shown = [out for out in cell.get("outputs", []) if "image/png" in out.get("data", {})]
    assert len(shown) == 1, f"{cell_id} displayed {len(shown)} pictures"
    picture = Image.open(io.BytesIO(base64.b64decode(shown[0]["data"]["image/png"]))).convert("RGB")
    return np.asarray(picture), shown[0].get("metadata", {}).get("image/png", {}).get("alt", "")


def _coloured(picture):
    """Pixels whose colour is not a grey (the colour map's ends, not the shaded white of ~0)."""
    picture = picture.astype(int)
    return (picture.max(axis=2) - picture.min(axis=2)) > 40


def test_05_the_top_eigenvector_is_seen_where_it_lives():
    run = ran("05_explicit_smoothing.ipynb", BREAK_ITERATIONS=20, ITERATIONS=0)
    still, alt = _still(run, "nb05-026")
    render = still[18 : 18 + 340]  # below the title, above the colour bar
    # 99 % of the mode sits on a handful of vertices: zoomed onto them, its colours cover a visible patch
    # (the whole plane's still had 0.02 % of its pixels coloured: one speck)
    assert _coloured(render).mean() > 0.02
    assert "zoomed onto the 7 of the 1681 vertices that hold 99 %" in alt.lower()


MEASURE_06 = """
import json
rows = []
slider_steps, value, view, top_count = knobs.positions, knobs.value, knobs.view, knobs.controls["iterations"].max
chosen = [slider_steps[0], value, slider_steps[-1]]
runs = [(s, n, keep, "fixed") for s in slider_steps for n in (1, ITERATIONS, top_count) for keep in (False, True)]
runs += [(s, top_count, keep, "rebuilt") for s in chosen for keep in (False, True)]
for s, n, keep, op in runs:
    knobs.update(s, n, keep, op)
    picture = view.still()[18 : 18 + view.height] if view.title else view.still()[: view.height]
    ink = (picture < 245).any(axis=2)
    rows.append(dict(step=float(s), n=n, keep=keep, op=op, pixels=int(ink.sum()),
                     border=int(ink[0].sum() + ink[-1].sum() + ink[:, 0].sum() + ink[:, -1].sum()),
                     title=view._title.value))
knobs.update(value, 0, False, "fixed")
input_pixels = int((view.still()[18 : 18 + view.height] < 245).any(axis=2).sum())
print(json.dumps(dict(rows=rows, input=input_pixels, top=float(slider_steps[-1] / value))))
"""


def test_06_every_position_of_the_sliders_shows_the_part_in_frame():
    run = ran("06_implicit_smoothing.ipynb", after=MEASURE_06)
    cell = run.notebook.cells[-1]
    found = json.loads("".join(out["text"] for out in cell.outputs if out.get("name") == "stdout"))
    rows = found["rows"]
    assert found["top"] == pytest.approx(10.0)  # STEP / 100 to 10 STEP
    assert len(rows) == 13 * 3 * 2 + 6
    # in frame: the mesh touches no edge of the picture; readable: at least a twentieth of the input's pixels
    # (at 100 STEP and 50 iterations the view was blank, 0 pixels; with the volume kept it ran out of the frame)
    assert [r for r in rows if r["border"]] == []
    assert min(r["pixels"] for r in rows) > found["input"] / 20, min(rows, key=lambda r: r["pixels"])
    # a collapse is drawn enlarged and says so; shrinkage short of it is drawn to the input's scale
    top = max(r["step"] for r in rows)
    shrunk = [r for r in rows if r["step"] == top and r["n"] == 50 and not r["keep"]]
    assert shrunk and all("x larger" in r["title"] for r in shrunk)
    assert any(r["pixels"] < 0.8 * found["input"] and "drawn" not in r["title"] for r in rows)


def test_07_says_the_assignments_noise_tangles_the_mesh_and_shows_a_level_that_does_not():
    run = ran("07_denoising_evaluation.ipynb")
    text = run.outputs_text()
    # sigma = 0.05 of the diagonal is 2.29 mean edges on the sphere: the noisy faces point almost anywhere
    assert "moves each coordinate by 2.29 mean edge" in text and "the noisy mesh is tangled" in text
    assert "its face normals are 87.9° off the clean ones" in text
    assert "At $\\sigma$ = 0.005 (0.23 mean edges) they are 25.2° off: a surface, the second row." in text
    cell = next(c for c in run.notebook.cells if c.get("id") == "nb07-008")
    alts = [out["metadata"]["image/png"]["alt"] for out in cell.outputs if "image/png" in out.get("data", {})]
    assert len(alts) == 2 and "3D view of noisy, sigma 0.005" in alts[1] and "Faces 25.2 degrees off" in alts[1]
    assert not run.notes, run.notes


def test_01_the_flat_plane_is_white_over_its_colour_bar():
    run = ran("01_uniform_laplace_curvature.ipynb")
    for cell_id in ("08d83201", "0f1b474c"):  # the rows of uniform H and of K: the plane left
        still, alt = _still(run, cell_id)
        plane = still[:, :380]
        render = plane[18 : 18 + 340]
        drawn = render[np.any(render < 250, axis=2) & ~_coloured(render)]  # the surface but its violet NaN rim
        assert np.median(drawn) > 220, cell_id  # white, as the text calls zero (a light at the eye drew it 156)
        bar = plane[18 + 340 + 6 + 5, 60:-60].astype(int)  # the colour bar's middle row
        assert bar[:, 2].max() - bar[:, 0].min() > 100, cell_id  # drawn: blue to red, 0 white between
        assert "0 everywhere" in alt


def test_02_while_graded_the_slider_plot_is_its_alt_text_on_nbgraders_feedback_pages(monkeypatch):
    # while nbgrader runs a notebook a widget would be text on the static feedback page, "VBox(children=...)";
    # a grading run draws no picture: each figure gives its alt text
    monkeypatch.setenv("NBGRADER_EXECUTION", "autograde")
    run = ran("02_fundamental_forms.ipynb")
    cell = next(c for c in run.notebook.cells if c.get("id") == "93d15836")
    (shown,) = [out["data"] for out in cell.get("outputs", []) if "data" in out]
    assert list(shown) == ["text/plain"]
    assert "".join(shown["text/plain"]).startswith("Figure: Line plot of the normal curvature at (a, 0, 0)")
    assert "VBox(" not in run.outputs_text()
    assert not any("image/png" in out.get("data", {}) for c in run.notebook.cells for out in c.get("outputs", []))
