#!/usr/bin/env python3
"""Write the assignment version of the workbook: solutions replaced by stubs.

    python tools/build_assignment.py [--out build/assignment]

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
The output folder holds the notebooks and a copy of nothing else: they import
geomlib from the installed package and find the shipped meshes through it.
"""

import argparse
import re
import sys
from pathlib import Path

import nbformat

ROOT = Path(__file__).resolve().parent.parent
BEGIN, END = "### BEGIN SOLUTION", "### END SOLUTION"
_BLOCK = re.compile(r"^([ \t]*)### BEGIN SOLUTION[^\n]*\n.*?^[ \t]*### END SOLUTION[^\n]*(\n|$)", re.M | re.S)


def stub_source(source, exercise, reread):
    """``source`` with every solution block replaced by a NotImplementedError stub."""
    message = f"Your turn: write this ({exercise}). Reread {reread}, then run the check below."

    def stub(match):
        return f'{match.group(1)}raise NotImplementedError("{message}")\n'

    out, count = _BLOCK.subn(stub, source)
    if count == 0 or BEGIN in out or END in out:
        raise ValueError(f"exercise {exercise}: unbalanced or missing {BEGIN} / {END} markers")
    return out.rstrip("\n")


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
        except ValueError as exc:
            raise SystemExit(f"{path.name}: {exc}") from None
        for cell in nb.cells:
            if (
                cell.cell_type == "code"
                and (BEGIN in cell.source or END in cell.source)
                and not cell.metadata.get("nbgrader", {}).get("solution")
            ):
                raise SystemExit(f"{path.name}: solution markers in a cell without nbgrader solution metadata")
        nbformat.write(nb, out / path.name)
        written.append(path.name)
    return written


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=ROOT / "build" / "assignment")
    args = parser.parse_args(argv)
    names = build(args.out)
    print(f"wrote {len(names)} assignment notebooks to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
