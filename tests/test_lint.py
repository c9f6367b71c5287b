"""ruff keeps the code of the package, the tests, the tools and the benchmarks to one
style (pyproject.toml [tool.ruff]): a lint finding or an unformatted file fails here."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
TARGETS = ["geomlib", "tests", "tools", "benchmarks", "workbook.py"]


def _ruff():
    found = shutil.which("ruff", path=str(Path(sys.executable).parent)) or shutil.which("ruff")
    if found is None:
        pytest.fail("ruff is not installed: `pip install -e .[dev]` (python3 workbook.py setup does it)")
    return found


def test_ruff_finds_nothing():
    done = subprocess.run([_ruff(), "check", *TARGETS], cwd=ROOT, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout[-4000:]


def test_the_code_is_formatted():
    done = subprocess.run([_ruff(), "format", "--check", *TARGETS], cwd=ROOT, capture_output=True, text=True)
    assert done.returncode == 0, "run `ruff format` on:\n" + done.stdout[-4000:]
