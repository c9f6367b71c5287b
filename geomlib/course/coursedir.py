"""A course folder as nbgrader's commands see it: its configuration, gradebook and submissions."""

import contextlib
import glob
import os
import shutil
import sys
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class Course:
    """The settings of an nbgrader course that the class tools need.

    ``root``: the course folder (``CourseDirectory.root``); ``db_url``: the gradebook
    (``CourseDirectory.db_url``, SQLite by default, PostgreSQL on a hub); ``course_id``:
    the gradebook's course; ``folder``: the directory the configuration was read in, where
    every ``nbgrader`` command of the class runs so that it reads the same configuration.
    """

    folder: Path
    root: Path
    db_url: str
    course_id: str
    submitted_directory: str
    autograded_directory: str
    source_directory: str
    release_directory: str

    def path(self, directory, student, assignment):
        """``root/directory/student/assignment`` (nbgrader's ``CourseDirectory.format_path``)."""
        return self.root / directory / student / assignment

    def submitted_students(self, assignment):
        """Sorted ids of the students with a submission of ``assignment``."""
        pattern = str(self.path(self.submitted_directory, "*", glob.escape(assignment)))
        return sorted(Path(p).parent.name for p in glob.glob(pattern) if os.path.isdir(p))

    @property
    def sqlite_file(self):
        """The gradebook's file when it is SQLite, else None."""
        prefix = "sqlite:///"
        return Path(self.db_url[len(prefix) :]) if self.db_url.startswith(prefix) else None


def load_course(folder):
    """The :class:`Course` of ``folder`` as ``nbgrader`` run in that folder reads it
    (its ``nbgrader_config.py`` and the user's and system's nbgrader configurations)."""
    from nbgrader.apps.baseapp import NbGrader
    from nbgrader.coursedir import CourseDirectory

    folder = Path(folder).resolve()
    if not folder.is_dir():
        raise FileNotFoundError(f"no course folder {folder}")
    with contextlib.chdir(folder):
        app = NbGrader()
        app.load_config_file()
        cd = CourseDirectory(config=app.config)
        db_url = cd.db_url
        if db_url.startswith("sqlite:///") and not Path(db_url[len("sqlite:///") :]).is_absolute():
            # a relative SQLite file is where nbgrader, run in the course folder, finds it
            db_url = f"sqlite:///{folder / db_url[len('sqlite:///') :]}"
        return Course(
            folder=folder,
            root=Path(cd.root).resolve(),
            db_url=db_url,
            course_id=cd.course_id,
            submitted_directory=cd.submitted_directory,
            autograded_directory=cd.autograded_directory,
            source_directory=cd.source_directory,
            release_directory=cd.release_directory,
        )


def nbgrader_command(*args):
    """The command line of ``nbgrader ARGS`` in this Python environment, and its environment
    variables (nbgrader calls ``alembic``, which must be on PATH)."""
    bin_dir = Path(sys.executable).parent
    exe = bin_dir / "nbgrader"
    command = [str(exe)] if exe.exists() else [shutil.which("nbgrader") or "nbgrader"]
    env = dict(os.environ, PATH=f"{bin_dir}{os.pathsep}{os.environ.get('PATH', '')}")
    env.pop("NBGRADER_EXECUTION", None)  # set by nbgrader itself inside the kernel only
    return [*command, *args], env
