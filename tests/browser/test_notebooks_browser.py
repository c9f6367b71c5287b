"""Every notebook, run in JupyterLab in a real browser (headless Chromium).

For each core notebook notebooks/NN_*.ipynb (new ones are picked up automatically; the
appendices NNa_*.ipynb run under nbval and as pages of the website, tests/browser/test_site.py):

1. open it, run all cells, wait until every code cell has run and the kernel is idle;
2. no cell has an error output (stderr text such as tqdm's progress bars is fine);
3. every 3D view (``.geomlib-canvas``) shows a picture: not one flat colour;
4. the first slider sharing an ipywidgets box with a view, or else displayed
   by the same cell as a view (the convention is in geomlib/teaching/display/viewer.py), is
   moved with the keyboard and the picture changes;
5. where views are shown with ``side_by_side``, an orbit drag in the first one
   also turns the second (linked cameras).

Screenshots of the page and of every canvas: build/screenshots/NAME/.
"""

import os
import time
from pathlib import Path

import lablib
import pytest

ROOT = Path(__file__).resolve().parents[2]
# GEOMLIB_NOTEBOOK_DIR runs the same checks on another folder of notebooks
NOTEBOOK_DIR = Path(os.environ.get("GEOMLIB_NOTEBOOK_DIR", ROOT / "notebooks"))
NOTEBOOKS = sorted(p.name for p in NOTEBOOK_DIR.glob("[0-9][0-9]_*.ipynb"))
# cores whose lesson has no 3D view, or no slider beside one; the test holds that this stays true
WITHOUT_VIEWS = {"02_fundamental_forms.ipynb": "its pictures are plots; the exact H in 3D is in 02a"}
WITHOUT_SLIDER = {"00_getting_started.ipynb": "it shows a reader's mesh; the first slider comes in 01"}
RUN_TIMEOUT = 180  # seconds for one notebook to run top to bottom
RENDER_TIMEOUT = 30  # seconds for a view to show a picture / react to a slider

pytestmark = pytest.mark.browser


def _not_blank(png):
    distinct, covered = lablib.image_stats(png)
    return distinct >= 20 and covered >= 0.01, distinct, covered


def _format_errors(errors):
    return "\n\n".join(f"cell {e['cell']}: {e['ename']}: {e['evalue']}\n{e['traceback'][-2000:]}" for e in errors)


