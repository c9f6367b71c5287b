"""geomlib-course grades a class as nbgrader does, several students at once, and reports its mistakes.

A course folder releases notebook 01 (the first task, quick to grade) and 22 simulated
students hand it in (tests/course_class.py: honest students, each typical mistake, catch-alls,
a forbidden call, copies, near-identical pairs, stubs). nbgrader's own serial ``autograde``
grades a copy of the course: its gradebook is the reference. ``geomlib-course autograde``
then grades other copies with ``--workers 4`` and ``--workers 1``, on the default SQLite
gradebook and on a PostgreSQL server started for the test (as root through ``runuser``:
PostgreSQL refuses to run as root): every grade and comment equals the reference's. The
class report counts each outcome exactly, and flags the copies and the pairs, nobody else.
"""

import csv
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import textwrap
from glob import glob
from pathlib import Path

import nbformat
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

import course_class as cc  # noqa: E402

from geomlib.course import autograde as parallel  # noqa: E402
from geomlib.course.cli import main as geomlib_course  # noqa: E402
from geomlib.course.gradebook import class_grades  # noqa: E402

ASSIGNMENT = "curvature"
NOTEBOOK = "01_uniform_laplace_curvature"
BIN = Path(sys.executable).parent
STUB_BODY = "    # YOUR CODE HERE\n    raise NotImplementedError()"


