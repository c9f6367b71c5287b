#!/usr/bin/env python3
"""Write the assignment version of the workbook: solutions replaced by stubs.

    python tools/build_assignment.py [--out build/assignment]
    python tools/build_assignment.py --solutions --out build/solutions

The notebooks in notebooks/ are the solution version. An exercise's solution
is marked as nbgrader marks it: the code cell has the metadata
``nbgrader.solution = true`` with ``grade_id`` naming its check in
``geomlib.teaching.check``, and the solution lines sit between ``### BEGIN SOLUTION``
and ``### END SOLUTION``. Each such block becomes, at the same indentation,

    raise NotImplementedError("Your turn: ... reread <the derivation>")

where the derivation is the one the check names. Everything else is copied
unchanged (a course running nbgrader can take notebooks/ as they are).

Every exercise carries nbgrader points in two autograded grade cells after its
solution cell (metadata ``nbgrader.grade = true``, ``locked``, ``points``):
``check.NAME(my_fn)`` (grade id ``NAME_check``) and
``check.NAME.partial_credit(my_fn)`` (``NAME_partial_credit``). The build
refuses a notebook whose exercise lacks either, so the output is an nbgrader
release as it stands.
The discussion is graded by hand: a markdown answer cell (``nbgrader.solution``
and ``grade`` true, ``points``) holds the model answer in notebooks/ and becomes
an empty answer box here, as nbgrader's ``generate_assignment`` makes it. A model
answer built from the notebook's numbers sits in a locked grade cell of 0 points
between ``### BEGIN HIDDEN TESTS`` and ``### END HIDDEN TESTS``: the region is
removed here (and by nbgrader, which puts it back when it grades, so the student
reads it in the feedback).

The output folder holds the notebooks and a copy of nothing else: they import
geomlib from the installed package and find the shipped meshes through it.

``--solutions`` writes the solution version instead, for a reader studying on
their own (``workbook.py lab --solutions``): the notebooks as they are, each
opening with a banner cell that says it holds the answers.
"""

import argparse
import re
import sys
from pathlib import Path

import nbformat

ROOT = Path(__file__).resolve().parent.parent
BEGIN, END = "### BEGIN SOLUTION", "### END SOLUTION"
_BLOCK = re.compile(r"^([ \t]*)### BEGIN SOLUTION[^\n]*\n.*?^[ \t]*### END SOLUTION[^\n]*(\n|$)", re.M | re.S)
HIDDEN_BEGIN, HIDDEN_END = "### BEGIN HIDDEN TESTS", "### END HIDDEN TESTS"
_HIDDEN = re.compile(r"^[ \t]*### BEGIN HIDDEN TESTS[^\n]*\n.*?^[ \t]*### END HIDDEN TESTS[^\n]*(\n|$)", re.M | re.S)
ANSWER_BOX = "*Your answer here: {points} point{s}, graded by hand.*"
SOLUTION_BANNER = (
    "> **Solution version.** Every exercise of this copy holds its answer and every **Discuss** its model "
    "answer. Attempt the exercise version first: `python3 workbook.py lab` opens it in your own folder, "
    "`my-work/`. This copy is rewritten each time `python3 workbook.py lab --solutions` runs, so edits here "
    "do not last."
)


def stub_source(source, exercise, reread):
    """``source`` with every solution block replaced by a NotImplementedError stub."""
    message = f"Your turn: write this ({exercise}). Reread {reread}, then run the check below."

    def stub(match):
        return f'{match.group(1)}raise NotImplementedError("{message}")\n'

    out, count = _BLOCK.subn(stub, source)
    if count == 0 or BEGIN in out or END in out:
        raise ValueError(f"exercise {exercise}: unbalanced or missing {BEGIN} / {END} markers")
    return out.rstrip("\n")


def without_hidden_tests(source):
    """``source`` with every hidden-tests region (markers included) removed."""
    out = _HIDDEN.sub("", source)
    if HIDDEN_BEGIN in out or HIDDEN_END in out:
        raise ValueError(f"unbalanced {HIDDEN_BEGIN} / {HIDDEN_END} markers")
    return out.rstrip("\n")


def answer_cells(nb):
    """The (index, cell) pairs of hand-graded markdown answer cells (nbgrader solution and grade)."""
    return [
        (i, c)
        for i, c in enumerate(nb.cells)
        if c.cell_type == "markdown"
        and c.metadata.get("nbgrader", {}).get("solution")
        and c.metadata.get("nbgrader", {}).get("grade")
    ]


