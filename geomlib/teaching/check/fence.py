"""The fence around an exercise's answer: the code it may not enter.

The ground rules are an allow-list. An answer may use numpy, scipy and sympy, and the
geomlib routines its exercise hands it (``allow``); it may not enter any other geomlib
routine (code in geomlib's package folder, outside ``teaching/check``) nor a geometry
library (``GEOMETRY_LIBRARIES``: libigl's ``igl``, trimesh, ...).

``Fence(allow).profile(on_hit)`` is a profile function (``sys.setprofile``) that calls
``on_hit(name)`` at the first *entry* into fenced code: a frame of a fenced routine whose
caller is not fenced (the learner's code, a lambda, numpy or scipy calling back), unless
the routine is allowed or runs inside an allowed one. Calls among geomlib's own routines
(an allowed routine using its helpers) are not entries. A copy of a routine's code object
(``types.FunctionType(f.__code__, ...)``, a reloaded module) lies in the same files, so it
is fenced too. Compiled routines that a profile never sees (libigl's are C++) are wrapped
by ``Fence.tripwires(namespace, on_hit)``; ``cold_caches()`` empties geomlib's caches so a
cached result cannot be had without entering the routine.

The same fence serves the learner's interactive check (``result.call``) and the grading
sandbox (``sandbox``), where nothing can switch it off.
"""

import importlib
import importlib.util
import inspect
import os
import sys
import types
from pathlib import Path

# libraries that compute discrete curvature, Laplacians or mesh areas for you
GEOMETRY_LIBRARIES = {
    "igl": "libigl",
    "trimesh": "trimesh",
    "gpytoolbox": "gpytoolbox",
    "robust_laplacian": "robust_laplacian",
    "pymeshlab": "pymeshlab",
    "potpourri3d": "potpourri3d",
    "open3d": "Open3D",
    "pyvista": "PyVista",
    "vtk": "VTK",
    "meshplex": "meshplex",
    "pymesh": "PyMesh",
    "point_cloud_utils": "point_cloud_utils",
    "pygeodesic": "pygeodesic",
    "libigl": "libigl",
}

# a package's lazy attributes (``geomlib.laplacian``), a module's body run by an import and geomlib's
# import hook (its short module names) compute nothing of an answer
_LAZY = ("__getattr__", "__dir__", "<module>", "find_spec", "create_module", "exec_module")
_GEOMLIB = str(Path(__file__).resolve().parents[2]) + os.sep
_CHECKS = str(Path(__file__).resolve().parent) + os.sep


def library_folders():
    """{folder + os.sep: the library's name} of the geometry libraries installed here (none imported)."""
    found = {}
    for module, name in GEOMETRY_LIBRARIES.items():
        try:
            spec = importlib.util.find_spec(module)
        except (ImportError, ValueError):
            spec = None
        if spec is None:
            continue
        for folder in spec.submodule_search_locations or [os.path.dirname(spec.origin or "")]:
            found[str(Path(folder).resolve()) + os.sep] = name
    return found


def resolve(dotted):
    """The object a dotted name inside geomlib stands for ("lessons.laplace.laplacian")."""
    module, _, name = dotted.rpartition(".")
    return getattr(importlib.import_module(f"geomlib.{module}"), name)


def code_objects(target):
    """The code objects of a routine, a class's methods and everything nested in them."""
    members = list(vars(target).values()) if isinstance(target, type) else [target]
    codes, todo = set(), []
    for member in members:
        f = member.fget if isinstance(member, property) else getattr(member, "__func__", member)
        f = getattr(f, "func", f)  # functools.cached_property
        code = getattr(inspect.unwrap(f), "__code__", None)
        if code is not None:
            todo.append(code)
    while todo:
        code = todo.pop()
        codes.add(code)
        todo.extend(c for c in code.co_consts if isinstance(c, types.CodeType))
    return codes


def fenced_file(filename):
    """Whether code from this file is geomlib's (outside the checks themselves)."""
    return filename.startswith(_GEOMLIB) and not filename.startswith(_CHECKS)


