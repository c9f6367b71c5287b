"""The README and the pages of docs/: their links resolve, their commands are tested, the
front page stays a front page.

* Every relative link (and picture) of README.md and docs/*.md leads to a file of the
  repository; every page of docs/ is reachable from the README (directly or through the
  index docs/README.md); every notebook, core and appendix, is in the README's table.
* Every command shown in a shell code block of those pages is one the test suite runs or
  checks: :data:`COMMANDS` maps each command to the test that exercises it, and a command
  it does not know fails the test (add it to the map with its test, or test it here).
  Commands whose run would take minutes or need a server are checked here instead: the
  subcommand exists (``workbook.py``, nbgrader), the files named exist, and every
  ``workbook.py run`` command of the pages (in code blocks or in the experiments table)
  passes ``tools/run_notebook.py``'s check of names and ranges.
* The README is at most 1,000 words, its picture is the one ``tools/make_front_image.py``
  makes (the same bytes) and stays under 150 KB; the time it gives a notebook is the one
  the notebook's opening block states.

The website's side (a page for every notebook and docs page, previous/next links both
ways, the reference listing every public name, 60 MB) is tested on the site the browser
tests build once (tests/browser/test_site.py).
"""

import ast
import re
import shlex
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import build_site  # noqa: E402
import run_notebook  # noqa: E402

PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
README_WORDS = 1000
IMAGE_BYTES = 150_000
SHELL = ("bash", "sh", "shell", "console")

#: every command a page shows, by pattern (matched against the start of the command,
#: words separated by single spaces), and the test that runs or checks it. "here" means
#: this module checks it (``test_commands_checked_here``).
# fmt: off
COMMANDS = [
    (r"python3 workbook\.py (lab|notebook)\b", "tests/test_environment.py::test_workbook_opens_notebook_00_and_passes_arguments_on"),
    (r"python3 workbook\.py test\b", "here"),  # the suite itself; its arguments are pytest's
    (r"python3 workbook\.py setup\b", "tests/test_environment.py::test_environment_yml_pip_section_installs_what_workbook_py_installs"),
    (r"python3 workbook\.py assignment\b", "tests/test_assignment.py::test_the_release_runs_with_the_stubs_and_reveals_nothing"),
    (r"python3 workbook\.py site\b", "tests/browser/test_site.py::test_page_offline"),
    (r"python3 workbook\.py run\b", "here"),  # names and ranges; runs: test_run_notebook.py
    (r"python3 workbook\.py course\b", "tests/test_environment.py::test_workbook_course_runs_geomlib_course_in_its_environment"),
    (r"pip install \.$", "tests/test_install.py::test_installing_geomlib_keeps_an_existing_jupyterlab_4"),
    # pip builds the same wheel from a clone as from the checkout
    (r"pip install git\+", "tests/test_install.py::test_installing_geomlib_keeps_an_existing_jupyterlab_4"),
    (r"conda env create -f environment\.yml$", "tests/test_environment.py::test_environment_yml_asks_conda_only_for_python_and_pip"),
    (r"conda activate geomlib-workbook$", "tests/test_environment.py::test_environment_yml_asks_conda_only_for_python_and_pip"),
    (r"jupyter lab\b", "tests/browser/test_notebooks_browser.py"),
    (r"python -m pytest$", "here"),
    (r"source \.venv/bin/activate$", "here"),
    (r"papermill --help-notebook ", "tests/test_run_notebook.py::test_papermill_help_notebook_shows_every_parameter_of_02"),
    (r"papermill notebooks/", "tests/test_run_notebook.py::test_a_run_with_a_changed_parameter_writes_the_notebook_and_its_page"),
    (r"\.venv/bin/python tools/strip_notebooks\.py\b", "tests/test_notebooks_clean.py::test_strip_tool_cleans_and_is_idempotent"),
    (r"\.venv/bin/python benchmarks/bench_\w+\.py\b", "here"),  # the script exists; tests/test_lint.py reads it
    (r"nbgrader (generate_assignment|autograde|export|generate_feedback|validate)\b", "tests/test_nbgrader.py"),
    (r"nbgrader (quickstart|release_assignment|collect|release_feedback|fetch_assignment|submit|fetch_feedback)\b", "here"),
    (r"cd geomlib-course$", "here"),
    (r"rm -r source/ps1 source/header\.ipynb$", "tests/test_course.py::test_the_guides_course_folder_and_one_machine_trial"),
    (r"mkdir -p source/curvature$", "here"),
    (r"cp \.\./notebooks/0\[1-7\]", "here"),
    (r"cat >> nbgrader_config\.py$", "tests/test_course.py::test_the_guides_course_folder_and_one_machine_trial"),
    (r"geomlib-course autograde \. \w+ --workers \d+$", "tests/test_course.py::test_progress_shows_each_student_with_the_count_seconds_and_time_left"),
    (r"geomlib-course report \. \w+$", "tests/test_course.py::test_the_class_report_counts_every_outcome_exactly"),
    # the guide's one-machine trial, run as a script by the test (the students' configuration too)
    (r"(mkdir -p (source/trial|\.\./alice|~/\.jupyter)|cd \.\./(alice|bob|geomlib-course)|cd \.\.$|cd bob$)", "tests/test_course.py::test_the_guides_course_folder_and_one_machine_trial"),
    (r"(cp \.\./notebooks/01_|cp -r alice bob$|rm -r \.cache trial$|sed -i s/alice/bob/ )", "tests/test_course.py::test_the_guides_course_folder_and_one_machine_trial"),
    (r"cat > (nbgrader_config\.py|~/\.jupyter/nbgrader_config\.py)$", "tests/test_course.py::test_the_guides_course_folder_and_one_machine_trial"),
]
# fmt: on


