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

``live_figure(draw, controls)`` does the same for a matplotlib figure: ``draw(**values)``
returns ``(fig, alt)`` and is called again at every move; where no widget front-end
runs (nbgrader's feedback pages) the box is the figure's still picture.
"""

import html
import time
import warnings

import numpy as np

from ...mesh.errors import MeshError, MeshWarning
from ..notebook import text_only
from .stills import png_base64
from .viewer import MeshView, ViewRow, box_alt, box_still, register_still

__all__ = ["live", "Live", "live_figure", "LiveFigure", "mesh_warnings"]


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
        # while nbgrader runs the notebook its feedback page is static HTML: the read-out only
        text = html.unescape(self.readout.value.replace("<br>", "\n")).replace("<code>", "").replace("</code>", "")
        if text_only():
            return {"text/plain": text}
        bundle = self.widget._repr_mimebundle_(include=include, exclude=exclude) or {}
        still = box_still(self.widget)
        bundle["text/plain"] = text
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


class LiveFigure:
    """Controls above a matplotlib figure redrawn at every move (:func:`live_figure`); displays as that box.

    Without a widget front-end (nbgrader's feedback pages, an exported page) the box is the
    figure drawn at the controls' values, a still picture with its alt text, instead of the
    text ``VBox(...)``.

    Attributes
    ----------
    widget : ipywidgets.VBox, the controls' rows and the figure's Output
    controls : dict name -> control
    """

    def __init__(self, draw, controls, per_row):
        import ipywidgets

        self.draw, self.controls = draw, dict(controls)
        items = list(self.controls.values())
        rows = [ipywidgets.HBox(items[k : k + per_row]) for k in range(0, len(items), per_row)]
        figure = ipywidgets.interactive_output(self._show, self.controls)
        self.widget = ipywidgets.VBox([*rows, figure])
        register_still(figure, self)
        self._drawn = None  # (values, picture, alt) of the last still

    def _show(self, **values):
        from ..notebook import show_figure

        show_figure(*self.draw(**values))

    def _picture(self):
        import io

        import matplotlib.pyplot as plt
        from PIL import Image

        values = {name: control.value for name, control in self.controls.items()}
        if self._drawn is None or self._drawn[0] != values:
            fig, alt = self.draw(**values)
            if text_only():  # the alt text only: nothing drawn
                plt.close(fig)
                self._drawn = values, None, " ".join(str(alt).split())
                return self._drawn
            buffer = io.BytesIO()
            fig.savefig(buffer, format="png", bbox_inches="tight")  # framed as show_figure frames it
            plt.close(fig)
            picture = np.asarray(Image.open(buffer).convert("RGB"))
            self._drawn = values, picture, " ".join(str(alt).split())
        return self._drawn

    def still(self):
        """(h, w, 3) uint8: the figure at the controls' current values."""
        return self._picture()[1]

    def alt_text(self):
        """The figure's alt text at the controls' current values."""
        return self._picture()[2]

    def summary(self):
        """The figure's text: its alt text at the controls' current values."""
        return f"Figure: {self.alt_text()}"

    def _repr_mimebundle_(self, include=None, exclude=None, **kwargs):
        if text_only():
            return {"text/plain": self.summary()}
        bundle = self.widget._repr_mimebundle_(include=include, exclude=exclude) or {}
        bundle["text/plain"] = self.summary()
        bundle["image/png"] = png_base64(self.still())
        return bundle, {"image/png": {"alt": self.alt_text()}}


def live_figure(draw, controls, per_row=3):
    """Sliders (or any controls) above a figure that ``draw`` redraws at every move: a plot cell in one call.

    Parameters
    ----------
    draw : callable
        Called with every control's value as a keyword argument (its name in ``controls``); returns
        ``(fig, alt)``, a matplotlib Figure and its alt text, as the workbook's figure functions do.
    controls : dict name -> ipywidgets control, shown ``per_row`` to a row above the figure.

    Returns
    -------
    LiveFigure, displayed as the box; where no widget front-end runs, as the figure's still picture.
    """
    return LiveFigure(draw, controls, per_row)
