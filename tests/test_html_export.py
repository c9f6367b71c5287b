"""Without a widget front-end, every 3D view still shows as a picture.

Notebook 00 is executed and exported to HTML the way ``jupyter nbconvert --to
html --execute`` does it, without saving the widget state (as a repository
preview or a course page shows a notebook). Each displayed output that holds
geomlib views must carry a still picture (image/png) of them, and the HTML
page must show every still picture: as many ``data:image/png`` images as the
executed notebook has image outputs, and no widget output left to a
JavaScript widget manager.

The views an output holds are counted in the widget state of the run (the
widgets with CSS class ``geomlib-view`` under the output's widget, at any
depth); the state is then dropped before the export.
"""

import re
from pathlib import Path

import ipywidgets
import nbformat
import numpy as np
import pytest
from nbconvert import HTMLExporter
from nbconvert.preprocessors import ExecutePreprocessor

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOK = ROOT / "notebooks" / "00_getting_started.ipynb"
WIDGET = "application/vnd.jupyter.widget-view+json"


def test_box_still_draws_the_views_inside_a_box_and_nothing_else():
    from geomlib.teaching.display.viewer import MeshView, box_still, side_by_side
    from geomlib.teaching.shapes import surfaces

    V, F = surfaces.icosphere(1)
    view = MeshView(V, F, values=V[:, 2], title="z")
    slider = ipywidgets.FloatSlider()
    assert np.array_equal(box_still(ipywidgets.VBox([slider, view.widget])), view.still())
    assert box_still(ipywidgets.VBox([slider, ipywidgets.HTML("no view")])) is None
    row = side_by_side(MeshView(V, F), MeshView(V, F))
    nested = ipywidgets.VBox([ipywidgets.HBox([slider]), row.widget])
    assert np.array_equal(box_still(nested), row.still())


def views_in(model_id, state):
    """How many geomlib views the widget ``model_id`` holds, at any depth."""
    model = state.get(model_id, {}).get("state", {})
    own = "geomlib-view" in model.get("_dom_classes", [])
    children = [c.removeprefix("IPY_MODEL_") for c in model.get("children", []) if isinstance(c, str)]
    return own + sum(views_in(c, state) for c in children)


@pytest.mark.slow
def test_html_export_without_widget_state_shows_a_still_for_every_view(monkeypatch):
    monkeypatch.setenv("PYTHONPATH", str(ROOT))
    nb = nbformat.read(NOTEBOOK, as_version=4)
    ExecutePreprocessor(timeout=600, store_widget_state=True).preprocess(
        nb, {"metadata": {"path": str(NOTEBOOK.parent)}}
    )
    state = nb.metadata.pop("widgets")["application/vnd.jupyter.widget-state+json"]["state"]

    views = stills = images = 0
    missing = []
    for i, cell in enumerate(nb.cells):
        for output in cell.get("outputs", []):
            data = output.get("data", {})
            images += "image/png" in data
            n = views_in(data[WIDGET]["model_id"], state) if WIDGET in data else 0
            views += n
            if n and "image/png" in data:
                stills += n
            elif n:
                missing.append(f"cell {i}: {n} view(s) shown without a still picture")
    assert views >= 3, f"expected the notebook's views, found {views}"

    page, _ = HTMLExporter().from_notebook_node(nb)
    shown = len(re.findall(r'<img[^>]*src="data:image/png;base64,', page))
    assert shown == images, f"the HTML page shows {shown} of the notebook's {images} pictures"
    assert stills == views, f"{stills} of {views} views have a still picture: {missing}"
