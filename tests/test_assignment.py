"""The assignment build (tools/build_assignment.py): solutions become stubs, answers become
empty answer boxes, model answers leave, and the release never shows an exercise's answer.

The page a student is handed holds no source of any routine an exercise asks for or
forbids (``check.NAME.forbid``), neither in a cell nor in an output once it runs with the
stubs in place: geomlib's own routine is shown only by ``reveal``, after the student's
function passes. nbgrader's own ``generate_assignment`` release is checked the same way in
tests/test_nbgrader.py.
"""

import inspect
import os
import re
import sys
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import build_assignment  # noqa: E402

from geomlib import check  # noqa: E402
from geomlib.teaching.check.fence import resolve  # noqa: E402

NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
EXERCISE_NOTEBOOKS = [p for p in NOTEBOOKS if p.name[:2] != "00" and p.name[2] == "_"]


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
    with pytest.raises(ValueError, match="unbalanced"):
        build_assignment.without_hidden_tests("# a\n### BEGIN HIDDEN TESTS\nx = 1\n")


def test_a_hidden_region_leaves_with_its_markers():
    source = "# The model answer\n### BEGIN HIDDEN TESTS\nexplain('x')\n### END HIDDEN TESTS\n"
    assert build_assignment.without_hidden_tests(source) == "# The model answer"


def _package_lines():
    """How often each stripped line occurs in geomlib's source: a line found twice is an idiom, not an answer."""
    counts = {}
    for path in (ROOT / "geomlib").rglob("*.py"):
        for line in path.read_text().splitlines():
            counts[line.strip()] = counts.get(line.strip(), 0) + 1
    return counts


PACKAGE_LINES = _package_lines()


def forbidden_lines(dotted):
    """Lines of a routine's source that only its answer would contain (its body, not its signature or docs)."""
    target = resolve(dotted)
    members = [m for m in vars(target).values() if callable(m)] if isinstance(target, type) else [target]
    lines = set()
    for member in members:
        try:
            source = inspect.getsource(inspect.unwrap(member))
        except (OSError, TypeError):
            continue
        body = source.split('"""')[-1] if source.count('"""') >= 2 else source
        for line in body.splitlines():
            line = line.strip()
            if len(line) >= 24 and PACKAGE_LINES.get(line) == 1 and not line.startswith(("#", "def ", "@")):
                lines.add(line)
    return lines


def exercises_of(nb):
    return [cell.metadata["nbgrader"]["grade_id"] for _, cell in build_assignment.solution_cells(nb)]


def answer_leaks(nb, exercises):
    """(exercise, routine, where) for every routine source line of the notebook's exercises found in it."""
    found = []
    for exercise in exercises:
        for dotted in getattr(check, exercise).forbid:
            name = dotted.rpartition(".")[2]
            lines = forbidden_lines(dotted)
            for i, cell in enumerate(nb.cells):
                if cell.cell_type == "code" and (hit := next((x for x in lines if x in cell.source), None)):
                    found.append((exercise, name, f"cell {i} source: {hit}"))
                shown = re.findall(r"show_source\(([^)]*)\)", cell.source) if cell.cell_type == "code" else []
                if any(re.search(rf"\b{name}\b", arg) for arg in shown):
                    found.append((exercise, name, f"cell {i} calls show_source on it"))
                for out in cell.get("outputs", []):
                    shown = "".join(out.get("data", {}).get("text/html", ""))
                    if f"{name} — geomlib/" in shown:
                        found.append((exercise, name, f"cell {i} output shows its source"))
    return found


@pytest.fixture(scope="module")
def assignment(tmp_path_factory):
    out = tmp_path_factory.mktemp("assignment")
    names = build_assignment.build(out)
    assert names == [p.name for p in NOTEBOOKS]
    return out


@pytest.mark.parametrize("path", EXERCISE_NOTEBOOKS, ids=[p.name for p in EXERCISE_NOTEBOOKS])
def test_every_exercise_is_stubbed_every_answer_blank_and_nothing_else_changes(assignment, path):
    solution = nbformat.read(path, as_version=4)
    stubbed = nbformat.read(assignment / path.name, as_version=4)
    marked = dict(build_assignment.solution_cells(solution))
    answers = dict(build_assignment.answer_cells(solution))
    assert marked, f"{path.name} has no exercise marked as an nbgrader solution cell"
    assert answers, f"{path.name} has no hand-graded answer cell"
    assert len(stubbed.cells) == len(solution.cells)
    for i, (a, b) in enumerate(zip(solution.cells, stubbed.cells)):
        hidden = build_assignment.HIDDEN_BEGIN in a.source
        if i in marked:
            assert "BEGIN SOLUTION" not in b.source and 'NotImplementedError("Your turn' in b.source
            assert b.source.splitlines()[0] == a.source.splitlines()[0]  # the def line stays
        elif i in answers:
            assert b.source.startswith("*Your answer here: ") and "graded by hand" in b.source
        elif hidden:
            assert a.metadata["nbgrader"]["grade"] and a.metadata["nbgrader"]["points"] == 0
            assert b.source == build_assignment.without_hidden_tests(a.source) and "HIDDEN" not in b.source
        else:
            assert a.source == b.source, f"{path.name}: cell {i} changed"


@pytest.mark.parametrize("path", EXERCISE_NOTEBOOKS, ids=[p.name for p in EXERCISE_NOTEBOOKS])
def test_no_cell_of_the_release_shows_an_exercise_routine(assignment, path):
    nb = nbformat.read(assignment / path.name, as_version=4)
    assert answer_leaks(nb, exercises_of(nb)) == []


def test_the_leak_finder_sees_a_shown_routine(tmp_path):
    nb = nbformat.v4.new_notebook()
    body = sorted(forbidden_lines("lessons.smoothing.explicit_step"))[0]
    nb.cells = [nbformat.v4.new_code_cell(f"x = 1\n{body}\n")]
    assert ("smoothing_loop", "explicit_step") in [(e, n) for e, n, _ in answer_leaks(nb, ["smoothing_loop"])]


@pytest.mark.slow
def test_the_release_runs_with_the_stubs_and_reveals_nothing(assignment):
    """Every released notebook with exercises runs top to bottom with its stubs (strict claims), and no
    output shows an answer (00 and the appendices hold no exercise: the build copies them unchanged)."""
    os.environ["GEOMLIB_STRICT_CLAIMS"] = "1"
    os.environ["PYTHONPATH"] = str(ROOT)
    leaks, errors = [], []
    for path in EXERCISE_NOTEBOOKS:
        nb = nbformat.read(assignment / path.name, as_version=4)
        client = NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": assignment}})
        try:
            client.execute()
        except Exception as exc:  # the cell and its traceback, for the failure message
            errors.append(f"{path.name}: {str(exc)[-3000:]}")
        leaks += [(path.name, *leak) for leak in answer_leaks(nb, exercises_of(nb))]
    assert errors == []
    assert leaks == []


def test_notebooks_without_exercises_are_copied_unchanged(assignment):
    for path in NOTEBOOKS:
        if path in EXERCISE_NOTEBOOKS:
            continue
        solution, released = (nbformat.read(p, as_version=4) for p in (path, assignment / path.name))
        assert [c.source for c in released.cells] == [c.source for c in solution.cells], path.name
