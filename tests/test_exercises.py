"""The exercises across the notebooks: the student's own work, nothing above a question that answers it.

* No line of a solution and no code snippet of the markdown above an exercise (inline or
  fenced) passes the exercise's check when handed in as the function: each is wrapped as the
  function (an expression is returned, statements run and their last assignment returned)
  and checked; none may pass. The whole solution body, wrapped the same way, must pass: the
  harness can tell a passing answer.
* Every Discuss answer's hidden model answer opens with a rubric (``**Rubric (P points).**``,
  then ``- (k) ...`` criteria, then ``**Model answer.**``) whose criteria add up to the answer
  cell's points P.
* No markdown cell of a core holds more than about 250 words.
* Before an exercise, no code cell imports (by name) a routine the exercise forbids, nor a
  ``reference_*`` routine: the student's namespace holds no answer one ``??`` away.
* The solutions are routines, not lines: at least 200 lines of code in all over 01-07, a
  median of at least 8 per exercise, none under 3.
"""

import ast
import re
import statistics
from pathlib import Path

import nbformat
import pytest

ROOT = Path(__file__).resolve().parents[1]
CORES = sorted((ROOT / "notebooks").glob("0[1-7]_*.ipynb"))
BEGIN, END = "### BEGIN SOLUTION", "### END SOLUTION"
HIDDEN = re.compile(r"### BEGIN HIDDEN TESTS\n(.*?)### END HIDDEN TESTS", re.S)
MAX_CELL_WORDS = 250
MIN_TOTAL, MIN_MEDIAN, MIN_LINES = 200, 8, 3


def _nb(path):
    return nbformat.read(path, as_version=4)


def _meta(cell):
    return cell.metadata.get("nbgrader", {})


def exercises(path):
    """[(exercise name, index of its solution cell, the cell)] of a notebook, in order."""
    return [
        (_meta(c)["grade_id"], i, c)
        for i, c in enumerate(_nb(path).cells)
        if c.cell_type == "code" and _meta(c).get("solution")
    ]


EXERCISES = [(path, name, i) for path in CORES for name, i, _ in exercises(path)]
IDS = [f"{p.name[:2]}-{name}" for p, name, _ in EXERCISES]


def solution_lines(source):
    """The code lines between the solution markers (blank lines and comments left out)."""
    body = source.split(BEGIN, 1)[1].split(END, 1)[0]
    return [line for line in body.splitlines() if line.strip() and not line.strip().startswith("#")]


def _dedent(lines):
    pad = min(len(line) - len(line.lstrip()) for line in lines)
    return [line[pad:] for line in lines]


def wrap(signature, snippet):
    """The source of a function with ``signature`` (its ``def`` line) whose body is ``snippet``:
    an expression is returned; statements run, and the name their last assignment binds is
    returned. None when the snippet is not Python."""
    try:
        tree = ast.parse(snippet)
    except SyntaxError:
        return None
    if not tree.body:
        return None
    body = [f"    {line}" for line in snippet.splitlines()]
    last = tree.body[-1]
    if len(tree.body) == 1 and isinstance(last, ast.Expr):
        body = [f"    return ({snippet.strip()})"]
    elif isinstance(last, ast.Assign) and isinstance(last.targets[0], ast.Name | ast.Tuple):
        body.append(f"    return {ast.unparse(last.targets[0])}")
    return "\n".join([signature, *body])


def _signature(source):
    (line,) = [line for line in source.splitlines() if line.startswith("def ")][:1]
    return line


def _calls_use(node):
    return isinstance(node, ast.Call) and getattr(node.func, "id", None) == "use"


def _namespace(cells):
    """The imports, function definitions and ``name = use(...)`` lines of ``cells`` (code cells), one source:
    what the student's cell sees of the notebook (its imports, the routines of the earlier exercises),
    without running the rest."""
    out = []
    for cell in cells:
        try:
            tree = ast.parse("\n".join(line for line in cell.source.splitlines() if not line.startswith(("%", "!"))))
        except SyntaxError:
            continue
        out += [ast.unparse(n) for n in tree.body if isinstance(n, ast.Import | ast.ImportFrom | ast.FunctionDef)]
        out += [ast.unparse(n) for n in tree.body if isinstance(n, ast.Assign) and _calls_use(n.value)]
    return "\n".join(out)


