"""nbgrader's autograde, with each exercise's points decided out of the student's reach.

``JudgeExercises`` is an nbgrader preprocessor for ``Autograde.autograde_preprocessors``,
placed first, before ``Execute``. For each exercise it asks ``check.judge.verdicts`` (a
fresh process holding the checks, calling the student's functions in a fenced sandbox)
and writes the verdicts as the outputs of the exercise's two grade cells: the diagnosis
as a ``CheckFailed`` error (no points), or the check's passing message. nbgrader's own
``SaveAutoGrades`` then scores those outputs, and the feedback page shows them. A course
turns it on with one line in its ``nbgrader_config.py`` (docs/grading.md)::

    c.Autograde.autograde_preprocessors.insert(0, "geomlib.course.grading.JudgeExercises")

It then tags every code cell the kernel need not run with nbclient's skip tag, so that
nbgrader's ``Execute`` leaves it as it is: the grade cells it has filled, and (with
``set_aside_lessons``, the default) the lesson's cells, which no grade cell needs once the
judge decides the points. The kernel runs the notebook's first code cell (its imports),
its ``parameters`` cell and the solution cells, so the feedback page shows the student's
code and whether it runs. The model-answer cells, which print the rubric with the
lesson's numbers, get the outputs of one run of the course's solution notebook
(``model_answers``, once per class); the lesson's other numbers, the model's once a
function passes, are in the student's own run. ``set_aside_lessons = False`` runs every
cell but the judge's, as the kernel would without the judge (the pictures stay text:
``text_only``). A skip tag the student set is taken off the cells the kernel must run.

The verdicts and the copy flags go into the autograded notebook's metadata
(``metadata.geomlib.grading``) for a class report; ``copy_flags(nb)`` reads them back.
"""

import os

import nbformat
from nbclient import NotebookClient
from nbgrader.coursedir import CourseDirectory
from nbgrader.preprocessors import NbGraderPreprocessor
from traitlets import Bool

from ..teaching.check import CheckFailed
from ..teaching.check.copies import flag_sentence
from ..teaching.check.judge import verdicts
from .model_answers import model_answers

CONFIG_LINE = 'c.Autograde.autograde_preprocessors.insert(0, "geomlib.course.grading.JudgeExercises")'


SET_ASIDE = (
    "Not run while grading. nbgrader ran only this notebook's first cell, its parameters and your solution cells "
    "(without the lesson's variables: a solution cell that uses one raises NameError here); the grading judge "
    "decided the check cells, and each model answer is the course's own run with the default parameters. "
    "The lesson's cells show their output in your own run."
)
SET_ASIDE_AGAIN = "Not run while grading (see the first cell set aside)."
MODEL_RUN = "*The model answer as the course's solution notebook prints it, with its default parameters:*"


class JudgeExercises(NbGraderPreprocessor):
    """Decide each exercise's grade cells in the grading judge, and set aside what the kernel need not run
    (module docstring)."""

    set_aside_lessons = Bool(
        True, help="Leave the lesson's cells unrun while grading (only the first cell, parameters and solutions run)."
    ).tag(config=True)

    def preprocess(self, nb, resources):
        # nbgrader reads the config of the folder it runs in twice, so the line inserts this twice
        if resources.get("geomlib_judged"):
            return nb, resources
        resources["geomlib_judged"] = True
        source = self._source(resources)
        found = verdicts(nb, nbformat.read(source, as_version=4) if source else None)
        model = model_answers(source) if source and self.set_aside_lessons else {}
        skip = self.config.get("Execute", {}).get("skip_cells_with_tag", NotebookClient.skip_cells_with_tag.default())
        first = next((i for i, c in enumerate(nb.cells) if c.cell_type == "code"), None)
        noted = False
        for index, cell in enumerate(nb.cells):
            if cell.cell_type != "code":
                continue
            grade_id = cell.metadata.get("nbgrader", {}).get("grade_id", "")
            filled = _model(model[grade_id]) if grade_id in model else _judged(grade_id, found)
            if filled is not None:
                cell.outputs = filled
            if grade_id in model:  # the feedback page shows the rubric once, as its output, not its source too
                cell.metadata["transient"] = {"remove_source": True}
            runs = filled is None and (not self.set_aside_lessons or index == first or _kernel_needs(cell))
            tags = [t for t in cell.metadata.get("tags", []) if t != skip] + ([] if runs else [skip])
            if tags or "tags" in cell.metadata:
                cell.metadata["tags"] = tags
            if not runs and filled is None:
                cell.outputs, noted = [_note(SET_ASIDE_AGAIN if noted else SET_ASIDE)], True
        nb.metadata.setdefault("geomlib", {})["grading"] = found
        return nb, resources

    def _source(self, resources):
        """The path of the solution version of this notebook in the course's source folder, if it is there."""
        info = resources.get("nbgrader", {})
        coursedir = CourseDirectory(config=self.config)
        path = os.path.join(
            coursedir.format_path(coursedir.source_directory, ".", info.get("assignment", "")),
            f"{info.get('notebook', '')}.ipynb",
        )
        return path if os.path.exists(path) else None


def _note(text):
    return nbformat.v4.new_output("display_data", data={"text/markdown": f"*{text}*", "text/plain": text})


def _model(outputs):
    """A model-answer cell's outputs from the course's run, under a line saying where they come from."""
    said = nbformat.v4.new_output("display_data", data={"text/markdown": MODEL_RUN, "text/plain": MODEL_RUN.strip("*")})
    return [said, *(nbformat.from_dict(o) for o in outputs)]


def _judged(grade_id, found):
    """The outputs the judge gives the grade cell ``grade_id`` (a check or partial-credit cell), else None."""
    for part, key in (("_check", "check"), ("_partial_credit", "partial_credit")):
        exercise, _, rest = grade_id.rpartition(part)
        if rest == "" and exercise in found:
            return _outputs(*found[exercise][key], found[exercise]["copies"] if key == "check" else [])
    return None


def _kernel_needs(cell):
    """Whether the kernel runs this cell while the judge grades: a solution cell or the parameters."""
    info = cell.metadata.get("nbgrader", {})
    return bool(info.get("solution")) or "parameters" in cell.metadata.get("tags", [])


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
            traceback=[
                *CheckFailed(message)._render_traceback_(),
                "(decided by the grading judge)",
                *([flagged] if flagged else []),
            ],  # as the kernel shows it
        )
    ]


def copy_flags(nb):
    """[(exercise, flag)] recorded by ``JudgeExercises`` in an autograded notebook (for a class report)."""
    grading = nb.get("metadata", {}).get("geomlib", {}).get("grading", {})
    return [(exercise, flag) for exercise, verdict in grading.items() for flag in verdict["copies"]]
