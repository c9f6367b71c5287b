"""The grading judge: each exercise's verdict, decided where the student's code cannot reach.

``verdicts(nb, solution=None)`` asks the judge process (``python -I -m
geomlib.teaching.check.judge``, started by the first call and kept for the next notebooks
of the grading run) and returns, for each auto-graded exercise of the notebook
``nb`` (nbformat JSON), ``{"check": (passed, message), "partial_credit": (earned,
message), "copies": [...]}``. The judge process holds the checks and their reference
answers and never runs a line of the student's code: for each exercise a fresh ``sandbox``
process runs the student's import statements and solution cells, and the check gets a
``Remote`` function that calls the student's function there through a pipe, with plain
data (``wire``). The sandboxes are forked by the grading run's one ``Zygote``, kept by the
judge process from notebook to notebook and student to student: it imports what the solution
notebook's import statements name (the lecturer's, never a student's: every later student's
sandbox starts from it) and runs nothing else; without a solution notebook a zygote of the
notebook's own serves it and ends with it. A refusal reported by the sandbox (or its exit
status 3) fails the check with no points, naming what it did. ``copies`` compares the
exercise's functions with geomlib's own code (a copy earns no points) and with the solution
notebook's (flagged for the grader).

The cells after an exercise see ``NAME = use(my_fn, check.X, reference)``: the sandbox binds
NAME to the student's ``my_fn`` when the judge passed X, else to the reference, as ``use``
does in the kernel.
"""

import ast
import atexit
import os
import select
import signal
import socket
import subprocess
import sys
import tempfile

from . import copies
from .result import Refused, credit, sandboxed_calls
from .sandbox import import_statements, names_used
from .wire import decode, encode, receive, send

CALL_TIMEOUT = 600  # seconds a single call of the student's function may take (nbgrader's cells: Execute.timeout)


_JUDGE = {}  # the judge process of this grading run, and its log: one nbgrader process grades notebook after notebook