def prompt_snippets(cells):
    """The inline and fenced code snippets of the markdown ``cells``."""
    snippets = []
    for cell in cells:
        text = cell.source
        for block in re.findall(r"```[a-z]*\n(.*?)```", text, re.S):
            snippets.append(block.strip())
        text = re.sub(r"```.*?```", "", text, flags=re.S)
        snippets += [s.strip() for s in re.findall(r"`([^`\n]+)`", text)]
    return [s for s in snippets if s]


def handed_in(path, index):
    """(signature, namespace source, markdown cells above) of the exercise whose solution cell is ``index``."""
    cells = _nb(path).cells
    previous = max([i for _, i, _ in exercises(path) if i < index], default=-1)
    above = [c for c in cells[previous + 1 : index] if c.cell_type == "markdown"]
    imports = _namespace([c for c in cells[:index] if c.cell_type == "code" and not _meta(c).get("grade")])
    return _signature(cells[index].source), imports, above


def verdict(name, signature, imports, snippet):
    """Whether the snippet, wrapped as the function and handed in, passes check.NAME (None: not Python)."""
    from geomlib import check

    source = wrap(signature, snippet)
    if source is None:
        return None
    namespace = {}
    try:
        exec(imports, namespace)  # the notebook's imports: what the student's cell sees
        exec(source, namespace)
    except Exception:  # a snippet that does not even define the function passes nothing
        return False
    fn = namespace[signature.split("(")[0][4:]]
    try:
        return getattr(check, name).evaluate(fn).passed
    except Exception:  # a check that stumbles over an odd answer has not passed it
        return False


def test_wrap_returns_an_expression_and_the_last_assignment():
    assert wrap("def f(x):", "x + 1") == "def f(x):\n    return (x + 1)"
    assert wrap("def f(x):", "y = 2 * x\nz = y + 1") == "def f(x):\n    y = 2 * x\n    z = y + 1\n    return z"
    assert wrap("def f(x):", "M^{-1} C") is None
    assert prompt_snippets([nbformat.v4.new_markdown_cell("Use `np.sum(a)` or\n```python\nb = a\n```")]) == [
        "b = a",
        "np.sum(a)",
    ]


@pytest.mark.parametrize("path, name, index", EXERCISES, ids=IDS)
def test_no_solution_line_and_no_prompt_snippet_passes_the_check(path, name, index):
    signature, imports, above = handed_in(path, index)
    lines = solution_lines(_nb(path).cells[index].source)
    whole = "\n".join(_dedent(lines))
    assert verdict(name, signature, imports, whole), f"{name}: the whole solution, wrapped, does not pass"
    passing = [
        s
        for s in [*(line.strip() for line in lines), *prompt_snippets(above)]
        if s != whole.strip() and verdict(name, signature, imports, s)
    ]
    assert not passing, f"{name}: these alone pass its check: {passing}"


def discuss_pairs(path):
    """[(answer cell, model-answer source)]: each hand-graded answer with the hidden region after it."""
    cells = _nb(path).cells
    pairs = []
    for i, cell in enumerate(cells):
        if cell.cell_type == "markdown" and _meta(cell).get("solution") and _meta(cell).get("grade"):
            hidden = [HIDDEN.search(c.source) for c in cells[i + 1 :] if _meta(c).get("grade")]
            hidden = [h for h in hidden if h]
            assert hidden, f"{path.name}: the answer {_meta(cell)['grade_id']} has no hidden model answer after it"
            pairs.append((cell, hidden[0].group(1)))
    return pairs


