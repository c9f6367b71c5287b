"""Copying graded submissions between nbgrader gradebooks, and reading a class's grades.

Parallel autograde on SQLite gives each worker its own copy of the course's gradebook
(SQLite takes one writer at a time); each student a worker grades is copied into the
course's gradebook right after, through nbgrader's own API (:func:`copy_submission`),
so the course's gradebook ends with the rows a serial ``nbgrader autograde`` writes.
"""

import warnings

from sqlalchemy import inspect as sa_inspect
from sqlalchemy.exc import SAWarning


def _copy_columns(source, target):
    """Set every column of ``target`` that is neither a key nor a link to ``source``'s value."""
    mapper = sa_inspect(type(source))
    for column in mapper.columns:
        if column.primary_key or column.foreign_keys:
            continue
        attr = mapper.get_property_by_column(column).key
        setattr(target, attr, getattr(source, attr))


def copy_submission(source, target, assignment, student):
    """Copy ``student``'s graded submission of ``assignment`` from the Gradebook ``source``
    into the Gradebook ``target``: the student, the submission (timestamp, extension), each
    notebook (flag, late penalty), each grade (auto, manual and extra score, needs manual
    grade) and each comment. The assignment must already be in ``target`` (as
    ``generate_assignment`` puts it there); a submission already there is overwritten,
    as autograde overwrites it."""
    with warnings.catch_warnings():
        # nbgrader's add_submission builds rows SQLAlchemy warns about (autograde's own log has them too)
        warnings.simplefilter("ignore", SAWarning)
        _copy(source, target, assignment, student)


def _copy(source, target, assignment, student):
    student_row = source.find_student(student)
    target.update_or_create_student(
        student, **{k: v for k, v in student_row.to_dict().items() if k not in ("id", "score", "max_score")}
    )
    graded = source.find_submission(assignment, student)
    copy = target.update_or_create_submission(assignment, student)
    _copy_columns(graded, copy)
    for notebook in graded.notebooks:
        into = target.find_submission_notebook(notebook.name, assignment, student)
        _copy_columns(notebook, into)
        for grade in notebook.grades:
            _copy_columns(grade, target.find_grade(grade.name, notebook.name, assignment, student))
        for comment in notebook.comments:
            _copy_columns(comment, target.find_comment(comment.name, notebook.name, assignment, student))
    target.db.commit()


def class_grades(gradebook, assignment):
    """Every grade of ``assignment`` in a Gradebook, as plain values:
    ``{(student, notebook, cell): (auto_score, manual_score, extra_credit, needs_manual_grade, score)}``,
    and ``{(student, notebook, cell): (auto_comment, manual_comment)}``; for comparing gradebooks."""
    grades, comments = {}, {}
    for submission in gradebook.assignment_submissions(assignment):
        student = submission.student_id
        for notebook in submission.notebooks:
            for g in notebook.grades:
                grades[(student, notebook.name, g.name)] = (
                    g.auto_score,
                    g.manual_score,
                    g.extra_credit,
                    g.needs_manual_grade,
                    g.score,
                )
            for c in notebook.comments:
                comments[(student, notebook.name, c.name)] = (c.auto_comment, c.manual_comment)
    return grades, comments
