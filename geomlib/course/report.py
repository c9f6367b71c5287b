"""The class report of an autograded assignment: what the class got right, and its mistakes.

``write_report(course_dir, assignment)`` reads the course's gradebook (the points, the
answers waiting for a grader) and the autograded notebooks (each failed check's message
under its grade cell names the mistake: ``CheckFailed: NAME: DIAGNOSIS. Hint: ...``) and
writes, under ``COURSE/reports/ASSIGNMENT/``:

* ``class-report.csv``: one row per exercise and outcome (columns ``exercise, notebook,
  kind, diagnosis, students, share, student_ids``), ranked by how many students it
  concerns: *passed*; each *named mistake* (the check names it: partial credit); the
  *catch-all* diagnoses (the check can only say that the answer differs, or the function
  raised); *refused* (a call of a routine the ground rules forbid); *not written* (the
  stub); for each Discuss question, the answers *waiting for a grader*, *left blank* and
  *graded*;
* ``flags.csv`` (``student_id, exercise, flag, detail``): copies of the solution notebook's
  or geomlib's routine, and near-identical pairs of students (:mod:`.similarity`);
* ``class-report.html``: the same for reading, with a picture of the outcomes per exercise
  and of the class's scores.
"""

import base64
import csv
import html
import io
import re
from collections import defaultdict
from dataclasses import dataclass, field

import nbformat

from .coursedir import load_course
from .similarity import COPIED, NEAR_IDENTICAL, geomlib_source, similar_answers

#: the outcomes of an auto-graded exercise, in the order the report shows them
KINDS = ("passed", "named mistake", "catch-all", "refused", "not written", "not submitted")
#: the states of a hand-graded answer
ANSWERS = ("waiting for a grader", "left blank", "graded")
COLOURS = {
    "passed": "#1a7f37",
    "named mistake": "#e69f00",
    "catch-all": "#d55e00",
    "refused": "#cc79a7",
    "not written": "#999999",
    "not submitted": "#dddddd",
}


@dataclass
class ClassResults:
    """What the class handed in and how it was graded.

    ``exercises`` and ``discussions``: [(notebook, name)] in notebook order;
    ``outcomes[(student, exercise)] = (kind, diagnosis)``; ``answers[(student, discussion)]``
    one of :data:`ANSWERS`; ``scores[student] = (score, max_score)`` of the assignment.
    """

    assignment: str
    students: list
    exercises: list = field(default_factory=list)
    discussions: list = field(default_factory=list)
    outcomes: dict = field(default_factory=dict)
    answers: dict = field(default_factory=dict)
    scores: dict = field(default_factory=dict)


def _text(source):
    return "".join(source) if isinstance(source, list) else source


def check_message(cell):
    """(exception name, message) of a grade cell's error output, or None if it ran cleanly."""
    for out in cell.get("outputs", []):
        if out.get("output_type") == "error":
            return out.get("ename", ""), out.get("evalue", "")
    return None


def diagnosis_of(exercise, error):
    """The mistake a check's message names: ``NAME: DIAGNOSIS. Hint: ... Reread ...`` -> DIAGNOSIS.

    A run's seed (checks that vary their cases say which) is left out, so that every
    student with the same mistake gets the same diagnosis; an error other than the check's
    is named by its type and message.
    """
    if error is None:
        return ""
    ename, message = error
    if ename != "CheckFailed":
        first = message.strip().splitlines()[0] if message.strip() else ""
        return f"the grade cell raised {ename}" + (f": {first}" if first else "")
    message = re.sub(rf"^{re.escape(exercise)}(, partial credit)?:\s*", "", message.strip())
    message = re.sub(r"\s*\((run )?seed[ =:]*\d+\)|\s*[,;]?\s*\b(run )?seed[ =:]*\d+", "", message)
    if message.startswith("not written yet"):
        return "not written yet"
    diagnosis = re.split(r"\.\s+(?:Hint:|Reread )", message, maxsplit=1)[0]
    return diagnosis.rstrip(".")