RUBRIC = re.compile(
    r"\*\*Rubric \((\d+) points?\)\.\*\*\n((?:- \(\d+\) [^\n]*\n(?:  [^\n]*\n)*)+)\n\*\*Model answer\.\*\*"
)


@pytest.mark.parametrize("path", CORES, ids=[p.name[:2] for p in CORES])
def test_every_discuss_model_answer_opens_with_a_rubric_of_its_points(path):
    pairs = discuss_pairs(path)
    assert pairs, f"{path.name} has no Discuss question"
    for cell, model in pairs:
        points = _meta(cell)["points"]
        m = RUBRIC.search(model)
        assert m, f"{path.name} {_meta(cell)['grade_id']}: no '**Rubric (N points).**' with '- (k) ...' criteria"
        assert model.index("**") == m.start(), f"{path.name}: something bold comes before the rubric"
        criteria = [int(k) for k in re.findall(r"^- \((\d+)\) ", m.group(2), re.M)]
        assert int(m.group(1)) == points == sum(criteria), (
            f"{path.name} {_meta(cell)['grade_id']}: rubric of {m.group(1)} points, criteria {criteria}, cell {points}"
        )


def test_the_rubric_reader_sees_a_wrong_sum():
    good = "**Rubric (2 points).**\n- (1) says a\n- (1) says b\n  and more\n\n**Model answer.** text"
    m = RUBRIC.search(good)
    assert m and sum(int(k) for k in re.findall(r"^- \((\d+)\) ", m.group(2), re.M)) == 2
    assert RUBRIC.search(good.replace("\n\n**Model", "\n**Model")) is None


@pytest.mark.parametrize("path", sorted((ROOT / "notebooks").glob("0[0-7]_*.ipynb")), ids=lambda p: p.name[:2])
def test_no_markdown_cell_of_a_core_is_long(path):
    long = {i: len(c.source.split()) for i, c in enumerate(_nb(path).cells) if c.cell_type == "markdown"}
    long = {i: words for i, words in long.items() if words > MAX_CELL_WORDS}
    assert not long, f"{path.name}: markdown cells over {MAX_CELL_WORDS} words (cell: words): {long}"


def imported_names(source):
    """The names a cell binds by ``import``/``from ... import`` (as bound, and as imported)."""
    try:
        tree = ast.parse("\n".join(line for line in source.splitlines() if not line.startswith(("%", "!"))))
    except SyntaxError:
        return set()
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            names |= {a.name for a in node.names} | {a.asname for a in node.names if a.asname}
    return names


@pytest.mark.parametrize("path, name, index", EXERCISES, ids=IDS)
def test_no_forbidden_routine_is_imported_before_its_exercise(path, name, index):
    from geomlib import check

    forbidden = {dotted.rsplit(".", 1)[-1] for dotted in getattr(check, name).forbid}
    cells = _nb(path).cells[:index]
    found = {}
    for i, cell in enumerate(cells):
        if cell.cell_type == "code":
            bad = {n for n in imported_names(cell.source) if n in forbidden or n.startswith("reference_")}
            if bad:
                found[i] = sorted(bad)
    assert not found, f"{path.name}: before {name}, cells import what it forbids (cell: names): {found}"


def test_the_import_scan_sees_a_from_import():
    assert imported_names("from geomlib import add_noise as an, check\nimport numpy as np") == {
        "add_noise",
        "an",
        "check",
    }


def solution_sizes():
    return {f"{p.name[:2]} {name}": len(solution_lines(c.source)) for p in CORES for name, _, c in exercises(p)}


def test_the_solutions_are_routines():
    sizes = solution_sizes()
    median = statistics.median(sizes.values())
    short = {name: n for name, n in sizes.items() if n < MIN_LINES}
    total = sum(sizes.values())
    assert total >= MIN_TOTAL and median >= MIN_MEDIAN and not short, (
        f"{len(sizes)} exercises, {total} solution lines in all (at least {MIN_TOTAL}), median {median} "
        f"(at least {MIN_MEDIAN}), under {MIN_LINES} lines: {short}; per exercise: {sizes}"
    )
