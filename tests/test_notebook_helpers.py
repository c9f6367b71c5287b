"""geomlib.teaching.notebook (show_source, explain, claim, note) and the check vocabulary."""

import warnings

import numpy as np
import pytest

import geomlib
from geomlib import check
from geomlib.teaching.check.catalogue import matrix_pair, vector
from geomlib.teaching.check.result import CheckFailed, Mistake, call, exercise, use
from geomlib.teaching.notebook import NOTE_PREFIX, ClaimFailed, claim, explain, note, show_source


@pytest.fixture
def shown(monkeypatch):
    """What the helpers display, as a list of mime bundles."""
    out = []
    monkeypatch.setattr("geomlib.teaching.notebook._display", out.append)
    return out


def test_show_source_names_the_file_and_lines_and_highlights():
    src = show_source(geomlib.laplacian)
    text = repr(src)
    assert text.startswith("# laplacian — geomlib/lessons/laplace.py, lines ")
    assert "def laplacian(V, F" in text
    first = int(text.split("lines ")[1].split("–")[0])
    assert open(geomlib.lessons.laplace.__file__).read().splitlines()[first - 1].startswith("def laplacian(")
    assert "<span" in src._repr_html_() and "geomlib/lessons/laplace.py" in src._repr_html_()


def test_show_source_of_a_check_shows_its_body_not_the_wrapper():
    assert "def uniform_laplacian(fn):" in repr(show_source(check.uniform_laplacian))


def test_explain_fills_placeholders_into_markdown(shown):
    explain(
        """
        **What happened?** The error is {err:.1%} on {n} vertices.
        """,
        err=0.0123,
        n=42,
    )
    assert shown == [
        {
            "text/markdown": "**What happened?** The error is 1.2% on 42 vertices.",
            "text/plain": "**What happened?** The error is 1.2% on 42 vertices.",
        }
    ]


def test_claim_that_holds_shows_nothing(shown, monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "1")
    assert claim(True, "anything") is True and shown == []


def test_failed_claim_raises_under_the_strict_tests(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "1")
    with pytest.raises(ClaimFailed, match=r"the text says K is within 10 %, but it does not hold: it is 31 %"):
        claim(False, "K is within 10 %", "it is {e:.0f} %", e=31)