def _grade_cells(nb):
    """{grade_id: cell} of a notebook's nbgrader cells, in order."""
    return {c.metadata["nbgrader"]["grade_id"]: c for c in nb.cells if c.metadata.get("nbgrader", {}).get("grade_id")}


def read_class(course_dir, assignment):
    """The :class:`ClassResults` of an autograded assignment."""
    from nbgrader.api import Gradebook, MissingEntry

    course = load_course(course_dir)
    students = course.submitted_students(assignment)
    results = ClassResults(assignment, students)
    source = course.root / course.source_directory / assignment
    notebooks = sorted(p.stem for p in source.glob("*.ipynb"))
    for name in notebooks:
        cells = _grade_cells(nbformat.read(source / f"{name}.ipynb", as_version=4))
        for grade_id, cell in cells.items():
            meta = cell.metadata["nbgrader"]
            if grade_id.endswith("_check") and grade_id[: -len("_check")] + "_partial_credit" in cells:
                results.exercises.append((name, grade_id[: -len("_check")]))
            elif meta.get("grade") and meta.get("solution") and cell.cell_type == "markdown":
                results.discussions.append((name, grade_id))
    with Gradebook(course.db_url, course.course_id) as gb:
        for student in students:
            try:
                submission = gb.find_submission(assignment, student)
            except MissingEntry:
                continue
            results.scores[student] = (submission.score, submission.max_score)
            grades = {(nb.name, g.name): g for nb in submission.notebooks for g in nb.grades}
            for name in notebooks:
                path = course.path(course.autograded_directory, student, assignment) / f"{name}.ipynb"
                cells = _grade_cells(nbformat.read(path, as_version=4)) if path.exists() else {}
                handed_in = (course.path(course.submitted_directory, student, assignment) / f"{name}.ipynb").exists()
                for nb_name, exercise in results.exercises:
                    if nb_name != name:
                        continue
                    if not handed_in or not cells:
                        results.outcomes[(student, exercise)] = ("not submitted", "")
                        continue
                    check, partial = grades[(name, f"{exercise}_check")], grades[(name, f"{exercise}_partial_credit")]
                    diagnosis = diagnosis_of(exercise, check_message(cells[f"{exercise}_check"]))
                    if check.score == check.max_score:
                        kind, diagnosis = "passed", ""
                    elif partial.score:
                        kind = "named mistake"
                    elif diagnosis == "not written yet":
                        kind = "not written"
                    elif "calls geomlib's" in diagnosis or "ground rules" in diagnosis:
                        kind = "refused"
                    else:
                        kind = "catch-all"
                    results.outcomes[(student, exercise)] = (kind, diagnosis)
                for nb_name, discussion in results.discussions:
                    if nb_name != name:
                        continue
                    grade = grades[(name, discussion)]
                    if grade.needs_manual_grade:
                        state = "waiting for a grader"
                    elif grade.manual_score is None and not grade.auto_score:
                        state = "left blank"
                    else:
                        state = "graded"
                    results.answers[(student, discussion)] = state
    return results


def report_rows(results):
    """The rows of class-report.csv: per exercise its outcomes, each mistake ranked by students."""
    n = len(results.students)
    rows = []
    for notebook, exercise in results.exercises:
        groups = defaultdict(list, {("passed", ""): []})  # a pass rate of 0 is a row too
        for student in results.students:
            kind, diagnosis = results.outcomes.get((student, exercise), ("not submitted", ""))
            groups[(kind, diagnosis)].append(student)
        ranked = sorted(groups.items(), key=lambda item: (KINDS.index(item[0][0]) > 0, -len(item[1]), item[0]))
        for (kind, diagnosis), ids in ranked:
            rows.append(_row(exercise, notebook, kind, diagnosis or kind, ids, n))
    for notebook, discussion in results.discussions:
        groups = defaultdict(list)
        for student in results.students:
            groups[results.answers.get((student, discussion), "left blank")].append(student)
        for state in ANSWERS:
            if groups[state]:
                rows.append(_row(discussion, notebook, state, state, groups[state], n))
    return rows


