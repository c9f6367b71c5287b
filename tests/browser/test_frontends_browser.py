"""The workbook in the front-ends `workbook.py` opens, as a newcomer meets them.

* Notebook 7 (``workbook.py notebook``): notebook 00 and notebook 05 (sliders)
  run top to bottom with no error output, every 3D view draws a picture, and
  the slider beside a view changes it. Notebook 7 swallows arrow keys on a
  focused slider, so the slider is moved with End (or Home when it starts at
  its maximum).
* First contact: the address `workbook.py lab` and `workbook.py notebook`
  open lands on notebook 00, with no dialog and no pop-up (such as
  JupyterLab's question about news) for a newcomer to dismiss. The server
  gets the settings workbook.py installs (and only those: its own
  installation-wide settings folder) and no user settings at all.

Screenshots: build/screenshots/NAME/.
"""

import importlib.util
from pathlib import Path

import lablib
import pytest

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOK_DIR = ROOT / "notebooks"
RUN_TIMEOUT = 180  # seconds for one notebook to run top to bottom
RENDER_TIMEOUT = 30  # seconds for a view to draw / react to a slider
WATCH = 25  # seconds a newcomer's page is watched for pop-ups (JupyterLab asks
# about news some 10-15 s after start-up when nothing answered it)

pytestmark = pytest.mark.browser


def _workbook():
    spec = importlib.util.spec_from_file_location("workbook", ROOT / "workbook.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


WORKBOOK = _workbook()


def _default_url_args(app):
    """The options of workbook.py's command line that choose the first page."""
    return [a for a in WORKBOOK.front_end_command(app, []) if ".default_url=" in a]


@pytest.fixture(scope="module")
def notebook7_server(browser):
    overrides = dict(WORKBOOK.LAB_OVERRIDES)
    # every cell attached to the page, so views below the fold render too
    overrides["@jupyterlab/notebook-extension:tracker"] = {"windowingMode": "none"}
    server = lablib.LabServer(NOTEBOOK_DIR, app="notebook", overrides=overrides, args=_default_url_args("notebook"))
    server.start()
    try:
        yield server
    finally:
        server.stop()


@pytest.fixture(scope="module")
def newcomer_lab_server(browser):
    server = lablib.LabServer(
        NOTEBOOK_DIR, app="lab", user_settings={}, overrides=WORKBOOK.LAB_OVERRIDES, args=_default_url_args("lab")
    )
    server.start()
    try:
        yield server
    finally:
        server.stop()


def _screenshots(name):
    folder = ROOT / "build" / "screenshots" / name
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def _drawn(png):
    distinct, covered = lablib.image_stats(png)
    return distinct >= 20 and covered >= 0.01


JS_OPEN_DOCUMENT = """
() => {
  const app = window.jupyterapp;
  const w = app && app.shell.currentWidget;
  return w && w.context ? w.context.path : null;
}
"""

# dialogs and notifications a newcomer would have to read or dismiss
JS_INTERRUPTIONS = """
() => [...document.querySelectorAll('.jp-Dialog, .Toastify__toast, .jp-Notification-Toast')]
  .filter(e => e.offsetParent !== null)
  .map(e => e.innerText.trim().slice(0, 200))
"""


def _first_contact(browser, server):
    """A page of ``server`` opened at the address workbook.py opens, once it shows a document."""
    page = browser.new_page(viewport=lablib.VIEWPORT)
    page.goto(f"{server.url}/?token={server.token}", wait_until="domcontentloaded", timeout=120_000)
    page.wait_for_function(JS_OPEN_DOCUMENT, timeout=120_000, polling=250)
    return page


def test_lab_and_notebook7_open_on_notebook_00_without_dialogs(browser, newcomer_lab_server, notebook7_server):
    # both front-ends watched over one window of WATCH seconds (each page for at least WATCH seconds
    # after it showed its document), rather than one window after the other
    servers = (newcomer_lab_server, notebook7_server)
    pages = {}
    try:
        for server in servers:
            pages[server.app] = _first_contact(browser, server)
        opened = {app: page.evaluate(JS_OPEN_DOCUMENT) for app, page in pages.items()}

        def interruptions():
            seen = {app: page.evaluate(JS_INTERRUPTIONS) for app, page in pages.items()}
            return {app: found for app, found in seen.items() if found}

        shown = lablib.wait_for(interruptions, WATCH, interval=0.5)
        for app, page in pages.items():
            page.screenshot(path=str(_screenshots(f"first_contact_{app}") / "page.png"))
    finally:
        for page in pages.values():
            lablib.shutdown_kernel(page)
            page.close()
    assert opened == {"lab": "00_getting_started.ipynb", "notebook": "00_getting_started.ipynb"}
    assert not shown, f"a newcomer has to dismiss: {shown}"


@pytest.mark.parametrize("notebook", ["01_uniform_laplace_curvature.ipynb", "05_explicit_smoothing.ipynb"])
def test_notebook_in_notebook7(notebook, browser, notebook7_server):
    screenshot_dir = _screenshots(f"notebook7_{Path(notebook).stem}")
    page = browser.new_page(viewport=lablib.VIEWPORT)
    try:
        lablib.open_notebook(page, notebook7_server, notebook)
        state = lablib.run_all(page, timeout_s=RUN_TIMEOUT)
        page.screenshot(path=str(screenshot_dir / "page.png"))
        assert not state.get("timeout"), f"{notebook}: {state['done']} of {state['code']} code cells ran in time"
        assert not state["errors"], (
            f"{notebook} has error outputs: {[(e['cell'], e['ename'], e['evalue']) for e in state['errors']]}"
        )
        assert state["done"] == state["code"]

        canvases = lablib.views(page, RENDER_TIMEOUT)
        assert canvases.count() >= 1, f"{notebook} shows no view in Notebook 7"
        for i in range(canvases.count()):
            shot = {}

            def drawn(canvas=canvases.nth(i)):
                shot["png"] = lablib.stable_screenshot(canvas)
                return _drawn(shot["png"])

            ok = lablib.wait_for(drawn, RENDER_TIMEOUT)
            (screenshot_dir / f"canvas{i}.png").write_bytes(shot["png"])
            assert ok, f"view {i} of {notebook} is blank in Notebook 7"

        found = lablib.find_slider(page, RENDER_TIMEOUT)
        assert found["found"], f"{notebook}: no slider beside a view"
        box_canvases = page.locator("[data-geomlib-box] .geomlib-canvas")
        before = [lablib.stable_screenshot(box_canvases.nth(i)) for i in range(box_canvases.count())]
        handle = page.locator("[data-geomlib-slider] .noUi-handle").first
        handle.scroll_into_view_if_needed()
        handle.focus()
        page.keyboard.press("Home" if found["now"] >= found["max"] else "End")
        moved = {}

        def changed():
            after = [lablib.stable_screenshot(box_canvases.nth(i)) for i in range(box_canvases.count())]
            moved["fraction"] = max(lablib.changed_fraction(a, b) for a, b in zip(before, after))
            moved["after"] = after
            return moved["fraction"] > 0.005

        ok = lablib.wait_for(changed, RENDER_TIMEOUT, interval=0.5)
        (screenshot_dir / "slider_after.png").write_bytes(moved["after"][0])
        assert ok, f"{notebook}: the slider '{found['description']}' changed {moved['fraction']:.2%} of the view"
        state = page.evaluate(lablib.JS_STATE)
        assert not state["errors"], f"the slider callback raised in Notebook 7: {state['errors']}"
    finally:
        lablib.shutdown_kernel(page)
        page.close()
