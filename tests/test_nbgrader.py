"""A course grades the workbook's exercises with nbgrader (the version pinned in the dev extra).

notebooks/ is the course's source version as it stands. A course folder in a
temporary directory releases every exercise notebook (``generate_assignment``);
no released cell shows the source of a routine an exercise asks for. Three
students hand in the graded notebooks: the stubs as released, every solution, and
every solution but one with a typical mistake (the sign of C flipped in the
uniform Laplacian). One ``autograde`` grades them all: the auto-graded points
are scored, the hand-graded discussion waits as "needs manual grade" until a
grader enters points; ``export`` writes the CSV; ``validate`` fails on the stubs,
naming the exercises, and passes on a full solution; ``generate_feedback`` writes
pages showing the student's code, the grading judge's verdict in each grade cell (a
failed one with the check's diagnosis) and the lesson's cells set aside, unrun.
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

from geomlib.course.grading import CONFIG_LINE, MODEL_RUN, SET_ASIDE, SET_ASIDE_AGAIN

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))
sys.path.insert(0, str(ROOT / "tests"))

import build_assignment  # noqa: E402
from test_assignment import answer_leaks, exercises_of  # noqa: E402

NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
EXERCISE_NOTEBOOKS = [p for p in NOTEBOOKS if p.name[:2] != "00" and p.name[2] == "_"]
BIN = Path(sys.executable).parent
ASSIGNMENT = "curvature"
# the notebooks the three students hand in: the first task and those whose exercises carry the
# coursework (the eigenproblem, the smoothing loop, the denoising experiment)
GRADED = {
    "01": "01_uniform_laplace_curvature",
    "04": "04_spectral_reconstruction",
    "05": "05_explicit_smoothing",
    "07": "07_denoising_evaluation",
}
WRONG_EXERCISE = "uniform_laplacian"
DIAGNOSIS = "the sign of C is flipped"
GRADING = ROOT / "docs" / "grading.md"


def guide_points():
    """{(notebook, exercise): (check, partial credit, by hand, total)} from the grading guide's table."""
    cell = r"\|\s*(\d*)\s*"
    rows = re.findall(rf"^\| (\d\d) \| `(\w+)` {cell * 3}\| (\d+) \|$", GRADING.read_text(), flags=re.M)
    return {(nb, ex): tuple(int(x or 0) for x in values) for nb, ex, *values in rows}


def notebook_points():
    """The same table from the notebooks' grade cells: exercises and hand-graded answers."""
    points = {}
    for path in EXERCISE_NOTEBOOKS:
        nb = nbformat.read(path, as_version=4)
        grade = {
            c.metadata["nbgrader"]["grade_id"]: c.metadata["nbgrader"]["points"]
            for c in nb.cells
            if c.metadata.get("nbgrader", {}).get("grade")
        }
        for exercise, total in build_assignment.exercise_points(nb).items():
            parts = (grade[f"{exercise}_check"], grade[f"{exercise}_partial_credit"])
            points[(path.name[:2], exercise)] = (*parts, 0, total)
        for answer, hand in build_assignment.discussion_points(nb).items():
            points[(path.name[:2], answer)] = (0, 0, hand, hand)
    return points


def auto_points(name):
    """Auto-graded points of a notebook."""
    return sum(a + b for (nb, _), (a, b, _, _) in notebook_points().items() if nb == name[:2])


def hand_points(name):
    return sum(h for (nb, _), (_, _, h, _) in notebook_points().items() if nb == name[:2])


def test_every_exercise_and_discussion_has_points_and_the_guide_lists_them():
    points = notebook_points()
    assert {nb for nb, _ in points} == {f"0{i}" for i in range(1, 8)}
    exercises = {k: v for k, v in points.items() if v[2] == 0}
    discussions = {k: v for k, v in points.items() if v[2] > 0}
    assert all(check >= 1 and partial == 1 for check, partial, _, _ in exercises.values())
    assert {nb for nb, _ in discussions} == {f"0{i}" for i in range(1, 8)}, "a notebook without a graded discussion"
    assert guide_points() == points
    total = sum(t for *_, t in points.values())
    assert f"| | **total** | | | | **{total}** |" in GRADING.read_text()


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
            for _, cell in build_assignment.answer_cells(nb):
                cell.source = "My answer, in a few sentences, from the numbers above."
        nbformat.write(nb, out / f"{name}.ipynb")


