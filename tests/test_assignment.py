"""The assignment build (tools/build_assignment.py): solutions become stubs, and the
assignment version runs end to end under nbval with every stub in place."""

import os
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import build_assignment  # noqa: E402

NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
EXERCISE_NOTEBOOKS = [p for p in NOTEBOOKS if not p.name.startswith("00_")]


def test_a_solution_block_becomes_a_stub_at_its_indentation():
    source = 'def f(V, F):\n    """Doc."""\n    ### BEGIN SOLUTION\n    M = 1\n    return M\n    ### END SOLUTION\n'
    out = build_assignment.stub_source(source, "uniform_laplacian", "section 2")
    assert out == (
        'def f(V, F):\n    """Doc."""\n'
        '    raise NotImplementedError("Your turn: write this (uniform_laplacian). '
        'Reread section 2, then run the check below.")'
    )


def test_unbalanced_markers_are_refused():
    with pytest.raises(ValueError, match="unbalanced or missing"):
        build_assignment.stub_source("### BEGIN SOLUTION\nx = 1\n", "e", "s")


@pytest.fixture(scope="module")
def assignment(tmp_path_factory):
    out = tmp_path_factory.mktemp("assignment")
    names = build_assignment.build(out)
    assert names == [p.name for p in NOTEBOOKS]
    return out


@pytest.mark.parametrize("path", EXERCISE_NOTEBOOKS, ids=[p.name for p in EXERCISE_NOTEBOOKS])
def test_every_exercise_is_stubbed_and_nothing_else_changes(assignment, path):
    solution = nbformat.read(path, as_version=4)
    stubbed = nbformat.read(assignment / path.name, as_version=4)
    marked = build_assignment.solution_cells(solution)
    assert marked, f"{path.name} has no exercise marked as an nbgrader solution cell"
    assert len(stubbed.cells) == len(solution.cells)
    for i, (a, b) in enumerate(zip(solution.cells, stubbed.cells)):
        if i in dict(marked):
            assert "BEGIN SOLUTION" not in b.source and 'NotImplementedError("Your turn' in b.source
            assert b.source.splitlines()[0] == a.source.splitlines()[0]  # the def line stays
        else:
            assert a.source == b.source, f"{path.name}: cell {i} changed"


def test_the_assignment_runs_under_nbval_with_the_stubs(assignment):
    env = dict(os.environ, GEOMLIB_STRICT_CLAIMS="1", PYTHONPATH=str(ROOT))
    cmd = [
        sys.executable,
        "-m",
        "pytest",
        "-q",
        "-p",
        "no:cacheprovider",
        "--nbval-lax",
        "--nbval-sanitize-with",
        str(ROOT / "tests" / "nbval_sanitize.cfg"),
        "-c",
        str(assignment / "pytest.ini"),
        "--rootdir",
        str(assignment),
        str(assignment),
    ]
    (assignment / "pytest.ini").write_text("[pytest]\n")
    done = subprocess.run(cmd, cwd=assignment, env=env, capture_output=True, text=True, timeout=1500)
    assert done.returncode == 0, done.stdout[-6000:] + done.stderr[-2000:]
