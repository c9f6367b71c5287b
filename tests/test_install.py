"""geomlib installed as a course installs it: a wheel, not the checkout, in an environment of its own.

Two fresh virtual environments, each used from a folder outside the checkout
(holding only a copy of notebook 00), so that nothing can be imported or read
from the checkout:

* the pinned set: the wheel (built from the sdist, tests/distributions.py) is
  installed with ``-c constraints.txt`` and what runs a notebook (nbclient,
  ipykernel). ``from geomlib import check`` works, ``geomlib.data_path`` finds
  the meshes inside site-packages, a check passes a correct routine and names
  a wrong one, every installed package is one constraints.txt pins at that
  version, and notebook 00 runs top to bottom with its claims checked strictly.
* a JupyterLab 4 front-end other than the pinned one (the previous minor
  release of JupyterLab and Notebook, an ipykernel 6, the widget packages one
  release back), as a course's JupyterHub image might have it, plus pytest and
  nbval. geomlib is installed into it the way the README says
  (``pip install <checkout>``, dependencies resolved by pip). ``pip freeze``
  before and after must agree on every package that was there, and notebook
  00 must then run there under nbval.

Needs the package index or a pip cache holding these releases (installs skip
byte-compiling, which the first imports do for what they use); the versions
and times are written to build/install-test.txt.
"""

import os
import shutil
import subprocess
import sys
import time
import venv
from pathlib import Path

import pytest
from distributions import build
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parents[1]
# a working JupyterLab 4 front-end other than constraints.txt's
EXISTING = {
    "jupyterlab": "4.5.11",
    "notebook": "7.5.8",
    "ipykernel": "6.30.1",
    "ipywidgets": "8.1.8",
    "jupyterlab-widgets": "3.0.16",
    "widgetsnbextension": "4.0.15",
}
TOOLS = ["pytest>=8,<10", "nbval>=0.11,<0.12"]
NOTEBOOK = ROOT / "notebooks" / "00_getting_started.ipynb"
# what runs a notebook without a front-end (versions from constraints.txt)
RUNNER = ["ipykernel", "nbclient"]
# the environments get no pip of their own: the running pip installs into them (--python),
# which saves creating one per environment and reads the same cache
PIP = [sys.executable, "-m", "pip", "--python"]
REPORT = ROOT / "build" / "install-test.txt"

pytestmark = [pytest.mark.slow, pytest.mark.install]

# run inside the fresh environment, from a folder outside the checkout
PROBE = """
import sys, sysconfig
from pathlib import Path

import numpy as np
import scipy.sparse as sp

import geomlib
from geomlib import check

site = Path(sysconfig.get_paths()["purelib"]).resolve()
print("geomlib", Path(geomlib.__file__).resolve().parent.relative_to(site))
saddle = geomlib.data_path("saddle.obj")
print("saddle", saddle.resolve().relative_to(site), saddle.is_file())
V, F = geomlib.load_mesh(saddle)
print("mesh", len(V), len(F))


def uniform(V, F):
    # a learner's correct uniform Laplacian: C_ij = 1 on edges, C_ii = -valence, M = diag(valence)
    n = len(V)
    A = sp.coo_matrix((np.ones(F.size), (F.ravel(), np.roll(F, -1, axis=1).ravel())), shape=(n, n))
    A = ((A + A.T) > 0).astype(float)
    valence = np.asarray(A.sum(axis=1)).ravel()
    return sp.diags(valence), A - sp.diags(valence)


right = check.uniform_laplacian(uniform)
wrong = check.uniform_laplacian(lambda V, F: (uniform(V, F)[0], -uniform(V, F)[1]))
print("check", right.passed, wrong.passed)
print("diagnosis", wrong.message.splitlines()[0])
"""

RUN_NOTEBOOK = """
import sys, time
from pathlib import Path

import nbclient
import nbformat

path = Path(sys.argv[1])
nb = nbformat.read(path, as_version=4)
t0 = time.perf_counter()
nbclient.NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(path.parent)}}).execute()
errors = [o for c in nb.cells for o in c.get("outputs", []) if o.get("output_type") == "error"]
print(len(nb.cells), "cells", len(errors), "errors", f"{time.perf_counter() - t0:.1f} s")
"""


def _pins():
    pins = {}
    for line in (ROOT / "constraints.txt").read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            name, version = line.split("==")
            pins[canonicalize_name(name)] = version.strip()
    return pins


def _install(python, *args):
    return [*PIP, python, "install", "--quiet", "--no-compile", *args]


def _freeze(python, *options):
    out = subprocess.run([*PIP, python, "freeze", *options], capture_output=True, text=True, check=True)
    versions = {}
    for line in out.stdout.splitlines():
        if line.startswith("#"):
            continue
        name, _, version = line.partition("==") if "==" in line else line.partition(" @ ")
        versions[canonicalize_name(name)] = version
    return versions


def _environment(tmp_path):
    """A fresh virtual environment: (its python, the environment variables to run it with)."""
    home = tmp_path / "venv"
    venv.EnvBuilder(with_pip=False).create(home)
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
    return python, env


def _elsewhere(tmp_path):
    """A folder outside the checkout holding only a copy of notebook 00."""
    work = tmp_path / "course"
    work.mkdir()
    shutil.copy(NOTEBOOK, work)
    return work


