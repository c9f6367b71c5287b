"""The set-up files agree with each other: environment.yml (conda) names the
same packages with the same version specifiers as pyproject.toml (pip), and
constraints.txt pins every one of them to a version inside its range."""

import re
import tomllib
from pathlib import Path

import yaml
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parents[1]


def _pyproject_requirements():
    data = tomllib.loads((ROOT / "pyproject.toml").read_text())
    reqs = list(data["project"]["dependencies"])
    for extra in data["project"]["optional-dependencies"].values():
        reqs += extra
    return {canonicalize_name(Requirement(r).name): Requirement(r).specifier for r in reqs}


def _conda_requirements():
    env = yaml.safe_load((ROOT / "environment.yml").read_text())
    out = {}
    for dep in env["dependencies"]:
        if not isinstance(dep, str):
            continue
        name, spec = re.match(r"^([A-Za-z0-9_.\-]+)\s*(.*)$", dep).groups()
        if name in ("python", "pip"):
            continue
        # conda writes a single '=' for "this version"; pip's '==' means the same
        spec = re.sub(r"(?<![=<>!~])=(?!=)", "==", spec)
        out[canonicalize_name(name)] = Requirement(f"{name}{spec}").specifier
    return out


def test_environment_yml_names_the_same_packages_as_pyproject():
    pip, conda = _pyproject_requirements(), _conda_requirements()
    assert sorted(pip) == sorted(conda), (
        f"only in pyproject.toml: {sorted(set(pip) - set(conda))}; "
        f"only in environment.yml: {sorted(set(conda) - set(pip))}")
    differing = {name: (str(pip[name]), str(conda[name])) for name in pip if pip[name] != conda[name]}
    assert not differing, f"version specifiers differ (pyproject, environment.yml): {differing}"


def test_constraints_pin_every_declared_package_inside_its_range():
    pins = {}
    for line in (ROOT / "constraints.txt").read_text().splitlines():
        line = line.strip()
        if line and not line.startswith("#"):
            req = Requirement(line)
            (spec,) = list(req.specifier)
            assert spec.operator == "==", f"constraints.txt must pin exactly: {line}"
            pins[canonicalize_name(req.name)] = spec.version
    for name, specifier in _pyproject_requirements().items():
        assert name in pins, f"{name} is declared in pyproject.toml but not pinned in constraints.txt"
        assert specifier.contains(pins[name], prereleases=True), (
            f"{name}=={pins[name]} in constraints.txt is outside {specifier} from pyproject.toml")


def test_widget_front_end_versions_are_pinned_together():
    """The widget packages whose drift breaks the front-end are pinned exactly."""
    pip = _pyproject_requirements()
    for name in ("jupyterlab", "ipywidgets", "jupyterlab-widgets", "widgetsnbextension", "pythreejs"):
        (spec,) = list(pip[name])
        assert spec.operator == "==", f"{name} must be pinned exactly in pyproject.toml"
