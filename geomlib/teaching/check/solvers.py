"""Ground rules about eigensolvers, enforced while a learner's function runs.

Notebook 04 asks for the reduction of ``C e = -lam M e`` to the symmetric ``Q z = lam z``:
a generalised solver handed the pair (``scipy.linalg.eigh(A, B)``, ``eigsh(A, k, M)``)
would do it for the learner. Notebook 05 asks for lambda_max by products with Q: a
dense solver computes all n eigenvalues (n^3 work) instead. :func:`refusing` wraps the
learner's function so that such a call, however the routine was imported, fails the
check with no points and names the routine.

A call counts as the learner's when nothing but scipy's batching wrapper stands between
it and code outside numpy, scipy and geomlib: their own solvers may call these routines inside
(``lobpcg`` calls ``eigh`` with a second matrix), and that is not the learner's doing.
"""

import inspect
import sys

import numpy as np
import scipy.linalg
import scipy.sparse.linalg

from .result import Mistake

__all__ = ["GENERALISED", "DENSE", "refusing"]


def _watch(table):
    """{code object: (public name, the argument that makes the call a refused one, or None: every call)}."""
    return {inspect.unwrap(f).__code__: (name, argument) for name, (f, argument) in table.items()}


#: Generalised solvers: refused when the second matrix is given.
GENERALISED = _watch(
    {
        "scipy.linalg.eigh": (scipy.linalg.eigh, "b"),
        "scipy.linalg.eigvalsh": (scipy.linalg.eigvalsh, "b"),
        "scipy.linalg.eig": (scipy.linalg.eig, "b"),
        "scipy.linalg.eigvals": (scipy.linalg.eigvals, "b"),
        "scipy.sparse.linalg.eigsh": (scipy.sparse.linalg.eigsh, "M"),
        "scipy.sparse.linalg.eigs": (scipy.sparse.linalg.eigs, "M"),
        "scipy.sparse.linalg.lobpcg": (scipy.sparse.linalg.lobpcg, "B"),
    }
)

#: Dense solvers of all n eigenpairs: refused whatever their arguments.
DENSE = _watch(
    {
        f"{module.__name__}.{name}": (getattr(module, name), None)
        for module in (np.linalg, scipy.linalg)
        for name in ("eigh", "eigvalsh", "eig", "eigvals")
    }
)

_LIBRARIES = ("numpy", "scipy", "geomlib")  # geomlib's own calls are judged by its ground rules (result.call)


def _learners(frame):
    """Whether the call in ``frame`` comes from outside numpy, scipy and geomlib (past scipy's batching wrapper)."""
    caller = frame.f_back
    while caller is not None and caller.f_code.co_filename.endswith(("_lib/_util.py", "_lib\\_util.py")):
        caller = caller.f_back
    return caller is not None and not str(caller.f_globals.get("__name__", "")).startswith(_LIBRARIES)


def refusing(fn, watch, why):
    """``fn`` wrapped: a call of a routine in ``watch`` (see :data:`GENERALISED`, :data:`DENSE`) made by the
    learner's code raises a ``Mistake`` (no partial credit) naming it, with ``why`` as the hint."""

    def wrapped(*args):
        hits, previous = [], sys.getprofile()

        def profile(frame, event, arg):
            if previous is not None:  # the geomlib ground rules of ``result.call`` keep watching
                previous(frame, event, arg)
            if event == "call" and not hits and frame.f_code in watch:
                name, argument = watch[frame.f_code]
                if (argument is None or frame.f_locals.get(argument) is not None) and _learners(frame):
                    hits.append(name if argument is None else f"{name} with a second matrix ({argument}=)")

        sys.setprofile(profile)
        try:
            out = fn(*args)
        finally:
            sys.setprofile(previous)
        if hits:
            raise Mistake(
                f"the function calls {hits[0]}, which the ground rules exclude, so it earns no points",
                why,
                typical=False,
            )
        return out

    wrapped.__name__ = getattr(fn, "__name__", "function")
    return wrapped
