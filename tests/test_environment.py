"""The set-up files ask for what they should.

* pyproject.toml: the package requires exactly the third-party modules geomlib
  imports (an AST scan of its files; the notebooks import nothing more), as
  ranges; the front-end (JupyterLab, Notebook, the kernel and the
  widget packages) is pinned only in the ``lab`` extra, so installing geomlib
  into a working Jupyter leaves that Jupyter alone.
* constraints.txt pins every declared package exactly, inside its range; the
  ``lab`` extra's pins are the same.
* environment.yml asks conda only for Python and pip (packages conda-forge has
  under those names) and pip for exactly what workbook.py installs.
* The Python version tested (environment.yml, docs/install.md, README) is one the package declares.
"""

import ast
import importlib.metadata
import importlib.util
import json
import re
import sys
import tomllib
import warnings
from pathlib import Path

import yaml
from packaging.requirements import Requirement
from packaging.specifiers import SpecifierSet
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parents[1]
FRONT_END = {
    "jupyterlab",
    "notebook",
    "ipykernel",
    "ipywidgets",
    "jupyterlab-widgets",
    "widgetsnbextension",
    "pythreejs",
    "ipydatawidgets",
}
# packages the front-end installs that must not be pinned by geomlib's own requirements
NOT_REQUIRED = {"jupyterlab", "notebook", "ipykernel", "jupyterlab-widgets", "widgetsnbextension"}
# what environment.yml may ask conda for: conda-forge packages of exactly these names
CONDA_FORGE = {"python", "pip"}


def _project():
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]


def _requirements(lines):
    return {canonicalize_name(Requirement(r).name): Requirement(r) for r in lines}


def _pins():
    pins = {}
    for line in (ROOT / "constraints.txt").read_text().splitlines():
        line = line.strip()
        if line and not line.startswith("#"):
            req = Requirement(line)
            (spec,) = list(req.specifier)
            assert spec.operator == "==", f"constraints.txt must pin exactly: {line}"
            pins[canonicalize_name(req.name)] = spec.version
    return pins


def _environment():
    env = yaml.safe_load((ROOT / "environment.yml").read_text())
    conda, pip = [], []
    for dep in env["dependencies"]:
        if isinstance(dep, dict):
            assert set(dep) == {"pip"}, f"environment.yml: unexpected entry {dep}"
            pip += dep["pip"]
        else:
            conda.append(dep)
    return env, conda, pip


def _imported_modules(sources):
    """Top-level names of the absolute imports in the Python sources (texts), the standard library left out."""
    names = set()
    for source in sources:
        with warnings.catch_warnings():  # escape sequences in the notebooks' strings are theirs to mind
            warnings.simplefilter("ignore")
            tree = ast.parse(source)
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                names.update(alias.name.partition(".")[0] for alias in node.names)
            elif isinstance(node, ast.ImportFrom) and node.level == 0:
                names.add(node.module.partition(".")[0])
    return {name for name in names if name not in sys.stdlib_module_names and name != "geomlib"}


def _distributions(modules):
    """{module: distribution name} for importable top-level modules, as installed here."""
    owners = importlib.metadata.packages_distributions()
    missing = sorted(m for m in modules if m not in owners)
    assert not missing, f"imported but installed by no distribution here: {missing}"
    ambiguous = {m: owners[m] for m in modules if len(set(map(canonicalize_name, owners[m]))) != 1}
    assert not ambiguous, f"modules provided by several distributions: {ambiguous}"
    return {m: canonicalize_name(owners[m][0]) for m in modules}


def _notebook_sources():
    for path in sorted((ROOT / "notebooks").glob("*.ipynb")):
        for cell in json.loads(path.read_text())["cells"]:
            if cell["cell_type"] == "code":
                # IPython's magics and shell escapes are not Python
                lines = "".join(cell["source"]).splitlines()
                yield "\n".join(line for line in lines if not line.lstrip().startswith(("%", "!")))


def _package_sources(course):
    """The sources of geomlib's modules outside (course False) or inside (course True) geomlib/course."""
    for path in sorted((ROOT / "geomlib").rglob("*.py")):
        if (path.parent.name == "course") == course:
            yield path.read_text()


def test_package_requires_exactly_what_geomlib_imports():
    imported = _distributions(_imported_modules(_package_sources(course=False)))
    required = set(_requirements(_project()["dependencies"]))
    unused = sorted(required - set(imported.values()))
    assert not unused, f"[project] dependencies that geomlib never imports (move them to an extra): {unused}"
    undeclared = sorted(f"{d} (import {m})" for m, d in imported.items() if d not in required)
    assert not undeclared, f"geomlib imports these, but [project] dependencies lacks them: {undeclared}"