def verdicts(nb, solution=None, timeout=1800):
    """The judge's verdicts on notebook ``nb`` (module docstring), from the judge process: a fresh one
    the first time, kept for the next notebooks (it holds the checks, never a student's code)."""
    judge = _JUDGE.get("process")
    if judge is None or judge.poll() is not None:
        log = _JUDGE["log"] = tempfile.TemporaryFile()
        judge = _JUDGE["process"] = subprocess.Popen(
            [sys.executable, "-I", "-m", "geomlib.teaching.check.judge"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=log,
            env={k: v for k, v in os.environ.items() if k not in ("NBGRADER_EXECUTION", "GEOMLIB_STRICT_CLAIMS")},
        )
        atexit.register(_end, judge)
    try:
        send(judge.stdin.fileno(), {"notebook": nb, "solution": solution})
        found = receive(judge.stdout.fileno()) if select.select([judge.stdout], [], [], timeout)[0] else None
    except OSError:
        found = None
    if found is None:
        judge.kill()
        judge.wait()
        _JUDGE["log"].seek(0)
        raise RuntimeError(f"the grading judge failed: {_JUDGE['log'].read().decode(errors='replace')[-2000:]}")
    return found


def _end(judge):
    """End the judge process as the grading run ends (its stdin closed, it exits)."""
    judge.stdin.close()
    try:
        judge.wait(timeout=30)
    except subprocess.TimeoutExpired:
        judge.kill()
        judge.wait()


class Zygote:
    """The process that holds the lecturer's imports and forks each exercise's sandbox from there
    (``sandbox.zygote``). Each sandbox is still a process of its own, started from the state a new
    interpreter has after those imports, talking to the judge over pipes of its own; the zygote
    only imports what ``load`` names, forks, and says over its socket which process it forked and
    how that process ended. It never runs a line of a student's notebook."""

    def __init__(self):
        self.control, theirs = socket.socketpair()
        self.process = subprocess.Popen(
            [sys.executable, "-I", "-m", "geomlib.teaching.check.sandbox", str(theirs.fileno())],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            pass_fds=[theirs.fileno()],
            env={k: v for k, v in os.environ.items() if k not in ("NBGRADER_EXECUTION", "GEOMLIB_STRICT_CLAIMS")},
        )
        theirs.close()
        self.loaded = set()

    def alive(self):
        return self.process.poll() is None

    def load(self, statements):
        """Have the zygote run the import ``statements`` (one a line) it has not run yet: every sandbox
        forked after starts with those modules imported."""
        new = [line for line in statements.splitlines() if line not in self.loaded]
        if new:
            try:
                socket.send_fds(self.control, [b"load"], [])
                send(self.control.fileno(), {"imports": new})
            except OSError:
                pass  # the zygote has ended: the next fork says so
            self.loaded.update(new)

    def fork(self):
        """(pid or None, fd writing to the new sandbox's stdin, fd reading its replies)."""
        its_stdin, to_it = os.pipe()
        from_it, its_replies = os.pipe()
        try:
            socket.send_fds(self.control, [b"fork"], [its_stdin, its_replies])
            forked = receive(self.control.fileno())
        except OSError:  # the zygote has ended: the pipes' other ends close with ours
            forked = None
        finally:
            os.close(its_stdin)
            os.close(its_replies)
        return (forked or {}).get("forked"), to_it, from_it

    def ended(self, timeout=30):
        """The exit status of the sandbox forked last (it is killed after ``timeout`` seconds)."""
        if not select.select([self.control], [], [], timeout)[0]:
            return None
        message = receive(self.control.fileno())
        return None if message is None else message["ended"]

    def close(self):
        try:
            socket.send_fds(self.control, [b"bye!"], [])
            self.process.wait(timeout=30)
        except (OSError, subprocess.TimeoutExpired):
            self.process.kill()
            self.process.wait()
        self.control.close()


_ZYGOTE = {}  # the zygote of this grading run: every student's sandboxes fork from it


def run_zygote(statements):
    """The grading run's zygote, holding the lecturer's import ``statements`` (a new one should the last
    have ended). What it holds depends on the solution notebooks alone, never on a student's."""
    zygote = _ZYGOTE.get("zygote")
    if zygote is None or not zygote.alive():
        zygote = _ZYGOTE["zygote"] = Zygote()
    zygote.load(statements)
    return zygote


def close_zygote():
    """End the grading run's zygote (the judge process does so as the run ends)."""
    zygote = _ZYGOTE.pop("zygote", None)
    if zygote is not None:
        zygote.close()


class Sandbox:
    """One exercise's sandbox process, forked by a ``Zygote``, holding the notebook's solution cells."""

    def __init__(self, plan, zygote):
        self.zygote, self.refusal, self.callables, self.status = zygote, None, [], None
        self.pid, self.stdin, self.stdout = zygote.fork()
        try:
            send(self.stdin, plan)
        except OSError:
            pass  # it has ended already: its replies say so
        try:
            self.ready = self.answer()
        except BaseException:
            self._close_pipes()
            raise

    def wait(self):
        """The sandbox process's exit status, once it has ended (killed if it does not end within 30 s)."""
        if self.status is None:
            status = self.zygote.ended() if self.zygote.alive() else None
            if status is None and self.zygote.alive():
                self.kill()
                status = self.zygote.ended()
            self.status = status if status is not None else -signal.SIGKILL
        return self.status

    def kill(self):
        if self.pid is not None:
            try:
                os.kill(self.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass

    def answer(self, timeout=CALL_TIMEOUT):
        """The sandbox's next reply; a refusal raises ``Refused``, an ended process ``Ended``."""
        while True:
            if not select.select([self.stdout], [], [], timeout)[0]:
                self.kill()
                self.wait()
                raise Ended(f"took longer than {timeout} s")
            message = receive(self.stdout)
            if message is None or "callback" not in message:
                break
            self._call_back(message)
        if message is None or "hit" in message:
            status = self.wait()
            if message is not None or status == 3:
                message = message or {"hit": "fenced code", "why": ""}
                self.refusal = Refused(message["hit"], message["why"])
                raise self.refusal
            raise Ended(f"ended its process (exit status {status})")
        return message

    def _call_back(self, message):
        """Answer the sandbox's call of a function the check handed the student's (judged data in, data out)."""
        try:
            args = [decode(a) for a in message["args"]]
            answer = {"ok": encode(self.callables[int(message["callback"])](*args))}
        except Exception as exc:  # noqa: BLE001 - the student's arguments may make the check's helper raise
            answer = {"raised": type(exc).__name__, "message": str(exc)[:500]}
        send(self.stdin, answer)

    def close(self):
        """End the sandbox; the refusal it reported while ending, if any."""
        if self.status is None:
            try:
                send(self.stdin, {"bye": True})
                leftover = receive(self.stdout)
            except OSError:
                leftover = None
            if leftover is not None and "hit" in leftover:
                self.refusal = Refused(leftover["hit"], leftover["why"])
            if self.wait() == 3 and self.refusal is None:
                self.refusal = Refused("fenced code")
        self._close_pipes()
        return self.refusal

    def _close_pipes(self):
        for fd in (self.stdin, self.stdout):
            os.close(fd)


class Ended(Exception):
    """The sandbox ended or hung while the student's function ran."""


class Raised(Exception):
    """The student's function raised; ``kind`` is its exception's type name."""

    def __init__(self, kind, message):
        super().__init__(message)
        self.kind = kind


class Remote:
    """The student's function ``name``, called in the sandbox: ``Remote(box, name)(*args)``."""

    def __init__(self, box, name):
        self.box, self.__name__ = box, name

    def beside(self, name):
        """The student's function ``name`` of the same notebook, called in the same sandbox (``result.earlier``)."""
        return Remote(self.box, name)

    def __call__(self, *args):
        if self.box.refusal is not None:
            raise self.box.refusal
        self.box.callables = []
        sent = [encode(a, self.box.callables) for a in args]
        try:
            send(self.box.stdin, {"call": self.__name__, "args": sent})
        except OSError:
            pass  # the sandbox has ended: its replies say so
        reply = self.box.answer()
        if "raised" in reply:
            if reply["stub"]:
                raise NotImplementedError(reply["message"])
            raise Raised(reply["raised"], reply["message"])
        for mine, theirs in zip(args, reply["args"]):  # what the function did to its inputs, as in the kernel
            _copy_back(mine, decode(theirs))
        return decode(reply["ok"])


def _copy_back(mine, theirs):
    import numpy as np

    if isinstance(mine, np.ndarray) and isinstance(theirs, np.ndarray) and mine.shape == theirs.shape:
        if mine.flags.writeable:
            np.copyto(mine, theirs, casting="unsafe")


def exercises(nb):
    """[(exercise, the function its grade cell checks)] of a notebook, in order."""
    found = []
    for cell in nb["cells"]:
        grade_id = cell.get("metadata", {}).get("nbgrader", {}).get("grade_id", "")
        if grade_id.endswith("_check") and cell["cell_type"] == "code":
            call = ast.parse(_text(cell)).body[0].value
            found.append((grade_id[: -len("_check")], call.args[0].id))
    return found


def solution_cells(nb):
    """{grade id: source} of a notebook's code solution cells."""
    return {
        c["metadata"]["nbgrader"]["grade_id"]: _text(c)
        for c in nb["cells"]
        if c["cell_type"] == "code" and c.get("metadata", {}).get("nbgrader", {}).get("solution")
    }


def bindings(nb):
    """{name: (function, exercise, reference)} of the cells ``name = use(function, check.exercise, reference)``."""
    found = {}
    for cell in nb["cells"]:
        if cell["cell_type"] != "code" or cell.get("metadata", {}).get("nbgrader"):
            continue
        try:
            tree = ast.parse("\n".join(line for line in _text(cell).splitlines() if not line.startswith("%")))
        except SyntaxError:
            continue
        for node in tree.body:
            value = getattr(node, "value", None)
            if (
                isinstance(node, ast.Assign)
                and isinstance(node.targets[0], ast.Name)
                and isinstance(value, ast.Call)
                and getattr(value.func, "id", "") == "use"
                and len(value.args) == 3
                and isinstance(value.args[0], ast.Name)
                and isinstance(value.args[1], ast.Attribute)
            ):
                reference = ast.unparse(value.args[2])
                if all(part.isidentifier() for part in reference.split(".")):
                    found[node.targets[0].id] = (value.args[0].id, value.args[1].attr, reference)
    return found


def _text(cell):
    return cell["source"] if isinstance(cell["source"], str) else "".join(cell["source"])


def needed_imports(nb):
    """The import statements of ``nb`` (one a line) that bind a name its solution cells or ``use`` cells
    read, wherever they are (a reference is imported where it is used); not the notebook's plotting."""
    sources = [_text(c) for c in nb["cells"] if c["cell_type"] == "code" and not c.get("metadata", {}).get("nbgrader")]
    targets = {name.partition(".")[0] for fn, _, reference in bindings(nb).values() for name in (fn, reference)}
    return import_statements(sources, names_used(solution_cells(nb).values()) | targets)


def judge_notebook(nb, solution=None):
    """The verdicts (module docstring), in this process: the judge's side of ``verdicts``.

    The sandboxes fork from the grading run's zygote, which imports what the solution notebook's
    import statements name; each sandbox runs the student's own import statements itself. Without
    a solution notebook, a zygote of this notebook's own, ended with it."""
    from geomlib.teaching import check

    imports = needed_imports(nb)
    cells = solution_cells(nb)
    uses = bindings(nb)
    model = solution_cells(solution) if solution else {}
    lecturers = needed_imports(solution) if solution else None
    found, own = {}, None
    try:
        for exercise, function in exercises(nb):
            checker = getattr(check, exercise, None)
            if checker is None:
                continue
            if lecturers is not None:
                zygote = run_zygote(lecturers)
            elif own is None or not own.alive():  # a new one should a sandbox end it
                zygote = own = Zygote()
                own.load(imports)
            bound = {
                name: ("student", fn) if found.get(ex, {}).get("passed") else ("reference", reference)
                for name, (fn, ex, reference) in uses.items()
                if ex in found
            }
            plan = {"imports": imports, "cells": list(cells.values()), "allow": list(checker.allow), "bindings": bound}
            result = _decide(checker, plan, function, zygote)
            flags = copies.exercise_copies(cells.get(exercise, ""), model.get(exercise, ""))
            copied = [f for f in flags if f["of"] == "geomlib"]
            if copied and result.written:
                result = checker_result(checker, copies.refusal(copied[0]), result)
            partial = credit(result)
            found[exercise] = {
                "passed": result.passed,
                "check": [result.passed, result.said],
                "partial_credit": [partial.passed, partial.said],
                "copies": flags,
            }
    finally:
        if own is not None:
            own.close()
    return found


def checker_result(checker, diagnosis, result):
    """A failed CheckResult of ``checker`` with ``diagnosis`` (no partial credit)."""
    from .result import CheckResult

    return CheckResult(result.name, False, f"{diagnosis} Reread {checker.reread}.", partial=False)


def _decide(checker, plan, function, zygote):
    box = None
    try:
        box = Sandbox(plan, zygote)
        if "raised" in box.ready:
            raise Raised(box.ready["raised"], box.ready["message"])
        result = checker.evaluate(Remote(box, function))
    except (Refused, Raised, Ended) as exc:
        result = checker.evaluate(_failing(exc))
    seen = box.refusal if box is not None else None
    refusal = box.close() if box is not None else None
    if refusal is not None and seen is None:  # reported only as the sandbox ended: it still counts
        result = checker.evaluate(_failing(refusal))
    return result


def _failing(exc):
    """A function that fails the way the sandbox did, for the check to diagnose in its own words."""

    def failing(*args):
        if isinstance(exc, Ended):
            raise Raised("an error in grading", f"the function {exc}")
        if isinstance(exc, Raised) and exc.kind == "NotImplementedError":
            raise NotImplementedError(str(exc))
        raise exc

    return failing


def main():
    sandboxed_calls()
    replies = os.dup(1)
    os.dup2(os.open(os.devnull, os.O_WRONLY), 1)  # what a check prints stays out of the replies
    try:
        while (request := receive(0)) is not None:
            send(replies, judge_notebook(request["notebook"], request.get("solution")))
    finally:
        close_zygote()


if __name__ == "__main__":
    main()
