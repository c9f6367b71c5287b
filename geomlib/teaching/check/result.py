"""What an exercise check returns, and the small vocabulary checks are written in.

A check runs a learner's function on small cases with known answers (one
triangle, a tetrahedron, a regular grid, a sphere, the ellipsoid) and stops at
the first thing that is wrong, named as the typical mistake it is ("the sign
is flipped") with a one-line hint and the derivation to reread.

Writing a check: the catalogue of typical mistakes is data, read by one matcher
(``check.catalogue``: its docstring is the guide, with a complete example)::

    @exercise("uniform_laplacian", reread="section 2 · The uniform Laplacian, derived", forbid=(...))
    def uniform_laplacian(fn):
        cases = uniform_cases(case_rng())                  # placed anew each run
        answers = run(fn, cases, matrix_pair)              # [(M, C), ...], or a Mistake for a wrong shape
        judge(C_MISTAKES, cases, [C for _, C in answers], right=lambda c: c.C)
        return [c.label for c in cases]                    # what was checked

``exercise`` turns the body into a function ``fn -> CheckResult``:

* ``Mistake`` raised by the body -> ``passed=False`` with its diagnosis;
* ``NotImplementedError`` from the learner's function (the assignment's stub)
  -> ``passed=False``, "not written yet";
* any other exception from the learner's function -> ``passed=False`` naming it;
* an array handed to the learner's function and changed by it -> ``passed=False``, "the
  function changed its input V in place" (``call`` compares every array argument after
  each call; V is the learner's own name for it);
* the body returning -> ``passed=True``, listing what was checked.

Cases that vary from run to run
-------------------------------
``case_rng()`` is the generator a check places its cases with (a random similarity,
a small jitter: ``check.meshes.placed``), from a fresh seed each time the check runs,
so that answers learned from one run's inputs cannot be replayed. A check that drew it
ends its message with the seed ("Cases seed 4182."); ``check.NAME(fn, seed=4182)`` or
the environment variable ``GEOMLIB_CHECK_SEED`` runs those cases again. A right answer
passes whatever the seed.

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

While graded, a check decides each function once: the first verdict on a function (its
grade cell's) is the one its partial-credit cell, ``reveal`` and ``use`` read, as the
grading judge derives partial credit from its one verdict per exercise; a reader's run
draws fresh cases at every call.

Ground rules
------------
The ground rules are an allow-list (``fence``): an answer may use numpy and scipy
(``tools``; sympy in 02) and the geomlib routines its exercise hands it
(``exercise(..., allow=("lessons.curvature.boundary_mask",))``); a call into any other
geomlib routine or a geometry library (libigl, trimesh, ...) fails the check with no
points, naming the routine. ``forbid`` names the routines that would compute the answer
(quoted in the rules' sentence), ``own`` the exercise's own routine. ``check.NAME.rules``
is the sentence the notebook and the grading guide print. ``reveal(fn, check.NAME)``
shows geomlib's own routine only once ``fn`` passes, so the page a student is handed
never shows the answer. Warnings raised by the learner's function while nbgrader grades
are silenced: nbgrader scores a grade cell that wrote to stderr as failed.

Where the points are decided
----------------------------
In the notebook the learner's function runs in the learner's kernel, so the check there
(a profile hook in this thread and the threads it starts, an audit hook refusing
``sys.setprofile``/``sys.settrace``, tripwires on libigl's compiled routines) is the
student's interactive check: fast, with the same diagnoses, but code in the kernel can
replace the check, its module or numpy. Under nbgrader the points are decided out of the
kernel's reach: the preprocessor ``geomlib.course.grading.JudgeExercises`` runs in
nbgrader's process before the kernel starts and hands each exercise to ``judge``, a fresh process holding the
check and its reference answers, which calls the student's function in a ``sandbox``
process through a pipe carrying plain data (arrays, sparse matrices as their components,
sympy as its srepr). The sandbox runs only the notebook's imports and the solution cells,
behind a fence the student's code cannot switch off (an audit hook ends the process on a
forbidden entry, thread, process, setprofile or compile). ``copies`` flags a function whose
syntax tree, names aside, is geomlib's routine (no points) or the solution notebook's
(flagged for the grader). See docs/grading.md.
"""

import contextlib
import functools
import html
import inspect
import os
import secrets
import sys
import textwrap
import threading
import warnings

import numpy as np
import scipy.sparse as sp

from ..notebook import graded, strict_claims
from .fence import GEOMETRY_LIBRARIES, Fence, cold_caches, resolve, untrip