def test_the_course_extra_brings_what_geomlib_course_imports_beyond_geomlib():
    """geomlib-course (geomlib/course) runs with geomlib[course]; nothing else of geomlib needs that extra."""
    imported = _distributions(_imported_modules(_package_sources(course=True)))
    provided = set(_requirements(_project()["dependencies"])) | set(
        _requirements(_project()["optional-dependencies"]["course"])
    )
    # SQLAlchemy comes with nbgrader, whose gradebook it is
    nbgrader = [r for r in importlib.metadata.requires("nbgrader") or () if "extra ==" not in r]
    provided |= {canonicalize_name(Requirement(r).name) for r in nbgrader}
    missing = sorted(f"{d} (import {m})" for m, d in imported.items() if d not in provided)
    assert not missing, (
        f"geomlib/course imports these, but neither [project] nor the course extra brings them: {missing}"
    )
    assert _project()["scripts"]["geomlib-course"] == "geomlib.course.cli:main"


def test_notebooks_import_nothing_the_package_does_not_require():
    """A course installs the package and opens the notebooks: they must need nothing more."""
    imported = _distributions(_imported_modules(_notebook_sources()))
    required = set(_requirements(_project()["dependencies"]))
    extra = sorted(f"{d} (import {m})" for m, d in imported.items() if d not in required)
    assert not extra, f"the notebooks import packages the installed geomlib does not bring: {extra}"


def test_import_scan_sees_imports_inside_functions_and_leaves_the_standard_library_out():
    source = "import os\nimport numpy.linalg as la\nfrom . import x\ndef f():\n    from PIL import Image\n"
    assert _imported_modules([source]) == {"numpy", "PIL"}
    assert _distributions({"numpy", "PIL"}) == {"numpy": "numpy", "PIL": "pillow"}