def _row(exercise, notebook, kind, diagnosis, ids, n):
    return {
        "exercise": exercise,
        "notebook": notebook,
        "kind": kind,
        "diagnosis": diagnosis,
        "students": len(ids),
        "share": f"{len(ids) / n:.3f}" if n else "0",
        "student_ids": " ".join(sorted(ids)),
    }


def solution_code(nb, grade_id):
    """The source of a notebook's solution cell ``grade_id`` ("" if it has none)."""
    cell = _grade_cells(nb).get(grade_id)
    return cell.source if cell is not None else ""


def class_flags(course_dir, assignment, results):
    """The rows of flags.csv: for each exercise, copies of the answer and near-identical pairs."""
    from geomlib.teaching import check

    course = load_course(course_dir)
    flags = []
    for notebook, exercise in results.exercises:
        source = nbformat.read(course.root / course.source_directory / assignment / f"{notebook}.ipynb", as_version=4)
        release = course.root / course.release_directory / assignment / f"{notebook}.ipynb"
        stub_nb = nbformat.read(release, as_version=4) if release.exists() else source
        answers = {}
        for student in results.students:
            path = course.path(course.submitted_directory, student, assignment) / f"{notebook}.ipynb"
            if path.exists():
                answers[student] = solution_code(nbformat.read(path, as_version=4), exercise)
        references = {
            "the solution notebook's answer": solution_code(source, exercise),
            "geomlib's own routine": geomlib_source(getattr(check, exercise, None)),
        }
        for student, flag, detail in similar_answers(answers, references, solution_code(stub_nb, exercise)):
            flags.append({"student_id": student, "exercise": exercise, "flag": flag, "detail": detail})
    return sorted(flags, key=lambda f: (f["exercise"], f["student_id"], f["flag"]))


def _png(fig):
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110, bbox_inches="tight")
    return base64.b64encode(buffer.getvalue()).decode()


