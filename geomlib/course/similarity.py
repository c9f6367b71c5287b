"""Submissions that look copied: near-identical pairs of students, and copies of the answer.

Each exercise's code, as each student wrote it in the exercise's solution cell, is compared
by copydetect (a maintained winnowing detector in the manner of MOSS: it tokenises the code,
so renamed variables, comments and spacing do not hide a copy) against every other
student's and against two references: the solution notebook's answer (the course's
``source/`` version) and geomlib's own routine for the exercise. The released stub is
boilerplate: what every student was handed matches nobody. A student who left the stub
is compared with no one.

A pair is flagged when each of the two answers is at least :data:`NEAR_IDENTICAL` covered by
the other; a copy when the answer is at least :data:`COPIED` covered by a reference (however
much of the reference it takes: geomlib's routine carries checks a copy leaves out).
"""

import ast
import importlib
import inspect
import re
import tempfile
import textwrap
from pathlib import Path

#: share of each answer's tokens found in the other above which two students' answers are flagged
NEAR_IDENTICAL = 0.9
#: share of an answer's tokens found in a reference above which it is flagged as a copy of it
#: (lower: a copier rewrites the helpers the ground rules refuse, such as geomlib's edge table;
#: honest answers share at most about a fifth of their code with a reference)
COPIED = 0.5
#: copydetect's noise threshold (characters of tokenised code): matches shorter than this are ignored
NOISE = 30


def _normalised(source):
    return re.sub(r"\s+", " ", source).strip()


def _without_docstrings(source):
    """A function's source with its docstrings' lines left out (what a student would copy)."""
    source = textwrap.dedent(source)
    drop = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and ast.get_docstring(node) is not None:
            drop.update(range(node.body[0].lineno, node.body[0].end_lineno + 1))
    return "\n".join(line for k, line in enumerate(source.splitlines(), 1) if k not in drop)


def _called_geomlib_functions(fn):
    """The geomlib functions ``fn`` calls by a plain name (its helpers that do the work)."""
    found = []
    for node in ast.walk(ast.parse(textwrap.dedent(inspect.getsource(fn)))):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            target = getattr(inspect.getmodule(fn), node.func.id, None)
            if inspect.isfunction(target) and target.__module__.startswith("geomlib.") and target not in found:
                found.append(target)
    return found


def geomlib_source(check_fn):
    """The code of geomlib's own routines of an exercise (``check.NAME.own``) and of the geomlib
    functions they call (a thin routine hands its work to one), docstrings left out; "" if none."""
    parts = []
    for dotted in getattr(check_fn, "own", ()):
        module, _, name = dotted.rpartition(".")
        try:
            fn = getattr(importlib.import_module(f"geomlib.{module}"), name)
            for f in [fn, *_called_geomlib_functions(fn)]:
                parts.append(_without_docstrings(inspect.getsource(f)))
        except (ImportError, AttributeError, OSError, TypeError):
            continue
    return "\n\n".join(parts)


def own_lines(code, stub):
    """The lines of an answer that are its own: not lines of the released stub (the def line,
    the docstring), nor imports (whose module paths would weigh as much as the code)."""
    handed = {line.strip() for line in stub.splitlines() if line.strip()}
    return "\n".join(
        line
        for line in code.splitlines()
        if line.strip() not in handed and not re.match(r"\s*(import|from)\s+\S+", line)
    )


def similar_answers(answers, references, stub):
    """Flags of one exercise.

    ``answers``: {student: code}; ``references``: {label: code} (the solution notebook's,
    geomlib's); ``stub``: the released cell. Returns a list of (student, flag, detail):
    ``(student, "copy of LABEL", "97% of the code shared")`` and
    ``(student, "near-identical pair", "with OTHER: 95% of the code shared")`` (once for each
    student of a pair).
    """
    from copydetect import CopyDetector

    written = {s: code for s, code in answers.items() if _normalised(code) != _normalised(stub)}
    if not written:
        return []
    with tempfile.TemporaryDirectory(prefix="geomlib-similarity-") as scratch:
        scratch = Path(scratch)
        for folder in ("students", "references", "stub"):
            (scratch / folder).mkdir()
        (scratch / "stub" / "stub.py").write_text(stub)
        files = {}
        for k, (student, code) in enumerate(sorted(written.items())):
            path = scratch / "students" / f"s{k}.py"
            path.write_text(own_lines(code, stub))
            files[str(path)] = ("student", student)
        for k, (label, code) in enumerate(sorted(references.items())):
            if code.strip():
                path = scratch / "references" / f"r{k}.py"
                path.write_text(own_lines(code, stub))
                files[str(path)] = ("reference", label)
        detector = CopyDetector(
            test_dirs=[str(scratch / "students")],
            ref_dirs=[str(scratch / "students"), str(scratch / "references")],
            boilerplate_dirs=[str(scratch / "stub")],
            extensions=["py"],
            noise_t=NOISE,
            guarantee_t=NOISE,
            display_t=0.0,
            autoopen=False,
            silent=True,
        )
        detector.run()
        flags = []
        for i, test in enumerate(detector.test_files):
            for j, ref in enumerate(detector.ref_files):
                mine, theirs = detector.similarity_matrix[i, j]
                _, student = files[test]
                kind, other = files[ref]
                # a copy of a reference: the student's code is the reference's (however much of the
                # reference's file it takes); a pair: each of the two is the other's
                share = float(mine if kind == "reference" else min(mine, theirs))
                if test == ref or share < (COPIED if kind == "reference" else NEAR_IDENTICAL):
                    continue
                if kind == "reference":
                    flags.append((student, f"copy of {other}", f"{share:.0%} of the code shared"))
                else:
                    flags.append((student, "near-identical pair", f"with {other}: {share:.0%} of the code shared"))
        return sorted(set(flags))