@pytest.mark.parametrize("notebook", NOTEBOOKS)
def test_notebook_in_browser(notebook, browser, lab_server, screenshot_dir):
    page = browser.new_page(viewport=lablib.VIEWPORT)
    console = []
    page.on("console", lambda m: console.append(f"{m.type}: {m.text}") if m.type in ("error", "warning") else None)
    page.on("pageerror", lambda e: console.append(f"pageerror: {e}"))
    try:
        lablib.open_notebook(page, lab_server, notebook)
        state = lablib.run_all(page, timeout_s=RUN_TIMEOUT)
        page.screenshot(path=str(screenshot_dir / "page.png"))

        # 1-2: ran to the end without error outputs
        assert not state.get("timeout"), (
            f"{notebook} did not finish within {RUN_TIMEOUT} s: {state['done']} of {state['code']} code cells ran"
        )
        assert not state["errors"], f"{notebook} has error outputs:\n{_format_errors(state['errors'])}"
        assert state["done"] == state["code"], f"only {state['done']} of {state['code']} code cells ran"

        # 3: every view shows a picture
        canvases = lablib.views(page, 5 if notebook in WITHOUT_VIEWS else RENDER_TIMEOUT)
        count = canvases.count()
        if notebook in WITHOUT_VIEWS:
            assert count == 0, f"{notebook} now shows a view: take it out of WITHOUT_VIEWS"
            return
        assert count >= 1, f"{notebook} shows no MeshView (.geomlib-canvas)"
        for i in range(count):
            canvas = canvases.nth(i)
            shot = {}

            def rendered(i=i, canvas=canvas):
                shot["png"] = lablib.stable_screenshot(canvas)
                return _not_blank(shot["png"])[0]

            ok = lablib.wait_for(rendered, RENDER_TIMEOUT)
            (screenshot_dir / f"canvas{i}.png").write_bytes(shot["png"])
            _, distinct, covered = _not_blank(shot["png"])
            assert ok, (
                f"view {i} of {notebook} looks blank: {distinct} colours, "
                f"{covered:.1%} of the pixels off the background"
            )

        # 4: a slider beside a view changes the picture
        found = lablib.find_slider(page, 5 if notebook in WITHOUT_SLIDER else RENDER_TIMEOUT)
        if notebook in WITHOUT_SLIDER:
            assert not found["found"], f"{notebook} now has a slider beside a view: take it out of WITHOUT_SLIDER"
            return
        assert found["found"], (
            f"{notebook}: no slider shares an ipywidgets box or a cell with a view; put them in one box, "
            "e.g. ipywidgets.VBox([slider, view.widget]), or display both from one cell (see geomlib/teaching/display/viewer.py)"
        )
        box_canvases = page.locator("[data-geomlib-box] .geomlib-canvas")
        before = [lablib.stable_screenshot(box_canvases.nth(i)) for i in range(box_canvases.count())]
        handle = page.locator("[data-geomlib-slider] .noUi-handle").first
        handle.scroll_into_view_if_needed()
        handle.focus()
        at_max = found["now"] is not None and found["max"] is not None and found["now"] >= found["max"]
        page.keyboard.press("Home" if at_max else "End")
        moved = {}

        def changed():
            moved["after"] = [lablib.stable_screenshot(box_canvases.nth(i)) for i in range(box_canvases.count())]
            moved["fraction"] = max(lablib.changed_fraction(a, b) for a, b in zip(before, moved["after"]))
            return moved["fraction"] > 0.005

        ok = lablib.wait_for(changed, RENDER_TIMEOUT, interval=0.5)
        for i, png in enumerate(moved["after"]):
            (screenshot_dir / f"slider_after{i}.png").write_bytes(png)
        page.screenshot(path=str(screenshot_dir / "page_after_slider.png"))
        assert ok, (
            f"{notebook}: moving the slider '{found['description']}' changed "
            f"{moved['fraction']:.2%} of the view's pixels"
        )
        state = page.evaluate(lablib.JS_STATE)
        assert not state["errors"], f"the slider callback raised:\n{_format_errors(state['errors'])}"

        # 5: linked cameras turn together (after the slider's work has finished)
        lablib.wait_for(lambda: page.evaluate(lablib.JS_STATE)["kernel"] == "idle", RUN_TIMEOUT)
        time.sleep(1.0)
        rows = page.locator(".geomlib-row")
        for r in range(rows.count()):
            views = rows.nth(r).locator(".geomlib-canvas")
            if views.count() < 2:
                continue
            first, second = views.nth(0), views.nth(1)
            turned = followed = False
            # a drag can miss while the page is still laying out; a shape that looks the same from
            # every side (a smooth sphere lit from the camera) shows no change when orbited, so the
            # last tries pan it (right button), which moves any shape in both linked views
            for button in ("left", "left", "right"):
                before_first = lablib.stable_screenshot(first)
                before_second = lablib.stable_screenshot(second)
                box = first.bounding_box()
                x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
                page.mouse.move(x, y)
                page.mouse.down(button=button)
                page.mouse.move(x + 90, y + 40, steps=10)
                page.mouse.up(button=button)
                turned = lablib.wait_for(
                    lambda: lablib.changed_fraction(before_first, lablib.stable_screenshot(first)) > 0.005, 10
                )
                if not turned:
                    continue
                followed = lablib.wait_for(
                    lambda: lablib.changed_fraction(before_second, lablib.stable_screenshot(second)) > 0.005,
                    RENDER_TIMEOUT,
                )
                break
            (screenshot_dir / f"row{r}_linked.png").write_bytes(second.screenshot())
            assert turned, f"{notebook}: neither an orbit nor a pan drag moved the first view of side_by_side row {r}"
            assert followed, (
                f"{notebook}: orbiting the first view of side_by_side row {r} "
                "did not turn the second (cameras not linked)"
            )
    finally:
        (screenshot_dir / "console.txt").write_text("\n".join(console))
        lablib.shutdown_kernel(page)
        page.close()