__all__ = [
    "CheckResult",
    "CheckFailed",
    "Mistake",
    "exercise",
    "call",
    "case_rng",
    "close",
    "use",
    "reveal",
    "earlier",
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
    mark : str       the verdict's word: "passed" / "not yet" for a check; "earned" / "not earned"
                     for partial credit, whose point a named mistake earns while its check says "not yet"
    """

    def __init__(self, name, passed, message, written=True, partial=None, mark=None):
        self.name, self.passed, self.message = name, bool(passed), message
        self.written = bool(written)
        self.partial = self.passed if partial is None else bool(partial)
        self.mark = mark or ("passed" if self.passed else "not yet")

    def __bool__(self):
        return self.passed

    def __repr__(self):
        return f"{self.name}: {self.mark}. {self.message}"

    @property
    def said(self):
        """The verdict as grading states it: ``NAME: MESSAGE`` for a check (a failure is its
        diagnosis), ``NAME, partial credit: earned. MESSAGE`` or ``... not earned. ...`` for
        partial credit, so that a grader reads a named mistake's point as earned, not as a pass."""
        plain = self.mark in ("passed", "not yet")
        return f"{self.name}: {self.message}" if plain else f"{self.name}: {self.mark}. {self.message}"

    def _repr_html_(self):
        colour, sign = ("#1a7f37", "✔") if self.passed else ("#b35900", "✘")
        return (
            f'<div class="geomlib-check" style="border-left:4px solid {colour};padding:0.3em 0.8em">'
            f'<b>{html.escape(self.name)}</b>: <b style="color:{colour}">{sign} {self.mark}</b>. '
            f"{html.escape(self.message)}</div>"
        )

    def _ipython_display_(self):
        # shown as display data, not as the cell's result: nbgrader would try to read a
        # grade cell's result as its partial score
        from IPython.display import display

        display({"text/plain": repr(self), "text/html": self._repr_html_()}, raw=True)


class Refused(Exception):
    """The learner's function entered fenced code (``name``) or did what grading refuses (``why``)."""

    def __init__(self, name, why=""):
        super().__init__(name)
        self.name, self.why = name, why


class _Rules:
    """The ground rules of one exercise: an allow-list (the module docstring of ``fence``)."""

    def __init__(self, forbid, own, allow=(), tools=("numpy", "scipy"), yours=()):
        self.forbid, self.own, self.allow, self.tools = tuple(forbid), tuple(own), tuple(allow), tuple(tools)
        self.yours = tuple(yours)
        self.fence = Fence(self.allow)

    def sentence(self):
        tools = list(self.tools)
        if self.allow:
            tools[-1:] = [tools[-1], "geomlib's " + _listed([f"`{_public(d)}`" for d in self.allow])]
        listed = _listed(tools) + (", and your own " + _listed([f"`{n}`" for n in self.yours]) if self.yours else "")
        return f"Ground rules: {listed} only: no other geomlib routine, geometry library or copied code."

    def refusal(self, name, why=""):
        if why:
            diagnosis = f"the function {why}; grading refuses it, so it earns no points"
        elif name.startswith("geomlib's") and name.split("`")[1] in {_public(d) for d in self.own}:
            diagnosis = f"the function calls {name}, which this exercise asks you to write, so it earns no points"
        elif name.startswith("geomlib's"):
            diagnosis = f"the function calls {name}, which this exercise does not hand you, so it earns no points"
        else:
            diagnosis = f"the function calls {name}: a geometry library computes it for you, so it earns no points"
        return Mistake(diagnosis, self.sentence().rstrip("."), typical=False)


def _public(dotted):
    return dotted.rpartition(".")[2]


def _listed(words):
    """'a', 'a and b', 'a, b and c'."""
    return ", ".join(words[:-1]) + (" and " if len(words) > 1 else "") + words[-1]


_RULES = [None]  # the rules of the exercise being checked (checks run one at a time)
_WATCHED = [None]  # while the learner's function runs in this process: the list its refusals go to
_SANDBOXED = [False]  # in the grading judge's process: every learner's function runs in a sandbox, fenced there


def sandboxed_calls():
    """Say that this process is the grading judge's, where every learner's function is a ``judge.Remote``
    running in a sandbox behind the sandbox's own fence: ``call`` arms no watcher here, which would
    watch only the judge's code (and empty geomlib's caches, which the checks' references use)."""
    _SANDBOXED[0] = True


def _audit(event, args):
    """While the learner's function runs, refuse switching the watcher off and importing a geometry
    library (sys.addaudithook: installed for good, idle between checks)."""
    hits = _WATCHED[0]
    if hits is None:
        return
    if event in ("sys.setprofile", "sys.settrace") and sys._getframe(1).f_code.co_filename != threading.__file__:
        hits.append(Refused(event, f"calls {event}, which would switch the check's watcher off"))
        raise RuntimeError(f"{event} is refused while an exercise is checked")
    if event == "import" and args[0].partition(".")[0] in GEOMETRY_LIBRARIES:
        hits.append(Refused(args[0], f"imports {args[0]}, a geometry library"))
        raise ImportError(f"{args[0]} is refused while an exercise is checked")


sys.addaudithook(_audit)


@contextlib.contextmanager
def _watching(fence, hits, namespaces=()):
    """Record the first entry into fenced code while the block runs, in this thread and the threads
    it starts (sys.setprofile, threading.setprofile); wrap the geometry libraries' compiled routines."""

    def on_hit(name):
        if not hits:
            hits.append(Refused(name))

    profile = fence.profile(on_hit)
    cold_caches()
    swapped = fence.tripwires(namespaces, on_hit)
    previous = sys.getprofile()
    sys.setprofile(profile)
    threading.setprofile(profile)
    _WATCHED[0] = hits
    try:
        yield
    finally:
        _WATCHED[0] = None
        if threading.getprofile() is not profile and not hits:
            hits.append(Refused("threading.setprofile", "calls threading.setprofile, which would unwatch its threads"))
        threading.setprofile(None)
        sys.setprofile(previous)
        untrip(swapped)


def call(fn, *args):
    """Call the learner's function under the exercise's ground rules; turn its exceptions into a diagnosis,
    and an array argument it changed in place into the mistake it is."""
    rules, hits, before = _RULES[0], [], [_dense(a).copy() if _is_array(a) else None for a in args]
    try:
        if rules is not None and not _SANDBOXED[0]:
            with _watching(rules.fence, hits, [getattr(fn, "__globals__", {})]):
                out = fn(*args)
        else:
            out = fn(*args)
    except Refused as exc:  # reported by the grading sandbox
        raise rules.refusal(exc.name, exc.why) from None
    except NotImplementedError as exc:
        if hits:
            raise rules.refusal(hits[0].name, hits[0].why) from None
        raise _NotWritten(str(exc)) from None
    except Mistake:
        raise
    except Exception as exc:  # the learner's code may raise anything; name it
        if hits:
            raise rules.refusal(hits[0].name, hits[0].why) from None
        raise Mistake(
            f"the function raised {getattr(exc, 'kind', type(exc).__name__)}: {exc}",
            "run it on the small example in the cell above and read the traceback",
            typical=False,
        ) from None
    if hits:
        raise rules.refusal(hits[0].name, hits[0].why)
    for k, (a, kept) in enumerate(zip(args, before)):
        if kept is not None and not np.array_equal(_dense(a), kept, equal_nan=kept.dtype.kind in "fc"):
            name = _parameter(fn, k)
            raise Mistake(
                f"the function changed its input {name} in place",
                f"work on a copy ({name} = {name}.copy()) or build a new array: the caller's {name} must stay as it was",
            )
    return out


def _is_array(a):
    return isinstance(a, np.ndarray) or sp.issparse(a)


def _parameter(fn, k):
    """The name of the learner's k-th positional parameter (``V``), or "argument k + 1"."""
    try:
        names = [
            p.name
            for p in inspect.signature(fn).parameters.values()
            if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)
        ]
    except (TypeError, ValueError):
        names = []
    return names[k] if k < len(names) else f"argument {k + 1}"