def flip_the_sign_of_C(exercise, source):
    if exercise != WRONG_EXERCISE:
        return source
    right = "C = (A - M)"
    assert right in source
    return source.replace(right, "C = (M - A)")


@pytest.fixture(scope="module")
def course(tmp_path_factory):
    course = tmp_path_factory.mktemp("course")
    (course / "nbgrader_config.py").write_text(
        "c = get_config()\n"
        f"c.CourseDirectory.root = {str(course)!r}\n"
        f"c.CourseDirectory.course_id = 'geomlib'\n"
        f"c.Exchange.root = {str(course / 'exchange')!r}\n"
        "c.Execute.timeout = 600\n"
        f"{CONFIG_LINE}\n"  # the points decided out of the kernel's reach (docs/grading.md)
    )
    (course / "exchange").mkdir()
    source = course / "source" / ASSIGNMENT
    source.mkdir(parents=True)
    for path in EXERCISE_NOTEBOOKS:
        (source / path.name).write_bytes(path.read_bytes())
    nbgrader(course, "generate_assignment", ASSIGNMENT)
    hand_in(course, "stubs")
    hand_in(course, "solved", lambda exercise, source: source)
    hand_in(course, "one_mistake", flip_the_sign_of_C)
    (course / "autograde.log").write_text(nbgrader(course, "autograde", ASSIGNMENT).stderr)
    nbgrader(course, "export", "--to", str(course / "grades.csv"))
    nbgrader(course, "generate_feedback", ASSIGNMENT)
    return course


@pytest.mark.slow
@pytest.mark.parametrize("path", EXERCISE_NOTEBOOKS, ids=[p.name for p in EXERCISE_NOTEBOOKS])
def test_nbgraders_release_shows_no_exercise_routine_and_no_model_answer(course, path):
    nb = nbformat.read(course / "release" / ASSIGNMENT / path.name, as_version=4)
    assert answer_leaks(nb, exercises_of(nb)) == []
    assert not any(build_assignment.HIDDEN_BEGIN in c.source for c in nb.cells)
    solution = nbformat.read(path, as_version=4)
    for i, cell in build_assignment.answer_cells(solution):
        assert nb.cells[i].source.strip() == "YOUR ANSWER HERE"


@pytest.mark.slow
def test_autograde_scores_stubs_zero_a_typical_mistake_fewer_solutions_full_and_waits_for_the_discussion(course):
    from nbgrader.api import Gradebook

    auto = [auto_points(name) for name in GRADED.values()]
    hand = [hand_points(name) for name in GRADED.values()]
    wrong = notebook_points()[("01", WRONG_EXERCISE)][0]  # the check cell's points; partial credit stays
    scores = {"stubs": [0.0] * len(auto), "solved": auto, "one_mistake": [auto[0] - wrong, *auto[1:]]}
    with Gradebook(f"sqlite:///{course / 'gradebook.db'}") as gb:
        for student, expected in scores.items():
            got = [gb.find_submission_notebook(name, ASSIGNMENT, student) for name in GRADED.values()]
            assert [nb.score for nb in got] == expected, student
            assert [nb.max_score for nb in got] == [a + h for a, h in zip(auto, hand)]
            # an answer box left blank scores 0 at once; a written answer waits for a grader
            assert all(nb.needs_manual_grade == (student != "stubs") for nb in got), student
        # a grader enters the hand-graded points of the solved student, as the formgrader's grade
        # handler does (the score and the flag): the score includes them
        for name in GRADED.values():
            submission = gb.find_submission_notebook(name, ASSIGNMENT, "solved")
            for grade in submission.grades:
                if grade.cell.max_score and grade.needs_manual_grade:
                    grade.manual_score, grade.needs_manual_grade = grade.cell.max_score, False
            gb.db.commit()
        got = [gb.find_submission_notebook(name, ASSIGNMENT, "solved") for name in GRADED.values()]
        assert [nb.score for nb in got] == [a + h for a, h in zip(auto, hand)]
        assert not any(nb.needs_manual_grade for nb in got)
    with open(course / "grades.csv", newline="") as f:
        rows = {row["student_id"]: row for row in csv.DictReader(f)}
    assert {s: float(r["score"]) for s, r in rows.items()} == {s: sum(v) for s, v in scores.items()}


