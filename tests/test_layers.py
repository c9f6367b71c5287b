"""The layer rule of geomlib (docs/developing.md, "Architecture: four layers"), held by reading every module's imports.

mesh (the core) imports no other layer; numerics imports the mesh core; lessons import the
mesh core and numerics; teaching aids import those three; course (the lecturer's class tools)
may import anything, and nothing imports it, not even a notebook. No module imports a private name
of another, and no two modules import each other in a circle.
"""

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parent.parent / "geomlib"
ALLOWED = {
    "mesh": {"mesh"},
    "numerics": {"mesh", "numerics"},
    "lessons": {"mesh", "numerics", "lessons"},
    "teaching": {"mesh", "numerics", "lessons", "teaching"},
    # a lecturer's class tools (geomlib-course): above the teaching aids, imported by nothing
    "course": {"mesh", "numerics", "lessons", "teaching", "course"},
}


def module_name(path):
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports(path):
    """(imported module, imported names) of every import in the file, as absolute dotted names."""
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
    return [(t, n) for t, n in found if t == "geomlib" or t.startswith("geomlib.")]


MODULES = sorted(PACKAGE.rglob("*.py"))


def layer(name):
    parts = name.split(".")
    return parts[1] if len(parts) > 1 and parts[1] in ALLOWED else None


def test_every_module_sits_in_a_layer():
    loose = [module_name(p) for p in MODULES if layer(module_name(p)) is None and module_name(p) != "geomlib"]
    assert loose == [], f"modules outside the four layers: {loose}"


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


def test_nothing_imports_the_course_layer():
    """geomlib.course needs the course extra (nbgrader, copydetect): the package and the notebooks
    work without it."""
    users = sorted(
        module_name(p)
        for p in MODULES
        if layer(module_name(p)) != "course" and any(layer(t) == "course" for t, _ in imports(p))
    )
    assert users == [], f"modules importing geomlib.course: {users}"
    notebooks = sorted(
        p.name for p in (PACKAGE.parent / "notebooks").glob("*.ipynb") if "geomlib.course" in p.read_text()
    )
    assert notebooks == [], f"notebooks importing geomlib.course: {notebooks}"


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
