"""papermill reads every parameter, and ``workbook.py run`` (tools/run_notebook.py).

* Every notebook's ``parameters`` cell: papermill lists every name the cell assigns,
  without a warning, and each comment ends with a range or choices the command
  line can read, which the default satisfies.
* The ranges, the values of a command line and the one-sentence answers to a
  wrong name or value.
* End to end: a notebook run with a changed parameter (its executed notebook and
  page), a mesh file that does not exist, and a wrong name through workbook.py.
"""

import ast
import json
import logging
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import run_notebook as rn  # noqa: E402
from run_notebook import Choice, FilePath, Number, NumberOrDict, Sequence, UsageError  # noqa: E402

NOTEBOOKS = sorted((ROOT / "notebooks").glob("[0-9][0-9]*_*.ipynb"))  # cores and appendices


def _parameters_cell(path):
    nb = nbformat.read(path, as_version=4)
    (cell,) = [c for c in nb.cells if "parameters" in c.metadata.get("tags", [])]
    return cell.source


def _assigned_names(source):
    """Every name the cell assigns, read by Python itself (tuple targets included)."""
    names = []
    for node in ast.parse(source).body:
        assert isinstance(node, ast.Assign), f"not an assignment: {ast.unparse(node)}"
        for target in node.targets:
            names += [n.id for n in ast.walk(target) if isinstance(n, ast.Name)]
    return names


# ---------------------------------------------------------------------------
# papermill and the parameters cells
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_papermill_lists_every_parameter_with_a_readable_range(path, caplog):
    import papermill

    with caplog.at_level(logging.WARNING, logger="papermill"):
        inspected = papermill.inspect_notebook(str(path))
    assert not caplog.records, [r.getMessage() for r in caplog.records]
    assert list(inspected) == _assigned_names(_parameters_cell(path))
    parameters = rn.notebook_parameters(path)
    assert [p.name for p in parameters] == list(inspected)
    for p in parameters:
        assert "=" not in p.help, f"{p.name}: papermill cannot parse a comment holding '='"
        default = rn.read_literal(p.default)
        if default is not rn.NOT_A_LITERAL:  # geomlib.data_path(...) is an expression
            assert p.spec.problem(default) is None, f"{path.stem}: {p.name} = {p.default} is outside ({p.range})"


