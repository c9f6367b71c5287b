"""The outputs of a notebook's model-answer cells, computed once per class from the course's solution.

A model-answer cell (grade id ``*_model_answer``, hidden in the release and put back by
``autograde``) prints the rubric and the model answer with the lesson's numbers, which
the lesson's cells compute. While the grading judge decides the points, the kernel
sets the lesson's cells aside (``grading.JudgeExercises``), so the model answers come
from one run of the course's own solution notebook (the one in ``source/``), as nbgrader
runs a student's (``NBGRADER_EXECUTION`` set: no picture drawn). They are the same for
every student: the lesson binds a student's function only once it passes its check.

``model_answers(path)`` runs the notebook once per content and geomlib source, and stores the
outputs as JSON under :func:`experiment_store.key <geomlib.numerics.experiment_store.key>`
in the ``model_answers`` folder beside the stored experiments. Workers grading in parallel
take a lock, so one of them runs the notebook and the others read its result.
"""

import fcntl
import hashlib
import json
import os
from pathlib import Path

import nbformat
from nbclient import NotebookClient

from ..numerics import experiment_store

CELL_SECONDS = 600  # the longest a cell of the solution notebook may take


def model_answers(path, cache_dir=None):
    """{grade id: outputs} of the model-answer cells of the notebook at ``path`` (nbformat outputs)."""
    path = Path(path)
    name = experiment_store.key("model answers", hashlib.sha256(path.read_bytes()).hexdigest())
    where = experiment_store.folder(cache_dir).parent / "model_answers"
    where.mkdir(parents=True, exist_ok=True)
    stored = where / f"{name}.json"
    with open(where / f"{name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes
        if not stored.exists():
            found = _run(path)
            tmp = where / f".{name}-{os.getpid()}.tmp"
            tmp.write_text(json.dumps(found))
            os.replace(tmp, stored)
    return json.loads(stored.read_text())


def _run(path):
    nb = nbformat.read(path, as_version=4)
    environment = {k: v for k, v in os.environ.items() if k != "GEOMLIB_STRICT_CLAIMS"}
    environment["NBGRADER_EXECUTION"] = "autograde"
    client = NotebookClient(
        nb,
        timeout=CELL_SECONDS,
        kernel_name="python3",
        allow_errors=True,
        resources={"metadata": {"path": str(path.parent)}},
    )
    client.execute(env=environment)
    return {
        cell.metadata["nbgrader"]["grade_id"]: cell.outputs
        for cell in nb.cells
        if cell.cell_type == "code" and cell.metadata.get("nbgrader", {}).get("grade_id", "").endswith("_model_answer")
    }
