#!/usr/bin/env python3
"""Set up and run the workbook: the two commands of the README.

    python3 workbook.py lab        # JupyterLab on your own copy of the exercises (my-work/), at notebook 00
    python3 workbook.py lab --solutions   # the solution version instead (a banner on each notebook says so)
    python3 workbook.py notebook   # the same in Jupyter Notebook 7 instead of JupyterLab
    python3 workbook.py test       # every test: unit, notebooks (nbval), browser
    python3 workbook.py assignment # the assignment version in build/assignment/
    python3 workbook.py site       # the workbook as a static website in build/site/
    python3 workbook.py run 05 STEP=1e-4 ...   # one notebook with those parameters, into build/runs/
    python3 workbook.py course autograde COURSE ASSIGNMENT --workers 4   # geomlib-course (docs/grading.md)
    python3 workbook.py setup      # only create or update .venv

Each creates the virtual environment ``.venv`` beside this file when it is
missing, and (re)installs the pinned package set (``constraints.txt``) when
``pyproject.toml`` or ``constraints.txt`` changed since the last install.
Needs only Python 3.11 or newer with its standard ``venv`` module.
Extra arguments after ``test`` go to pytest, after ``lab`` to JupyterLab,
after ``notebook`` to Jupyter Notebook; ``run`` takes a notebook and NAME=VALUE
pairs (tools/run_notebook.py says more); ``course`` runs the lecturer's
``geomlib-course`` with the arguments given, in the caller's folder.

``lab`` and ``notebook`` open the exercise version (stubs where the solutions
are, empty answer boxes; built as ``assignment`` builds it) in a working folder
of the reader's own, ``my-work/`` beside ``notebooks/`` (``--work DIR`` for
another; git ignores my-work/). A notebook already there is the reader's and
is never overwritten, whatever the workbook's update brought; a notebook the
folder lacks is added. ``--solutions`` opens the solution version instead,
rewritten into ``build/solutions/`` on every run, each notebook opening with a
banner that says what it is.
"""

import hashlib
import json
import os
import subprocess
import sys
import venv
from pathlib import Path

ROOT = Path(__file__).resolve().parent
NOTEBOOKS = ROOT / "notebooks"
FIRST_NOTEBOOK = "00_getting_started.ipynb"
WORK = ROOT / "my-work"  # the reader's own copies of the exercise version (kept across runs and updates)
EXERCISES = ROOT / "build" / "exercises"  # the exercise version as this checkout builds it
SOLUTIONS = ROOT / "build" / "solutions"  # the solution version with its banner
VENV = ROOT / ".venv"
BIN = VENV / ("Scripts" if os.name == "nt" else "bin")
PY = BIN / ("python.exe" if os.name == "nt" else "python")
STAMP = VENV / ".workbook-stamp"
# the tested package set and geomlib with its front-end and test extras
# (environment.yml's pip section says the same; tests/test_environment.py checks it)
INSTALL_ARGS = ["-c", "constraints.txt", "-e", ".[dev,lab]"]


def _fingerprint():
    h = hashlib.sha256()
    for name in ("pyproject.toml", "constraints.txt"):
        h.update((ROOT / name).read_bytes())
    return h.hexdigest()


def _run(cmd, **kw):
    print("+", " ".join(str(c) for c in cmd), flush=True)
    subprocess.run([str(c) for c in cmd], check=True, cwd=ROOT, **kw)


# JupyterLab and Notebook 7 settings for .venv: no news or update pop-up for a
# newcomer to dismiss (it also covers the notebook in screenshots)
LAB_OVERRIDES = {"@jupyterlab/apputils-extension:notification": {"fetchNews": "false", "checkForUpdates": False}}


def _lab_settings():
    folder = VENV / "share" / "jupyter" / "lab" / "settings"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "overrides.json").write_text(json.dumps(LAB_OVERRIDES, indent=2))


def ensure_environment():
    if sys.version_info < (3, 11):
        sys.exit(f"Python 3.11 or newer is needed; this is {sys.version.split()[0]}")
    if not PY.exists():
        print(f"Creating the virtual environment in {VENV.name}/ ...", flush=True)
        venv.EnvBuilder(with_pip=True).create(VENV)
    fingerprint = _fingerprint()
    if not STAMP.exists() or STAMP.read_text() != fingerprint:
        print("Installing the pinned packages (first run takes a few minutes) ...", flush=True)
        _run([PY, "-m", "pip", "install", "--quiet", "--upgrade", "pip"])
        _run([PY, "-m", "pip", "install", "--quiet", *INSTALL_ARGS])
        _lab_settings()
        STAMP.write_text(fingerprint)


def front_end_command(app, args, root=False, folder=NOTEBOOKS):
    """The command line that opens ``folder`` in ``app`` ("lab" or "notebook").

    The browser opens at notebook 00 (the app's default URL), so a newcomer
    lands on the first lesson; ``args`` go to the app unchanged.
    """
    first = "/lab/tree/" if app == "lab" else "/notebooks/"
    app_class = "LabApp" if app == "lab" else "JupyterNotebookApp"
    cmd = [
        BIN / "jupyter",
        app,
        "--notebook-dir",
        folder,
        f"--{app_class}.default_url={first}{FIRST_NOTEBOOK}",
        *args,
    ]
    if root and "--allow-root" not in args:
        cmd.append("--allow-root")  # containers and CI machines often run as root
    return [str(c) for c in cmd]