@pytest.mark.slow
def test_grading_puts_the_model_answers_back(course):
    for name in GRADED.values():
        solution = nbformat.read(ROOT / "notebooks" / f"{name}.ipynb", as_version=4)
        graded = nbformat.read(course / "autograded" / "solved" / ASSIGNMENT / f"{name}.ipynb", as_version=4)
        hidden = [i for i, c in enumerate(solution.cells) if build_assignment.HIDDEN_BEGIN in c.source]
        for i in hidden:
            assert graded.cells[i].source == solution.cells[i].source


@pytest.mark.slow
def test_autograde_warns_only_of_the_model_answers_it_puts_back(course):
    """The grading guide tells a lecturer to expect these warnings, and no others."""
    lines = (course / "autograde.log").read_text().splitlines()
    # "No submitted file": these students hand in only the GRADED notebooks, a class all seven
    warnings = [line for line in lines if "| WARNING]" in line and "No submitted file: " not in line]
    expected = [
        (student, answer)
        for student in ("stubs", "solved", "one_mistake")
        for name in GRADED.values()
        for answer in model_answers(ROOT / "notebooks" / f"{name}.ipynb")
    ]
    cells = [re.search(r"Attribute 'checksum' for cell (\w+_model_answer) has changed!", w) for w in warnings]
    assert all(cells), warnings
    assert sorted(c.group(1) for c in cells) == sorted(answer for _, answer in expected)
    assert '_model_answer has changed!": expected' in " ".join(GRADING.read_text().split())


def model_answers(path):
    """The grade ids of a notebook's model-answer cells."""
    ids = (c.metadata.get("nbgrader", {}).get("grade_id", "") for c in nbformat.read(path, as_version=4).cells)
    return [grade_id for grade_id in ids if grade_id.endswith("_model_answer")]


def ran(cell):
    """Whether the kernel ran a cell while grading (nbclient records when it started it)."""
    return "iopub.execute_input" in cell.get("metadata", {}).get("execution", {})


@pytest.mark.slow
@pytest.mark.parametrize("student", ("stubs", "solved", "one_mistake"))
def test_feedback_pages_show_the_judges_verdicts_and_the_students_code_with_the_lesson_set_aside(course, student):
    # the kernel runs the first cell, the parameters and the solution cells; the judge fills the grade cells
    for name in GRADED.values():
        nb = json.loads((course / "autograded" / student / ASSIGNMENT / f"{name}.ipynb").read_text())
        code = [c for c in nb["cells"] if c["cell_type"] == "code"]
        for i, cell in enumerate(code):
            info = cell["metadata"].get("nbgrader", {})
            kernel = i == 0 or "parameters" in cell["metadata"].get("tags", []) or info.get("solution")
            assert ran(cell) == bool(kernel and not info.get("grade")), (name, cell["source"][:80])
        ids = [c["metadata"].get("nbgrader", {}).get("grade_id", "") for c in code]
        judged = [c for c, g in zip(code, ids) if g.endswith(("_check", "_partial_credit"))]
        assert judged and all(not ran(c) and c["outputs"] for c in judged)
        # the rubric and the model answer with the lesson's numbers, from one run of the course's solution
        answers = [c for c, g in zip(code, ids) if g.endswith("_model_answer")]
        assert answers and all(not ran(c) for c in answers)
        for cell in answers:
            said, *shown = cell["outputs"]
            assert "".join(said["data"]["text/markdown"]) == MODEL_RUN and shown, name
            assert all("Rubric (" in "".join(o["data"]["text/markdown"]) for o in shown), name
        # every cell of the lesson is left unrun and says so, the first at length
        lesson = [c for c in code if not ran(c) and c not in judged + answers]
        notes = ["".join(c["outputs"][0]["data"]["text/plain"]) for c in lesson]
        assert lesson and notes == [SET_ASIDE] + [SET_ASIDE_AGAIN] * (len(lesson) - 1), name
        assert all(len(c["outputs"]) == 1 for c in lesson)
        page = (course / "feedback" / student / ASSIGNMENT / f"{name}.html").read_text()
        assert "widget-view+json" not in page and "data:image/png;base64," not in page
        assert page.count("(decided by the grading judge)") == len(judged)  # each verdict, passed or failed
        assert (DIAGNOSIS in page) == (student == "one_mistake" and name == GRADED["01"])
        if student == "stubs":
            assert page.count("not written yet") >= 4  # each exercise's two grade cells
        # the model answer the release hid, put back: its rubric and its prose, not only numbers, once
        assert "Rubric (" in page and "Model answer" in page, name
        assert "BEGIN HIDDEN TESTS" not in page and page.count("Rubric (") == len(answers), name