def test_papermill_help_notebook_shows_every_parameter_of_02():
    """The notebook whose tuple assignments papermill used to leave out."""
    path = ROOT / "notebooks" / "02_fundamental_forms.ipynb"
    bin_dir = Path(sys.executable).parent
    out = subprocess.run(
        [str(bin_dir / "papermill"), "--help-notebook", str(path)], capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 0, out.stderr
    assert "Unable to parse" not in out.stdout + out.stderr
    for name in _assigned_names(_parameters_cell(path)):
        assert f"  {name}: " in out.stdout, f"{name} missing from:\n{out.stdout}"
    assert "semi-axis along y, in length units (0.2 to 3)" in out.stdout


# ---------------------------------------------------------------------------
# ranges and values
# ---------------------------------------------------------------------------


def test_number_ranges_closed_open_and_whole():
    r = rn.parse_spec("0 to 1000", default=30)
    assert r == Number(0, 1000, integer=True)
    assert r.problem(0) is None and r.problem(1000) is None
    assert r.problem(1001) == "is out of range" and r.problem(-1) == "is out of range"
    assert r.problem(3.0) == "is not a whole number" and r.problem(True) == "is not a number"
    assert r.problem("30") == "is not a number"
    f = rn.parse_spec("0.005 to 0.3", default=0.02)
    assert not f.integer and f.problem(1) == "is out of range" and f.problem(0.1) is None
    assert f.problem(float("nan")) == "is not a number"
    u = rn.parse_spec("above 0 to below 1.5708", default=0.7)
    assert u.problem(0) == "is out of range" and u.problem(1.5708) == "is out of range" and u.problem(1e-9) is None
    assert rn.parse_spec("above 0").problem(1e-12) is None and rn.parse_spec("above 0").problem(0) is not None
    assert rn.parse_spec("at least 1", default=5).problem(1) is None
    assert rn.parse_spec("at most 9").problem(9.5) == "is out of range"
    assert rn.parse_spec("below 1").problem(1) == "is out of range"
    assert rn.parse_spec("1000 to 10_000_000", default=50_000).hi == 10_000_000
    seed = rn.parse_spec("any integer", default=2)
    assert seed.problem(-7) is None and seed.problem(0.5) == "is not a whole number"
    with pytest.raises(ValueError):
        rn.parse_spec("5 to 1")
    with pytest.raises(ValueError):
        rn.parse_spec("small")


def test_choices_and_paths():
    unit = rn.parse_spec('"ell^2" or "length^2"', default="ell^2")
    assert unit == Choice(("ell^2", "length^2"))
    assert unit.problem("length^2") is None and unit.problem("mm") == "is not one of the choices"
    assert rn.parse_spec('"x", "y" or "z"').options == ("x", "y", "z")
    assert rn.parse_spec("a path") == FilePath(False) and rn.parse_spec("a path").problem(None) == "is not a path"
    assert rn.parse_spec("a path or None").problem(None) is None


def test_sequences_count_order_and_places():
    axes = rn.parse_spec("3 values, each 0.1 to 10", default=(1.0, 0.7, 0.5))
    assert axes.problem([1, 2, 3]) is None and axes.problem((1.0, 2.0)) == "has the wrong number of values"
    assert axes.problem((1.0, 0.05, 2.0)) == "holds 0.05, which is out of range"
    assert axes.problem(1.0) == "is not a tuple or list"
    levels = rn.parse_spec("1 to 6 distinct values, each 1 to 7", default=[2, 3, 4, 5, 6])
    assert levels == Sequence(items=Number(1, 7, integer=True), min_count=1, max_count=6, order="distinct")
    assert levels.problem([1]) is None and levels.problem([2, 2]) == "has values twice"
    assert levels.problem([1, 2, 3, 4, 5, 6, 7]) == "has the wrong number of values"
    assert levels.problem([2.5]) == "holds 2.5, which is not a whole number"
    sigmas = rn.parse_spec("increasing values, each 0 to 0.1", default=(0.001, 0.02))
    assert sigmas.problem((0.0, 0.1)) is None and sigmas.problem((0.02, 0.01)) == "is not increasing"
    assert sigmas.problem(()) == "has the wrong number of values"
    taubin = rn.parse_spec("above 0 to 1, then -1 to below 0", default=(0.5, -0.5))
    assert taubin.problem((1.0, -1.0)) is None and taubin.problem((0.5, 0.0)) == "holds 0.0, which is out of range"
    assert taubin.problem((0.5,)) == "does not have 2 values"


def test_a_number_or_one_per_mesh():
    """The form a per-mesh step takes: ``STEP = {"PLANE": 1e-6, "PART": 1e-4}``."""
    step = rn.parse_spec("above 0, or a dict of such values", default=0.03)
    assert step == NumberOrDict(Number(0, None, lo_open=True))
    assert step.problem(1e-4) is None and step.problem({"PLANE": 1e-6, "PART": 1e-4}) is None
    assert step.problem({"PLANE": -1e-6}) == "holds 'PLANE': -1e-06, which is out of range"
    assert step.problem({}) == "is an empty dict" and step.problem({1: 0.1}) == "has the key 1, which is not a name"


def test_values_are_literals_or_bare_words():
    number, path = Number(), FilePath(True)
    assert rn.parse_value("1e-4", number) == 1e-4 and rn.parse_value("(1.0, 0.7, 0.5)", number) == (1.0, 0.7, 0.5)
    assert rn.parse_value('{"PLANE": 1e-6, "PART": 1e-4}', number) == {"PLANE": 1e-6, "PART": 1e-4}
    assert rn.parse_value("length^2", Choice(("length^2",))) == "length^2"
    assert rn.parse_value('"length^2"', Choice(("length^2",))) == "length^2"
    assert rn.parse_value("course/smoothing/fandisk_ns.obj", path) == "course/smoothing/fandisk_ns.obj"
    assert rn.parse_value("None", path) is None and rn.parse_value("2024", path) == "2024"
    assert rn.parse_value("abc", number) == "abc"  # then refused as "is not a number"


def test_tuples_reach_papermill_as_lists():
    """papermill writes a tuple as the string of its text (``K_VALUES = "(5, 15, 200)"``)."""
    from papermill.translators import PythonTranslator

    values = rn.for_papermill({"K": (5, 15, 200), "STEP": {"PART": (1, 2)}, "UP": "y"})
    assert values == {"K": [5, 15, 200], "STEP": {"PART": [1, 2]}, "UP": "y"}
    assert "K = [5, 15, 200]" in PythonTranslator.codify(values)


def _fake_notebook():
    return Path("notebooks/05_explicit_smoothing.ipynb"), [
        rn.Parameter("PART", "x", "a part (a path)", FilePath()),
        rn.Parameter("STEP", "0.03", "the step (above 0)", rn.parse_spec("above 0", 0.03)),
        rn.Parameter("UNIT", '"ell^2"', 'unit ("ell^2" or "length^2")', rn.parse_spec('"ell^2" or "length^2"')),
    ]


def test_assignments_checked_and_paths_made_absolute(tmp_path):
    nb, parameters = _fake_notebook()
    values = rn.read_assignments(nb, parameters, ["STEP=1e-4", "UNIT=length^2", "PART=course/part.obj"], tmp_path)
    assert values == {"STEP": 1e-4, "UNIT": "length^2", "PART": str(tmp_path / "course" / "part.obj")}


@pytest.mark.parametrize(
    "arg, start",
    [
        ("STPE=1", "05_explicit_smoothing has no parameter STPE; "),
        ("STEP=-1", "STEP=-1 is out of range (above 0); "),
        ("STEP=fast", "STEP=fast is not a number (above 0); "),
        ("UNIT=mm", 'UNIT=mm is not one of the choices ("ell^2" or "length^2"); '),
        ("STEP", "'STEP' is not NAME=VALUE; "),
    ],
)
def test_a_wrong_name_or_value_gets_one_sentence_listing_the_ranges(arg, start):
    nb, parameters = _fake_notebook()
    with pytest.raises(UsageError) as e:
        rn.read_assignments(nb, parameters, [arg], ".")
    message = str(e.value)
    assert message.startswith(start)
    assert message.endswith(
        """05_explicit_smoothing's parameters are PART (a path), STEP (above 0), UNIT ("ell^2" or "length^2")."""
    )
    assert "\n" not in message


def test_a_notebook_by_number_name_or_file_name():
    path = ROOT / "notebooks" / "05_explicit_smoothing.ipynb"
    assert rn.find_notebook("05") == rn.find_notebook("05_explicit_smoothing") == path
    assert rn.find_notebook("05_explicit_smoothing.ipynb") == rn.find_notebook("notebooks/" + path.name) == path
    with pytest.raises(UsageError, match=r"^There is no notebook '5'; the notebooks are 00_getting_started, "):
        rn.find_notebook("5")
    (appendix,) = (ROOT / "notebooks").glob("05a_*.ipynb")
    assert rn.find_notebook("05a") == rn.find_notebook(appendix.name) == appendix


@pytest.mark.parametrize(
    "error, sentence",
    [
        (("MeshError", "/m/x.obj: no such file"), "stopped in cell [4]: /m/x.obj: no such file (see "),
        (("ValueError", "bad value"), "stopped in cell [4]: ValueError: bad value (see "),
        ("timeout", "did not finish: A cell timed out while it was being executed, after 9 seconds. (see "),
    ],
)
def test_a_notebook_that_stops_is_one_sentence(error, sentence, tmp_path, monkeypatch):
    import papermill
    from nbclient.exceptions import CellTimeoutError
    from papermill.exceptions import PapermillExecutionError

    def execute_notebook(*args, **kwargs):
        if error == "timeout":
            raise CellTimeoutError.error_from_timeout_and_cell("A cell timed out", 9, nbformat.v4.new_code_cell("x"))
        raise PapermillExecutionError(4, 4, "load_mesh(MESH)", *error, ["Traceback ...", "more"])

    monkeypatch.setattr(papermill, "execute_notebook", execute_notebook)
    monkeypatch.setattr(rn, "RUNS", tmp_path)
    with pytest.raises(UsageError) as e:
        rn.run(rn.find_notebook("00"), {})
    assert str(e.value).startswith("00_getting_started " + sentence) and "\n" not in str(e.value)


# ---------------------------------------------------------------------------
# end to end
# ---------------------------------------------------------------------------


@pytest.mark.slow
def test_a_run_with_a_changed_parameter_writes_the_notebook_and_its_page(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(rn, "RUNS", tmp_path)
    assert rn.main(["00", "UP=y"]) == 0
    page = Path(capsys.readouterr().out.strip().splitlines()[-1])
    assert page.parent.parent == tmp_path and page.name == "00_getting_started.html" and page.is_file()
    assert page.parent.name.startswith("00_getting_started-")
    nb = nbformat.read(page.with_suffix(".ipynb"), as_version=4)
    (injected,) = [c for c in nb.cells if "injected-parameters" in c.metadata.get("tags", [])]
    assert "UP = 'y'" in injected.source or 'UP = "y"' in injected.source
    assert not [o for c in nb.cells if c.cell_type == "code" for o in c.outputs if o.output_type == "error"]
    # the 3D views are live on the page: widget state saved, the renderer's script beside it
    html = page.read_text()
    state = json.loads(html.split('<script type="application/vnd.jupyter.widget-state+json">')[1].split("</script>")[0])
    assert any(m["model_name"] == "RendererModel" for m in state["state"].values())
    assert (page.parent / "assets" / "html-manager" / "dist" / "embed-amd.js").is_file()


@pytest.mark.slow
def test_a_mesh_file_that_is_not_there_is_one_sentence(tmp_path, monkeypatch, capfd):
    """Nothing else on the screen either: the kernel's own log (file descriptor 2) stays quiet."""
    monkeypatch.setattr(rn, "RUNS", tmp_path)
    assert rn.main(["00", "MESH=nowhere/saddle.obj"], cwd=tmp_path) == 1
    err = capfd.readouterr().err.strip()
    assert "\n" not in err and err.startswith("00_getting_started stopped in cell [")
    assert f"{tmp_path / 'nowhere' / 'saddle.obj'}: no such file" in err


@pytest.mark.slow
def test_workbook_run_with_a_wrong_name_exits_2_with_one_sentence():
    out = subprocess.run(
        [sys.executable, str(ROOT / "workbook.py"), "run", "05", "STPE=1e-4"], capture_output=True, text=True
    )
    assert out.returncode == 2
    assert out.stdout == ""
    assert out.stderr.startswith("05_explicit_smoothing has no parameter STPE; 05_explicit_smoothing's parameters ")
    assert out.stderr.count("\n") == 1 and "STEP (above 0, or a dict of such values)" in out.stderr
