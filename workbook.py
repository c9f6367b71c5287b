#!/usr/bin/env python3
"""Set up and run the workbook: the two commands of the README.

    python3 workbook.py lab        # JupyterLab on notebooks/, opened at notebook 00
    python3 workbook.py notebook   # the same in Jupyter Notebook 7 instead of JupyterLab
    python3 workbook.py test       # every test: unit, notebooks (nbval), browser
    python3 workbook.py assignment # the assignment version in build/assignment/
    python3 workbook.py site       # the workbook as a static website in build/site/
    python3 workbook.py run 05 STEP=1e-4 ...   # one notebook with those parameters, into build/runs/
    python3 workbook.py setup      # only create or update .venv

Each creates the virtual environment ``.venv`` beside this file when it is
missing, and (re)installs the pinned package set (``constraints.txt``) when
``pyproject.toml`` or ``constraints.txt`` changed since the last install.
Needs only Python 3.11 or newer with its standard ``venv`` module.
Extra arguments after ``test`` go to pytest, after ``lab`` to JupyterLab,
after ``notebook`` to Jupyter Notebook; ``run`` takes a notebook and NAME=VALUE
pairs (tools/run_notebook.py says more).
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


def front_end_command(app, args, root=False):
    """The command line that opens notebooks/ in ``app`` ("lab" or "notebook").

    The browser opens at notebook 00 (the app's default URL), so a newcomer
    lands on the first lesson; ``args`` go to the app unchanged.
    """
    first = "/lab/tree/" if app == "lab" else "/notebooks/"
    app_class = "LabApp" if app == "lab" else "JupyterNotebookApp"
    cmd = [
        BIN / "jupyter",
        app,
        "--notebook-dir",
        NOTEBOOKS,
        f"--{app_class}.default_url={first}{FIRST_NOTEBOOK}",
        *args,
    ]
    if root and "--allow-root" not in args:
        cmd.append("--allow-root")  # containers and CI machines often run as root
    return [str(c) for c in cmd]


def test_workers(args):
    """pytest-xdist options for the test command: one worker per core, each notebook file
    kept whole on one worker (nbval runs a notebook's cells in order in one kernel), unless
    the arguments choose the workers themselves (``-n 0`` runs everything in one process)."""
    if any(a == "-n" or a.startswith(("-n", "--numprocesses")) or "xdist" in a for a in args):
        return []
    return ["-n", "auto", "--dist", "loadfile"]


def main(argv):
    if not argv or argv[0] not in ("lab", "notebook", "test", "setup", "assignment", "site", "run"):
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
    if command in ("lab", "notebook"):
        cmd = front_end_command(command, rest, root=hasattr(os, "geteuid") and os.geteuid() == 0)
        print("+", " ".join(cmd), flush=True)
        return subprocess.call(cmd, cwd=NOTEBOOKS, env=env)
    cmd = [PY, "-m", "pytest", *test_workers(rest), *rest]
    print("+", " ".join(str(c) for c in cmd), flush=True)
    return subprocess.call([str(c) for c in cmd], cwd=ROOT, env=env)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
