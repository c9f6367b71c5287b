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

Graded by nbgrader
------------------
While nbgrader runs a notebook (``autograde``, ``validate``: ``NBGRADER_EXECUTION``
is set) every failed check raises ``CheckFailed`` with its diagnosis, stubs
included, so the grade cell that called it loses its points and the feedback
page shows the diagnosis. Each exercise has two grade cells:

* ``check.NAME(fn)``: all of the exercise's remaining points, for a function
  that passes;
* ``check.NAME.partial_credit(fn)``: one point, for a function that is right
  or whose first mistake is one the check names (``Mistake(..., typical=True)``,
  the default). A catch-all diagnosis ("C differs from ..."), a wrong shape or
  type, an exception or a stub earn nothing.

``use`` calls ``check.NAME.evaluate(fn)``, which never raises, so the cells after
an exercise run on geomlib's own function in every mode.

Ground rules
------------
As in Jacobson's geometry-processing assignments, each exercise names the geomlib
routines its answer may not call: its own routine, and whatever computes the answer
for it (``exercise(..., forbid=("lessons.laplace.laplacian", ...))``, dotted names
inside geomlib, a class standing for all its methods). While the learner's function
runs, a profile hook watches for a call of any of them (through a lambda, a helper,
a cache or another geomlib routine that calls it); one such call fails the check with
no points, naming the routine. ``check.NAME.rules`` is the sentence the notebook and
the grading guide print. ``reveal(fn, check.NAME)`` shows geomlib's own routine only
once ``fn`` passes, so the page a student is handed never shows the answer. Warnings raised by the
learner's function while nbgrader grades are silenced: nbgrader scores a grade
cell that wrote to stderr as failed.
"""

import contextlib
import functools
import html
import importlib
import inspect
import sys
import textwrap
import warnings

import numpy as np
import scipy.sparse as sp

from ..notebook import graded, strict_claims

__all__ = [
    "CheckResult",
    "CheckFailed",
    "Mistake",
    "exercise",
    "call",
    "matrix_pair",
    "vector",
    "close",
    "use",
    "reveal",
]


#: the width of the lines of a failed check's message under its grade cell
TRACEBACK_WIDTH = 80


class CheckFailed(AssertionError):
    """A function failed its check while nbgrader grades, or a written one under the strict test run."""

    def _render_traceback_(self):
        # IPython shows these lines instead of the frames: under the grade cell a reader
        # (and nbgrader's feedback page) gets the diagnosis, not geomlib's insides; in lines
        # short enough for `nbgrader validate`, which cuts every line at 87 characters
        return textwrap.wrap(f"{type(self).__name__}: {self}", width=TRACEBACK_WIDTH, subsequent_indent="  ")


class Mistake(Exception):
    """Raised inside a check: ``diagnosis`` names the mistake, ``hint`` says how to fix it.

    ``typical=False`` marks a diagnosis that can only say *that* something is wrong (a
    catch-all "differs from", a wrong shape or type), not which typical mistake it is:
    no partial credit under nbgrader.
    """

    def __init__(self, diagnosis, hint="", typical=True):
        super().__init__(diagnosis)
        self.diagnosis, self.hint, self.typical = diagnosis, hint, typical


class _NotWritten(Exception):
    pass


class CheckResult:
    """Outcome of one exercise check.

    Attributes
    ----------
    name : str       the exercise
    passed : bool
    message : str    what was checked (passed) or the diagnosis, hint and what to reread
    written : bool   False for a stub (the function raises NotImplementedError)
    partial : bool   passed, or failed by a typical mistake the check names (partial credit)
    """

    def __init__(self, name, passed, message, written=True, partial=None):
        self.name, self.passed, self.message = name, bool(passed), message
        self.written = bool(written)
        self.partial = self.passed if partial is None else bool(partial)

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

    def _ipython_display_(self):
        # shown as display data, not as the cell's result: nbgrader would try to read a
        # grade cell's result as its partial score
        from IPython.display import display

        display({"text/plain": repr(self), "text/html": self._repr_html_()}, raw=True)


def _resolve(dotted):
    """The object a dotted name inside geomlib stands for ("lessons.laplace.laplacian")."""
    module, _, name = dotted.rpartition(".")
    return getattr(importlib.import_module(f"geomlib.{module}"), name)


def _entry_points(dotted):
    """{code object or id of a callable: public name} by which a call of ``dotted`` shows in a profile."""
    target = _resolve(dotted)
    members = [m for m in vars(target).values()] if isinstance(target, type) else [target]
    found = {}
    for member in members:
        f = member.fget if isinstance(member, property) else getattr(member, "__func__", member)
        if not callable(f):
            continue
        found[id(f)] = dotted  # a C-level wrapper (functools.lru_cache) shows as a "c_call" of itself
        code = getattr(inspect.unwrap(f), "__code__", None)
        if code is not None:
            found[code] = dotted
    return found


class _Rules:
    """The ground rules of one exercise: the geomlib routines its answer may not call."""

    def __init__(self, forbid, own, allow=()):
        self.forbid, self.own, self.allow = tuple(forbid), tuple(own), tuple(allow)
        self._watch = None

    def watch(self):
        if self._watch is None:  # resolved on first use: a check module imports no lesson it forbids
            self._watch = {}
            for dotted in self.forbid:
                self._watch.update(_entry_points(dotted))
        return self._watch

    def sentence(self):
        if not self.forbid:
            return "Any geomlib routine may be used."
        names = ", ".join(f"`{_public(d)}`" for d in self.forbid)
        tools = "numpy, scipy or sympy"
        if self.allow:
            tools += " and geomlib's " + ", ".join(f"`{_public(d)}`" for d in self.allow)
        return f"Ground rules: write it yourself with {tools}; do not call geomlib's {names}."

    def refusal(self, dotted):
        why = (
            "which this exercise asks you to write"
            if dotted in self.own
            else "which computes this exercise's answer for you"
        )
        return Mistake(
            f"the function calls geomlib's `{_public(dotted)}`, {why}, so it earns no points",
            self.sentence().rstrip("."),
            typical=False,
        )


def _public(dotted):
    return dotted.rpartition(".")[2]


_RULES = [None]  # the rules of the exercise being checked (checks run one at a time)


@contextlib.contextmanager
def _watching(watch, hits):
    """Record the first forbidden routine entered while the block runs (sys.setprofile)."""

    def profile(frame, event, arg):
        if hits:
            return
        if event == "call":
            name = watch.get(frame.f_code)
        elif event == "c_call":
            name = watch.get(id(arg))
        else:
            return
        if name is not None:
            hits.append(name)

    previous = sys.getprofile()
    sys.setprofile(profile)
    try:
        yield
    finally:
        sys.setprofile(previous)


def call(fn, *args):
    """Call the learner's function under the exercise's ground rules; turn its exceptions into a diagnosis."""
    rules, hits = _RULES[0], []
    try:
        if rules is not None and rules.forbid:
            with _watching(rules.watch(), hits):
                out = fn(*args)
        else:
            out = fn(*args)
    except NotImplementedError as exc:
        if hits:
            raise rules.refusal(hits[0]) from None
        raise _NotWritten(str(exc)) from None
    except Mistake:
        raise
    except Exception as exc:  # the learner's code may raise anything; name it
        if hits:
            raise rules.refusal(hits[0]) from None
        raise Mistake(
            f"the function raised {type(exc).__name__}: {exc}",
            "run it on the small example in the cell above and read the traceback",
            typical=False,
        ) from None
    if hits:
        raise rules.refusal(hits[0])
    return out


def _dense(A):
    return A.toarray() if sp.issparse(A) else np.asarray(A)


def matrix_pair(out, n):
    """Check that ``out`` is a pair (M, C) of n x n matrices; return them dense as float arrays."""
    if not isinstance(out, tuple) or len(out) != 2:
        raise Mistake(
            f"the function returned {type(out).__name__}, not the pair (M, C)",
            "end with `return M, C`, M the diagonal mass matrix and C the weight matrix",
            typical=False,
        )
    M, C = (_dense(A) for A in out)
    for name, A in (("M", M), ("C", C)):
        if A.shape == (n,) and name == "M":
            raise Mistake("M is a vector, not a matrix", "return the diagonal matrix scipy.sparse.diags(areas)")
        if A.shape != (n, n):
            raise Mistake(
                f"{name} has shape {A.shape}, expected ({n}, {n}) for a mesh with {n} vertices",
                "one row and one column per vertex",
                typical=False,
            )
    return M.astype(float), C.astype(float)


def vector(out, n, what="the function"):
    """Check that ``out`` is a length-n vector of numbers; return it as a float array."""
    x = np.asarray(out, dtype=float) if not sp.issparse(out) else _dense(out).astype(float)
    if x.shape not in ((n,), (n, 1), (1, n)):
        raise Mistake(
            f"{what} returned shape {x.shape}, expected ({n},): one value per vertex",
            "return a flat numpy array with one entry per vertex",
            typical=False,
        )
    return x.reshape(n)


def close(a, b, rtol=1e-8, atol=1e-10):
    """Whether two arrays agree (shapes must match)."""
    a, b = _dense(a), _dense(b)
    return a.shape == b.shape and np.allclose(a, b, rtol=rtol, atol=atol)


@contextlib.contextmanager
def _quiet_while_graded():
    with warnings.catch_warnings():
        if graded():
            warnings.simplefilter("ignore")
        yield


def _enforce(result):
    """``result``, or CheckFailed with its message: for any failure while nbgrader grades,
    for a written function's failure under the strict test run."""
    if not result.passed and (graded() or (strict_claims() and result.written)):
        raise CheckFailed(f"{result.name}: {result.message}")
    return result


