"""Notebook helpers: show a function's source, and tie a lesson's text to its numbers.

Machinery, not a lesson: nothing here computes geometry.

``show_source(fn)``
    Renders the source of a geomlib function with syntax highlighting, headed by
    its file (relative to the repository) and first line, so a reader goes from
    a derivation to the code that runs it without opening a file browser.

``explain(template, **values)``
    Displays a paragraph written with ``{placeholders}`` (``str.format``
    syntax), filled from the notebook's own numbers. Cells that call it carry
    the metadata ``jupyter.source_hidden`` so the reader sees the paragraph.

``claim(holds, statement, why="", **values)``
    Ties one sentence of the lesson to the numbers. When ``holds`` is true it
    shows nothing and returns True. When it is false:

    * under the test suite with the default parameters (the environment
      variable ``GEOMLIB_STRICT_CLAIMS=1``, set by ``tests/conftest.py``) it
      raises ``ClaimFailed``, so a lesson whose text no longer follows from its
      numbers fails its test;
    * otherwise (a reader's own mesh or parameters) it displays a visible note,
      "The text says ...; with these inputs ... because ...", and returns
      False, so the notebook keeps going.

``show_figure(fig, alt)``
    Displays a matplotlib figure as a PNG whose alt text (output metadata
    ``image/png: {alt: ...}``, and the ``text/plain`` form) says what the figure
    shows and, for a data plot, what it finds; the website carries it into the
    page's ``<img alt>``. Closes the figure, so it is shown once.

The runs of notebooks with other inputs (``tests/test_reader_inputs.py``) set
``GEOMLIB_STRICT_CLAIMS=0`` and collect the notes, whose ``text/plain`` form starts with ``Note:``.
"""

import html
import inspect
import os
from pathlib import Path

import numpy as np

from ..mesh.geometry import zero_area_faces
from ..mesh.repair import largest_component, remove_unreferenced_vertices, remove_zero_area_faces
from ..mesh.topology import boundary_vertices, connected_components
from ..mesh.validate import as_mesh

__all__ = [
    "show_source",
    "show_figure",
    "explain",
    "claim",
    "note",
    "prepare",
    "ClaimFailed",
    "strict_claims",
    "graded",
    "text_only",
    "NOTE_PREFIX",
]

#: first word of the text/plain form of every note (the input tests look for it)
NOTE_PREFIX = "Note:"

_ROOT = Path(__file__).resolve().parents[2]  # the folder holding geomlib/


class ClaimFailed(AssertionError):
    """A claim of a lesson's text does not hold for the default parameters."""


def strict_claims():
    """True when failed claims must raise (the test suite's default runs)."""
    return os.environ.get("GEOMLIB_STRICT_CLAIMS", "0") == "1"


def graded():
    """True while nbgrader runs the notebook (``nbgrader autograde`` and ``validate`` set
    ``NBGRADER_EXECUTION`` in the kernel): exercise checks then raise, views give stills."""
    return bool(os.environ.get("NBGRADER_EXECUTION"))


def text_only():
    """Whether views and figures are shown as their text alone (a view's one-line summary, a
    figure's alt text), without a widget or a picture: while nbgrader runs the notebook
    (:func:`graded`). Its feedback pages are static HTML, where a widget is an empty
    placeholder, and no grade cell needs a picture; drawing the pictures was about a fifth of
    the kernels' work in a grading run (benchmarks/README.md). A reader's run, nbval's and the
    website's draw everything."""
    return graded()


def _display(bundle):
    from IPython.display import display

    display(bundle, raw=True)


class _Source:
    """The highlighted source of one function; renders as HTML or plain text."""

    def __init__(self, obj):
        target = inspect.unwrap(obj)
        self.lines, self.first = inspect.getsourcelines(target)
        path = Path(inspect.getsourcefile(target)).resolve()
        try:
            self.where = path.relative_to(_ROOT).as_posix()
        except ValueError:
            self.where = path.name
        self.name = getattr(target, "__qualname__", repr(target))
        self.code = "".join(self.lines)

    @property
    def heading(self):
        last = self.first + len(self.lines) - 1
        return f"{self.name} — {self.where}, lines {self.first}–{last}"

    def _repr_html_(self):
        from pygments import highlight
        from pygments.formatters import HtmlFormatter
        from pygments.lexers import PythonLexer

        formatter = HtmlFormatter(
            noclasses=True, style="default", linenos="inline", linenostart=self.first, nobackground=True
        )
        body = highlight(self.code, PythonLexer(), formatter)
        return (
            f'<div class="geomlib-source"><div style="font-family:monospace;font-size:90%;'
            f'color:#555">{html.escape(self.heading)}</div>{body}</div>'
        )

    def __repr__(self):
        return f"# {self.heading}\n{self.code}"


