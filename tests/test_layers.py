"""The layer rule of geomlib (docs/developing.md, "Architecture: four layers"), held by reading every module's imports.

mesh (the core) imports no other layer; numerics imports the mesh core; lessons import the
mesh core and numerics; teaching aids may import those three; course tools (grading a class)
sit above the teaching aids and nothing below imports them, nor does any notebook. No module
imports a private name of another, and no two modules import each other in a circle.

Inside the teaching aids the parts are found from the file list (shapes/, experiments/,
display/, figures/, check/): the exercise checks and the figures do not import each other.
No display library (pythreejs, ipywidgets, matplotlib, IPython's display) is imported below
the teaching aids, and importing geomlib or any of its modules sets up no display: the
set-up cell of a notebook calls ``geomlib.setup_display()``.
"""

import ast
import json
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "geomlib"
ALLOWED = {
    "mesh": {"mesh"},
    "numerics": {"mesh", "numerics"},
    "lessons": {"mesh", "numerics", "lessons"},
    "teaching": {"mesh", "numerics", "lessons", "teaching"},
    "course": {"mesh", "numerics", "lessons", "teaching", "course"},
}
NOTEBOOKS = sorted((PACKAGE.parent / "notebooks").glob("*.ipynb"))
# libraries that draw or display: the teaching aids' business, never a layer below them
DISPLAY_LIBRARIES = ("pythreejs", "ipywidgets", "matplotlib", "mpl_toolkits", "IPython")