def exercise(name, reread, forbid=(), own=None, allow=()):
    """Decorator making a check body into ``check(fn) -> CheckResult`` (see the module docstring).

    ``forbid``: dotted names inside geomlib of the routines the answer may not call;
    ``own``: those of them that are the exercise's own routine, revealed by ``reveal``
    (default: the first); ``allow``: geomlib routines the exercise hands the student
    (named in the ground rules' sentence; any routine not forbidden may be called).
    """
    overlap = set(forbid) & set(allow)
    if overlap:
        raise ValueError(f"exercise {name}: {sorted(overlap)} both forbidden and allowed")
    rules = _Rules(forbid, forbid[:1] if own is None else own, allow)

    def wrap(body):
        def evaluate(fn):
            """The CheckResult of ``fn``; never raises."""
            try:
                _RULES[0] = rules
                with _quiet_while_graded():
                    checked = body(fn)
            except _NotWritten as exc:
                detail = f" ({exc})" if str(exc) else ""
                message = (
                    f"not written yet: the function raises NotImplementedError{detail}. Reread {reread} and fill it in."
                )
                return CheckResult(name, False, message, written=False)
            except Mistake as m:
                message = f"{m.diagnosis}." + (f" Hint: {m.hint}." if m.hint else "") + f" Reread {reread}."
                return CheckResult(name, False, message, partial=m.typical)
            finally:
                _RULES[0] = None
            return CheckResult(name, True, "checked on " + ", ".join(checked) + ".")

        @functools.wraps(body)
        def check(fn):
            return _enforce(evaluate(fn))

        def partial_credit(fn):
            """Partial credit: ``fn`` is right, or the first thing wrong is a typical mistake the check names."""
            result = evaluate(fn)
            if result.passed:
                message = "earned: the function passes its check."
            elif result.partial:
                message = "earned: what is wrong is a typical mistake, named by the check above."
            elif not result.written:
                message = result.message
            else:
                message = f"not earned: the check cannot name what is wrong. {result.message}"
            return _enforce(CheckResult(f"{name}, partial credit", result.partial, message, written=result.written))

        check.exercise, check.reread = name, reread
        check.forbid, check.own, check.allow, check.rules = rules.forbid, rules.own, rules.allow, rules.sentence()
        check.evaluate, check.partial_credit = evaluate, partial_credit
        return check

    return wrap