# ---------------------------------------------------------------------------
# reading the pages
# ---------------------------------------------------------------------------


def _blocks(text):
    """(info string, lines) of every fenced code block."""
    return re.findall(r"^ *```(\w*)\n(.*?)^ *```", text, flags=re.M | re.S)


def _links(text):
    """Every markdown link and picture target outside code blocks and code spans."""
    prose = re.sub(r"^ *```.*?^ *```", "", text, flags=re.M | re.S)
    prose = re.sub(r"`[^`\n]*`", "", prose)
    return re.findall(r"!?\[[^\]]*\]\(([^)\s]+)\)", prose)


def commands(text):
    """The words of each command of the shell code blocks: continuation lines joined,
    comments and here-documents left out, ``a && b`` as two commands, leading
    VAR=value assignments dropped."""
    found = []
    for info, body in _blocks(text):
        if info not in SHELL:
            continue
        end = None
        for line in body.replace("\\\n", " ").splitlines():
            if end is not None:
                end = None if line.strip() == end else end
                continue
            heredoc = re.search(r"<<-?\s*'?(\w+)'?", line)
            if heredoc:
                end, line = heredoc.group(1), line[: heredoc.start()]
            words = shlex.split(line, comments=True)
            while words:
                part = words[: words.index("&&")] if "&&" in words else words
                words = words[len(part) + 1 :]
                while part and re.fullmatch(r"[A-Z_]+=\S*", part[0]):
                    part = part[1:]
                if part:
                    found.append(part)
    return found


def page_commands():
    """(page, command words) of every shell code block of the pages."""
    return [(page.relative_to(ROOT).as_posix(), c) for page in PAGES for c in commands(page.read_text())]


def _test_of(words):
    command = " ".join(words)
    for pattern, test in COMMANDS:
        if re.match(pattern, command):
            return test
    return None


# ---------------------------------------------------------------------------
# links
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_relative_link_leads_to_a_file(page):
    text = page.read_text()
    missing = []
    for target in _links(text):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith("#"):
            continue
        path = (page.parent / target.partition("#")[0]).resolve()
        if not path.is_relative_to(ROOT) or not path.exists():
            missing.append(target)
    assert not missing, f"{page.name} links to files that do not exist: {missing}"


