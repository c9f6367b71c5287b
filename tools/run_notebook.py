"""Run one notebook with parameters of your choice, outside Jupyter.

    python3 workbook.py run NOTEBOOK NAME=VALUE ...
    python3 workbook.py run 05 STEP_UNIT=length^2 STEP=1e-4 PART=course/smoothing/fandisk_ns.obj

NOTEBOOK is ``05``, ``05_explicit_smoothing`` or its file name. The notebook runs
top to bottom in a fresh kernel (papermill underneath), with the values set in a
cell after its ``parameters`` cell. The executed notebook and an HTML page with its
3D views live, as on the workbook's website (tools/build_site.py), go to
``build/runs/<notebook>-<date>-<time>/``; the page's path is printed.

A VALUE is read as a Python literal (``1e-4``, ``(1.0, 0.7, 0.5)``, ``[2, 3]``,
``{"PLANE": 1e-6, "PART": 1e-4}``, ``None``); anything else is taken as a string, so
paths and unit names need no quotes (``length^2``). A relative path is relative to
the folder the command is run from.

Every parameter's comment in a notebook's ``parameters`` cell ends with its range
or choices in parentheses (papermill shows the comment as the parameter's help),
in one of these forms, which this tool checks values against:

    (0 to 1000)            a number from 0 to 1000; a whole number if the default is one
    (above 0 to below 1.5) "above" and "below" leave an end out; also (above 0),
                           (below 1), (at least 1), (at most 9)
    (any integer)          also (any number)
    ("ell^2" or "length^2")   one of these values; ("x", "y" or "z")
    (a path)               a file name; (a path or None)
    (3 values, each 0.1 to 10)              a tuple or list; also (1 to 6 values, ...),
    (1 to 6 distinct values, each 1 to 7)   (values, ...) of any length, and
    (increasing values, each 0 to 0.1)      "distinct" or "increasing" before "values"
    (above 0 to 1, then -1 to below 0)      a pair, one range per place
    (above 0, or a dict of such values)     one number, or one per name in a dict

A name the notebook does not have, or a value of the wrong kind or out of its range,
gets one sentence listing the notebook's parameters with their ranges (exit status 2);
a notebook that stops (a mesh file it cannot use, for example) gets one sentence with
its message (exit status 1).
"""

import ast
import logging
import math
import re
import sys
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"
RUNS = ROOT / "build" / "runs"


class UsageError(Exception):
    """A command line the tool cannot run: its message is the one sentence the reader sees."""


# ---------------------------------------------------------------------------
# ranges and choices: the parenthesised end of a parameter's comment
# ---------------------------------------------------------------------------


def _number(text):
    value = ast.literal_eval(text.strip())
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{text!r} is not a number")
    return value


def _is_number(value):
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


@dataclass
class Number:
    """A number in a range; ``None`` for an end that is open; ``integer`` for whole numbers only."""

    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    integer: bool = False

    def problem(self, value):
        """Why ``value`` is not allowed, or None."""
        if not _is_number(value):
            return "is not a number"
        if self.integer and not isinstance(value, int):
            return "is not a whole number"
        if self.lo is not None and (value < self.lo or (self.lo_open and value == self.lo)):
            return "is out of range"
        if self.hi is not None and (value > self.hi or (self.hi_open and value == self.hi)):
            return "is out of range"
        return None


@dataclass
class Choice:
    options: tuple

    def problem(self, value):
        return None if value in self.options else "is not one of the choices"


@dataclass
class FilePath:
    none_allowed: bool = False

    def problem(self, value):
        if value is None:
            return None if self.none_allowed else "is not a path"
        return None if isinstance(value, str) and value else "is not a path"


@dataclass
class Sequence:
    """A tuple or list: ``items`` is one range for every element, or one per place (``places``)."""

    items: Number | None = None
    places: tuple = ()
    min_count: int = 1
    max_count: int | None = None
    order: str = ""  # "", "distinct" or "increasing"

    def problem(self, value):
        if not isinstance(value, (tuple, list)):
            return "is not a tuple or list"
        if self.places:
            if len(value) != len(self.places):
                return f"does not have {len(self.places)} values"
            for place, v in zip(self.places, value):
                why = place.problem(v)
                if why:
                    return f"holds {v!r}, which {why}"
            return None
        if len(value) < self.min_count or (self.max_count is not None and len(value) > self.max_count):
            return "has the wrong number of values"
        for v in value:
            why = self.items.problem(v)
            if why:
                return f"holds {v!r}, which {why}"
        if self.order == "distinct" and len(set(value)) != len(value):
            return "has values twice"
        if self.order == "increasing" and any(b <= a for a, b in zip(value, value[1:])):
            return "is not increasing"
        return None


@dataclass
class NumberOrDict:
    """One number, or a dict of them by name (a value per mesh)."""

    number: Number

    def problem(self, value):
        if isinstance(value, dict):
            for key, v in value.items():
                if not isinstance(key, str):
                    return f"has the key {key!r}, which is not a name"
                why = self.number.problem(v)
                if why:
                    return f"holds {key!r}: {v!r}, which {why}"
            return None if value else "is an empty dict"
        return self.number.problem(value)


