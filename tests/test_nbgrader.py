"""A course grades the workbook's exercises with nbgrader (the version pinned in the dev extra).

notebooks/ is the course's source version as it stands. A course folder in a
temporary directory releases notebooks 01 and 05 (``generate_assignment``);
three students hand them in: the stubs as released, every solution, and every
solution but one with a typical mistake (the sign of C flipped in the uniform
Laplacian). One ``autograde`` grades them all; ``export`` writes the CSV;
``validate`` fails on the stubs, naming the exercises, and passes on a full
solution; ``generate_feedback`` writes pages whose 3D views are pictures and
whose failed grade cell shows the check's diagnosis.
"""

import csv
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import build_assignment  # noqa: E402

NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
BIN = Path(sys.executable).parent
ASSIGNMENT = "curvature"
GRADED = {"01": "01_uniform_laplace_curvature", "05": "05_explicit_smoothing"}
WRONG_EXERCISE = "uniform_laplacian"
DIAGNOSIS = "the sign of C is flipped"
# (notebook 01, notebook 05) scores of each student, out of (6, 4): the README's table
SCORES = {"stubs": (0.0, 0.0), "solved": (6.0, 4.0), "one_mistake": (4.0, 4.0)}
MAX_SCORES = (6.0, 4.0)


def readme_points():
    """{(notebook, exercise): (check points, partial-credit points, total)} from the README's table."""
    rows = re.findall(
        r"^\| (\d\d) \| `(\w+)` \| (\d+) \| (\d+) \| (\d+) \|$", (ROOT / "README.md").read_text(), flags=re.M
    )
    return {(nb, ex): (int(a), int(b), int(t)) for nb, ex, a, b, t in rows}


def notebook_points():
    points = {}
    for path in NOTEBOOKS:
        nb = nbformat.read(path, as_version=4)
        grade = {
            c.metadata["nbgrader"]["grade_id"]: c.metadata["nbgrader"]["points"]
            for c in nb.cells
            if c.metadata.get("nbgrader", {}).get("grade")
        }
        for exercise, total in build_assignment.exercise_points(nb).items():
            parts = (grade[f"{exercise}_check"], grade[f"{exercise}_partial_credit"])
            points[(path.name[:2], exercise)] = (*parts, total)
    return points


def test_every_exercise_has_points_and_the_readme_lists_them():
    points = notebook_points()
    assert {nb for nb, _ in points} == {f"0{i}" for i in range(1, 8)}
    assert all(check >= 1 and partial == 1 for check, partial, _ in points.values())
    assert readme_points() == points
    total = sum(t for _, _, t in points.values())
    assert f"| | **total** | | | **{total}** |" in (ROOT / "README.md").read_text()
    assert tuple(sum(t for (nb, _), (_, _, t) in points.items() if nb == k) for k in GRADED) == MAX_SCORES


def nbgrader(course, *args, check=True):
    env = dict(os.environ, PATH=f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}")  # nbgrader calls alembic
    env.pop("NBGRADER_EXECUTION", None)
    env.pop("GEOMLIB_STRICT_CLAIMS", None)  # graded as a course grades: the reader's mode
    done = subprocess.run(
        [str(BIN / "nbgrader"), *args], cwd=course, env=env, capture_output=True, text=True, timeout=900
    )
    if check:
        assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    return done


def solutions(name):
    nb = nbformat.read(ROOT / "notebooks" / f"{name}.ipynb", as_version=4)
    return {c.metadata["nbgrader"]["grade_id"]: c.source for _, c in build_assignment.solution_cells(nb)}


def hand_in(course, student, edit=None):
    """The released notebooks as a student hands them in: stubs (edit None) or solutions, edited."""
    out = course / "submitted" / student / ASSIGNMENT
    out.mkdir(parents=True)
    for name in GRADED.values():
        nb = nbformat.read(course / "release" / ASSIGNMENT / f"{name}.ipynb", as_version=4)
        if edit is not None:
            written = solutions(name)
            for _, cell in build_assignment.solution_cells(nb):
                exercise = cell.metadata["nbgrader"]["grade_id"]
                cell.source = edit(exercise, written[exercise])
        nbformat.write(nb, out / f"{name}.ipynb")


def flip_the_sign_of_C(exercise, source):
    if exercise != WRONG_EXERCISE:
        return source
    right = "(adjacency - sparse.diags(valence))"
    assert right in source
    return source.replace(right, "(sparse.diags(valence) - adjacency)")