def nbgrader(folder, *args):
    env = dict(os.environ, PATH=f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}")
    env.pop("GEOMLIB_STRICT_CLAIMS", None)
    done = subprocess.run([str(BIN / "nbgrader"), *args], cwd=folder, env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    return done


def write_config(folder, db_url=None):
    lines = [
        "c = get_config()",
        f"c.CourseDirectory.root = {str(folder)!r}",
        "c.CourseDirectory.course_id = 'geomlib'",
        f"c.Exchange.root = {str(folder / 'exchange')!r}",
        "c.Execute.timeout = 600",
    ]
    if db_url:
        lines.append(f"c.CourseDirectory.db_url = {db_url!r}")
    (folder / "nbgrader_config.py").write_text("\n".join(lines) + "\n")


def solution_body(exercise, renamed=False):
    nb = nbformat.read(ROOT / "notebooks" / f"{NOTEBOOK}.ipynb", as_version=4)
    (cell,) = [c for c in nb.cells if c.metadata.get("nbgrader", {}).get("grade_id") == exercise]
    body = textwrap.dedent(cell.source.split("### BEGIN SOLUTION\n")[1].split("### END SOLUTION")[0])
    return cc.renamed_solution(body) if renamed else body


def answer(stub, exercise, spec):
    """The solution cell a student hands in: the released cell with their body in place of the stub."""
    if spec is None:
        return stub
    body = {cc.SOLUTION: lambda: solution_body(exercise), cc.RENAMED: lambda: solution_body(exercise, True)}
    body["geomlib"] = cc.geomlib_copy
    code = body[spec]() if spec in body else spec
    assert STUB_BODY in stub
    return stub.replace(STUB_BODY, textwrap.indent(code.strip("\n"), "    "))


def hand_in(course):
    release = nbformat.read(course / "release" / ASSIGNMENT / f"{NOTEBOOK}.ipynb", as_version=4)
    for student, (uniform, gaussian, wrote) in cc.CLASS.items():
        nb = nbformat.from_dict(release)
        for cell in nb.cells:
            grade_id = cell.metadata.get("nbgrader", {}).get("grade_id")
            if grade_id == cc.UNIFORM:
                cell.source = answer(cell.source, grade_id, uniform)
            elif grade_id == cc.GAUSSIAN:
                cell.source = answer(cell.source, grade_id, gaussian)
            elif grade_id == cc.DISCUSSION and wrote:
                cell.source = "The uniform H does not converge: it measures the tessellation, not the surface."
        out = course / "submitted" / student / ASSIGNMENT
        out.mkdir(parents=True)
        nbformat.write(nb, out / f"{NOTEBOOK}.ipynb")


@pytest.fixture(scope="module")
def released(tmp_path_factory):
    """A course folder with notebook 01 released and the class's submissions, not graded yet."""
    course = tmp_path_factory.mktemp("class") / "course"
    (course / "source" / ASSIGNMENT).mkdir(parents=True)
    (course / "exchange").mkdir()
    shutil.copy(ROOT / "notebooks" / f"{NOTEBOOK}.ipynb", course / "source" / ASSIGNMENT)
    write_config(course)
    nbgrader(course, "generate_assignment", ASSIGNMENT)
    hand_in(course)
    return course


def copy_course(released, where, db_url=None):
    course = where / "course"
    shutil.copytree(released, course)
    write_config(course, db_url)
    return course


@pytest.fixture(scope="module", autouse=True)
def readers_mode():
    """Graded as a course grades: without the test suite's strict claims."""
    with pytest.MonkeyPatch.context() as mp:
        mp.delenv("GEOMLIB_STRICT_CLAIMS", raising=False)
        yield


@pytest.fixture(scope="module")
def reference(released, tmp_path_factory):
    """The grades nbgrader's own serial autograde gives the class."""
    course = copy_course(released, tmp_path_factory.mktemp("serial"))
    nbgrader(course, "autograde", ASSIGNMENT)
    return grades_of(f"sqlite:///{course / 'gradebook.db'}")


def grades_of(db_url):
    from nbgrader.api import Gradebook

    with Gradebook(db_url, "geomlib") as gb:
        return class_grades(gb, ASSIGNMENT)


@pytest.fixture(scope="module")
def graded(released, tmp_path_factory):
    """The class graded by geomlib-course autograde --workers 4 on SQLite, and its report."""
    course = copy_course(released, tmp_path_factory.mktemp("workers4"))
    lines = []
    done = parallel.autograde_class(course, ASSIGNMENT, workers=4, out=lines.append)
    assert all(g.ok for g in done), [g.log[-2000:] for g in done if not g.ok]
    assert geomlib_course(["report", str(course), ASSIGNMENT]) == 0
    return course, lines


@pytest.fixture(scope="module")
def postgres():
    """A PostgreSQL server of its own for the test: (url of a database maker, stop)."""
    binaries = [shutil.which("initdb"), *sorted(glob("/usr/lib/postgresql/*/bin/initdb"))]
    initdb = next((Path(b) for b in binaries if b), None)
    assert initdb is not None, "PostgreSQL is not installed (Debian: apt-get install postgresql; .ci/run does)"
    pg_ctl = initdb.parent / "pg_ctl"
    if not pg_ctl.exists():
        pg_ctl = Path(shutil.which("pg_ctl"))
    data = Path(tempfile.mkdtemp(prefix="geomlib-pg-"))
    as_user = ["runuser", "-u", "postgres", "--"] if os.geteuid() == 0 else []
    if as_user:
        shutil.chown(data, "postgres")
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    run = lambda *args: subprocess.run([*as_user, *map(str, args)], check=True, capture_output=True, text=True)
    run(initdb, "-D", data / "db", "-A", "trust", "-U", "postgres")
    run(
        pg_ctl,
        "-D",
        data / "db",
        "-o",
        f"-p {port} -k {data} -c listen_addresses=127.0.0.1",
        "-l",
        data / "log",
        "-w",
        "start",
    )
    import psycopg

    def database(name):
        with psycopg.connect(f"host=127.0.0.1 port={port} user=postgres dbname=postgres", autocommit=True) as db:
            db.execute(f"CREATE DATABASE {name}")
        return f"postgresql+psycopg://postgres@127.0.0.1:{port}/{name}"

    yield database
    run(pg_ctl, "-D", data / "db", "-m", "fast", "-w", "stop")
    shutil.rmtree(data, ignore_errors=True)


def test_a_checks_message_gives_its_diagnosis_the_same_for_every_student():
    from geomlib.course.report import diagnosis_of

    message = "uniform_laplacian: the sign of C is flipped. Hint: C_ii = -valence. Reread section 2."
    assert diagnosis_of("uniform_laplacian", ("CheckFailed", message)) == cc.SIGN
    seeded = "add_noise: the noise is not scaled (seed 81723). Hint: h. Reread section 1."
    assert diagnosis_of("add_noise", ("CheckFailed", seeded)) == "the noise is not scaled"
    partial = "uniform_laplacian, partial credit: not written yet: the function raises NotImplementedError."
    assert diagnosis_of("uniform_laplacian", ("CheckFailed", partial)) == "not written yet"
    assert diagnosis_of("x", ("NameError", "name 'my_x' is not defined")) == (
        "the grade cell raised NameError: name 'my_x' is not defined"
    )
    assert diagnosis_of("x", None) == ""


def test_progress_line_says_done_of_total_seconds_and_time_left():
    line = parallel.progress_line(3, 20, "alice", 5.24, 12.0)
    assert line == "[ 3/20] alice graded in 5.2 s; 12 s elapsed, about 68 s left"
    assert parallel.progress_line(20, 20, "bob", 4.0, 80.0, ok=False).endswith(
        "FAILED in 4.0 s; 80 s elapsed, about 0 s left"
    )


def test_the_course_is_read_as_nbgrader_reads_it_in_its_folder(tmp_path):
    from geomlib.course.coursedir import load_course

    (tmp_path / "nbgrader_config.py").write_text(
        "c = get_config()\nc.CourseDirectory.course_id = 'geo'\nc.CourseDirectory.db_url = 'sqlite:///grades.db'\n"
    )
    for student in ("bob", "alice"):
        (tmp_path / "submitted" / student / "hw1").mkdir(parents=True)
    (tmp_path / "submitted" / "carol" / "hw2").mkdir(parents=True)
    course = load_course(tmp_path)
    assert course.course_id == "geo" and course.root == tmp_path.resolve()
    assert course.sqlite_file == tmp_path.resolve() / "grades.db"  # relative to the course folder
    assert course.submitted_students("hw1") == ["alice", "bob"]


@pytest.mark.slow
def test_the_class_has_twenty_students_or_more_and_every_kind_of_answer():
    assert len(cc.CLASS) >= 20
    students = {s for ids in cc.EXPECTED.values() for s in ids}
    assert students == set(cc.CLASS)


@pytest.mark.slow
def test_four_workers_on_sqlite_leave_the_grades_of_nbgraders_serial_autograde(graded, reference):
    course, lines = graded
    assert grades_of(f"sqlite:///{course / 'gradebook.db'}") == reference
    grades, _ = reference
    assert {s for s, _, _ in grades} == set(cc.CLASS)
    # the honest student's auto-graded points are all there; the stub's are 0
    auto = lambda student: sum(v[0] or 0 for (s, _, _), v in grades.items() if s == student)
    assert auto("honest_1") == 6 and auto("stub_1") == 0 and auto("sign_1") == 1


@pytest.mark.slow
def test_progress_shows_each_student_with_the_count_seconds_and_time_left(graded):
    _, lines = graded
    assert len(lines) == len(cc.CLASS)
    total = len(cc.CLASS)
    for k, line in enumerate(lines, 1):
        m = re.fullmatch(rf"\[\s*{k}/{total}\] (\w+) graded in [\d.]+ s; \d+ s elapsed, about (\d+) s left", line)
        assert m and m.group(1) in cc.CLASS, line
    assert lines[-1].endswith("about 0 s left")


@pytest.mark.slow
def test_one_worker_on_sqlite_grades_as_nbgrader_does(released, reference, tmp_path):
    course = copy_course(released, tmp_path)
    few = ["honest_2", "sign_2", "boundary_1", "stub_2"]
    assert (
        geomlib_course(
            ["autograde", str(course), ASSIGNMENT, "--workers", "1", *sum((["--student", s] for s in few), [])]
        )
        == 0
    )
    grades, comments = grades_of(f"sqlite:///{course / 'gradebook.db'}")
    assert grades == {k: v for k, v in reference[0].items() if k[0] in few}
    assert comments == {k: v for k, v in reference[1].items() if k[0] in few}


@pytest.mark.slow
@pytest.mark.parametrize("workers", [4, 1])
def test_workers_writing_to_postgresql_leave_the_grades_of_nbgraders_serial_autograde(
    released, reference, postgres, tmp_path, workers
):
    db_url = postgres(f"class_{workers}")
    course = copy_course(released, tmp_path, db_url)
    nbgrader(course, "generate_assignment", ASSIGNMENT, "--force")  # the assignment into the new gradebook
    # a part of the class (the SQLite runs grade all of it): each worker grades two students
    few = ["honest_3", "identity_1", "forbidden_1", "copy_solution", "pair_b1", "degrees_1", "stub_1", "sign_3"]
    students = few[: 2 * workers] if workers > 1 else few[:3]
    done = parallel.autograde_class(course, ASSIGNMENT, workers=workers, students=students, out=lambda line: None)
    assert all(g.ok for g in done)
    grades, comments = grades_of(db_url)
    keep = lambda table: {k: v for k, v in table.items() if k[0] in students}
    assert grades == keep(reference[0]) and comments == keep(reference[1])


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


@pytest.mark.slow
def test_the_class_report_counts_every_outcome_exactly(graded):
    course, _ = graded
    rows = read_csv(course / "reports" / ASSIGNMENT / "class-report.csv")
    assert {"exercise", "diagnosis", "students", "share", "student_ids"} <= set(rows[0])
    n = len(cc.CLASS)
    for (exercise, kind, diagnosis), expected in cc.EXPECTED.items():
        found = [r for r in rows if r["exercise"] == exercise and r["kind"] == kind]
        if diagnosis is not None:
            found = [r for r in found if r["diagnosis"] == diagnosis]
        ids = {s for r in found for s in r["student_ids"].split()}
        assert ids == expected, (exercise, kind, diagnosis)
        for r in found:
            assert int(r["students"]) == len(r["student_ids"].split())
            assert float(r["share"]) == pytest.approx(int(r["students"]) / n, abs=1e-3)
    # per exercise the rows cover the class once; the named mistakes are ranked by students
    for exercise in (cc.UNIFORM, cc.GAUSSIAN):
        ids = [s for r in rows if r["exercise"] == exercise for s in r["student_ids"].split()]
        assert sorted(ids) == sorted(cc.CLASS)
        counts = [int(r["students"]) for r in rows if r["exercise"] == exercise and r["kind"] != "passed"]
        assert counts == sorted(counts, reverse=True)
    assert [r["diagnosis"] for r in rows if r["exercise"] == cc.UNIFORM and r["kind"] == "named mistake"] == [
        cc.SIGN,
        cc.IDENTITY,
    ]
    (refused,) = [r for r in rows if r["kind"] == "refused"]
    assert "calls geomlib's `uniform_laplacian`" in refused["diagnosis"]
    wrote = {s for s, (_, _, w) in cc.CLASS.items() if w}
    waiting = [r for r in rows if r["exercise"] == cc.DISCUSSION and r["kind"] == "waiting for a grader"]
    assert set(waiting[0]["student_ids"].split()) == wrote
    blank = [r for r in rows if r["exercise"] == cc.DISCUSSION and r["kind"] == "left blank"]
    assert set(blank[0]["student_ids"].split()) == set(cc.CLASS) - wrote


@pytest.mark.slow
def test_copies_and_near_identical_pairs_are_flagged_and_nobody_else(graded):
    course, _ = graded
    flags = read_csv(course / "reports" / ASSIGNMENT / "flags.csv")
    assert {(f["student_id"], f["exercise"], f["flag"]) for f in flags} == cc.FLAGGED
    pairs = {f["student_id"]: f["detail"] for f in flags if f["flag"] == "near-identical pair"}
    assert pairs["pair_a1"].startswith("with pair_a2") and pairs["pair_b2"].startswith("with pair_b1")


@pytest.mark.slow
def test_the_html_report_shows_the_counts_a_picture_and_the_flags(graded):
    course, _ = graded
    page = (course / "reports" / ASSIGNMENT / "class-report.html").read_text()
    assert page.count("<img src='data:image/png;base64,") == 1
    passed = len(cc.EXPECTED[(cc.UNIFORM, "passed", None)])
    assert f"passed by {passed} of {len(cc.CLASS)}" in page
    assert cc.SIGN in page and "near-identical pair" in page and "copy of geomlib" in page


GUIDE = ROOT / "docs" / "grading.md"
MARK = "<!-- run by tests/test_course.py::test_the_guides_course_folder_and_one_machine_trial -->"


def marked_blocks():
    """The shell code blocks of the grading guide that this module runs, in order."""
    return re.findall(re.escape(MARK) + r"\n```bash\n(.*?)^```", GUIDE.read_text(), flags=re.M | re.S)


@pytest.mark.slow
def test_the_guides_course_folder_and_one_machine_trial(tmp_path):
    """The guide's commands as a lecturer types them from a checkout: the course folder from
    nbgrader quickstart, then a trial on one machine with two students."""
    setup, trial = marked_blocks()
    assert setup.startswith("source .venv/bin/activate\n")
    exchange = tmp_path / "exchange"
    script = setup.split("\n", 1)[1].replace("/srv/nbgrader/exchange", str(exchange)) + trial
    (tmp_path / "notebooks").symlink_to(ROOT / "notebooks")
    (tmp_path / "home").mkdir()
    env = dict(os.environ, PATH=f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}", HOME=str(tmp_path / "home"))
    done = subprocess.run(
        ["bash", "-euo", "pipefail", "-c", script], cwd=tmp_path, env=env, capture_output=True, text=True
    )
    log = done.stdout + done.stderr
    assert done.returncode == 0, log[-4000:]
    course = tmp_path / "geomlib-course"
    config = (course / "nbgrader_config.py").read_text()
    assert len(re.findall(r"^c\.CourseDirectory\.course_id", config, flags=re.M)) == 1
    # no header cell: the released notebook starts as the workbook's does, and no cell lacks an id
    released = nbformat.read(course / "release" / "trial" / f"{NOTEBOOK}.ipynb", as_version=4)
    source = nbformat.read(ROOT / "notebooks" / f"{NOTEBOOK}.ipynb", as_version=4)
    assert released.cells[0].source == source.cells[0].source
    assert "missing an id" not in log.lower()
    # each student filed under their own name, graded, and alice fetched her pages only
    assert sorted(p.name for p in (course / "submitted").iterdir()) == ["alice", "bob"]
    assert re.search(r"\[2/2\] (alice|bob) graded in", log)
    pages = sorted((tmp_path / "alice" / "trial" / "feedback").glob("*/*.html"))
    assert [p.name for p in pages] == [f"{NOTEBOOK}.html"]
    assert not (tmp_path / "bob" / "trial" / "feedback").exists()
    assert "geomlib-course/" in (ROOT / ".gitignore").read_text().splitlines()


def test_the_syllabus_feedback_sample_is_what_the_check_says(monkeypatch):
    """docs/syllabus.md's sample feedback: the lines a sign-flipped uniform Laplacian gets
    under its two grade cells while nbgrader grades with the judge (the run's seed aside)."""
    import numpy as np
    import scipy.sparse as sparse

    from geomlib import check

    monkeypatch.setenv("NBGRADER_EXECUTION", "autograde")
    namespace = {"np": np, "sparse": sparse}
    body = cc.U_DENSE.replace("{C}", "np.diag(A.sum(axis=1)) - A").strip("\n")
    exec("def my_uniform_laplacian(V, F):\n" + textwrap.indent(body, "    "), namespace)
    with pytest.raises(Exception) as failed:
        check.uniform_laplacian(namespace["my_uniform_laplacian"])
    partial = check.uniform_laplacian.partial_credit(namespace["my_uniform_laplacian"])
    judge = "(decided by the grading judge)"  # as the judge writes it
    said = [*failed.value._render_traceback_(), judge, f"{partial!r} {judge}"]
    (sample,) = re.findall(r"```text\n(.*?)```", (ROOT / "docs" / "syllabus.md").read_text(), flags=re.S)
    shown = [line for line in sample.splitlines() if line and not line.startswith("check.")]
    seedless = lambda lines: [re.sub(r"seed \d+", "seed N", line) for line in lines]
    assert seedless(shown) == seedless(said)


def test_model_answers_come_from_one_run_of_the_solution_and_are_read_back(tmp_path, monkeypatch):
    from geomlib.course import model_answers as answers

    nb = nbformat.v4.new_notebook()
    lesson = nbformat.v4.new_code_cell("import os\nn = 6 * 7")
    answer = nbformat.v4.new_code_cell("print(f'Rubric (3 points): {n}', os.environ['NBGRADER_EXECUTION'])")
    answer.metadata["nbgrader"] = {"grade": True, "grade_id": "q_model_answer", "locked": True, "points": 0}
    nb.cells = [lesson, answer]
    path = tmp_path / "solution.ipynb"
    nbformat.write(nb, path)
    monkeypatch.delenv("NBGRADER_EXECUTION", raising=False)
    first = answers.model_answers(path, cache_dir=tmp_path / "cache" / "eigenbases")
    assert [o["text"] for o in first["q_model_answer"]] == ["Rubric (3 points): 42 autograde\n"]
    monkeypatch.setattr(answers, "_run", lambda path: pytest.fail("ran the notebook again"))
    assert answers.model_answers(path, cache_dir=tmp_path / "cache" / "eigenbases") == first
    nbformat.write(nbformat.v4.new_notebook(cells=[answer]), path)  # another notebook: run anew
    monkeypatch.undo()
    again = answers.model_answers(path, cache_dir=tmp_path / "cache" / "eigenbases")
    assert again["q_model_answer"][0]["output_type"] == "error"  # n is the lesson's, not there