_NUM = r"(-?[0-9][0-9_.eE+-]*)"
_SCALARS = [
    (re.compile(rf"(above )?{_NUM} to (below )?{_NUM}"), lambda m: (m[2], m[4], bool(m[1]), bool(m[3]))),
    (re.compile(rf"at least {_NUM}"), lambda m: (m[1], None, False, False)),
    (re.compile(rf"above {_NUM}"), lambda m: (m[1], None, True, False)),
    (re.compile(rf"at most {_NUM}"), lambda m: (None, m[1], False, False)),
    (re.compile(rf"below {_NUM}"), lambda m: (None, m[1], False, True)),
]
_SEQUENCE = re.compile(r"(?:(\d+)(?: to (\d+))? )?(?:(distinct|increasing) )?values, each (.+)")
_DICT = ", or a dict of such values"
SPEC = re.compile(r"\(([^()]*)\)\s*$")


def parse_number(text, integer=False):
    """A :class:`Number` from ``text`` such as ``0 to 1000``, ``above 0``, ``any integer``."""
    if text == "any integer":
        return Number(integer=True)
    if text == "any number":
        return Number(integer=integer)
    for pattern, ends in _SCALARS:
        m = pattern.fullmatch(text)
        if m:
            lo, hi, lo_open, hi_open = ends(m)
            lo = None if lo is None else _number(lo)
            hi = None if hi is None else _number(hi)
            if lo is not None and hi is not None and lo > hi:
                raise ValueError(f"the range {text!r} is empty")
            return Number(lo, hi, lo_open, hi_open, integer)
    raise ValueError(f"{text!r} is not a range")


def _whole(value):
    return isinstance(value, int) and not isinstance(value, bool)


def parse_spec(text, default=None):
    """The range or choices written as ``text`` (the inside of the parentheses).

    ``default`` is the parameter's default value where it is a literal: a whole
    number there (or in every place of a tuple) makes the range one of whole numbers.
    """
    if text in ("a path", "a path or None"):
        return FilePath(none_allowed=text.endswith("None"))
    if text.endswith(_DICT):
        return NumberOrDict(parse_number(text[: -len(_DICT)], _whole(default)))
    if text.startswith('"') or " or " in text:
        options = tuple(ast.literal_eval(o) for o in re.split(r",\s*|\s+or\s+", text))
        return Choice(options)
    elements = default if isinstance(default, (tuple, list)) else ()
    integer = bool(elements) and all(_whole(v) for v in elements)
    m = _SEQUENCE.fullmatch(text)
    if m:
        count, most, order, each = m.groups()
        lo = int(count) if count else 1
        hi = int(most) if most else (lo if count else None)
        return Sequence(items=parse_number(each, integer), min_count=lo, max_count=hi, order=order or "")
    if ", then " in text:
        parts = text.split(", then ")
        integers = [_whole(v) for v in elements] if len(elements) == len(parts) else [False] * len(parts)
        return Sequence(places=tuple(parse_number(p, i) for p, i in zip(parts, integers)))
    return parse_number(text, _whole(default))


@dataclass
class Parameter:
    name: str
    default: str  # as written in the notebook
    help: str  # the comment, as papermill shows it
    spec: object

    @property
    def range(self):
        return SPEC.search(self.help)[1]


NOT_A_LITERAL = object()


def read_literal(text):
    try:
        return ast.literal_eval(text.strip())
    except (ValueError, SyntaxError, TypeError, MemoryError, RecursionError):
        return NOT_A_LITERAL


def notebook_parameters(path):
    """The parameters of the notebook at ``path`` as papermill reads them, each with its range.

    Raises ValueError naming a parameter whose comment does not end with a range or
    choices in one of the forms of this module's docstring.
    """
    import papermill

    result = []
    for p in papermill.inspect_notebook(str(path)).values():
        name, default, comment = p["name"], p["default"], p["help"]
        m = SPEC.search(comment)
        if not m:
            raise ValueError(f"{Path(path).name}: the comment of {name} does not end with its range in parentheses")
        try:
            spec = parse_spec(m[1], read_literal(default))
        except (ValueError, SyntaxError) as e:
            raise ValueError(f"{Path(path).name}: the range of {name}, ({m[1]}), cannot be read: {e}") from None
        result.append(Parameter(name, default, comment, spec))
    return result


# ---------------------------------------------------------------------------
# the command line
# ---------------------------------------------------------------------------


def find_notebook(name):
    """The notebook ``name`` means: ``05``, ``05_explicit_smoothing`` or ``05_explicit_smoothing.ipynb``
    (an appendix as ``05a`` or its full name)."""
    notebooks = sorted([*NOTEBOOKS.glob("[0-9][0-9]_*.ipynb"), *NOTEBOOKS.glob("[0-9][0-9]a_*.ipynb")])
    stem = Path(name).name.removesuffix(".ipynb")
    found = [p for p in notebooks if p.stem == stem or p.stem.split("_", 1)[0] == stem]
    if len(found) != 1:
        names = ", ".join(p.stem for p in notebooks)
        raise UsageError(f"There is no notebook {name!r}; the notebooks are {names} (give one as 05, for example).")
    return found[0]