SEED_VARIABLE = "GEOMLIB_CHECK_SEED"
_SEED = {"asked": None, "used": None}  # of the check being run (checks run one at a time)


def case_rng():
    """The numpy Generator of the running check's cases: one seed per check run (see the module docstring)."""
    if _SEED["used"] is None:
        asked = _SEED["asked"] if _SEED["asked"] is not None else os.environ.get(SEED_VARIABLE, "")
        _SEED["used"] = int(asked) if str(asked).strip() else secrets.randbelow(1_000_000)
    return np.random.default_rng(_SEED["used"])


def _dense(A):
    return A.toarray() if sp.issparse(A) else np.asarray(A)


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
        raise CheckFailed(result.said)
    return result


def _seed_said():
    return "" if _SEED["used"] is None else f" Cases seed {_SEED['used']}."


def exercise(name, reread, forbid=(), own=None, allow=(), tools=("numpy", "scipy"), yours=()):
    """Decorator making a check body into ``check(fn) -> CheckResult`` (see the module docstring).

    The ground rules are an allow-list: the answer may use ``tools`` and the geomlib
    routines ``allow`` names (dotted names inside geomlib); any other geomlib routine or a
    geometry library is refused. ``forbid``: the routines that would compute the answer,
    named in the rules' sentence; ``own``: those that are the exercise's own routine,
    revealed by ``reveal`` (default: the first of ``forbid``); ``yours``: the names of the
    learner's routines of earlier exercises the answer builds on (``earlier`` looks them up).
    """
    overlap = set(forbid) & set(allow)
    if overlap:
        raise ValueError(f"exercise {name}: {sorted(overlap)} both forbidden and allowed")
    rules = _Rules(forbid, forbid[:1] if own is None else own, allow, tools, yours)

    def wrap(body):
        decided = {}  # while graded: id(fn) -> (fn, its CheckResult), the first verdict on each function

        def evaluate(fn, seed=None):
            """The CheckResult of ``fn`` (its cases drawn with ``seed``, default a fresh one); never raises.
            While graded, a function is decided once (module docstring)."""
            if seed is not None or not graded():
                return decide(fn, seed)
            if id(fn) not in decided or decided[id(fn)][0] is not fn:
                decided[id(fn)] = fn, decide(fn, seed)
            return decided[id(fn)][1]

        def decide(fn, seed):
            try:
                _RULES[0] = rules
                _SEED.update(asked=seed, used=None)
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
                return CheckResult(name, False, message + _seed_said(), partial=m.typical)
            except Exception as exc:  # what came back could not be read as an answer: no points, never a crash
                message = (
                    f"what the function returned could not be read as an answer ({type(exc).__name__}: {exc}). "
                    f"Hint: return what the exercise asks for, of the shape it states. Reread {reread}."
                )
                return CheckResult(name, False, message + _seed_said(), partial=False)
            finally:
                _RULES[0] = None
            return CheckResult(name, True, "checked on " + ", ".join(checked) + "." + _seed_said())

        @functools.wraps(body)
        def check(fn, seed=None):
            return _enforce(evaluate(fn, seed))

        def partial_credit(fn, seed=None):
            """Partial credit: ``fn`` is right, or the first thing wrong is a typical mistake the check names."""
            return _enforce(credit(evaluate(fn, seed)))

        check.exercise, check.reread = name, reread
        check.forbid, check.own, check.allow, check.rules = rules.forbid, rules.own, rules.allow, rules.sentence()
        check.yours = rules.yours
        check.evaluate, check.partial_credit = evaluate, partial_credit
        return check

    return wrap