def test_every_docs_page_is_reachable_from_the_readme():
    def linked(page):
        return {(page.parent / t.partition("#")[0]).resolve() for t in _links(page.read_text())}

    readme = linked(ROOT / "README.md")
    assert (ROOT / "docs" / "README.md").resolve() in readme, "the README does not link the docs index"
    reachable = readme | linked(ROOT / "docs" / "README.md")
    lost = [p.name for p in sorted((ROOT / "docs").glob("*.md")) if p.resolve() not in reachable]
    assert not lost, f"docs pages no link from README.md or docs/README.md leads to: {lost}"


def test_the_readme_table_lists_every_notebook_core_and_appendix():
    targets = {Path(t).name for t in _links((ROOT / "README.md").read_text())}
    notebooks = [p.name for p in build_site.notebook_paths()]
    assert notebooks and not [n for n in notebooks if n not in targets]


def test_the_link_extractor_sees_links_but_not_code():
    text = "[a](x.md) and ![p](i.png), `[b](y.md)`\n```bash\n[c](z.md)\n```\n[d](w.ipynb#s)"
    assert _links(text) == ["x.md", "i.png", "w.ipynb#s"]


# ---------------------------------------------------------------------------
# commands
# ---------------------------------------------------------------------------


def test_every_command_of_the_pages_is_one_a_test_runs_or_checks():
    unknown = [f"{page}: {' '.join(words)}" for page, words in page_commands() if _test_of(words) is None]
    assert not unknown, "commands no test runs or checks (add them to COMMANDS with their test):\n" + "\n".join(unknown)


def test_the_tests_named_for_the_commands_exist():
    for _, test in COMMANDS:
        if test == "here":
            continue
        path, _, name = test.partition("::")
        assert (ROOT / path).is_file(), test
        if name:
            tree = ast.parse((ROOT / path).read_text())
            assert name in {f.name for f in ast.walk(tree) if isinstance(f, ast.FunctionDef)}, test


def test_the_command_reader_joins_splits_and_skips():
    text = (
        "```bash\nsource .venv/bin/activate   # the environment\n"
        "cd a && rm -r b\nX=1 python3 workbook.py test \\\n    -m 'not browser'\n"
        "cat >> f.py <<'END'\nc.x = 1\nEND\n```\n```python\nimport geomlib\n```\n"
    )
    assert commands(text) == [
        ["source", ".venv/bin/activate"],
        ["cd", "a"],
        ["rm", "-r", "b"],
        ["python3", "workbook.py", "test", "-m", "not browser"],
        ["cat", ">>", "f.py"],
    ]
    assert _test_of(["python3", "workbook.py", "frobnicate"]) is None and _test_of(["make", "all"]) is None


def _run_commands():
    """The words of every ``workbook.py run`` command of the pages, in code blocks and in
    inline code (the experiments table), but not its pattern ``run NOTEBOOK NAME=VALUE``."""
    found = [words for _, words in page_commands() if words[:3] == ["python3", "workbook.py", "run"]]
    for page in PAGES:
        found += [shlex.split(span) for span in re.findall(r"`(python3 workbook\.py run \d[^`]*)`", page.read_text())]
    return found