def outcome_figure(results):
    """A bar per exercise split by outcome (shares of the class), and the class's scores."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = max(len(results.students), 1)
    names = [exercise for _, exercise in results.exercises]
    fig, (bars, hist) = plt.subplots(
        1, 2, figsize=(11, 0.45 * len(names) + 2.2), gridspec_kw={"width_ratios": [2.2, 1]}
    )
    left = [0.0] * len(names)
    for kind in KINDS:
        share = [
            sum(results.outcomes.get((s, e), ("not submitted",))[0] == kind for s in results.students) / n
            for _, e in results.exercises
        ]
        if any(share):
            bars.barh(names, share, left=left, color=COLOURS[kind], label=kind, edgecolor="white")
            left = [a + b for a, b in zip(left, share)]
    bars.invert_yaxis()
    bars.set_xlim(0, 1)
    bars.set_xlabel("share of the class")
    bars.set_title("Outcome of each exercise")
    bars.legend(loc="upper center", bbox_to_anchor=(0.5, -0.25 if len(names) < 4 else -0.12), ncol=3, frameon=False)
    scores = [score for score, _ in results.scores.values()]
    top = max((m for _, m in results.scores.values()), default=1) or 1
    hist.hist(scores, bins=min(20, int(top) + 1), range=(0, top), color="#0072b2", edgecolor="white")
    hist.set_xlabel(f"points (of {top:g}; hand-graded answers not yet counted)")
    hist.set_ylabel("students")
    hist.set_title("The class's scores")
    fig.tight_layout()
    picture = _png(fig)
    plt.close(fig)
    return picture


def render_html(results, rows, flags, picture):
    """The class report as one self-contained HTML page."""
    e = html.escape
    n = len(results.students)
    parts = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        f"<title>Class report: {e(results.assignment)}</title>",
        "<style>body{font-family:sans-serif;max-width:60em;margin:2em auto;padding:0 1em;color:#222}"
        "table{border-collapse:collapse;margin:0.5em 0 1.5em}td,th{border-bottom:1px solid #ccc;padding:0.25em 0.6em;"
        "text-align:left;vertical-align:top}td.n{text-align:right}small{color:#555}</style></head><body>",
        f"<h1>Class report: {e(results.assignment)}</h1>",
        f"<p>{n} students handed in. Each exercise below lists what the class's functions did, the mistakes "
        "the checks named ranked by how many students made them, and the students concerned.</p>",
        f"<img src='data:image/png;base64,{picture}' alt='Bar per exercise: share of the class that passed, "
        "made a named mistake, got a catch-all diagnosis, was refused or left the stub; and a histogram of the "
        "scores' style='max-width:100%'>",
    ]
    by_exercise = defaultdict(list)
    for row in rows:
        by_exercise[(row["notebook"], row["exercise"])].append(row)
    for (notebook, exercise), group in by_exercise.items():
        passed = sum(r["students"] for r in group if r["kind"] == "passed")
        hand = group[0]["kind"] in ANSWERS
        head = "Discuss (graded by hand)" if hand else f"passed by {passed} of {n} ({passed / n:.0%})" if n else ""
        parts.append(f"<h2><code>{e(exercise)}</code> <small>{e(notebook)} · {e(head)}</small></h2>")
        parts.append("<table><tr><th>outcome</th><th>diagnosis</th><th>students</th><th>share</th><th>who</th></tr>")
        for r in group:
            diagnosis = "" if r["diagnosis"].startswith(r["kind"]) else r["diagnosis"]
            parts.append(
                f"<tr><td>{e(r['kind'])}</td><td>{e(diagnosis)}</td><td class='n'>{r['students']}</td>"
                f"<td class='n'>{float(r['share']):.0%}</td><td><small>{e(r['student_ids'])}</small></td></tr>"
            )
        parts.append("</table>")
    parts.append("<h2>Flags: submissions that look copied</h2>")
    if flags:
        parts.append("<table><tr><th>student</th><th>exercise</th><th>flag</th><th>detail</th></tr>")
        for f in flags:
            parts.append(
                f"<tr><td>{e(f['student_id'])}</td><td><code>{e(f['exercise'])}</code></td>"
                f"<td>{e(f['flag'])}</td><td>{e(f['detail'])}</td></tr>"
            )
        parts.append("</table>")
    else:
        parts.append("<p>None: no answer shares most of its code with another student's or with the solution.</p>")
    parts.append(
        "<p><small>A flag is a reason to look, not a verdict: read the two answers side by side. "
        f"Near-identical means copydetect finds at least {NEAR_IDENTICAL:.0%} of each answer's tokenised code "
        f"in the other; a copy, at least {COPIED:.0%} of the answer's in the solution notebook's or geomlib's "
        "(names, comments and spacing ignored).</small></p></body></html>"
    )
    return "\n".join(parts)


def write_report(course_dir, assignment):
    """Write class-report.csv, flags.csv and class-report.html; return their paths."""
    course = load_course(course_dir)
    results = read_class(course_dir, assignment)
    rows = report_rows(results)
    flags = class_flags(course_dir, assignment, results)
    out = course.root / "reports" / assignment
    out.mkdir(parents=True, exist_ok=True)
    paths = [out / "class-report.csv", out / "flags.csv", out / "class-report.html"]
    with open(paths[0], "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(_row("", "", "", "", [], 1)))
        writer.writeheader()
        writer.writerows(rows)
    with open(paths[1], "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=["student_id", "exercise", "flag", "detail"])
        writer.writeheader()
        writer.writerows(flags)
    paths[2].write_text(render_html(results, rows, flags, outcome_figure(results)))
    return paths