def _workbook():
    spec = importlib.util.spec_from_file_location("workbook", ROOT / "workbook.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_package_requirements_are_ranges_without_the_front_end():
    required = _requirements(_project()["dependencies"])
    pinned = {
        name: str(r.specifier) for name, r in required.items() if any(s.operator in ("==", "===") for s in r.specifier)
    }
    assert not pinned, f"exact pins in [project] dependencies (they belong in constraints.txt): {pinned}"
    unbounded = [name for name, r in required.items() if not any(s.operator == "<" for s in r.specifier)]
    assert not unbounded, f"give these an upper bound (next major release): {unbounded}"
    assert not NOT_REQUIRED & set(required), (
        f"the package requires front-end packages {sorted(NOT_REQUIRED & set(required))}; "
        "they belong in the 'lab' extra"
    )
    # what the notebooks import for the views must still come with the package
    assert {"ipywidgets", "pythreejs"} <= set(required)


def test_constraints_pin_every_declared_package_inside_its_range():
    pins = _pins()
    project = _project()
    declared = list(project["dependencies"])
    for extra in project["optional-dependencies"].values():
        declared += extra
    for name, req in _requirements(declared).items():
        assert name in pins, f"{name} is declared in pyproject.toml but not pinned in constraints.txt"
        assert req.specifier.contains(pins[name], prereleases=True), (
            f"{name}=={pins[name]} in constraints.txt is outside {req.specifier} from pyproject.toml"
        )


def test_lab_extra_pins_the_front_end_as_constraints_do():
    """The widget packages whose drift breaks the views are pinned together."""
    lab = _requirements(_project()["optional-dependencies"]["lab"])
    assert set(lab) == FRONT_END
    pins = _pins()
    for name, req in lab.items():
        (spec,) = list(req.specifier)
        assert spec.operator == "==" and spec.version == pins[name], (
            f"geomlib[lab] asks for {name}{req.specifier}, constraints.txt pins {pins[name]}"
        )


def test_environment_yml_asks_conda_only_for_python_and_pip():
    env, conda, _ = _environment()
    assert env["channels"] == ["conda-forge"]
    names = {re.match(r"[A-Za-z0-9_.\-]+", dep).group(0) for dep in conda}
    assert names == CONDA_FORGE, f"conda is asked for {sorted(names)}; only {sorted(CONDA_FORGE)} are meant"


def test_environment_yml_pip_section_installs_what_workbook_py_installs():
    _, _, pip = _environment()
    args = [word for line in pip for word in line.split()]
    assert args == _workbook().INSTALL_ARGS
    # the paths are relative to the folder of environment.yml (conda runs pip there)
    constraints = args[args.index("-c") + 1]
    assert (ROOT / constraints).is_file()
    extras = re.fullmatch(r"\.\[([a-z,]+)\]", args[args.index("-e") + 1]).group(1).split(",")
    assert set(extras) <= set(_project()["optional-dependencies"])
    assert "--no-deps" not in args


def test_tested_python_is_declared_and_stated_in_the_install_page():
    _, conda, _ = _environment()
    (python,) = [dep for dep in conda if dep.startswith("python")]
    tested = re.fullmatch(r"python\s*=\s*(\d+\.\d+)", python).group(1)
    assert SpecifierSet(_project()["requires-python"]).contains(f"{tested}.0")
    install = (ROOT / "docs" / "install.md").read_text()
    assert f"tested with Python {tested}" in install
    assert f'requires-python = "{_project()["requires-python"]}"' in install
    assert f"Python {tested}" in (ROOT / "README.md").read_text()  # the front page's two commands


def test_workbook_opens_notebook_00_and_passes_arguments_on():
    workbook = _workbook()
    lab = workbook.front_end_command("lab", ["--port", "8899"])
    notebook = workbook.front_end_command("notebook", ["--port", "8899"], root=True)
    assert lab[1:3] == ["lab", "--notebook-dir"] and notebook[1:3] == ["notebook", "--notebook-dir"]
    assert "--LabApp.default_url=/lab/tree/00_getting_started.ipynb" in lab
    assert "--JupyterNotebookApp.default_url=/notebooks/00_getting_started.ipynb" in notebook
    assert lab[-2:] == ["--port", "8899"] and "--allow-root" not in lab
    assert notebook[-3:] == ["--port", "8899", "--allow-root"]
    assert workbook.front_end_command("lab", ["--allow-root"], root=True).count("--allow-root") == 1
    assert (workbook.NOTEBOOKS / workbook.FIRST_NOTEBOOK).is_file()


def test_workbook_course_runs_geomlib_course_in_its_environment(tmp_path):
    # in the caller's folder, with the environment's bin/ first on PATH (nbgrader calls alembic)
    import subprocess

    done = subprocess.run(
        [sys.executable, str(ROOT / "workbook.py"), "course", "report", "--help"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("usage: geomlib-course report") and "course_dir" in done.stdout
    missing = subprocess.run(
        [sys.executable, str(ROOT / "workbook.py"), "course", "report", "no-such-course", "a1"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert missing.returncode != 0 and f"no course folder {tmp_path / 'no-such-course'}" in missing.stderr


def test_lab_options_choose_the_version_and_the_working_folder(tmp_path):
    workbook = _workbook()
    assert workbook.front_end_options(["--port", "8899"]) == (False, workbook.WORK, ["--port", "8899"])
    assert workbook.front_end_options(["--solutions"]) == (True, workbook.WORK, [])
    solutions, work, rest = workbook.front_end_options(["--work", str(tmp_path), "--no-browser"])
    assert (solutions, work, rest) == (False, tmp_path.resolve(), ["--no-browser"])
    assert workbook.front_end_options([f"--work={tmp_path}"])[1] == tmp_path.resolve()
    lab = workbook.front_end_command("lab", [], folder=tmp_path)
    assert lab[lab.index("--notebook-dir") + 1] == str(tmp_path)
    # the default working folder sits beside notebooks/ (so ../docs links hold) and git ignores it
    assert workbook.WORK.parent == workbook.NOTEBOOKS.parent
    assert "/my-work/" in (ROOT / ".gitignore").read_text().split()


def test_lab_adds_new_notebooks_and_never_overwrites_the_readers(tmp_path):
    workbook = _workbook()
    built, work = tmp_path / "built", tmp_path / "work"
    built.mkdir()
    (built / "00_a.ipynb").write_text("exercise version 00")
    assert workbook.add_missing_notebooks(built, work) == (["00_a.ipynb"], [])
    (work / "00_a.ipynb").write_text("the reader's attempt")  # the reader works on it
    (built / "00_a.ipynb").write_text("an update of 00")  # the workbook is updated
    (built / "01_b.ipynb").write_text("a new notebook")
    assert workbook.add_missing_notebooks(built, work) == (["01_b.ipynb"], ["00_a.ipynb"])
    assert (work / "00_a.ipynb").read_text() == "the reader's attempt"
    assert (work / "01_b.ipynb").read_text() == "a new notebook"


def test_lab_builds_the_exercise_version_and_the_solutions_with_a_banner(tmp_path):
    import nbformat

    spec = importlib.util.spec_from_file_location("build_assignment", ROOT / "tools" / "build_assignment.py")
    build_assignment = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(build_assignment)
    names = build_assignment.build_solutions(tmp_path / "solutions")
    assert names == sorted(p.name for p in (ROOT / "notebooks").glob("*.ipynb"))
    for name in names:
        original = nbformat.read(ROOT / "notebooks" / name, 4)
        shown = nbformat.read(tmp_path / "solutions" / name, 4)
        assert shown.cells[0].source == build_assignment.SOLUTION_BANNER
        assert [c.source for c in shown.cells[1:]] == [c.source for c in original.cells]
    assert "Solution version" in build_assignment.SOLUTION_BANNER
    build_assignment.build(tmp_path / "exercises")
    stubbed = nbformat.read(tmp_path / "exercises" / "07_denoising_evaluation.ipynb", 4)
    sources = "\n".join(c.source for c in stubbed.cells)
    assert "NotImplementedError" in sources and "### BEGIN SOLUTION" not in sources