def test_failed_claim_is_a_visible_note_for_a_reader(shown, monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")
    assert claim(False, "K is within 10 %", "on this mesh it is {e:.0f} % because the grid is coarse", e=31) is False
    (bundle,) = shown
    assert bundle["text/plain"] == (
        f"{NOTE_PREFIX} The text says K is within 10 %. With these inputs it does not "
        "hold: on this mesh it is 31 % because the grid is coarse"
    )
    assert bundle["text/markdown"].startswith("> **Note.** The text says")


def test_note_quotes_every_line(shown):
    note("first\nsecond")
    assert shown[0]["text/markdown"] == "> **Note.** first\n> second"


# -- the check vocabulary ---------------------------------------------------------------------


@exercise("double", reread="section 1")
def _check_double(fn):
    x = vector(call(fn, np.arange(3.0)), 3)
    if np.allclose(x, np.arange(3.0)):
        raise Mistake("nothing was doubled", "multiply by 2")
    if not np.allclose(x, 2 * np.arange(3.0)):
        raise Mistake("the result is not twice the input", typical=False)
    return ["a vector of three numbers"]


def test_check_passes_and_says_what_was_checked():
    r = _check_double(lambda x: 2 * x)
    assert r.passed and bool(r) and r.message == "checked on a vector of three numbers."
    assert "passed" in r._repr_html_()


def test_check_names_the_mistake_with_hint_and_reread(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")
    r = _check_double(lambda x: x)
    assert not r.passed and r.message == "nothing was doubled. Hint: multiply by 2. Reread section 1."


def test_failed_check_of_a_written_function_raises_under_the_strict_tests(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "1")
    with pytest.raises(CheckFailed, match="nothing was doubled"):
        _check_double(lambda x: x)


def test_a_stub_is_not_written_yet_and_never_raises(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "1")

    def stub(x):
        raise NotImplementedError("Your turn")

    r = _check_double(stub)
    assert not r.passed and r.message.startswith("not written yet") and "Reread section 1" in r.message


def test_exceptions_and_wrong_shapes_are_diagnosed(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")
    assert "raised ZeroDivisionError" in _check_double(lambda x: 1 / 0).message
    assert "returned shape (2,)" in _check_double(lambda x: x[:2]).message
    with pytest.raises(Mistake, match="not the pair"):
        matrix_pair(np.eye(2), 2)


def test_use_falls_back_to_the_reference(capsys, monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")

    def mine(x):
        raise NotImplementedError

    def reference(x):
        return 2 * x

    assert use(mine, _check_double, reference) is reference
    assert "has not passed its check yet" in capsys.readouterr().out
    good = lambda x: 2 * x  # noqa: E731
    assert use(good, _check_double, reference) is good


def _stub(x):
    raise NotImplementedError


def test_while_nbgrader_grades_a_failed_check_raises_its_diagnosis_and_use_still_falls_back(monkeypatch, capsys):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")
    monkeypatch.setenv("NBGRADER_EXECUTION", "autograde")
    with pytest.raises(CheckFailed, match="^double: not written yet"):
        _check_double(_stub)
    with pytest.raises(CheckFailed) as failed:
        _check_double(lambda x: x)
    # IPython (and so nbgrader's feedback page) shows this line instead of geomlib's frames
    assert failed.value._render_traceback_() == [
        "CheckFailed: double: nothing was doubled. Hint: multiply by 2. Reread section 1."
    ]
    # a long message in lines nbgrader validate shows whole (it cuts every line at 87 characters)
    long = CheckFailed("double: " + "the answer is wrong in a long and careful way, " * 6)
    lines = long._render_traceback_()
    assert len(lines) > 1 and all(len(line) <= 80 for line in lines)
    assert " ".join(line.strip() for line in lines) == f"CheckFailed: {long}".strip()
    assert _check_double(lambda x: 2 * x).passed
    assert use(_stub, _check_double, np.negative) is np.negative
    assert "has not passed its check yet" in capsys.readouterr().out


def test_while_graded_a_check_decides_each_function_once(monkeypatch, capsys):
    calls = []

    def double(x):
        calls.append(1)
        return 2 * x

    monkeypatch.setenv("NBGRADER_EXECUTION", "autograde")
    first = _check_double(double)  # the grade cell; its partial credit and use read the same verdict
    assert _check_double.partial_credit(double).passed and use(double, _check_double, np.negative) is double
    assert len(calls) == 1 and _check_double.evaluate(double) is first
    assert _check_double.evaluate(double, seed=3).passed and len(calls) == 2  # a seed asked for: a run of its own
    assert not _check_double.evaluate(lambda x: x).passed  # another function: its own verdict
    monkeypatch.delenv("NBGRADER_EXECUTION")
    _check_double(double), _check_double(double)
    assert len(calls) == 4  # a reader's run checks afresh at every call


def test_partial_credit_for_a_mistake_the_check_names(monkeypatch):
    monkeypatch.setenv("NBGRADER_EXECUTION", "validate")
    assert _check_double.partial_credit(lambda x: 2 * x).passed
    named = _check_double.partial_credit(lambda x: x)  # "nothing was doubled"
    assert named.passed and named.name == "double, partial credit"
    for wrong, reason in (
        (lambda x: 3 * x, "not earned. the check cannot name what is wrong"),  # only the catch-all fits
        (lambda x: x[:2], "not earned. the check cannot name what is wrong"),  # a wrong shape
        (lambda x: 1 / 0, "not earned. the check cannot name what is wrong"),  # an exception
        (_stub, "not written yet"),
    ):
        with pytest.raises(CheckFailed, match=f"^double, partial credit: {reason}"):
            _check_double.partial_credit(wrong)


def test_interactively_partial_credit_only_reports(monkeypatch):
    monkeypatch.delenv("NBGRADER_EXECUTION", raising=False)
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")
    r = _check_double.partial_credit(lambda x: 3 * x)
    assert not r.passed and "the result is not twice the input" in r.message


def test_warnings_of_the_learners_function_are_silenced_while_graded(monkeypatch):
    # nbgrader scores a grade cell that wrote to stderr as failed
    monkeypatch.setenv("NBGRADER_EXECUTION", "autograde")

    def noisy(x):
        warnings.warn("a library's warning", RuntimeWarning)
        return 2 * x

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert _check_double(noisy).passed and _check_double.partial_credit(noisy).passed


def test_braces_in_the_values_are_not_placeholders(shown, monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")
    claim(False, "the set is {s}", "$\\frac{{1}}{{2}}$ differs", s={1, 2})
    assert (
        shown[0]["text/plain"]
        == f"{NOTE_PREFIX} The text says the set is {{1, 2}}. With these inputs it does not hold: $\\frac{{1}}{{2}}$ differs"
    )


def test_loop_over_meshes_shows_a_bar_only_for_large_meshes(capsys):
    from geomlib.numerics.progress import LARGE_MESH, loop

    assert list(loop(range(3), "small meshes", LARGE_MESH)) == [0, 1, 2]
    assert capsys.readouterr().err == ""
    assert list(loop(range(3), "large meshes", LARGE_MESH + 1)) == [0, 1, 2]
    assert "large meshes" in capsys.readouterr().err
