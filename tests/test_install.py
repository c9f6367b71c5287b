"""Installing geomlib into a Jupyter that already works leaves that Jupyter alone.

A fresh virtual environment gets a JupyterLab 4 front-end other than the
pinned one (the previous minor release of JupyterLab and Notebook, an
ipykernel 6, the widget packages one release back), as a course's JupyterHub
image might have it, plus pytest and nbval. Then geomlib is installed into it
the way the README says (``pip install -e <checkout>``, dependencies resolved
by pip). ``pip freeze`` before and after must agree on every front-end
package, and notebook 00 must then run there under nbval.

Needs the package index or a pip cache holding these releases; the versions
and times are written to build/install-test.txt.
"""

import os
import subprocess
import sys
import time
import venv
from pathlib import Path

import pytest
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parents[1]
# a working JupyterLab 4 front-end other than constraints.txt's
EXISTING = {
    "jupyterlab": "4.5.11",
    "notebook": "7.5.8",
    "ipykernel": "6.31.0",
    "ipywidgets": "8.1.8",
    "jupyterlab-widgets": "3.0.16",
    "widgetsnbextension": "4.0.15",
}
TOOLS = ["pytest>=8,<10", "nbval>=0.11,<0.12"]
NOTEBOOK = "notebooks/00_getting_started.ipynb"

pytestmark = [pytest.mark.slow, pytest.mark.install]


def _pins():
    pins = {}
    for line in (ROOT / "constraints.txt").read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            name, version = line.split("==")
            pins[canonicalize_name(name)] = version.strip()
    return pins


def _freeze(python):
    out = subprocess.run([python, "-m", "pip", "freeze", "--all"], capture_output=True, text=True, check=True)
    versions = {}
    for line in out.stdout.splitlines():
        if line.startswith(("#", "-e ")):
            continue  # editable installs: geomlib itself
        name, sep, version = line.partition("==") if "==" in line else line.partition(" @ ")
        versions[canonicalize_name(name)] = version
    return versions


def _run(cmd, env, timeout=900, cwd=ROOT):
    done = subprocess.run([str(c) for c in cmd], cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    assert done.returncode == 0, f"{' '.join(map(str, cmd))} failed:\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
    return done


def test_installing_geomlib_keeps_an_existing_jupyterlab_4(tmp_path):
    pins = _pins()
    same = [name for name, version in EXISTING.items() if pins.get(name) == version]
    assert not same, f"the existing front-end must differ from constraints.txt to show anything: {same}"

    home = tmp_path / "venv"
    venv.EnvBuilder(with_pip=True).create(home)
    bindir = home / ("Scripts" if os.name == "nt" else "bin")
    python = bindir / ("python.exe" if os.name == "nt" else "python")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "JUPYTER_PATH", "VIRTUAL_ENV")}
    env.update(
        PATH=os.pathsep.join([str(bindir), env.get("PATH", "")]),
        PYTHONNOUSERSITE="1",
        JUPYTER_PREFER_ENV_PATH="1",
        JUPYTER_DATA_DIR=str(tmp_path / "jupyter-data"),
        JUPYTER_CONFIG_DIR=str(tmp_path / "jupyter-config"),
        GEOMLIB_STRICT_CLAIMS="1",
        PIP_DISABLE_PIP_VERSION_CHECK="1",
    )
    seconds = {}

    t0 = time.perf_counter()
    _run([python, "-m", "pip", "install", "--quiet", *(f"{n}=={v}" for n, v in EXISTING.items()), *TOOLS], env)
    seconds["existing front-end"] = time.perf_counter() - t0
    before = _freeze(python)
    assert {name: before.get(name) for name in EXISTING} == EXISTING

    t0 = time.perf_counter()
    _run([python, "-m", "pip", "install", "--quiet", "-e", ROOT], env)
    seconds["pip install -e geomlib"] = time.perf_counter() - t0
    after = _freeze(python)

    changed = {name: (before.get(name), after.get(name)) for name in EXISTING if after.get(name) != before.get(name)}
    moved = {name: (before[name], after.get(name)) for name in before if after.get(name) != before[name]}
    added = sorted(f"{name}=={after[name]}" for name in after if name not in before)

    t0 = time.perf_counter()
    nbval = subprocess.run(
        [python, "-m", "pytest", NOTEBOOK, "-q", "-p", "no:cacheprovider"],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    seconds["nbval notebook 00"] = time.perf_counter() - t0

    report = ROOT / "build" / "install-test.txt"
    report.parent.mkdir(exist_ok=True)
    report.write_text(
        "\n".join(
            [
                f"Python {sys.version.split()[0]}",
                "existing front-end (unchanged by pip: {}): {}".format(
                    not changed, ", ".join(f"{n}=={v}" for n, v in EXISTING.items())
                ),
                f"packages pip changed: {moved or 'none'}",
                f"packages pip added with geomlib: {', '.join(added)}",
                *(f"{what}: {s:.1f} s" for what, s in seconds.items()),
                f"nbval: {nbval.stdout.strip().splitlines()[-1] if nbval.stdout.strip() else nbval.stderr[-500:]}",
            ]
        )
        + "\n"
    )

    assert not changed, f"installing geomlib changed the front-end (before, after): {changed}"
    assert not moved, f"installing geomlib changed packages that were there (before, after): {moved}"
    where = _run([python, "-c", "import geomlib; print(geomlib.__file__)"], env, cwd=tmp_path)
    assert Path(where.stdout.strip()).parent == ROOT / "geomlib", f"geomlib imported from {where.stdout}"
    assert nbval.returncode == 0, (
        f"{NOTEBOOK} failed under nbval there:\n{nbval.stdout[-4000:]}\n{nbval.stderr[-2000:]}"
    )
