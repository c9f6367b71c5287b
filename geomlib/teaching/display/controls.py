"""Sliders wired to 3D views in one call, with a read-out line: the notebooks' live cells.

``live(update, controls, views)`` is to a lesson what ipywidgets' ``interact`` is:
the lesson writes a pure ``update`` that recomputes and calls ``view.update``;
the call lays the controls out above the views, observes them, times every
update and shows a read-out line under the controls: the text ``update``
returns, the warnings the run raised (a diverging run's ``MeshWarning``), and
the time it took.

    steps = log_slider(STEP, lo, hi, "τ / ℓ²")      # geomlib.teaching.experiments.steps
    n = ipywidgets.IntSlider(30, min=0, max=300, description="iterations", continuous_update=False)

    def update(step, iterations):
        P = smoother.smooth(step, iterations)
        view.update(V=P, values=np.linalg.norm(P - V, axis=1))
        return f"tau = {step:.3g}"

    live(update, {"step": steps, "iterations": n}, view)

The controls are real ipywidgets and the views real :class:`MeshView` widgets in
one box, as the browser tests and the website expect (geomlib/teaching/display/viewer.py
says how they find them). ``mesh_warnings(run, ...)`` gives the same read-out of
warnings for a run outside a live cell.
"""

import html
import time
import warnings

from ...mesh.errors import MeshError, MeshWarning
from .stills import png_base64
from .viewer import MeshView, ViewRow, box_alt, box_still, stills_only

__all__ = ["live", "Live", "mesh_warnings"]


def mesh_warnings(run, *args, **kwargs):
    """``run(*args, **kwargs)`` with its MeshWarnings caught: (result, list of the messages)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", MeshWarning)
        result = run(*args, **kwargs)
    return result, [str(w.message) for w in caught if issubclass(w.category, MeshWarning)]


class Live:
    """Controls, a read-out line and views in one box (:func:`live`); displays as that box.

    Attributes
    ----------
    widget : ipywidgets.VBox
    controls : dict name -> control
    readout : ipywidgets.HTML, the line under the controls
    timings : list of float, seconds each update took
    """

    def __init__(self, update, controls, views, per_row):
        import ipywidgets

        self.update, self.controls, self.timings = update, dict(controls), []
        self.readout = ipywidgets.HTML()
        if isinstance(views, (MeshView, ViewRow)):
            shown = views.widget
        elif all(isinstance(v, MeshView) for v in views):
            shown = ipywidgets.HBox([v.widget for v in views])  # each framed by its own camera
        else:
            raise MeshError("live shows a MeshView, a side_by_side row, or a list of MeshViews")
        items = list(self.controls.values())
        rows = [ipywidgets.HBox(items[k : k + per_row]) for k in range(0, len(items), per_row)]
        self.widget = ipywidgets.VBox([*rows, self.readout, shown])
        for control in items:
            control.observe(self.refresh, "value")
        self.refresh()

    def refresh(self, change=None):
        """Run the update with the controls' values and write the read-out line."""
        start = time.perf_counter()
        values = {name: control.value for name, control in self.controls.items()}
        text, caught = mesh_warnings(self.update, **values)
        self.timings.append(time.perf_counter() - start)
        lines = [text] if isinstance(text, str) else list(text or [])
        lines += [f"⚠ {message}" for message in caught]
        lines[-1:] = (
            [f"{lines[-1]} ({1e3 * self.timings[-1]:.0f} ms)"] if lines else [f"{1e3 * self.timings[-1]:.0f} ms"]
        )
        self.readout.value = "<code>" + "<br>".join(html.escape(line) for line in lines) + "</code>"

    def _repr_mimebundle_(self, include=None, exclude=None, **kwargs):
        # while nbgrader runs the notebook its feedback page is static HTML: the still and the read-out only
        bundle = {} if stills_only() else self.widget._repr_mimebundle_(include=include, exclude=exclude) or {}
        still = box_still(self.widget)
        bundle["text/plain"] = html.unescape(self.readout.value.replace("<br>", "\n")).replace("<code>", "")
        bundle["text/plain"] = bundle["text/plain"].replace("</code>", "")
        if still is None:
            return bundle
        bundle["image/png"] = png_base64(still)
        return bundle, {"image/png": {"alt": box_alt(self.widget)}}


def live(update, controls, views, per_row=2):
    """Wire ``controls`` to ``update`` and show them with ``views``: a slider cell in one call.

    Parameters
    ----------
    update : callable
        Called with every control's value as a keyword argument (its name in
        ``controls``), once now and after every move. It recomputes and calls
        ``view.update``; it may return a read-out line (str) or several (list).
    controls : dict name -> ipywidgets control (slider, checkbox, toggle, dropdown)
        Shown ``per_row`` to a row, above the read-out line.
    views : MeshView, ViewRow (``side_by_side``) or list of MeshViews
        A list is shown in a row, each view framed by its own camera.

    Returns
    -------
    Live, displayed as the box of controls, read-out and views. The read-out
    adds the MeshWarnings of the update ("⚠ ...", not on stderr) and its time.
    """
    return Live(update, controls, views, per_row)