def _run(cmd, env, cwd, timeout=900):
    done = subprocess.run([str(c) for c in cmd], cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    assert done.returncode == 0, f"{' '.join(map(str, cmd))} failed:\n{done.stdout[-4000:]}\n{done.stderr[-3000:]}"
    return done


def _timed(seconds, what, fn, *args, **kw):
    t0 = time.perf_counter()
    result = fn(*args, **kw)
    seconds[what] = time.perf_counter() - t0
    return result


def _report(title, lines):
    """Append this test's section to build/install-test.txt (the first test of a run starts it anew)."""
    REPORT.parent.mkdir(exist_ok=True)
    mode = "a" if getattr(_report, "started", False) else "w"
    with REPORT.open(mode) as fh:
        if mode == "w":
            fh.write(f"Python {sys.version.split()[0]}\n")
        fh.write(f"\n{title}\n" + "".join(f"  {line}\n" for line in lines))
    _report.started = True


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    return build(tmp_path_factory.mktemp("dist"))[1]


def test_wheel_with_the_pinned_set_runs_notebook_00_from_any_folder(wheel, tmp_path):
    seconds = {}
    python, env = _timed(seconds, "fresh environment", _environment, tmp_path)
    work = _elsewhere(tmp_path)
    install = _install(python, "-c", ROOT / "constraints.txt", wheel, *RUNNER)
    _timed(seconds, "pip install the wheel with the pinned set", _run, install, env, work)

    installed = _freeze(python)
    pins = _pins()
    unpinned = {n: v for n, v in installed.items() if n != "geomlib" and pins.get(n) != v}
    assert not unpinned, f"installed at versions constraints.txt does not pin: {unpinned}"

    reader = dict(env, GEOMLIB_STRICT_CLAIMS="0")  # as a reader runs it: a failed check answers, it does not raise
    probe = _timed(seconds, "import, data_path, check", _run, [python, "-c", PROBE], reader, work).stdout.splitlines()
    facts = dict(line.split(" ", 1) for line in probe)
    assert facts["geomlib"] == "geomlib"
    assert facts["saddle"] == str(Path("geomlib", "meshes", "saddle.obj")) + " True"
    assert facts["check"] == "True False"
    assert "sign of C is flipped" in facts["diagnosis"]

    ran = _timed(seconds, "notebook 00", _run, [python, "-c", RUN_NOTEBOOK, work / NOTEBOOK.name], env, work)
    assert " 0 errors " in ran.stdout, ran.stdout

    _report(
        "geomlib wheel + constraints.txt in a fresh environment",
        [
            f"wheel: {wheel.name}, {wheel.stat().st_size / 1e6:.2f} MB",
            f"packages installed: {len(installed)}",
            *(f"{line}" for line in probe),
            f"notebook 00: {ran.stdout.strip()}",
            *(f"{what}: {s:.1f} s" for what, s in seconds.items()),
        ],
    )


def test_installing_geomlib_keeps_an_existing_jupyterlab_4(tmp_path):
    pins = _pins()
    same = [name for name, version in EXISTING.items() if pins.get(name) == version]
    assert not same, f"the existing front-end must differ from constraints.txt to show anything: {same}"

    seconds = {}
    python, env = _timed(seconds, "fresh environment", _environment, tmp_path)
    work = _elsewhere(tmp_path)
    existing = _install(python, *(f"{n}=={v}" for n, v in EXISTING.items()), *TOOLS)
    _timed(seconds, "existing front-end", _run, existing, env, work)
    before = _freeze(python, "--all")
    assert {name: before.get(name) for name in EXISTING} == EXISTING

    # the README's command: a plain (not editable) install from the checkout
    _timed(seconds, "pip install <checkout>", _run, _install(python, ROOT), env, work)
    after = _freeze(python, "--all")

    changed = {name: (before.get(name), after.get(name)) for name in EXISTING if after.get(name) != before.get(name)}
    moved = {name: (before[name], after.get(name)) for name in before if after.get(name) != before[name]}
    added = sorted(f"{name}=={after[name]}" for name in after if name not in before and name != "geomlib")

    nbval = _timed(
        seconds,
        "nbval notebook 00",
        subprocess.run,
        [python, "-m", "pytest", NOTEBOOK.name, "-q", "-p", "no:cacheprovider", "--nbval-lax"]
        + ["--nbval-sanitize-with", str(ROOT / "tests" / "nbval_sanitize.cfg")],
        cwd=work,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )

    _report(
        "pip install <checkout> into an existing JupyterLab 4",
        [
            "existing front-end (unchanged by pip: {}): {}".format(
                not changed, ", ".join(f"{n}=={v}" for n, v in EXISTING.items())
            ),
            f"packages pip changed: {moved or 'none'}",
            f"packages pip added with geomlib: {', '.join(added)}",
            *(f"{what}: {s:.1f} s" for what, s in seconds.items()),
            f"nbval: {nbval.stdout.strip().splitlines()[-1] if nbval.stdout.strip() else nbval.stderr[-500:]}",
        ],
    )

    assert not changed, f"installing geomlib changed the front-end (before, after): {changed}"
    assert not moved, f"installing geomlib changed packages that were there (before, after): {moved}"
    assert "geomlib" in after and "-e " not in after["geomlib"], f"geomlib installed as {after.get('geomlib')}"
    where = _run(
        [python, "-c", "import geomlib, sysconfig; print(geomlib.__file__, sysconfig.get_paths()['purelib'])"],
        env,
        work,
    )
    package, site = where.stdout.split()
    assert Path(package).parent == Path(site) / "geomlib", f"geomlib imported from {package}, not {site}"
    assert nbval.returncode == 0, (
        f"{NOTEBOOK.name} failed under nbval there:\n{nbval.stdout[-4000:]}\n{nbval.stderr[-2000:]}"
    )
