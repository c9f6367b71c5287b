"""nbgrader's ``autograde`` for a whole class, several students at once, with progress.

Each student is graded by nbgrader itself, ``nbgrader autograde ASSIGNMENT --student ID``,
run in the course folder so that it reads the course's own configuration (its
preprocessors, timeouts, exchange). Where the gradebook lives decides how workers share it:

* SQLite (nbgrader's default ``gradebook.db``) takes one writer at a time, so with more
  than one worker each worker grades into its own copy of the gradebook (made when the
  class starts) and every student it grades is copied into the course's gradebook at once,
  under a lock, through nbgrader's API (:func:`.gradebook.copy_submission`);
* PostgreSQL (``c.CourseDirectory.db_url = "postgresql+psycopg://..."``) takes many
  writers: the workers write to it directly, so workers on several machines sharing the
  course folder can grade one class.

Either way the gradebook ends with the grades a serial ``nbgrader autograde ASSIGNMENT``
leaves. Seconds per student and the time left are printed as each student is done.
"""

import shutil
import subprocess
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

from .coursedir import load_course, nbgrader_command
from .gradebook import copy_submission


@dataclass
class Graded:
    """One student's autograde: ``ok`` when nbgrader exited 0; ``log`` its output."""

    student: str
    seconds: float
    ok: bool
    log: str


def progress_line(done, total, student, seconds, elapsed, ok=True):
    """``[ 3/20] alice graded in 5.2 s; 12 s elapsed, about 40 s left``: the time left is
    the mean time per student so far times the students still to grade."""
    left = elapsed / done * (total - done)
    width = len(str(total))
    verdict = "graded" if ok else "FAILED"
    return f"[{done:{width}d}/{total}] {student} {verdict} in {seconds:.1f} s; {elapsed:.0f} s elapsed, about {left:.0f} s left"


def _ensure_gradebook(course, assignment):
    """Open the course's gradebook once (creating its tables and course row before any
    worker does) and check that ``generate_assignment`` has put the assignment in it."""
    from nbgrader.api import Gradebook, MissingEntry

    with Gradebook(course.db_url, course.course_id) as gb:
        try:
            gb.find_assignment(assignment)
        except MissingEntry:
            raise SystemExit(
                f"the gradebook {course.db_url} has no assignment {assignment!r}: "
                f"run `nbgrader generate_assignment {assignment}` in {course.folder} first"
            ) from None


#: Seconds a notebook's kernel may take to start. nbclient's default, 60 s, is for one kernel on
#: a quiet machine; ``workers`` kernels start at once, and on a loaded 2-core machine one of
#: them took longer, so a student's grading failed without a fault of theirs.
KERNEL_START_SECONDS = 300
KERNEL_START = f"--Execute.startup_timeout={KERNEL_START_SECONDS}"


def autograde_class(course_dir, assignment, workers=1, students=None, force=False, out=print, extra_args=()):
    """Autograde every submitted student of ``assignment`` (or ``students``), ``workers`` at once.

    Returns the list of :class:`Graded`, in the order they finished; ``out`` receives one
    progress line per student. ``force`` regrades students already graded (nbgrader's
    ``--force``); ``extra_args`` are passed on to every ``nbgrader autograde``, after
    ``--Execute.startup_timeout`` (:data:`KERNEL_START_SECONDS`), which they may override.
    """
    if workers < 1:
        raise ValueError(f"workers must be at least 1, not {workers}")
    course = load_course(course_dir)
    everyone = course.submitted_students(assignment)
    if students is None:
        students = everyone
    else:
        missing = sorted(set(students) - set(everyone))
        if missing:
            raise SystemExit(f"no submission of {assignment} from {', '.join(missing)}")
    _ensure_gradebook(course, assignment)
    if not students:
        out(f"no submissions of {assignment} under {course.root / course.submitted_directory}")
        return []
    workers = min(workers, len(students))
    copies = workers > 1 and course.sqlite_file is not None
    args = ["autograde", assignment, *(["--force"] if force else []), KERNEL_START, *extra_args]
    total, finished, lock, start = len(students), [], threading.Lock(), time.perf_counter()

    with tempfile.TemporaryDirectory(prefix="geomlib-course-") as scratch:
        slots = []
        for k in range(workers):
            if copies:
                db = Path(scratch) / f"worker-{k}.db"
                shutil.copyfile(course.sqlite_file, db)
                slots.append(f"sqlite:///{db}")
            else:
                slots.append(None)
        free = list(range(workers))

        def grade(student):
            with lock:
                slot = free.pop()
            try:
                db_url = slots[slot]
                extra = [f"--CourseDirectory.db_url={db_url}"] if db_url else []
                command, env = nbgrader_command(*args, "--student", student, *extra)
                began = time.perf_counter()
                run = subprocess.run(command, cwd=course.folder, env=env, capture_output=True, text=True)
                seconds = time.perf_counter() - began
                with lock:
                    if db_url:
                        _copy_back(db_url, course, assignment, student)
                    result = Graded(student, seconds, run.returncode == 0, run.stdout + run.stderr)
                    finished.append(result)
                    out(progress_line(len(finished), total, student, seconds, time.perf_counter() - start, result.ok))
                return result
            finally:
                with lock:
                    free.append(slot)

        with ThreadPoolExecutor(max_workers=workers) as pool:
            list(pool.map(grade, students))
    return finished


def _copy_back(db_url, course, assignment, student):
    """Copy a student a worker graded from its gradebook into the course's."""
    from nbgrader.api import Gradebook, MissingEntry

    with Gradebook(db_url, course.course_id) as source, Gradebook(course.db_url, course.course_id) as target:
        try:
            source.find_submission(assignment, student)
        except MissingEntry:  # nbgrader stopped before it recorded the submission
            return
        copy_submission(source, target, assignment, student)