def discussion_points(nb):
    """{grade id: points} of the hand-graded answer cells of a notebook.

    Raises ValueError for an answer cell without points, or a model-answer cell (a grade
    cell whose source has a hidden-tests region) that carries points: model answers earn nothing.
    """
    points = {}
    for _, cell in answer_cells(nb):
        meta = cell.metadata["nbgrader"]
        if not meta.get("points"):
            raise ValueError(f"answer cell {meta.get('grade_id')!r} has no points")
        points[meta["grade_id"]] = meta["points"]
    for cell in nb.cells:
        meta = cell.metadata.get("nbgrader", {})
        if cell.cell_type == "code" and meta.get("grade") and HIDDEN_BEGIN in cell.source and meta.get("points"):
            raise ValueError(f"model answer {meta.get('grade_id')!r} carries points; it must carry 0")
    return points


def solution_cells(nb):
    """The (index, cell) pairs marked as nbgrader solution cells."""
    return [
        (i, c)
        for i, c in enumerate(nb.cells)
        if c.cell_type == "code" and c.metadata.get("nbgrader", {}).get("solution")
    ]


def exercise_points(nb):
    """{exercise: points} of a notebook, its grade cells' points summed per exercise.

    Raises ValueError naming an exercise without both of its grade cells.
    """
    grade = {
        c.metadata["nbgrader"]["grade_id"]: (c.source, c.metadata["nbgrader"].get("points"))
        for c in nb.cells
        if c.cell_type == "code" and c.metadata.get("nbgrader", {}).get("grade")
    }
    points = {}
    for _, cell in solution_cells(nb):
        exercise = cell.metadata["nbgrader"]["grade_id"]
        total = 0
        for suffix, call in (
            ("_check", f"check.{exercise}("),
            ("_partial_credit", f"check.{exercise}.partial_credit("),
        ):
            source, value = grade.get(exercise + suffix, ("", None))
            if not source.startswith(call) or not value:
                raise ValueError(
                    f"exercise {exercise}: no grade cell {exercise + suffix!r} calling {call}...) with points"
                )
            total += value
        points[exercise] = total
    return points


def build(out):
    sys.path.insert(0, str(ROOT))
    import geomlib.teaching.check as check

    out.mkdir(parents=True, exist_ok=True)
    written = []
    for path in sorted((ROOT / "notebooks").glob("*.ipynb")):
        nb = nbformat.read(path, as_version=4)
        for _, cell in solution_cells(nb):
            exercise = cell.metadata["nbgrader"]["grade_id"]
            checker = getattr(check, exercise, None)
            if checker is None or not hasattr(checker, "reread"):
                raise SystemExit(f"{path.name}: solution cell {exercise!r} names no check in geomlib.teaching.check")
            cell.source = stub_source(cell.source, exercise, checker.reread)
        try:
            exercise_points(nb)
            for _, cell in answer_cells(nb):
                points = cell.metadata["nbgrader"]["points"]
                cell.source = ANSWER_BOX.format(points=points, s="" if points == 1 else "s")
            discussion_points(nb)
            for cell in nb.cells:
                if cell.cell_type == "code" and cell.metadata.get("nbgrader", {}).get("grade"):
                    cell.source = without_hidden_tests(cell.source)
        except ValueError as exc:
            raise SystemExit(f"{path.name}: {exc}") from None
        for cell in nb.cells:
            if (
                cell.cell_type == "code"
                and (BEGIN in cell.source or END in cell.source)
                and not cell.metadata.get("nbgrader", {}).get("solution")
            ):
                raise SystemExit(f"{path.name}: solution markers in a cell without nbgrader solution metadata")
            if HIDDEN_BEGIN in cell.source or HIDDEN_END in cell.source:
                raise SystemExit(f"{path.name}: hidden-tests markers in a cell that is not a grade cell")
        nbformat.write(nb, out / path.name)
        written.append(path.name)
    return written


def build_solutions(out):
    """The notebooks of notebooks/ into ``out``, each with SOLUTION_BANNER as its first cell."""
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for path in sorted((ROOT / "notebooks").glob("*.ipynb")):
        nb = nbformat.read(path, as_version=4)
        banner = nbformat.v4.new_markdown_cell(SOLUTION_BANNER)
        banner.id = "solution-version-banner"
        nb.cells.insert(0, banner)
        nbformat.write(nb, out / path.name)
        written.append(path.name)
    return written


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "build" / "assignment")
    parser.add_argument("--solutions", action="store_true", help="the solution version, with a banner")
    parser.add_argument("--quiet", action="store_true", help="print nothing when all goes well")
    args = parser.parse_args(argv)
    names = build_solutions(args.out) if args.solutions else build(args.out)
    if not args.quiet:
        print(f"wrote {len(names)} {'solution' if args.solutions else 'assignment'} notebooks to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