def test_commands_checked_here():
    subcommands = workbook_commands()
    from nbgrader.apps.nbgraderapp import NbGraderApp

    nbgrader = set(NbGraderApp.subcommands)
    for page, words in page_commands():
        command = " ".join(words)
        if words[:2] == ["python3", "workbook.py"]:
            assert words[2] in subcommands, f"{page}: {command}: workbook.py has no command {words[2]}"
        elif words[0] == "nbgrader":
            assert words[1] in nbgrader, f"{page}: {command}: nbgrader {NbGraderApp.version} has no {words[1]}"
        elif words[0] == "source" or words[:2] == [".venv/bin/python", "tools/strip_notebooks.py"]:
            assert (ROOT / words[1]).is_file() or words[1] == ".venv/bin/activate", command
        elif words[0] == ".venv/bin/python":
            assert (ROOT / words[1]).is_file(), f"{page}: {command}: no script {words[1]}"
        elif words[:2] == ["conda", "activate"]:
            assert f"name: {words[2]}" in (ROOT / "environment.yml").read_text(), command
        elif words[:2] == ["cp", "../notebooks/0[1-7]_*.ipynb"]:
            assert len(list((ROOT / "notebooks").glob("0[1-7]_*.ipynb"))) == 7, command
    pytest_args = [w[3:] for _, w in page_commands() if w[:3] == ["python3", "workbook.py", "test"]]
    for args in pytest_args:  # paths given to the test command exist
        for a in args:
            if a.endswith((".py", ".ipynb")):
                assert (ROOT / a).is_file(), f"workbook.py test {a}: no such file"


def workbook_commands():
    text = (ROOT / "workbook.py").read_text()
    (choices,) = re.findall(r"argv\[0\] not in \(([^)]*)\)", text)
    return set(ast.literal_eval(f"({choices})"))


@pytest.mark.parametrize("words", _run_commands(), ids=lambda w: " ".join(w[3:5]))
def test_every_run_command_passes_the_check_of_names_and_ranges(words, tmp_path):
    args = words[3:]
    notebook = run_notebook.find_notebook(args[0])
    values = run_notebook.read_assignments(notebook, run_notebook.notebook_parameters(notebook), args[1:], tmp_path)
    assert set(values) == {a.partition("=")[0] for a in args[1:]}


# ---------------------------------------------------------------------------
# the front page
# ---------------------------------------------------------------------------


def test_the_readme_is_a_front_page():
    words = len((ROOT / "README.md").read_text().split())
    assert words <= README_WORDS, f"README.md has {words} words; a front page has at most {README_WORDS}"


def test_the_picture_is_geomlibs_own_still_and_small(tmp_path):
    picture = ROOT / "docs" / "images" / "front.png"
    assert "](docs/images/front.png)" in (ROOT / "README.md").read_text()
    assert picture.stat().st_size < IMAGE_BYTES
    out = tmp_path / "front.png"
    subprocess.run([sys.executable, str(ROOT / "tools" / "make_front_image.py"), "--out", str(out)], check=True)
    assert out.read_bytes() == picture.read_bytes(), (
        "docs/images/front.png is not what tools/make_front_image.py makes now (the stills changed?): "
        "run python tools/make_front_image.py and commit the picture"
    )


def _stated_minutes(path):
    nb = nbformat.read(path, as_version=4)
    for cell in nb.cells[:3]:
        m = re.search(r"\*\*Time\*\*[^0-9]*(\d+)\s*min", cell.source) if cell.cell_type == "markdown" else None
        if m:
            return int(m.group(1))
    return None


def test_the_readme_gives_each_notebook_the_time_its_opening_block_states():
    rows = re.findall(
        r"^\| \[(\d\d) [^|]*\]\(notebooks/([^)]+)\)[^|]*\|[^|]*\| (\d+) min \|", (ROOT / "README.md").read_text(), re.M
    )
    assert [n for n, _, _ in rows] == [f"{i:02d}" for i in range(8)]
    for _, name, minutes in rows:
        stated = _stated_minutes(ROOT / "notebooks" / name)
        assert stated is None or stated == int(minutes), f"{name} says about {stated} minutes, the README {minutes}"