class Fence:
    """What an exercise's answer may not enter: geomlib outside ``allow``, and geometry libraries."""

    def __init__(self, allow=()):
        self.allow = tuple(allow)
        self._allowed = None
        self.libraries = library_folders()

    def allowed(self):
        if self._allowed is None:  # resolved on first use: a check module imports no lesson it allows
            self._allowed = frozenset(c for dotted in self.allow for c in code_objects(resolve(dotted)))
        return self._allowed

    def profile(self, on_hit):
        """A profile function calling ``on_hit(name)`` at an entry into fenced code (module docstring).

        Everything it uses is bound as a default argument, none looked up by name when it
        runs: code in the sandbox cannot swap a module global or a builtin under it.
        """

        def profile(
            frame,
            event,
            arg,
            allowed=self.allowed(),
            libraries=tuple(self.libraries.items()),
            fenced=(_GEOMLIB, *self.libraries),
            on_hit=on_hit,
            geomlib=_GEOMLIB,
            checks=_CHECKS,
            lazy=_LAZY,
        ):
            if event != "call":
                return
            code = frame.f_code
            name = code.co_filename
            if not name.startswith(fenced):  # neither geomlib's nor a geometry library's file: most calls, one test
                return
            caller = frame.f_back
            where = "" if caller is None else caller.f_code.co_filename
            inside = where.startswith(geomlib) and not where.startswith(checks)
            if name.startswith(geomlib) and not name.startswith(checks):
                if inside or code.co_name in lazy or code in allowed:
                    return
                up = caller
                while up is not None:  # a callback of an allowed routine (through numpy, scipy)
                    if up.f_code in allowed:
                        return
                    up = up.f_back
                on_hit(f"geomlib's `{code.co_qualname}`")
                return
            for folder, library in libraries:
                if name.startswith(folder):
                    for other, _ in libraries:
                        if where.startswith(other):
                            return
                    if not inside:
                        on_hit(f"{library}'s `{code.co_qualname}`")
                    return

        return profile

    def tripwires(self, namespaces, on_hit):
        """Wrap the compiled routines of the loaded geometry libraries (in their modules and in
        ``namespaces``, dicts such as a function's globals) so a call reports ``on_hit``.

        Returns the list of (dict, key, original) to put back (``untrip``).
        """
        originals = {}
        for module_name, module in list(sys.modules.items()):
            top = module_name.partition(".")[0]
            if top not in GEOMETRY_LIBRARIES or module is None:
                continue
            for key, value in list(vars(module).items()):
                if callable(value) and not isinstance(value, (types.FunctionType, type, types.ModuleType)):
                    originals[id(value)] = (value, f"{GEOMETRY_LIBRARIES[top]}'s `{key}`")
        swapped = []
        for space in [vars(m) for n, m in list(sys.modules.items()) if m and n.partition(".")[0] in GEOMETRY_LIBRARIES]:
            swapped += _swap(space, originals, on_hit)
        for space in namespaces:
            swapped += _swap(space, originals, on_hit)
        return swapped


def _swap(space, originals, on_hit):
    swapped = []
    for key, value in list(space.items()):
        if id(value) in originals and originals[id(value)][0] is value:
            name = originals[id(value)][1]

            def tripwire(*args, _name=name, **kwargs):
                on_hit(_name)
                raise RuntimeError(f"{_name} is fenced off while an exercise is checked")

            space[key] = tripwire
            swapped.append((space, key, value))
    return swapped


def untrip(swapped):
    for space, key, value in reversed(swapped):
        space[key] = value


def cold_caches():
    """Empty the caches of geomlib's routines (functools.lru_cache): a cached answer is not free."""
    for name, module in list(sys.modules.items()):
        if name.startswith("geomlib.") and module is not None and fenced_file(getattr(module, "__file__", "") or ""):
            for value in list(vars(module).values()):
                if callable(getattr(value, "cache_clear", None)) and hasattr(value, "cache_info"):
                    value.cache_clear()