def module_name(path):
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports(path, everything=False):
    """(imported module, imported names) of every import in the file, as absolute dotted names.

    Only geomlib's own modules, unless ``everything``.
    """
    name = module_name(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            for alias in node.names:
                # "from . import cache" imports a module, "from .x import y" a name
                as_module = f"{target}.{alias.name}"
                found.append(
                    (
                        as_module
                        if (PACKAGE.parent / (as_module.replace(".", "/") + ".py")).exists()
                        or (PACKAGE.parent / as_module.replace(".", "/")).is_dir()
                        else target,
                        alias.name,
                    )
                )
        elif isinstance(node, ast.Import):
            found.extend((alias.name, None) for alias in node.names)
    return [(t, n) for t, n in found if everything or t == "geomlib" or t.startswith("geomlib.")]


MODULES = sorted(PACKAGE.rglob("*.py"))


def layer(name):
    parts = name.split(".")
    return parts[1] if len(parts) > 1 and parts[1] in ALLOWED else None


def test_every_module_sits_in_a_layer():
    loose = [module_name(p) for p in MODULES if layer(module_name(p)) is None and module_name(p) != "geomlib"]
    assert loose == [], f"modules outside the layers: {loose}"


@pytest.mark.parametrize("path", MODULES, ids=lambda p: module_name(p))
def test_layer_rule(path):
    here = layer(module_name(path))
    if here is None:  # geomlib/__init__.py: the public facade over every layer
        return
    wrong = sorted({t for t, _ in imports(path) if layer(t) not in ALLOWED[here]})
    assert wrong == [], f"{module_name(path)} ({here}) imports {wrong}, outside {sorted(ALLOWED[here])}"


@pytest.mark.parametrize("path", MODULES, ids=lambda p: module_name(p))
def test_no_private_names_across_modules(path):
    private = sorted(f"{t}.{n}" for t, n in imports(path) if n and n.startswith("_") and n != "__version__")
    assert private == [], f"{module_name(path)} imports private names {private}"


def test_no_import_cycles():
    graph = {module_name(p): {t for t, _ in imports(p) if t != "geomlib"} for p in MODULES}
    state, cycle = {}, []

    def visit(node, stack):
        state[node] = "open"
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == "open":
                cycle.append(stack[stack.index(nxt) :] + [nxt] if nxt in stack else [node, nxt])
            elif nxt not in state:
                visit(nxt, stack + [nxt])
        state[node] = "done"

    for node in sorted(graph):
        if node not in state:
            visit(node, [node])
    assert cycle == [], f"import cycles: {cycle}"


def test_the_rule_catches_a_breach(tmp_path, monkeypatch):
    # a core module that imports a lesson must be reported
    bad = PACKAGE / "mesh" / "geometry.py"
    text = bad.read_text() + "\nfrom ..lessons.laplace import laplacian\n"
    fake = tmp_path / "geomlib" / "mesh" / "geometry.py"
    fake.parent.mkdir(parents=True)
    fake.write_text(text)
    monkeypatch.setattr(__import__(__name__), "PACKAGE", tmp_path / "geomlib")
    assert any(layer(t) == "lessons" for t, _ in imports(fake))


def part(name):
    """The part of the teaching aids a module belongs to (``check``, ``figures``, ...), or None."""
    parts = name.split(".")
    return parts[2] if len(parts) > 2 and parts[1] == "teaching" else None


@pytest.mark.parametrize("path", MODULES, ids=lambda p: module_name(p))
def test_checks_and_figures_do_not_import_each_other(path):
    here = part(module_name(path))
    other = {"check": "figures", "figures": "check"}.get(here)
    wrong = sorted({t for t, _ in imports(path) if other and part(t) == other})
    assert wrong == [], f"{module_name(path)} ({here}) imports {wrong} from teaching/{other}/"


@pytest.mark.parametrize("path", MODULES, ids=lambda p: module_name(p))
def test_no_display_library_below_the_teaching_aids(path):
    if layer(module_name(path)) not in ("mesh", "numerics", "lessons"):
        return
    wrong = sorted({t for t, _ in imports(path, everything=True) if t.split(".")[0] in DISPLAY_LIBRARIES})
    assert wrong == [], f"{module_name(path)} imports the display libraries {wrong}"


def test_nothing_below_imports_the_course_tools_and_no_notebook_does():
    below = sorted(
        module_name(p)
        for p in MODULES
        if layer(module_name(p)) != "course" and any(layer(t) == "course" for t, _ in imports(p))
    )
    assert below == [], f"modules below the course tools import them: {below}"
    course = re.compile(r"^\s*(from geomlib\.course|import geomlib\.course|from geomlib import .*\bcourse\b)", re.M)
    for notebook in NOTEBOOKS:
        cells = json.loads(notebook.read_text(encoding="utf-8"))["cells"]
        sources = ["".join(c["source"]) for c in cells if c["cell_type"] == "code"]
        assert not any(course.search(s) for s in sources), f"{notebook.name} imports geomlib.course"


# in a fresh IPython shell: import every module, look at the display; then set it up and look again
DISPLAY_PROBE = textwrap.dedent("""
    import importlib, json, sys
    from IPython.core.interactiveshell import InteractiveShell
    shell = InteractiveShell.instance()
    import ipywidgets, matplotlib
    default = matplotlib.rcParams["axes.prop_cycle"]

    def state():
        png = shell.display_formatter.formatters["image/png"]
        return {"box_png": ipywidgets.Box in png.type_printers,
                "plot_style": matplotlib.rcParams["axes.prop_cycle"] != default}

    for name in sys.argv[1:]:
        importlib.import_module(name)
    before = state()
    importlib.import_module("geomlib").setup_display()
    print(json.dumps({"before": before, "after": state()}))
""")


def test_importing_sets_up_no_display_and_setup_display_does(tmp_path):
    names = [module_name(p) for p in MODULES if layer(module_name(p)) != "course"]
    done = subprocess.run(
        [sys.executable, "-c", DISPLAY_PROBE, *names],
        capture_output=True,
        text=True,
        timeout=300,
        env=dict(
            os.environ, MPLBACKEND="agg", IPYTHONDIR=str(tmp_path)
        ),  # the shell's history stays out of the checkout
        cwd=PACKAGE.parent,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    report = json.loads(done.stdout.strip().splitlines()[-1])
    assert report["before"] == {"box_png": False, "plot_style": False}, "importing geomlib set up the display"
    assert report["after"] == {"box_png": True, "plot_style": True}, "setup_display() did not set up the display"
