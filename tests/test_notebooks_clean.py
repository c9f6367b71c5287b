"""Every notebook is committed clean: no outputs, no execution counts, no widget
state, the standard python3 kernel. tools/strip_notebooks.py makes them so."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
STRIP = ROOT / "tools" / "strip_notebooks.py"
HOW = "run `python tools/strip_notebooks.py` before committing"


def test_there_are_notebooks():
    assert any(p.name.startswith("00_") for p in NOTEBOOKS), "notebooks/00_getting_started.ipynb is missing"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_notebook_is_clean(path):
    nb = json.loads(path.read_text(encoding="utf-8"))
    assert nb["nbformat"] == 4
    with_outputs = [i for i, c in enumerate(nb["cells"]) if c["cell_type"] == "code" and c.get("outputs")]
    counted = [
        i for i, c in enumerate(nb["cells"]) if c["cell_type"] == "code" and c.get("execution_count") is not None
    ]
    assert not with_outputs, f"cells {with_outputs} have outputs; {HOW}"
    assert not counted, f"cells {counted} have execution counts; {HOW}"
    assert "widgets" not in nb["metadata"], f"widget state saved in the metadata; {HOW}"
    assert nb["metadata"].get("kernelspec", {}).get("name") == "python3", f"kernelspec is not python3; {HOW}"
    assert nb["metadata"]["kernelspec"].get("language") == "python"


def _dirty_notebook():
    return {
        "nbformat": 4,
        "nbformat_minor": 5,
        "metadata": {
            "kernelspec": {"name": "myenv", "display_name": "My env", "language": "python"},
            "language_info": {"name": "python", "version": "3.11.2"},
            "widgets": {"application/vnd.jupyter.widget-state+json": {"state": {"abc": {}}}},
        },
        "cells": [
            {"cell_type": "markdown", "id": "m1", "metadata": {}, "source": "# Title"},
            {
                "cell_type": "code",
                "id": "c1",
                "execution_count": 7,
                "metadata": {"execution": {"iopub.status.busy": "2026-01-01"}, "tags": ["keep"], "scrolled": True},
                "outputs": [{"output_type": "stream", "name": "stdout", "text": "hi\n"}],
                "source": "print('hi')",
            },
        ],
    }


def test_strip_tool_cleans_and_is_idempotent(tmp_path):
    path = tmp_path / "dirty.ipynb"
    path.write_text(json.dumps(_dirty_notebook()))
    check = subprocess.run([sys.executable, STRIP, "--check", path], capture_output=True, text=True)
    assert check.returncode == 1 and "not clean" in check.stdout
    assert json.loads(path.read_text())["cells"][1]["outputs"]  # --check changes nothing

    subprocess.run([sys.executable, STRIP, path], check=True, capture_output=True)
    nb = json.loads(path.read_text())
    code = nb["cells"][1]
    assert code["outputs"] == [] and code["execution_count"] is None
    assert code["metadata"] == {"tags": ["keep"]}  # tags survive
    assert code["source"] == "print('hi')" and code["id"] == "c1"
    assert "widgets" not in nb["metadata"]
    assert nb["metadata"]["kernelspec"]["name"] == "python3"
    assert nb["cells"][0]["source"] == "# Title"

    text = path.read_text()
    again = subprocess.run([sys.executable, STRIP, "--check", path], capture_output=True, text=True)
    assert again.returncode == 0 and again.stdout == ""
    subprocess.run([sys.executable, STRIP, path], check=True)
    assert path.read_text() == text