@pytest.fixture(scope="module")
def course(tmp_path_factory):
    course = tmp_path_factory.mktemp("course")
    (course / "nbgrader_config.py").write_text(
        "c = get_config()\n"
        f"c.CourseDirectory.root = {str(course)!r}\n"
        f"c.CourseDirectory.course_id = 'geomlib'\n"
        f"c.Exchange.root = {str(course / 'exchange')!r}\n"
        "c.Execute.timeout = 600\n"
    )
    (course / "exchange").mkdir()
    source = course / "source" / ASSIGNMENT
    source.mkdir(parents=True)
    for name in GRADED.values():
        (source / f"{name}.ipynb").write_bytes((ROOT / "notebooks" / f"{name}.ipynb").read_bytes())
    nbgrader(course, "generate_assignment", ASSIGNMENT)
    hand_in(course, "stubs")
    hand_in(course, "solved", lambda exercise, source: source)
    hand_in(course, "one_mistake", flip_the_sign_of_C)
    nbgrader(course, "autograde", ASSIGNMENT)
    nbgrader(course, "export", "--to", str(course / "grades.csv"))
    nbgrader(course, "generate_feedback", ASSIGNMENT)
    return course


@pytest.mark.slow
def test_autograde_scores_stubs_zero_a_typical_mistake_fewer_and_solutions_full(course):
    from nbgrader.api import Gradebook

    with Gradebook(f"sqlite:///{course / 'gradebook.db'}") as gb:
        for student, expected in SCORES.items():
            got = [gb.find_submission_notebook(name, ASSIGNMENT, student) for name in GRADED.values()]
            assert tuple(nb.score for nb in got) == expected, student
            assert tuple(nb.max_score for nb in got) == MAX_SCORES
    with open(course / "grades.csv", newline="") as f:
        rows = {row["student_id"]: row for row in csv.DictReader(f)}
    assert {s: (float(r["score"]), float(r["max_score"])) for s, r in rows.items()} == {
        s: (sum(scores), sum(MAX_SCORES)) for s, scores in SCORES.items()
    }


def view_outputs(nb):
    """Outputs of a notebook that show a 3D view (a MeshView, a side_by_side row or a box of views)."""
    for cell in nb["cells"]:
        for out in cell.get("outputs", []):
            text = "".join(out.get("data", {}).get("text/plain", ""))
            if text.startswith("MeshView:") or text.startswith("still picture of the 3D views"):
                yield out


@pytest.mark.slow
@pytest.mark.parametrize("student", SCORES)
def test_feedback_pages_show_a_picture_for_every_view_and_the_diagnosis(course, student):
    for name in GRADED.values():
        nb = json.loads((course / "autograded" / student / ASSIGNMENT / f"{name}.ipynb").read_text())
        views = list(view_outputs(nb))
        assert views, f"{name}: no 3D view found"
        assert all(set(out["data"]) == {"image/png", "text/plain"} for out in views)
        pictures = sum("image/png" in out.get("data", {}) for c in nb["cells"] for out in c.get("outputs", []))
        page = (course / "feedback" / student / ASSIGNMENT / f"{name}.html").read_text()
        assert "widget-view+json" not in page
        assert len(re.findall(r'<img [^>]*src="data:image/png;base64,', page)) == pictures
        assert (DIAGNOSIS in page) == (student == "one_mistake" and name == GRADED["01"])
        if student == "stubs":
            assert page.count("not written yet") >= 4  # each exercise's two grade cells


@pytest.mark.slow
def test_validate_names_the_exercises_still_to_do_and_passes_a_solution(course):
    stubs = nbgrader(course, "validate", str(course / "submitted" / "stubs" / ASSIGNMENT / f"{GRADED['01']}.ipynb"))
    assert "VALIDATION FAILED ON 4 CELL(S)" in stubs.stdout
    for exercise in ("uniform_laplacian", "gaussian_curvature"):
        assert f"CheckFailed: {exercise}: not written yet" in stubs.stdout
        assert f"CheckFailed: {exercise}, partial credit: not written yet" in stubs.stdout
    solved = nbgrader(course, "validate", str(course / "submitted" / "solved" / ASSIGNMENT / f"{GRADED['05']}.ipynb"))
    assert "Success! Your notebook passes all the tests." in solved.stdout


@pytest.mark.slow
def test_the_assignment_build_is_an_nbgrader_release_like_generate_assignments(course, tmp_path):
    from nbgrader.nbgraderformat import MetadataValidator

    build_assignment.build(tmp_path)
    for name in GRADED.values():
        ours = nbformat.read(tmp_path / f"{name}.ipynb", as_version=4)
        theirs = nbformat.read(course / "release" / ASSIGNMENT / f"{name}.ipynb", as_version=4)
        MetadataValidator().validate_nb(ours)
        keys = ("grade", "grade_id", "locked", "points", "solution")
        assert [{k: c.metadata.get("nbgrader", {}).get(k) for k in keys} for c in ours.cells] == [
            {k: c.metadata.get("nbgrader", {}).get(k) for k in keys} for c in theirs.cells
        ]