def show_source(obj):
    """Display the source of a function (or class) with its file and first line.

    Parameters
    ----------
    obj : function, method or class defined in a Python file.

    Returns the displayable object, so ``show_source(fn)`` as the last line of a
    cell shows it once.
    """
    return _Source(obj)


def show_figure(fig, alt):
    """Display ``fig`` (a matplotlib Figure) as a PNG with the alt text ``alt``, then close it.

    ``alt`` says what the figure shows and, for a data plot, what it finds, in a sentence
    or two built from the numbers plotted (WCAG 2.1, 1.1.1 Non-text content). While
    nbgrader grades (:func:`text_only`) it shows the alt text alone: nothing is drawn.
    """
    import base64
    import io

    import matplotlib.pyplot as plt
    from IPython.display import display

    alt = " ".join(str(alt).split())
    if not alt:
        raise ValueError("show_figure needs an alt text that says what the figure shows")
    if text_only():
        plt.close(fig)
        display({"text/plain": f"Figure: {alt}"}, raw=True)
        return
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", bbox_inches="tight")
    plt.close(fig)
    data = base64.b64encode(buffer.getvalue()).decode("ascii")
    display({"image/png": data, "text/plain": f"Figure: {alt}"}, metadata={"image/png": {"alt": alt}}, raw=True)


def _fill(template, values):
    return inspect.cleandoc(template).format(**values)


def explain(template, **values):
    """Display a Markdown paragraph: ``template`` with ``{placeholders}`` filled from ``values``."""
    text = _fill(template, values)
    _display({"text/markdown": text, "text/plain": text})


def _show_note(text):
    quoted = "\n".join("> " + line for line in f"**Note.** {text}".splitlines())
    _display({"text/markdown": quoted, "text/plain": f"{NOTE_PREFIX} {text}"})


def note(text, **values):
    """Display a visible note about the reader's inputs (a quoted Markdown paragraph)."""
    _show_note(_fill(text, values))


def claim(holds, statement, why="", **values):
    """Check one claim of the text; raise under the strict tests, else show a note.

    Parameters
    ----------
    holds : bool
        Whether the claim holds for the numbers just computed.
    statement : str
        The claim as the text makes it ("the angle-deficit K is within 10 % of
        the exact curvature"), with ``{placeholders}`` for ``values``.
    why : str, optional
        What differs with these inputs and why ("on this mesh K is {err:.0%}
        off because ..."), with ``{placeholders}``.

    Returns
    -------
    bool : ``holds``.
    """
    if bool(holds):
        return True
    said, differs = _fill(statement, values), _fill(why, values) if why else ""
    if strict_claims():
        raise ClaimFailed(f"the text says {said}, but it does not hold" + (f": {differs}" if differs else ""))
    # the text is filled already: braces in the values (a dict, LaTeX) must not be read as placeholders
    _show_note(f"The text says {said}. With these inputs it does not hold" + (f": {differs}" if differs else "."))
    return False


def prepare(V, F, *, one_component=False, closed=False, what="this notebook"):
    """Make a reader's mesh usable by a lesson, saying in one sentence per step what was done.

    Parameters
    ----------
    V, F : the mesh as loaded.
    one_component : bool, keep only the largest component (the lesson needs one).
    closed : bool, the lesson needs a closed mesh; an open one is kept, with a note of what
        differs (nothing can close it automatically).
    what : str, how the notes name the lesson.

    Returns
    -------
    V2, F2, kept : the mesh used and the indices of its vertices in the input V.
    """
    V, F = as_mesh(V, F)
    kept = np.arange(len(V))
    zero = zero_area_faces(V, F)
    if len(zero):
        V, F, _ = remove_zero_area_faces(V, F)
        note(
            f"The mesh has {len(zero)} zero-area faces; their angles are undefined, so {what} leaves them "
            "out (`geomlib.mesh.repair.remove_zero_area_faces(V, F)`)."
        )
    unused = len(V) - len(np.unique(F))
    if unused:
        V, F, k = remove_unreferenced_vertices(V, F)
        kept = kept[k]
        note(
            f"{unused} vertices are not used by any face (they have no area); {what} computes on the "
            f"{len(V)} vertices the faces use (`geomlib.mesh.repair.remove_unreferenced_vertices(V, F)`)."
        )
    count = connected_components(F, len(V)).max() + 1
    if one_component and count > 1:
        n_before = len(V)
        V, F, k = largest_component(V, F)
        kept = kept[k]
        note(
            f"The mesh has {count} connected components; {what} needs one, so it keeps the largest "
            f"({len(V)} of {n_before} vertices; `geomlib.mesh.repair.largest_component(V, F)`)."
        )
    if closed and len(boundary_vertices(F, len(V))):
        note(
            f"The mesh is open ({len(boundary_vertices(F, len(V)))} boundary vertices); {what} assumes a "
            "closed surface, so boundary vertices are held fixed and volumes are not meaningful."
        )
    return V, F, kept
