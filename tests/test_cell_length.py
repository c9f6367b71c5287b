"""Lesson cells a reader can take in: no code cell runs over MAX_LINES lines.

Slider wiring, read-outs, arrows and markers are one named call each
(geomlib.teaching.display.controls, .glyphs), so a lesson cell shows the lesson. Collapsed
cells (metadata ``jupyter.source_hidden``) count too: a reader who opens one to see
how a sentence was computed should take it in as well. Exempt:

* the cell tagged ``parameters``: one line per knob, every knob in one place;
* the cells in LONGER, each with its reason (a formula the notebook deliberately
  writes out). An entry that is no longer needed (the cell is gone or fits) fails
  too, so the list stays short.
"""

import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
MAX_LINES = 15
#: a listed cell may still not run on for ever
LONGEST = 22

LONGER = {}


def code_cells(path):
    """(id, lines, is the parameters cell) of every code cell."""
    nb = json.loads(path.read_text(encoding="utf-8"))
    for cell in nb["cells"]:
        if cell["cell_type"] == "code":
            source = "".join(cell["source"])
            parameters = "parameters" in cell.get("metadata", {}).get("tags", [])
            yield cell["id"], len(source.strip("\n").splitlines()), parameters


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_code_cells_are_short(path):
    long = [
        f"cell {cid}: {n} lines"
        for cid, n, parameters in code_cells(path)
        if n > MAX_LINES and not parameters and (path.name, cid) not in LONGER
    ]
    assert not long, (
        f"{path.name}: code cells over {MAX_LINES} lines: {long}; move machinery into geomlib.teaching, "
        "computations into a cell of their own, and an explain() apart from its claim() calls"
    )


def test_every_exemption_is_still_needed_and_bounded():
    lengths = {(path.name, cid): (n, parameters) for path in NOTEBOOKS for cid, n, parameters in code_cells(path)}
    for key, reason in LONGER.items():
        assert reason, key
        assert key in lengths, f"{key} is listed in LONGER but no longer exists"
        n, parameters = lengths[key]
        assert MAX_LINES < n <= LONGEST and not parameters, f"{key} has {n} lines: take it out of LONGER"