def test_the_readme_names_every_exercise_in_its_notebooks_row():
    """The "you will write" column: each exercise of geomlib.check, in the row of the notebook
    whose grade cells hold it, and no name that is not an exercise."""
    from geomlib import check

    exercises = {name for name in dir(check) if hasattr(getattr(check, name), "evaluate")}
    rows = re.findall(
        r"^\| \[\d\d [^|]*\]\(notebooks/([^)]+)\)[^|]*\| ([^|]*) \|", (ROOT / "README.md").read_text(), re.M
    )
    named = {}
    for notebook, written in rows:
        for name in re.findall(r"`(\w+)`", written):
            assert name in exercises, (
                f"the README says {notebook} asks for {name}, which is no exercise of geomlib.check"
            )
            named[name] = notebook
    graded = {}
    for path in build_site.notebook_paths():
        for cell in nbformat.read(path, as_version=4).cells:
            grade_id = cell.metadata.get("nbgrader", {}).get("grade_id", "")
            if cell.metadata.get("nbgrader", {}).get("solution") and grade_id in exercises:
                graded[grade_id] = path.name
    assert named == graded


def test_the_syllabus_gives_each_notebook_the_time_its_opening_block_states():
    """docs/syllabus.md's table and its total: the minutes of each notebook's **Time** line."""
    text = (ROOT / "docs" / "syllabus.md").read_text()
    rows = re.findall(r"^\| \[(\d\d)\]\(\.\./notebooks/([^)]+)\) \|[^|]*\| (\d+) \|$", text, re.M)
    assert [n for n, *_ in rows] == [f"{i:02d}" for i in range(8)]
    for _, name, stated in rows:
        assert int(stated) == _stated_minutes(ROOT / "notebooks" / name), name
    assert f"{sum(int(m) for *_, m in rows)} minutes" in " ".join(text.split())


def _time_lines():
    """{notebook number: minutes} from the cores' **Time** lines."""
    return {p.name[:2]: _stated_minutes(p) for p in sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))}


def test_the_readme_total_is_the_sum_of_the_notebooks_time_lines():
    times = _time_lines()
    assert None not in times.values(), f"a core without a Time line in minutes: {times}"
    (total,) = re.findall(
        r"the times below include the exercises, (\d+) minutes in all", (ROOT / "README.md").read_text()
    )
    assert int(total) == sum(times.values()), (
        f"the README says {total} minutes, the Time lines add up to {sum(times.values())}"
    )


def test_the_assignment_page_states_each_notebooks_points_and_time():
    """docs/assignment.md's table against the notebooks: every exercise and Discuss answer with the
    points of its nbgrader grade cells, no other, and the notebook's Time line."""
    import build_assignment

    text = (ROOT / "docs" / "assignment.md").read_text()
    rows = re.findall(r"^\| (\d) \| (\d\d) \| ([^|]*) \| ([^|]*) \| (\d+) min \|$", text, re.M)
    assert [task for task, *_ in rows] == [str(i) for i in range(1, 8)], "seven tasks, in order"
    times = _time_lines()
    for task, notebook, functions, answers, minutes in rows:
        (path,) = (ROOT / "notebooks").glob(f"{notebook}_*.ipynb")
        nb = nbformat.read(path, as_version=4)
        stated = {name: int(points) for name, points in re.findall(r"`(\w+)` \((\d+)\)", functions)}
        assert stated == build_assignment.exercise_points(nb), (
            f"task {task}: the functions' points differ from {path.name}"
        )
        stated = {name: int(points) for name, points in re.findall(r"`(\w+)` \((\d+)\)", answers)}
        assert stated == build_assignment.discussion_points(nb), (
            f"task {task}: the answers' points differ from {path.name}"
        )
        assert int(minutes) == times[notebook], f"task {task}: {minutes} min, {path.name} says {times[notebook]}"
    assert f"adds {times['00']} minutes" in text


def test_the_assignment_page_is_on_the_site_after_the_front_pages():
    pages = list(build_site.doc_pages())
    assert pages.index("docs/assignment.md") == pages.index("docs/README.md") + 1
    assert build_site.doc_pages()["docs/assignment.md"] == "assignment.html"
