"""nbgrader's autograde, with each exercise's points decided out of the student's reach.

``JudgeExercises`` is an nbgrader preprocessor for ``Autograde.autograde_preprocessors``,
placed right after ``Execute``. The notebook has run in the student's kernel, where a
solution cell could replace a check, its module, numpy or geomlib; so for each
exercise it asks ``check.judge.verdicts`` (a fresh process holding the checks, calling
the student's functions in a fenced sandbox) and writes the verdicts as the outputs of
the exercise's two grade cells: the diagnosis as a ``CheckFailed`` error (no points), or
the check's passing message. nbgrader's own ``SaveAutoGrades`` then scores those
outputs, and the feedback page shows them. A course turns it on with one line in its
``nbgrader_config.py`` (docs/grading.md)::

    c.Autograde.autograde_preprocessors.insert(1, "geomlib.course.grading.JudgeExercises")

The verdicts and the copy flags go into the autograded notebook's metadata
(``metadata.geomlib.grading``) for a class report; ``copy_flags(nb)`` reads them back.
"""

import os

import nbformat
from nbgrader.coursedir import CourseDirectory
from nbgrader.preprocessors import NbGraderPreprocessor

from ..teaching.check.copies import flag_sentence
from ..teaching.check.judge import verdicts

CONFIG_LINE = 'c.Autograde.autograde_preprocessors.insert(1, "geomlib.course.grading.JudgeExercises")'


class JudgeExercises(NbGraderPreprocessor):
    """Decide each exercise's grade cells in the grading judge (module docstring)."""

    def preprocess(self, nb, resources):
        found = verdicts(nb, self._solution(resources))
        for cell in nb.cells:
            grade_id = cell.metadata.get("nbgrader", {}).get("grade_id", "")
            exercise, _, part = grade_id.rpartition("_check")
            if part == "" and exercise in found:
                cell.outputs = _outputs(*found[exercise]["check"], found[exercise]["copies"])
            exercise, _, part = grade_id.rpartition("_partial_credit")
            if part == "" and exercise in found:
                cell.outputs = _outputs(*found[exercise]["partial_credit"], [])
        nb.metadata.setdefault("geomlib", {})["grading"] = found
        return nb, resources

    def _solution(self, resources):
        """The solution version of this notebook in the course's source folder, if it is there."""
        info = resources.get("nbgrader", {})
        coursedir = CourseDirectory(config=self.config)
        path = os.path.join(
            coursedir.format_path(coursedir.source_directory, ".", info.get("assignment", "")),
            f"{info.get('notebook', '')}.ipynb",
        )
        return nbformat.read(path, as_version=4) if os.path.exists(path) else None


def _outputs(passed, message, flags):
    flagged = " ".join(flag_sentence(f) for f in flags if f["of"] == "solution")
    if passed:
        text = f"{message} (decided by the grading judge){' ' + flagged if flagged else ''}"
        return [nbformat.v4.new_output("display_data", data={"text/plain": text})]
    return [
        nbformat.v4.new_output(
            "error",
            ename="CheckFailed",
            evalue=message,
            traceback=[f"CheckFailed: {message}", *([flagged] if flagged else [])],
        )
    ]


def copy_flags(nb):
    """[(exercise, flag)] recorded by ``JudgeExercises`` in an autograded notebook (for a class report)."""
    grading = nb.get("metadata", {}).get("geomlib", {}).get("grading", {})
    return [(exercise, flag) for exercise, verdict in grading.items() for flag in verdict["copies"]]
