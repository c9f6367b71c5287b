"""What an exercise check returns, and the small vocabulary checks are written in.

A check runs a learner's function on small cases with known answers (one
triangle, a tetrahedron, a regular grid, a sphere, the ellipsoid) and stops at
the first thing that is wrong, named as the typical mistake it is ("the sign
is flipped") with a one-line hint and the derivation to reread.

Writing a check::

    @exercise("uniform_laplacian", reread="section 2 · The uniform Laplacian, derived")
    def uniform_laplacian(fn):
        M, C = matrix_pair(call(fn, V, F), n=len(V))
        if close(C, -C_true):
            raise Mistake("the sign of C is flipped", "C_ii = -valence, C_ij = +1 on edges")
        ...
        return ["one triangle", "a regular grid"]        # what was checked

``exercise`` turns the body into a function ``fn -> CheckResult``:

* ``Mistake`` raised by the body -> ``passed=False`` with its diagnosis;
* ``NotImplementedError`` from the learner's function (the assignment's stub)
  -> ``passed=False``, "not written yet";
* any other exception from the learner's function -> ``passed=False`` naming it;
* the body returning -> ``passed=True``, listing what was checked.

Under the test suite's strict mode (``GEOMLIB_STRICT_CLAIMS=1``) a failed check
of a function that is written (not a stub) raises ``CheckFailed``, so a
solution notebook whose own answer fails its check fails its test.
"""

import functools
import html

import numpy as np
import scipy.sparse as sp

from ..notebook import strict_claims

__all__ = ["CheckResult", "CheckFailed", "Mistake", "exercise", "call", "matrix_pair", "vector", "close", "use"]


class CheckFailed(AssertionError):
    """A written (non-stub) function failed its check under the strict test run."""


class Mistake(Exception):
    """Raised inside a check: ``diagnosis`` names the mistake, ``hint`` says how to fix it."""

    def __init__(self, diagnosis, hint=""):
        super().__init__(diagnosis)
        self.diagnosis, self.hint = diagnosis, hint


class _NotWritten(Exception):
    pass


class CheckResult:
    """Outcome of one exercise check.

    Attributes
    ----------
    name : str       the exercise
    passed : bool
    message : str    what was checked (passed) or the diagnosis, hint and what to reread
    """

    def __init__(self, name, passed, message):
        self.name, self.passed, self.message = name, bool(passed), message

    def __bool__(self):
        return self.passed

    def __repr__(self):
        mark = "passed" if self.passed else "not yet"
        return f"{self.name}: {mark}. {self.message}"

    def _repr_html_(self):
        colour, mark = ("#1a7f37", "✔ passed") if self.passed else ("#b35900", "✘ not yet")
        return (
            f'<div class="geomlib-check" style="border-left:4px solid {colour};padding:0.3em 0.8em">'
            f'<b>{html.escape(self.name)}</b>: <b style="color:{colour}">{mark}</b>. '
            f"{html.escape(self.message)}</div>"
        )


def call(fn, *args):
    """Call the learner's function; turn its exceptions into a diagnosis."""
    try:
        return fn(*args)
    except NotImplementedError as exc:
        raise _NotWritten(str(exc)) from None
    except Mistake:
        raise
    except Exception as exc:  # the learner's code may raise anything; name it
        raise Mistake(
            f"the function raised {type(exc).__name__}: {exc}",
            "run it on the small example in the cell above and read the traceback",
        ) from None


def _dense(A):
    return A.toarray() if sp.issparse(A) else np.asarray(A)


def matrix_pair(out, n):
    """Check that ``out`` is a pair (M, C) of n x n matrices; return them dense as float arrays."""
    if not isinstance(out, tuple) or len(out) != 2:
        raise Mistake(
            f"the function returned {type(out).__name__}, not the pair (M, C)",
            "end with `return M, C`, M the diagonal mass matrix and C the weight matrix",
        )
    M, C = (_dense(A) for A in out)
    for name, A in (("M", M), ("C", C)):
        if A.shape == (n,) and name == "M":
            raise Mistake("M is a vector, not a matrix", "return the diagonal matrix scipy.sparse.diags(areas)")
        if A.shape != (n, n):
            raise Mistake(
                f"{name} has shape {A.shape}, expected ({n}, {n}) for a mesh with {n} vertices",
                "one row and one column per vertex",
            )
    return M.astype(float), C.astype(float)


def vector(out, n, what="the function"):
    """Check that ``out`` is a length-n vector of numbers; return it as a float array."""
    x = np.asarray(out, dtype=float) if not sp.issparse(out) else _dense(out).astype(float)
    if x.shape not in ((n,), (n, 1), (1, n)):
        raise Mistake(
            f"{what} returned shape {x.shape}, expected ({n},): one value per vertex",
            "return a flat numpy array with one entry per vertex",
        )
    return x.reshape(n)


def close(a, b, rtol=1e-8, atol=1e-10):
    """Whether two arrays agree (shapes must match)."""
    a, b = _dense(a), _dense(b)
    return a.shape == b.shape and np.allclose(a, b, rtol=rtol, atol=atol)


def exercise(name, reread):
    """Decorator making a check body into ``check(fn) -> CheckResult`` (see the module docstring)."""

    def wrap(body):
        @functools.wraps(body)
        def check(fn):
            try:
                checked = body(fn)
            except _NotWritten as exc:
                detail = f" ({exc})" if str(exc) else ""
                return CheckResult(
                    name,
                    False,
                    f"not written yet: the function raises NotImplementedError{detail}. "
                    f"Reread {reread} and fill it in.",
                )
            except Mistake as m:
                message = f"{m.diagnosis}." + (f" Hint: {m.hint}." if m.hint else "") + f" Reread {reread}."
                if strict_claims():
                    raise CheckFailed(f"{name}: {message}") from None
                return CheckResult(name, False, message)
            return CheckResult(name, True, "checked on " + ", ".join(checked) + ".")

        check.exercise, check.reread = name, reread
        return check

    return wrap


def use(fn, check, reference):
    """The learner's ``fn`` when it passes ``check``, else ``reference``, saying which.

    Lets the cells after an unfinished exercise run on geomlib's own function.
    """
    result = check(fn)
    if result.passed:
        print(f"Using your {fn.__name__} (its check passed).")
        return fn
    print(
        f"Your {getattr(fn, '__name__', 'function')} has not passed its check yet; "
        f"the cells below use geomlib's {reference.__module__}.{reference.__name__}."
    )
    return reference
