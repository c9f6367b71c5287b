"""Fixtures of the browser tests: one JupyterLab server and one headless
Chromium for the whole session.

The server serves a temporary copy of notebooks/ (nothing is written into the
repository); the notebooks still import geomlib and find the shipped meshes
through the installed package (``geomlib.data_path``). Screenshots go to
build/screenshots/ (git-ignored).

Without /usr/bin/chromium the tests are skipped with a message saying how to
enable them, except on CI (environment variable CI set), where they fail.
"""

import fcntl
import json
import os
import shutil
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import lablib  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOK_DIR = Path(os.environ.get("GEOMLIB_NOTEBOOK_DIR", ROOT / "notebooks"))
SCREENSHOTS = ROOT / "build" / "screenshots"


def _on_ci():
    return os.environ.get("CI", "").strip().lower() not in ("", "0", "false", "no")


def _unavailable(reason):
    message = (
        f"browser tests skipped: {reason}. To run them install Chromium "
        "(`apt-get install chromium` on Debian/Ubuntu; the binary must be /usr/bin/chromium, "
        "or set GEOMLIB_CHROMIUM to another Chromium binary)."
    )
    if _on_ci():
        pytest.fail(
            f"CI is set but the browser tests cannot run: {reason}. "
            "Install Chromium (`apt-get install -y chromium`; .ci/run does this).",
            pytrace=False,
        )
    pytest.skip(message)


@pytest.fixture(scope="session")
def browser():
    if not (Path(lablib.CHROMIUM).exists() or shutil.which(lablib.CHROMIUM)):
        _unavailable(f"{lablib.CHROMIUM} is missing")
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        _unavailable("the Python package playwright is not installed (pip install -e '.[dev]')")
    with lablib.chromium_browser() as b:
        yield b


@pytest.fixture(scope="session")
def lab_server(browser):
    server = lablib.LabServer(NOTEBOOK_DIR)
    server.start()
    try:
        yield server
    finally:
        server.stop()


@pytest.fixture(scope="session")
def site(browser, tmp_path_factory):
    """The website, built once per session for every test that opens it (test_site.py,
    test_accessibility.py): (folder, {page file: its entry of pages.json}). GEOMLIB_SITE_DIR
    names a folder built by ``python3 workbook.py site`` to use instead."""
    sys.path.insert(0, str(ROOT / "tools"))
    import build_site

    given = os.environ.get("GEOMLIB_SITE_DIR")
    if given:
        folder = Path(given)
        assert (folder / "pages.json").exists(), f"GEOMLIB_SITE_DIR={given} holds no built site"
    elif os.environ.get("PYTEST_XDIST_WORKER"):
        # several worker processes: the first to get here builds the site into the run's shared
        # temporary folder, the others wait for it and read it (a build takes minutes of both cores)
        shared = tmp_path_factory.getbasetemp().parent
        folder = shared / "site"
        with open(shared / "site.lock", "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            if not (folder / "pages.json").exists():
                build_site.build(folder)
    else:
        folder = tmp_path_factory.mktemp("site")
        build_site.build(folder)
    pages = {p["file"]: p for p in json.loads((folder / "pages.json").read_text())}
    return folder, pages


@pytest.fixture
def screenshot_dir(request):
    name = request.node.callspec.params.get("notebook", request.node.name)
    folder = SCREENSHOTS / Path(str(name)).stem
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True, exist_ok=True)
    return folder
