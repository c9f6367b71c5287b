"""Colab, simulated: a notebook's set-up cell enables Colab's custom widget
manager exactly once when ``google.colab`` is there, and calls nothing
anywhere else.

A stand-in ``google/colab/output.py`` records each call of
``enable_custom_widget_manager``; the set-up cell runs in a fresh IPython
shell in a subprocess (so the module cache of this test process plays no
part).
"""

import json
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))

STAND_IN_OUTPUT = """
CALLS = []

def enable_custom_widget_manager(*args, **kwargs):
    CALLS.append((args, kwargs))
"""

# runs the set-up cell twice, as a reader who re-runs it does, then reports
RUNNER = textwrap.dedent("""
    import json, sys
    from IPython.terminal.interactiveshell import TerminalInteractiveShell as InteractiveShell
    shell = InteractiveShell.instance()
    source = open(sys.argv[1], encoding="utf-8").read()
    for _ in range(2):
        result = shell.run_cell(source)
        if not result.success:
            raise SystemExit(f"the set-up cell failed: {result.error_in_exec or result.error_before_exec!r}")
    output = sys.modules.get("google.colab.output")
    print(json.dumps({"colab_imported": "google.colab" in sys.modules,
                      "calls": None if output is None else len(output.CALLS)}))
""")


def setup_cell(notebook):
    """Source of the notebook's set-up cell: the first code cell that imports geomlib."""
    cells = json.loads(notebook.read_text(encoding="utf-8"))["cells"]
    for cell in cells:
        source = "".join(cell["source"])
        if cell["cell_type"] == "code" and "import geomlib" in source:
            return source
    raise AssertionError(f"{notebook.name} has no code cell that imports geomlib")


def run_setup_cell(tmp_path, source, site):
    cell = tmp_path / "setup_cell.py"
    cell.write_text(source, encoding="utf-8")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(site), str(ROOT)]), MPLBACKEND="agg")
    done = subprocess.run(
        [sys.executable, "-c", RUNNER, str(cell)],
        cwd=ROOT / "notebooks",
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_every_notebook_imports_geomlib_in_its_first_code_cell():
    for notebook in NOTEBOOKS:
        cells = json.loads(notebook.read_text(encoding="utf-8"))["cells"]
        first = next(c for c in cells if c["cell_type"] == "code")
        source = "".join(first["source"])
        assert re.search(r"^(import geomlib|from geomlib[.\w]* import)", source, flags=re.M), (
            f"{notebook.name}: the first code cell does not import geomlib, so in Colab the 3D views "
            "would appear before the custom widget manager is enabled"
        )


@pytest.mark.slow
def test_in_colab_the_setup_cell_enables_the_custom_widget_manager_once(tmp_path):
    site = tmp_path / "site"
    (site / "google" / "colab").mkdir(parents=True)
    (site / "google" / "colab" / "__init__.py").write_text("")
    (site / "google" / "colab" / "output.py").write_text(STAND_IN_OUTPUT)
    report = run_setup_cell(tmp_path, setup_cell(ROOT / "notebooks" / "00_getting_started.ipynb"), site)
    assert report == {"colab_imported": True, "calls": 1}


@pytest.mark.slow
def test_elsewhere_the_setup_cell_calls_nothing(tmp_path):
    # a 'google' namespace without colab, as protobuf and other Google packages install it
    site = tmp_path / "site"
    (site / "google" / "protobuf").mkdir(parents=True)
    (site / "google" / "protobuf" / "__init__.py").write_text("")
    report = run_setup_cell(tmp_path, setup_cell(ROOT / "notebooks" / "00_getting_started.ipynb"), site)
    assert report == {"colab_imported": False, "calls": None}