def front_end_options(args):
    """``(solutions, work, rest)`` from the arguments of ``lab``/``notebook``: the ``--solutions`` flag,
    the working folder (``--work DIR``, else my-work/) and the arguments left for the app."""
    solutions, work, rest = False, WORK, []
    args = list(args)
    while args:
        a = args.pop(0)
        if a == "--solutions":
            solutions = True
        elif a == "--work" and args:
            work = Path(args.pop(0)).expanduser().resolve()
        elif a.startswith("--work="):
            work = Path(a.split("=", 1)[1]).expanduser().resolve()
        else:
            rest.append(a)
    return solutions, work, rest


def add_missing_notebooks(built, work):
    """Copy into ``work`` each notebook of ``built`` that ``work`` lacks; leave the others alone.

    Returns ``(added, kept)``, the names copied and the names already there (the reader's:
    never overwritten, so an update of the workbook cannot erase an attempt).
    """
    work.mkdir(parents=True, exist_ok=True)
    added, kept = [], []
    for path in sorted(built.glob("*.ipynb")):
        target = work / path.name
        if target.exists():
            kept.append(path.name)
        else:
            target.write_bytes(path.read_bytes())
            added.append(path.name)
    return added, kept


def open_folder(solutions, work, env):
    """Build the version asked for and return the folder to open (printing what it holds)."""
    builder = [str(PY), str(ROOT / "tools" / "build_assignment.py"), "--quiet"]
    if solutions:
        subprocess.run([*builder, "--solutions", "--out", str(SOLUTIONS)], check=True, cwd=ROOT, env=env)
        print(
            f"The SOLUTION version (every answer filled in), rewritten in {SOLUTIONS.relative_to(ROOT)}/; "
            f"your own work stays in {work}.",
            flush=True,
        )
        return SOLUTIONS
    subprocess.run([*builder, "--out", str(EXERCISES)], check=True, cwd=ROOT, env=env)
    added, kept = add_missing_notebooks(EXERCISES, work)
    print(f"Your working folder: {work}", flush=True)
    if added:
        print(f"  added the exercise version of {len(added)} notebook(s): {', '.join(added)}", flush=True)
    if kept:
        print(
            f"  kept your {len(kept)} notebook(s) already there, unchanged (delete one to start it afresh)", flush=True
        )
    print("  the solution version: python3 workbook.py lab --solutions", flush=True)
    return work


def test_workers(args):
    """pytest-xdist options for the test command: one worker per core, unless the arguments
    choose the workers themselves (``-n 0`` runs everything in one process). Each notebook
    file stays whole on one worker (nbval runs a notebook's cells in order in one kernel):
    the checkout's conftest.py sees to that for every pytest run (``--dist loadfile``)."""
    if any(a == "-n" or a.startswith(("-n", "--numprocesses")) or "xdist" in a for a in args):
        return []
    return ["-n", "auto"]


def main(argv):
    if not argv or argv[0] not in ("lab", "notebook", "test", "setup", "assignment", "site", "run", "course"):
        print(__doc__)
        return 2
    command, rest = argv[0], argv[1:]
    ensure_environment()
    # the kernel and packages of .venv win over any in the user's home folder
    env = dict(os.environ, PYTHONNOUSERSITE="1", JUPYTER_PREFER_ENV_PATH="1")
    if command == "setup":
        return 0
    if command == "assignment":
        return subprocess.call([str(PY), str(ROOT / "tools" / "build_assignment.py"), *rest], cwd=ROOT, env=env)
    if command == "site":
        return subprocess.call([str(PY), str(ROOT / "tools" / "build_site.py"), *rest], cwd=ROOT, env=env)
    if command == "run":
        # in the caller's folder: relative paths in the values are relative to it
        return subprocess.call([str(PY), str(ROOT / "tools" / "run_notebook.py"), *rest], env=env)
    if command == "course":
        # the lecturer's geomlib-course, with the environment's bin/ first on PATH (nbgrader calls alembic)
        env["PATH"] = f"{BIN}{os.pathsep}{env.get('PATH', '')}"
        return subprocess.call([str(PY), "-m", "geomlib.course.cli", *rest], env=env)
    if command in ("lab", "notebook"):
        solutions, work, rest = front_end_options(rest)
        folder = open_folder(solutions, work, env)
        cmd = front_end_command(command, rest, root=hasattr(os, "geteuid") and os.geteuid() == 0, folder=folder)
        print("+", " ".join(cmd), flush=True)
        return subprocess.call(cmd, cwd=folder, env=env)
    cmd = [PY, "-m", "pytest", *test_workers(rest), *rest]
    print("+", " ".join(str(c) for c in cmd), flush=True)
    return subprocess.call([str(c) for c in cmd], cwd=ROOT, env=env)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
