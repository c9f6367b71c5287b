"""The website from the keyboard, in headless Chromium, pages opened from ``file://`` with
the network cut off (issue 32): a 3D view turns with the arrow keys, zooms with + and - and
comes back with 0; a precomputed slider moved from the keyboard is announced in the live
region with the value it shows.

The site is the one the session builds for tests/browser/test_site.py (or
GEOMLIB_SITE_DIR). The WCAG 2.1 AA audit of every page (axe-core and the page's own
structure, tests/browser/axe_audit.py) is in test_site.py, on the very page its offline
checks load, so that each page is opened once for both.
"""

import sys
from pathlib import Path

import lablib
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import axe_audit  # noqa: E402

pytestmark = [pytest.mark.browser, pytest.mark.slow]


def _open(browser, folder, name, views):
    context = axe_audit.offline_context(browser)
    page = context.new_page()
    errors = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto((folder / name).resolve().as_uri(), wait_until="load")
    return context, page, errors


def _view_page(pages):
    """The first page with a precomputed slider (its views and sliders are wired), else with a view."""
    with_sliders = [f for f, p in pages.items() if p.get("sliders")]
    with_views = [f for f, p in pages.items() if p.get("views")]
    return (with_sliders or with_views or [None])[0]


def test_a_view_turns_zooms_and_resets_from_the_keyboard(site, browser):
    folder, pages = site
    name = _view_page(pages)
    assert name, "no page has a live 3D view"
    context, page, errors = _open(browser, folder, name, pages[name]["views"])
    try:
        page.evaluate(axe_audit.JS_SETTLED, pages[name]["views"])
        box = page.locator(".geomlib-canvas").first
        box.scroll_into_view_if_needed()
        box.focus()
        assert page.evaluate("() => document.activeElement.classList.contains('geomlib-canvas')")
        canvas = box.locator("canvas")
        start = lablib.wait_for(lambda: lablib.stable_screenshot(canvas), 30)
        for key, what in (("ArrowRight", "turn"), ("ArrowUp", "turn"), ("+", "zoom"), ("-", "zoom")):
            before = lablib.stable_screenshot(canvas)
            page.keyboard.press(key)
            assert lablib.wait_for(
                lambda before=before: lablib.changed_fraction(before, lablib.stable_screenshot(canvas)) > 0.002, 15
            ), f"{key} does not {what} the view"
        page.keyboard.press("0")
        assert lablib.wait_for(lambda: lablib.changed_fraction(start, lablib.stable_screenshot(canvas)) < 0.002, 15), (
            "0 does not bring the view back to its first camera"
        )
        assert not errors, errors
    finally:
        context.close()


def test_a_slider_move_is_announced(site, browser):
    folder, pages = site
    name = next((f for f, p in pages.items() if p.get("sliders") and p.get("views")), None)
    assert name, "no page has a precomputed slider beside a view"
    context, page, errors = _open(browser, folder, name, pages[name]["views"])
    try:
        assert page.evaluate(axe_audit.JS_SETTLED, pages[name]["views"]), "the page did not settle"
        handle = page.locator(".widget-slider [role=slider]:not([aria-disabled=true])").first
        handle.scroll_into_view_if_needed()
        handle.focus()
        default = page.evaluate("() => document.activeElement.getAttribute('aria-valuetext')")
        page.keyboard.press("End")
        said = lambda: page.evaluate("() => document.getElementById('site-live').textContent")  # noqa: E731
        assert lablib.wait_for(lambda: said() != "", 10), "moving the slider announced nothing"
        now = page.evaluate("() => document.activeElement.getAttribute('aria-valuetext')")
        assert now != default and now in said(), f"the announcement {said()!r} does not give the value {now!r}"
        assert not errors, errors
    finally:
        context.close()
