"""The grading judge: each exercise's verdict, decided where the student's code cannot reach.

``verdicts(nb, solution=None)`` starts a fresh judge process (``python -I -m
geomlib.teaching.check.judge``) and returns, for each auto-graded exercise of the notebook
``nb`` (nbformat JSON), ``{"check": (passed, message), "partial_credit": (earned,
message), "copies": [...]}``. The judge process holds the checks and their reference
answers and never runs a line of the student's code: for each exercise it starts a
``sandbox`` holding the notebook's imports and its solution cells, and hands the check a
``Remote`` function that calls the student's function there through a pipe, with plain
data (``wire``). A refusal reported by the sandbox (or its exit status 3) fails the check
with no points, naming what it did. ``copies`` compares the exercise's functions with
geomlib's own code (a copy earns no points) and with the solution notebook's (flagged for
the grader).

The cells after an exercise see ``NAME = use(my_fn, check.X, reference)``: the sandbox binds
NAME to the student's ``my_fn`` when the judge passed X, else to the reference, as ``use``
does in the kernel.
"""

import ast
import json
import os
import select
import subprocess
import sys

from . import copies
from .result import Refused, credit
from .wire import decode, encode, receive, send

CALL_TIMEOUT = 600  # seconds a single call of the student's function may take (nbgrader's cells: Execute.timeout)


def verdicts(nb, solution=None, timeout=1800):
    """The judge's verdicts on notebook ``nb`` (module docstring), from a fresh process."""
    done = subprocess.run(
        [sys.executable, "-I", "-m", "geomlib.teaching.check.judge"],
        input=json.dumps({"notebook": nb, "solution": solution}),
        capture_output=True,
        text=True,
        timeout=timeout,
        env={k: v for k, v in os.environ.items() if k not in ("NBGRADER_EXECUTION", "GEOMLIB_STRICT_CLAIMS")},
    )
    if done.returncode != 0:
        raise RuntimeError(f"the grading judge failed: {done.stderr[-2000:]}")
    return json.loads(done.stdout.splitlines()[-1])


class Sandbox:
    """A sandbox process holding one notebook's imports and solution cells (``sandbox``)."""

    def __init__(self, plan):
        self.process = subprocess.Popen(
            [sys.executable, "-I", "-m", "geomlib.teaching.check.sandbox"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            env={k: v for k, v in os.environ.items() if k not in ("NBGRADER_EXECUTION", "GEOMLIB_STRICT_CLAIMS")},
        )
        self.refusal, self.callables = None, []
        send(self.process.stdin.fileno(), plan)
        self.ready = self.answer()

    def answer(self, timeout=CALL_TIMEOUT):
        """The sandbox's next reply; a refusal raises ``Refused``, an ended process ``Ended``."""
        fd = self.process.stdout.fileno()
        while True:
            if not select.select([fd], [], [], timeout)[0]:
                self.process.kill()
                raise Ended(f"took longer than {timeout} s")
            message = receive(fd)
            if message is None or "callback" not in message:
                break
            self._call_back(message)
        if message is None or "hit" in message:
            status = self.process.wait()
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
        send(self.process.stdin.fileno(), answer)

    def close(self):
        """End the sandbox; the refusal it reported while ending, if any."""
        if self.process.poll() is None:
            try:
                send(self.process.stdin.fileno(), {"bye": True})
                leftover = receive(self.process.stdout.fileno())
            except OSError:
                leftover = None
            if leftover is not None and "hit" in leftover:
                self.refusal = Refused(leftover["hit"], leftover["why"])
            try:
                status = self.process.wait(timeout=30)
            except subprocess.TimeoutExpired:
                self.process.kill()
                status = self.process.wait()
            if status == 3 and self.refusal is None:
                self.refusal = Refused("fenced code")
        return self.refusal


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

    def __call__(self, *args):
        if self.box.refusal is not None:
            raise self.box.refusal
        self.box.callables = []
        sent = [encode(a, self.box.callables) for a in args]
        send(self.box.process.stdin.fileno(), {"call": self.__name__, "args": sent})
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


def judge_notebook(nb, solution=None):
    """The verdicts (module docstring), in this process: the judge's side of ``verdicts``."""
    from geomlib.teaching import check

    imports = [  # the notebook's import statements, wherever they are (a reference is imported where it is used)
        _text(c) for c in nb["cells"] if c["cell_type"] == "code" and not c.get("metadata", {}).get("nbgrader")
    ]
    cells = solution_cells(nb)
    uses = bindings(nb)
    model = solution_cells(solution) if solution else {}
    found = {}
    for exercise, function in exercises(nb):
        checker = getattr(check, exercise, None)
        if checker is None:
            continue
        bound = {
            name: ("student", fn) if found.get(ex, {}).get("passed") else ("reference", reference)
            for name, (fn, ex, reference) in uses.items()
            if ex in found
        }
        plan = {"imports": imports, "cells": list(cells.values()), "allow": list(checker.allow), "bindings": bound}
        result = _decide(checker, plan, function)
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
    return found


def checker_result(checker, diagnosis, result):
    """A failed CheckResult of ``checker`` with ``diagnosis`` (no partial credit)."""
    from .result import CheckResult

    return CheckResult(result.name, False, f"{diagnosis} Reread {checker.reread}.", partial=False)


def _decide(checker, plan, function):
    box = None
    try:
        box = Sandbox(plan)
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
    request = json.loads(sys.stdin.read())
    out = judge_notebook(request["notebook"], request.get("solution"))
    print(json.dumps(out))


if __name__ == "__main__":
    main()