def earlier(fn, name, *args):
    """What the learner's routine ``name`` of an earlier exercise returns on ``args``, or None where there is
    none, it is not written or it raises.

    It is looked up where ``fn`` was written: the notebook's namespace (``fn.__globals__``) in
    the kernel, the grading sandbox (``fn.beside(name)``: ``judge.Remote``) under nbgrader. A
    check whose answer calls the learner's earlier routines asks them first, to say which
    exercise to fix rather than blame the new one.
    """
    other = fn.beside(name) if hasattr(fn, "beside") else getattr(fn, "__globals__", {}).get(name)
    if not callable(other):
        return None
    try:
        return call(other, *args)
    except (Mistake, _NotWritten):
        return None


def credit(result):
    """The partial-credit verdict on a check's ``result``: right, or a typical mistake the check names."""
    if result.passed:
        mark, message = "earned", "the function passes its check."
    elif result.partial:
        mark, message = (
            "earned",
            "what is wrong is a typical mistake, named by the check above; its fix earns the check's points.",
        )
    elif not result.written:
        mark, message = "not yet", result.message
    else:
        mark, message = "not earned", f"the check cannot name what is wrong. {result.message}"
    return CheckResult(f"{result.name}, partial credit", result.partial, message, written=result.written, mark=mark)


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
    """Show geomlib's own routine for an exercise once the learner's ``fn`` passes ``check``; returns None.

    It displays what it shows itself, so it can stand anywhere in a cell (not only last).

    Placed after an exercise: the solution version (whose answer passes) shows the
    routine to compare with; a released assignment shows it only once the student's
    own function passes, so the page a student is handed never holds the answer.
    """
    from IPython.display import display

    from ..notebook import show_source

    result = check.evaluate(fn)
    if result.passed:
        print(f"Your {getattr(fn, '__name__', 'function')} passes its check. geomlib's own, to compare with yours:")
        for dotted in check.own:
            display(show_source(resolve(dotted)))
        return None
    print(
        f"geomlib's own {_public(check.own[0])} is shown here once your "
        f"{getattr(fn, '__name__', 'function')} passes its check above: write yours first."
    )
    return None
