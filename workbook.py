#!/usr/bin/env python3
"""Set up and run the workbook: the two commands of the README.

    python3 workbook.py lab     # JupyterLab on notebooks/ (creates .venv first if needed)
    python3 workbook.py test    # every test: unit, notebooks (nbval), browser
    python3 workbook.py assignment   # the assignment version in build/assignment/
    python3 workbook.py site    # the workbook as a static website in build/site/

Both create the virtual environment ``.venv`` beside this file when it is
missing, and (re)install the pinned package set (``constraints.txt``) when
``pyproject.toml`` or ``constraints.txt`` changed since the last install.
Needs only Python 3.10-3.13 with its standard ``venv`` module.
Extra arguments after ``test`` go to pytest, after ``lab`` to JupyterLab.
"""

import hashlib
import json
import os
import subprocess
import sys
import venv
from pathlib import Path

ROOT = Path(__file__).resolve().parent
VENV = ROOT / ".venv"
BIN = VENV / ("Scripts" if os.name == "nt" else "bin")
PY = BIN / ("python.exe" if os.name == "nt" else "python")
STAMP = VENV / ".workbook-stamp"


def _fingerprint():
    h = hashlib.sha256()
    for name in ("pyproject.toml", "constraints.txt"):
        h.update((ROOT / name).read_bytes())
    return h.hexdigest()


def _run(cmd, **kw):
    print("+", " ".join(str(c) for c in cmd), flush=True)
    subprocess.run([str(c) for c in cmd], check=True, cwd=ROOT, **kw)


def _lab_settings():
    """Quiet JupyterLab's news pop-up (it covers the notebook in screenshots)."""
    folder = VENV / "share" / "jupyter" / "lab" / "settings"
    folder.mkdir(parents=True, exist_ok=True)
    overrides = {"@jupyterlab/apputils-extension:notification": {"fetchNews": "false",
                                                                  "checkForUpdates": False}}
    (folder / "overrides.json").write_text(json.dumps(overrides, indent=2))


def ensure_environment():
    if sys.version_info < (3, 10):
        sys.exit(f"Python 3.10 or newer is needed; this is {sys.version.split()[0]}")
    if not PY.exists():
        print(f"Creating the virtual environment in {VENV.name}/ ...", flush=True)
        venv.EnvBuilder(with_pip=True).create(VENV)
    fingerprint = _fingerprint()
    if not STAMP.exists() or STAMP.read_text() != fingerprint:
        print("Installing the pinned packages (first run takes a few minutes) ...", flush=True)
        _run([PY, "-m", "pip", "install", "--quiet", "--upgrade", "pip"])
        _run([PY, "-m", "pip", "install", "--quiet", "-c", "constraints.txt", "-e", ".[dev]"])
        _lab_settings()
        STAMP.write_text(fingerprint)


def main(argv):
    if not argv or argv[0] not in ("lab", "test", "setup", "assignment", "site"):
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
    if command == "lab":
        cmd = [BIN / "jupyter", "lab", "--notebook-dir", ROOT / "notebooks", *rest]
        if hasattr(os, "geteuid") and os.geteuid() == 0 and "--allow-root" not in rest:
            cmd.append("--allow-root")  # containers and CI machines often run as root
        print("+", " ".join(str(c) for c in cmd), flush=True)
        return subprocess.call([str(c) for c in cmd], cwd=ROOT / "notebooks", env=env)
    cmd = [PY, "-m", "pytest", *rest]
    print("+", " ".join(str(c) for c in cmd), flush=True)
    return subprocess.call([str(c) for c in cmd], cwd=ROOT, env=env)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