def use(fn, check, reference):
    """The learner's ``fn`` when it passes ``check``, else ``reference``, saying which.

    Lets the cells after an unfinished exercise run on geomlib's own function.
    """
    result = check.evaluate(fn)
    if result.passed:
        print(f"Using your {fn.__name__} (its check passed).")
        return fn
    print(
        f"Your {getattr(fn, '__name__', 'function')} has not passed its check yet; "
        f"the cells below use geomlib's {reference.__module__}.{reference.__name__}."
    )
    return reference


def reveal(fn, check):
    """geomlib's own routine for an exercise, shown once the learner's ``fn`` passes ``check``.

    Placed after an exercise: the solution version (whose answer passes) shows the
    routine to compare with; a released assignment shows it only once the student's
    own function passes, so the page a student is handed never holds the answer.
    """
    from IPython.display import display

    from ..notebook import show_source

    result = check.evaluate(fn)
    if result.passed:
        print(f"Your {getattr(fn, '__name__', 'function')} passes its check. geomlib's own, to compare with yours:")
        for dotted in check.own[1:]:
            display(show_source(_resolve(dotted)))
        return show_source(_resolve(check.own[0]))
    print(
        f"geomlib's own {_public(check.own[0])} is shown here once your "
        f"{getattr(fn, '__name__', 'function')} passes its check above: write yours first."
    )
    return None
