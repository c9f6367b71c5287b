"""Run a notebook with a reader's inputs, as a reader would, and collect what it said.

``run_notebook(name, **parameters)`` copies ``notebooks/NAME`` to a temporary
folder, inserts a cell after the cell tagged ``parameters`` that sets the given
names (papermill's convention: the injected cell overrides the defaults), and
executes it top to bottom with nbclient in a fresh kernel with
``GEOMLIB_STRICT_CLAIMS=0``. Values are written with ``repr``, so pass
strings, numbers, lists, or ``Raw("python expression")``.

It returns a ``Run`` with the executed notebook, the wall time, the notes the
notebook displayed (``geomlib.teaching.notebook.note``; text/plain starting ``Note:``),
and every error output. A cell that raises stops the run and is reported with
its index and traceback by ``Run.assert_ran()``.
"""

import os
import shutil
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import nbformat
from nbclient import NotebookClient
from nbclient.exceptions import CellExecutionError

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"
NOTE_PREFIX = "Note:"


class Raw(str):
    """A Python expression injected as written (``Raw('geomlib.data_path("cube.obj")')``)."""

    def __repr__(self):
        return str(self)


@dataclass
class Run:
    name: str
    parameters: dict
    seconds: float
    notebook: object
    error: str = ""
    notes: list = field(default_factory=list)

    def assert_ran(self):
        assert not self.error, f"{self.name} with {self.parameters} raised:\n{self.error}"

    def notes_text(self):
        """The notes, one a line."""
        return "\n".join(self.notes)

    def assert_said(self, *phrases):
        """Every phrase stands in some note (the failure lists the notes)."""
        text = self.notes_text()
        for phrase in phrases:
            assert phrase in text, f"no note says {phrase!r}; the notes were:\n{text}"

    def outputs_text(self):
        """All text/plain and text/markdown of the outputs, joined."""
        parts = []
        for cell in self.notebook.cells:
            for out in cell.get("outputs", []):
                if out.get("output_type") == "stream":
                    parts.append(out.get("text", ""))
                data = out.get("data", {})
                parts += [data.get("text/markdown", ""), data.get("text/plain", "")]
        return "\n".join(p if isinstance(p, str) else "".join(p) for p in parts)


def _notes(nb):
    found = []
    for cell in nb.cells:
        for out in cell.get("outputs", []):
            text = out.get("data", {}).get("text/plain", "")
            text = text if isinstance(text, str) else "".join(text)
            if text.startswith(NOTE_PREFIX):
                found.append(text)
    return found


def inject(nb, parameters):
    """Insert the parameter cell after the cell tagged 'parameters' (which must exist)."""
    where = [i for i, c in enumerate(nb.cells) if "parameters" in c.get("metadata", {}).get("tags", [])]
    assert where, "the notebook has no cell tagged 'parameters'"
    source = "\n".join(f"{k} = {v!r}" for k, v in parameters.items())
    cell = nbformat.v4.new_code_cell(source, metadata={"tags": ["injected-parameters"]})
    nb.cells.insert(where[0] + 1, cell)
    return nb


def run_notebook(name, timeout=600, after=None, **parameters):
    """Execute notebooks/NAME with ``parameters`` injected; return a Run (see the module docstring).

    ``after``: code run as one more cell at the end, in the notebook's kernel (a test's
    measurements of the notebook's own objects); its outputs are those of the last cell.
    """
    nb = inject(nbformat.read(NOTEBOOKS / name, as_version=4), parameters)
    if after is not None:
        nb.cells.append(nbformat.v4.new_code_cell(after, metadata={"tags": ["test-measurements"]}))
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp) / "notebooks"
        shutil.copytree(NOTEBOOKS, work, ignore=shutil.ignore_patterns("*.ipynb"))
        env = dict(os.environ, GEOMLIB_STRICT_CLAIMS="0", GEOMLIB_CACHE_DIR=str(Path(tmp) / "cache"))
        client = NotebookClient(nb, timeout=timeout, kernel_name="python3", resources={"metadata": {"path": str(work)}})
        error, start = "", time.perf_counter()
        saved = dict(os.environ)
        os.environ.update(env)  # the kernel inherits the environment of this process
        try:
            client.execute()
        except CellExecutionError as exc:
            error = str(exc)
        finally:
            os.environ.clear()
            os.environ.update(saved)
        seconds = time.perf_counter() - start
    return Run(name, parameters, seconds, nb, error, _notes(nb))


def ran(name, after=None, **parameters):
    """run_notebook, asserting that it ran; its time and note count are printed (``pytest -s``)."""
    run = run_notebook(name, after=after, **parameters)
    run.assert_ran()
    print(f"{name} {sorted(parameters)}: {run.seconds:.1f} s, {len(run.notes)} notes")
    return run