@pytest.mark.slow
def test_validate_names_the_exercises_still_to_do_and_passes_a_solution(course):
    stubs = nbgrader(course, "validate", str(course / "submitted" / "stubs" / ASSIGNMENT / f"{GRADED['01']}.ipynb"))
    assert re.search(r"VALIDATION FAILED ON \d+ CELL\(S\)", stubs.stdout), stubs.stdout[-2000:]
    for exercise in ("uniform_laplacian", "gaussian_curvature"):
        assert f"CheckFailed: {exercise}: not written yet" in stubs.stdout
        assert f"CheckFailed: {exercise}, partial credit: not written yet" in stubs.stdout
    # every line of the checks' messages whole: nbgrader cuts a longer line with "..."
    errors = re.findall(r"The error was:\n\n(.*?)(?:\n=====|\Z)", stubs.stdout, flags=re.S)
    assert "Reread section 2" in stubs.stdout and errors
    assert not [line for e in errors for line in e.splitlines() if line.endswith("...")], errors
    solved = nbgrader(course, "validate", str(course / "submitted" / "solved" / ASSIGNMENT / f"{GRADED['05']}.ipynb"))
    assert "Success! Your notebook passes all the tests." in solved.stdout


@pytest.mark.slow
def test_the_assignment_build_is_an_nbgrader_release_like_generate_assignments(course, tmp_path):
    from nbgrader.nbgraderformat import MetadataValidator

    build_assignment.build(tmp_path)
    for path in EXERCISE_NOTEBOOKS:
        ours = nbformat.read(tmp_path / path.name, as_version=4)
        theirs = nbformat.read(course / "release" / ASSIGNMENT / path.name, as_version=4)
        MetadataValidator().validate_nb(ours)
        keys = ("grade", "grade_id", "locked", "points", "solution")
        assert [{k: c.metadata.get("nbgrader", {}).get(k) for k in keys} for c in ours.cells] == [
            {k: c.metadata.get("nbgrader", {}).get(k) for k in keys} for c in theirs.cells
        ]


@pytest.mark.parametrize("set_aside", (True, False))
def test_the_judge_tags_what_the_kernel_skips_and_untags_what_it_must_run(set_aside):
    from traitlets.config import Config

    from geomlib.course.grading import JudgeExercises

    nb = nbformat.read(ROOT / "notebooks" / "05_explicit_smoothing.ipynb", as_version=4)
    solution = next(c for c in nb.cells if c.metadata.get("nbgrader", {}).get("grade_id") == "lam_max")
    solution.metadata["tags"] = ["skip-execution"]  # a student's tag, to keep a cell from nbgrader's run
    config = Config({"JudgeExercises": {"set_aside_lessons": set_aside}})
    resources = {"nbgrader": {"notebook": "none", "assignment": "none"}}  # no source folder: no model answers
    nb, resources = JudgeExercises(config=config).preprocess(nb, resources)
    assert JudgeExercises(config=config).preprocess(nb, resources)[0] is nb  # judged once per conversion
    code = [c for c in nb.cells if c.cell_type == "code"]
    skipped = ["skip-execution" in c.metadata.get("tags", []) for c in code]
    for i, (cell, skip) in enumerate(zip(code, skipped)):
        info = cell.metadata.get("nbgrader", {})
        judged = info.get("grade_id", "").endswith(("_check", "_partial_credit"))
        kernel = i == 0 or "parameters" in cell.metadata.get("tags", []) or info.get("solution")
        assert skip == (judged or (set_aside and not kernel)), cell.source[:80]
        assert bool(cell.outputs) == (judged or (set_aside and skip)), cell.source[:80]
    assert not solution.metadata["tags"]
    assert set(nb.metadata["geomlib"]["grading"]) == {"lam_max", "smoothing_loop"}