def listing(notebook, parameters):
    """One sentence's end: the notebook's parameters with their ranges."""
    return f"{notebook.stem}'s parameters are " + ", ".join(f"{p.name} ({p.range})" for p in parameters) + "."


def parse_value(text, spec):
    """The value ``text`` stands for: a Python literal, or else the text itself (a path, a unit)."""
    value = read_literal(text)
    if value is NOT_A_LITERAL or (isinstance(spec, FilePath) and not (value is None or isinstance(value, str))):
        return text  # a bare word, or a file name that happens to read as a number
    return value


def read_assignments(notebook, parameters, args, cwd):
    """The values ``args`` (``NAME=VALUE``, ...) give, checked against the notebook's ranges.

    A relative path is made absolute against ``cwd`` (the kernel runs in the notebook's folder, the paths are the reader's).
    Raises UsageError with one sentence when a name or value is not allowed.
    """
    by_name = {p.name: p for p in parameters}
    values = {}
    for arg in args:
        name, eq, text = arg.partition("=")
        name = name.strip()
        if not eq:
            raise UsageError(f"{arg!r} is not NAME=VALUE; {listing(notebook, parameters)}")
        if name not in by_name:
            raise UsageError(f"{notebook.stem} has no parameter {name}; {listing(notebook, parameters)}")
        spec = by_name[name].spec
        value = parse_value(text, spec)
        why = spec.problem(value)
        if why:
            raise UsageError(f"{name}={text} {why} ({by_name[name].range}); {listing(notebook, parameters)}")
        if isinstance(spec, FilePath) and value is not None:
            value = str((Path(cwd) / Path(value).expanduser()).resolve())
        values[name] = value
    return values


def run_folder(notebook):
    stamp = time.strftime("%Y%m%d-%H%M%S")
    folder = RUNS / f"{notebook.stem}-{stamp}"
    n = 2
    while folder.exists():
        folder, n = RUNS / f"{notebook.stem}-{stamp}-{n}", n + 1
    folder.mkdir(parents=True)
    return folder


def for_papermill(value):
    """``value`` with every tuple made a list: papermill writes a list as a list literal,
    but a tuple as the string of its text."""
    if isinstance(value, (tuple, list)):
        return [for_papermill(v) for v in value]
    if isinstance(value, dict):
        return {k: for_papermill(v) for k, v in value.items()}
    return value


def run(notebook, values, timeout=3600):
    """Execute ``notebook`` with ``values`` in a fresh kernel; write the notebook and its page.

    Returns the page's path. Raises UsageError with one sentence when a cell raises.
    """
    import papermill
    from nbclient.exceptions import CellTimeoutError, DeadKernelError
    from papermill.exceptions import PapermillExecutionError

    sys.path.insert(0, str(ROOT / "tools"))
    import build_site

    # what papermill logs about a failure (a timeout, a dead kernel) is in the one sentence below
    logging.getLogger("papermill").addHandler(logging.NullHandler())
    folder = run_folder(notebook)
    executed = folder / notebook.name
    try:
        nb = papermill.execute_notebook(
            notebook,
            executed,
            parameters=for_papermill(values),
            kernel_name="python3",
            cwd=notebook.parent,  # as in Jupyter: the notebook's own folder (03 and 04 read ../benchmarks)
            progress_bar=False,
            execution_timeout=timeout,
            # the kernel's start-up log (a warning about its local TCP sockets) is not the reader's business
            extra_arguments=["--IPKernelApp.log_level=ERROR"],
        )
    except PapermillExecutionError as e:
        message = e.evalue.strip()
        if e.ename != "MeshError":
            message = f"{e.ename}: {message}"
        raise UsageError(f"{notebook.stem} stopped in cell [{e.exec_count}]: {message} (see {executed})") from None
    except (CellTimeoutError, DeadKernelError) as e:
        raise UsageError(f"{notebook.stem} did not finish: {str(e).strip().splitlines()[0]} (see {executed})") from None
    return build_site.write_page(nb, folder, notebook.stem)


def main(argv=None, cwd=None):
    argv = sys.argv[1:] if argv is None else argv
    if not argv or argv[0] in ("-h", "--help"):
        print(__doc__)
        return 0 if argv else 2
    try:
        notebook = find_notebook(argv[0])
        values = read_assignments(notebook, notebook_parameters(notebook), argv[1:], cwd or Path.cwd())
    except UsageError as e:
        print(e, file=sys.stderr)
        return 2
    start = time.perf_counter()
    try:
        page = run(notebook, values)
    except UsageError as e:
        print(e, file=sys.stderr)
        return 1
    print(f"{notebook.stem} ran in {time.perf_counter() - start:.0f} s", file=sys.stderr)
    print(page)
    return 0


if __name__ == "__main__":
    sys.exit(main())
