"""Build geomlib's sdist and wheel the way a release does: the sdist from a copy
of the checkout as a fresh clone has it, the wheel from the unpacked sdist.

The copy leaves out what earlier builds and installs leave in a checkout: a
``geomlib.egg-info`` folder (setuptools adds every file its SOURCES.txt lists
to the next sdist, which would hide a sub-package or a mesh missing from the
package configuration) and ``build/`` (a wheel built in place takes what
``build/lib`` still holds).

Both builds call setuptools, the build backend pyproject.toml names, as
installed in the running environment (the dev extra pins it); no network.
"""

import shutil
import subprocess
import sys
import tarfile
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "geomlib"
# what a fresh clone does not have (.gitignore's entries, and git's own folder)
_LEFT_BY_BUILDS = shutil.ignore_patterns(
    ".git", ".venv", "build", "*.egg-info", "__pycache__", "*.pyc", ".pytest_cache", ".ipynb_checkpoints", ".cache"
)
_BACKEND = "import sys; from setuptools import build_meta; print(build_meta.build_{}(sys.argv[1]))"


def package_files():
    """Every file the package must carry: its modules, the shipped meshes and their README (relative paths)."""
    modules = {p for p in PACKAGE.rglob("*.py") if "__pycache__" not in p.parts}
    meshes = set((PACKAGE / "meshes").glob("*.obj")) | {PACKAGE / "meshes" / "README.md"}
    return sorted(p.relative_to(ROOT).as_posix() for p in modules | meshes)


def _backend(hook, cwd, out):
    done = subprocess.run(
        [sys.executable, "-c", _BACKEND.format(hook), str(out)], cwd=cwd, capture_output=True, text=True
    )
    assert done.returncode == 0, (
        f"setuptools build_{hook} failed in {cwd}:\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
    )
    return out / done.stdout.strip().splitlines()[-1]


def build(out):
    """(sdist, wheel) paths, both written into the folder ``out``."""
    out = Path(out)
    clone = out / "checkout"
    shutil.copytree(ROOT, clone, ignore=_LEFT_BY_BUILDS)
    sdist = _backend("sdist", clone, out)
    with tarfile.open(sdist) as tar:
        tar.extractall(out / "unpacked", filter="data")
    (source,) = (out / "unpacked").iterdir()
    wheel = _backend("wheel", source, out)
    return sdist, wheel


def wheel_files(wheel):
    with zipfile.ZipFile(wheel) as z:
        return sorted(name for name in z.namelist() if not name.endswith("/"))


def sdist_files(sdist):
    """Paths inside the sdist, without its top folder (``geomlib-0.1.0/``)."""
    with tarfile.open(sdist) as tar:
        return sorted(m.name.partition("/")[2] for m in tar.getmembers() if m.isfile())
