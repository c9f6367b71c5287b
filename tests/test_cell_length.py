"""Lesson cells a reader can take in: no code cell a reader sees runs over MAX_LINES lines.

Slider wiring, read-outs, arrows and markers are one named call each
(geomlib.teaching.controls, .glyphs), so a lesson cell shows the lesson. Exempt:

* cells whose source is collapsed (metadata ``jupyter.source_hidden``): they only
  compute what the prose says (``explain``, ``claim``), and JupyterLab and the
  website show their paragraph, not their code;
* the cell tagged ``parameters``: one line per knob, every knob in one place;
* the cells in LONGER, each with its reason. An entry that is no longer needed
  (the cell is gone or fits) fails too, so the list stays short.
"""

import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
MAX_LINES = 15
#: a listed cell may still not run on for ever
LONGEST = 22

IMPORTS = "the imports: one line per module the lesson draws on, so a reader sees which layer each name comes from"
LONGER = {
    ("01_uniform_laplace_curvature.ipynb", "ea2841b8"): IMPORTS,
    ("03_cotangent_laplace.ipynb", "nb03-02"): IMPORTS,
    ("04_spectral_reconstruction.ipynb", "nb04-02"): IMPORTS,
    ("05_explicit_smoothing.ipynb", "nb05-002"): IMPORTS,
    ("06_implicit_smoothing.ipynb", "nb06-002"): IMPORTS,
    ("07_denoising_evaluation.ipynb", "n07-002"): IMPORTS,
    ("03_cotangent_laplace.ipynb", "nb03-20"): "an exercise's model solution written out corner by corner, as the "
    "derivation goes (nbgrader hands the learner a stub)",
}


def code_cells(path):
    """(id, lines, exempt as a class) of every code cell."""
    nb = json.loads(path.read_text(encoding="utf-8"))
    for cell in nb["cells"]:
        if cell["cell_type"] == "code":
            source = "".join(cell["source"])
            metadata = cell.get("metadata", {})
            hidden = metadata.get("jupyter", {}).get("source_hidden", False) or "parameters" in metadata.get("tags", [])
            yield cell["id"], len(source.strip("\n").splitlines()), hidden


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_code_cells_a_reader_sees_are_short(path):
    long = [
        f"cell {cid}: {n} lines"
        for cid, n, hidden in code_cells(path)
        if n > MAX_LINES and not hidden and (path.name, cid) not in LONGER
    ]
    assert not long, f"{path.name}: code cells over {MAX_LINES} lines: {long}; move machinery into geomlib.teaching"


def test_every_exemption_is_still_needed_and_bounded():
    lengths = {(path.name, cid): (n, hidden) for path in NOTEBOOKS for cid, n, hidden in code_cells(path)}
    for key, reason in LONGER.items():
        assert reason, key
        assert key in lengths, f"{key} is listed in LONGER but no longer exists"
        n, hidden = lengths[key]
        assert MAX_LINES < n <= LONGEST and not hidden, f"{key} has {n} lines: take it out of LONGER"
