"""Ground rules about eigensolvers, enforced while a learner's function runs.

Notebook 04 asks for the reduction of ``C e = -lam M e`` to the symmetric ``Q z = lam z``:
a generalised solver handed the pair (``scipy.linalg.eigh(A, B)``, ``eigsh(A, k, M)``)
would do it for the learner. Notebook 05 asks for lambda_max by products with Q: a
dense solver computes all n eigenvalues (n^3 work) instead. ``with refusing(watch, fn,
why): ...`` fails the check with no points, naming the routine, when the learner's code
calls one of them during the block.

Tripwires, not a profile (the profile belongs to the check's fence, ``fence``, which
refuses a second one): for the block, each watched routine is replaced by a wrapper in
its public module (``scipy.linalg``, ``numpy.linalg``, ``scipy.sparse.linalg``) and in the
learner's globals (``from scipy.linalg import eigh``) and closure. scipy's own code keeps its module-
internal references (``lobpcg`` calls ``eigh`` with a second matrix), so only the learner's
calls are seen.
"""

import contextlib
import inspect
import sys

import numpy as np
import scipy.linalg
import scipy.sparse.linalg

from .result import Mistake

__all__ = ["GENERALISED", "DENSE", "refusing"]

#: Generalised solvers: refused when the second matrix is given. public name -> (module, argument)
GENERALISED = {
    "scipy.linalg.eigh": (scipy.linalg, "b"),
    "scipy.linalg.eigvalsh": (scipy.linalg, "b"),
    "scipy.linalg.eig": (scipy.linalg, "b"),
    "scipy.linalg.eigvals": (scipy.linalg, "b"),
    "scipy.sparse.linalg.eigsh": (scipy.sparse.linalg, "M"),
    "scipy.sparse.linalg.eigs": (scipy.sparse.linalg, "M"),
    "scipy.sparse.linalg.lobpcg": (scipy.sparse.linalg, "B"),
}

#: Dense solvers of all n eigenpairs: refused whatever their arguments.
DENSE = {
    f"{module.__name__}.{name}": (module, None)
    for module in (np.linalg, scipy.linalg)
    for name in ("eigh", "eigvalsh", "eig", "eigvals")
}


def _wire(name, original, argument, hits):
    signature = inspect.signature(original)

    def wired(*args, **kwargs):
        caller = str(sys._getframe(1).f_globals.get("__name__", ""))
        given = argument is None and not caller.startswith("geomlib")  # geomlib's own calls: the fence's business
        if not given:
            try:
                given = (
                    not caller.startswith("geomlib")
                    and signature.bind_partial(*args, **kwargs).arguments.get(argument) is not None
                )
            except TypeError:
                given = False
        if given and not hits:
            hits.append(name if argument is None else f"{name} with a second matrix ({argument}=)")
        return original(*args, **kwargs)

    return wired


@contextlib.contextmanager
def refusing(watch, fn, why):
    """Within the block, a call of a routine of ``watch`` (:data:`GENERALISED`, :data:`DENSE`) made by the
    learner's ``fn`` raises a ``Mistake`` (no partial credit) naming it, with ``why`` as the hint."""
    hits, swapped = [], []
    spaces = [getattr(fn, "__globals__", {})]
    cells = [cell for cell in getattr(fn, "__closure__", None) or () if cell.cell_contents is not None]
    for name, (module, argument) in watch.items():
        attribute = name.rpartition(".")[2]
        original = getattr(module, attribute)
        wired = _wire(name, original, argument, hits)
        for space in [vars(module), *spaces]:
            for key, value in list(space.items()):
                if value is original:
                    swapped.append((space, key, value))
                    space[key] = wired
        for cell in cells:  # a routine imported inside the function that made fn
            if cell.cell_contents is original:
                swapped.append((cell, None, original))
                cell.cell_contents = wired
    try:
        yield
    except Mistake as m:
        if not hits or "earns no points" in m.diagnosis:  # the fence's refusal comes first
            raise
    finally:
        for space, key, value in reversed(swapped):
            if key is None:
                space.cell_contents = value
            else:
                space[key] = value
    if hits:
        raise Mistake(
            f"the function calls {hits[0]}, which the ground rules exclude, so it earns no points", why, typical=False
        )
