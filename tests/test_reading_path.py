"""A course's reading path: a short core per notebook, its depth in an appendix, the machinery out of the way.

Each core notebook (``NN_*.ipynb``) holds at most 1,500 markdown words and 40 cells, opens
with what the student will be able to do, what they need first and how long it takes, asks
at least one question before its answer (**Predict.**), and links its appendix
(``NNa_dig_deeper_*.ipynb``), which links back. A student reads code cells that each do one
thing: every cell that holds a claim is hidden, no core cell times itself, every figure goes
through ``show_figure`` with an alt text, and every 3D view is described. Each exercise
states its ground rules (the sentence ``check.NAME.rules``) and each of the notebooks
01-07 has a discussion graded by hand.
"""

import ast
import re
from pathlib import Path

import nbformat
import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
CORES = [p for p in NOTEBOOKS if re.match(r"\d\d_", p.name)]
APPENDICES = [p for p in NOTEBOOKS if re.match(r"\d\da_dig_deeper_", p.name)]
MAX_WORDS, MAX_CELLS = 1500, 40
OPENING = ("**You will be able to**", "**You need first**", "**Time**")


def read(path):
    return nbformat.read(path, as_version=4)


def markdown_words(nb):
    return sum(len(c.source.split()) for c in nb.cells if c.cell_type == "markdown")


def links(nb):
    return set(re.findall(r"\]\(([^)#\s]+\.ipynb)", "\n".join(c.source for c in nb.cells if c.cell_type == "markdown")))


def hidden(cell):
    return bool(cell.metadata.get("jupyter", {}).get("source_hidden"))


def test_every_notebook_is_a_core_or_an_appendix_of_one():
    assert {p.name for p in NOTEBOOKS} == {p.name for p in CORES + APPENDICES}
    cores = {p.name[:2] for p in CORES}
    assert all(p.name[:2] in cores for p in APPENDICES)
    assert len({p.name[:2] for p in APPENDICES}) == len(APPENDICES), "one appendix per core"


@pytest.mark.parametrize("path", CORES, ids=[p.name for p in CORES])
def test_a_core_is_short(path):
    nb = read(path)
    assert markdown_words(nb) <= MAX_WORDS, f"{markdown_words(nb)} markdown words"
    assert len(nb.cells) <= MAX_CELLS, f"{len(nb.cells)} cells"


@pytest.mark.parametrize("path", CORES, ids=[p.name for p in CORES])
def test_a_lesson_opens_with_objectives_prerequisites_and_time(path):
    cells = read(path).cells
    assert cells[0].cell_type == "markdown" and cells[0].source.startswith("# ")
    opening = cells[1].source
    assert cells[1].cell_type == "markdown"
    places = [opening.find(label) for label in OPENING]
    assert -1 not in places and places == sorted(places), f"the opening block lacks or misorders {OPENING}"
    assert re.search(r"\*\*Time\*\*[^\n]*\d+\s*(minutes|min|hours?)", opening), "no time in minutes or hours"


@pytest.mark.parametrize("path", [p for p in CORES if p.name[:2] != "00"], ids=lambda p: p.name)
def test_a_lesson_asks_before_it_answers(path):
    assert any(c.cell_type == "markdown" and "**Predict.**" in c.source for c in read(path).cells)


@pytest.mark.parametrize("path", APPENDICES, ids=[p.name for p in APPENDICES])
def test_an_appendix_and_its_core_link_each_other(path):
    core = next(p for p in CORES if p.name[:2] == path.name[:2])
    assert path.name in links(read(core)), f"{core.name} does not link {path.name}"
    assert core.name in links(read(path)), f"{path.name} does not link back to {core.name}"
    assert read(path).cells[0].source.startswith("# ")


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_every_link_to_a_notebook_resolves(path):
    missing = {name for name in links(read(path)) if not (path.parent / name).exists()}
    assert not missing


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_claims_are_hidden_and_cores_do_not_time_themselves(path):
    for i, cell in enumerate(read(path).cells):
        if cell.cell_type != "code":
            continue
        assert "claim(" not in cell.source or hidden(cell), f"cell {i} shows a claim to the student"
        if path in CORES:
            assert not re.search(r"perf_counter|time\.time\(|%%?time", cell.source), f"cell {i} times itself"


def calls(source, name):
    """The Call nodes of ``name(...)`` in a cell (magics and shell lines dropped)."""
    code = "\n".join(line for line in source.splitlines() if not line.lstrip().startswith(("%", "!")))
    return [
        node
        for node in ast.walk(ast.parse(code))
        if isinstance(node, ast.Call) and getattr(node.func, "id", getattr(node.func, "attr", None)) == name
    ]


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_every_figure_has_an_alt_text_and_every_view_a_description(path):
    for i, cell in enumerate(read(path).cells):
        if cell.cell_type != "code":
            continue
        assert "plt.show(" not in cell.source, f"cell {i}: a figure shown by plt.show() has no alt text"
        for node in calls(cell.source, "show_figure"):
            assert len(node.args) >= 2 or any(k.arg == "alt" for k in node.keywords), f"cell {i}: no alt"
        for node in calls(cell.source, "MeshView"):
            assert any(k.arg == "description" for k in node.keywords), f"cell {i}: a MeshView without description"


def exercises(nb):
    return [
        (i, c.metadata["nbgrader"]["grade_id"])
        for i, c in enumerate(nb.cells)
        if c.cell_type == "code" and c.metadata.get("nbgrader", {}).get("solution")
    ]


@pytest.mark.parametrize("path", CORES, ids=[p.name for p in CORES])
def test_every_exercise_states_its_ground_rules(path):
    from geomlib import check

    nb = read(path)
    for i, name in exercises(nb):
        text = next(c.source for c in reversed(nb.cells[:i]) if c.cell_type == "markdown")
        assert "**Ground rules:**" in text, f"{name}: no ground rules above the exercise"
        rules = getattr(check, name).rules.removeprefix("Ground rules: ")
        assert " ".join(rules.split()) in " ".join(text.split()), f"{name}: the ground rules are not check.{name}.rules"


@pytest.mark.parametrize("path", [p for p in CORES if p.name[:2] != "00"], ids=lambda p: p.name)
def test_every_lesson_has_a_discussion_graded_by_hand(path):
    cells = read(path).cells
    answers = [
        i
        for i, c in enumerate(cells)
        if c.cell_type == "markdown"
        and c.metadata.get("nbgrader", {}).get("grade")
        and c.metadata["nbgrader"]["solution"]
    ]
    assert answers, "no hand-graded answer cell"
    for i in answers:
        assert cells[i].metadata["nbgrader"]["points"] >= 1
        assert cells[i - 1].cell_type == "markdown" and cells[i - 1].source.startswith("**Discuss (")


def test_appendices_carry_no_exercises():
    for path in APPENDICES:
        assert not any(c.metadata.get("nbgrader") for c in read(path).cells), path.name
