"""geomlib as a course installs it: the wheel and the sdist carry every module and every shipped mesh.

The sdist is built from the checkout and the wheel from the sdist (tests/distributions.py),
in a few seconds and without the network. The wheel's geomlib files must be exactly the
package's modules, meshes and mesh README (a missing sub-package or mesh fails, and so does
a stray file); installed on its own into a folder outside the checkout, ``geomlib.data_path``
must find the meshes there. The full install into a fresh environment is tests/test_install.py.
"""

import os
import subprocess
import sys
import tomllib

import pytest
from distributions import ROOT, build, package_files, sdist_files, wheel_files
from packaging.requirements import Requirement


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    return build(tmp_path_factory.mktemp("dist"))


def test_wheel_holds_exactly_the_modules_and_the_shipped_meshes(built):
    _, wheel = built
    files = wheel_files(wheel)
    inside = [f for f in files if f.startswith("geomlib/")]
    expected = package_files()
    assert set(inside) == set(expected), (
        f"missing from the wheel: {sorted(set(expected) - set(inside))}; "
        f"in the wheel but not in the package: {sorted(set(inside) - set(expected))}"
    )
    # the four layers and the exercise checks, by name (so an empty package list cannot pass)
    for sub in ("mesh", "numerics", "lessons", "teaching", "teaching/check"):
        assert f"geomlib/{sub}/__init__.py" in inside
    assert "geomlib/meshes/saddle.obj" in inside and "geomlib/meshes/README.md" in inside
    others = {f.split("/")[0] for f in files} - {"geomlib"}
    assert others == {"geomlib-0.1.0.dist-info"}, f"the wheel installs more than geomlib: {others}"


def test_wheel_metadata_requires_what_pyproject_declares(built):
    import zipfile

    _, wheel = built
    with zipfile.ZipFile(wheel) as z:
        metadata = z.read("geomlib-0.1.0.dist-info/METADATA").decode()
    requires = [
        Requirement(line.split(":", 1)[1]) for line in metadata.splitlines() if line.startswith("Requires-Dist:")
    ]
    runtime = sorted(str(r) for r in requires if r.marker is None)
    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    assert runtime == sorted(str(Requirement(d)) for d in declared)


def test_sdist_holds_the_modules_the_meshes_and_the_build_files(built):
    sdist, _ = built
    files = set(sdist_files(sdist))
    missing = sorted(set(package_files()) - files)
    assert not missing, f"missing from the sdist: {missing}"
    assert {"pyproject.toml", "README.md", "LICENSE"} <= files


def test_installed_wheel_finds_its_meshes_from_any_folder(built, tmp_path):
    """Installed alone into a folder (no checkout on the path), geomlib finds its meshes and checks there."""
    _, wheel = built
    target = tmp_path / "site"
    subprocess.run(
        [sys.executable, "-m", "pip", "install", "--quiet", "--no-deps", "--no-index", "--no-compile"]
        + ["--target", str(target), str(wheel)],
        check=True,
        capture_output=True,
    )
    probe = (
        "import geomlib, pathlib; from geomlib import check; "
        "print(geomlib.__file__); print(geomlib.data_path('saddle.obj')); print(check.__file__); "
        "print(' '.join(sorted(p.name for p in geomlib.data_path().glob('*.obj'))))"
    )
    env = dict(os.environ, PYTHONPATH=str(target))
    done = subprocess.run([sys.executable, "-c", probe], cwd=tmp_path, env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    package, saddle, checks, meshes = done.stdout.splitlines()
    installed = target / "geomlib"
    assert os.path.dirname(package) == str(installed)
    assert saddle == str(installed / "meshes" / "saddle.obj") and os.path.isfile(saddle)
    assert checks.startswith(str(installed / "teaching" / "check"))
    assert meshes.split() == sorted(f.rpartition("/")[2] for f in package_files() if f.endswith(".obj"))
