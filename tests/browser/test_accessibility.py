"""The website against WCAG 2.1 AA, in headless Chromium, every page opened from
``file://`` with the network cut off (issue 32).

The site is the one the session builds for tests/browser/test_site.py (or
GEOMLIB_SITE_DIR). Every HTML page of it, whatever pages exist (core notebooks,
appendices, documentation, reference, index), settled (formulas typeset, views
drawn, slider states wired), is checked by:

1. axe-core 4.14.1 with its WCAG 2.0/2.1 A and AA rules: no serious or critical
   violation (tests/browser/axe_audit.py; axe comes pinned from the npm registry
   through the site builder's cached download);
2. the page's own structure: a skip link to ``<main>`` first in the Tab order,
   navigation bars labelled and outside ``<main>``, formulas out of the Tab order;
3. on pages with widgets: every slider named, announcing the value its read-out shows
   (a log slider's exponent is not what a reader sees) and, if disabled, out of the Tab
   order and announced disabled; every image with an alt that is not nbconvert's
   placeholder; every 3D view focusable, labelled, described by its text alternative
   (mesh, vertices, faces) and by the visible line naming its keys; a polite live region;
   slider tracks at 3:1 against the page; slider labels not cut under WCAG's text spacing.

A 3D view turns with the arrow keys, zooms with + and - and comes back with 0; a
precomputed slider moved from the keyboard is announced in the live region with the
value it shows.
"""

import json
import sys
from pathlib import Path

import lablib
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import axe_audit  # noqa: E402

pytestmark = [pytest.mark.browser, pytest.mark.slow]

PLACEHOLDER = "No description has been provided"

JS_PAGE = r"""
() => {
  const text = el => el ? el.textContent.replace(/\s+/g, ' ').trim() : '';
  const described = el => (el.getAttribute('aria-describedby') || '').split(/\s+/).filter(Boolean)
    .map(id => text(document.getElementById(id))).join(' ');
  const main = document.querySelector('main');
  const focusable = Array.from(document.querySelectorAll('a[href], button, input, select, textarea, [tabindex]'))
    .filter(el => el.tabIndex >= 0 && !el.disabled);
  const skip = document.querySelector('a.site-skip');
  const sliders = Array.from(document.querySelectorAll('[role=slider]')).map(h => {
    const widget = h.closest('.widget-slider');
    const target = widget && widget.querySelector('.noUi-target');
    return {name: h.getAttribute('aria-label') || text(document.getElementById(h.getAttribute('aria-labelledby'))),
            valuetext: h.getAttribute('aria-valuetext'), readout: text(widget && widget.querySelector('.widget-readout')),
            disabled: !!(target && target.hasAttribute('disabled')), tabindex: h.tabIndex,
            ariaDisabled: h.getAttribute('aria-disabled')};
  });
  const views = Array.from(document.querySelectorAll('.geomlib-canvas')).map(v => ({
    tabindex: v.tabIndex, label: v.getAttribute('aria-label') || '', described: described(v)}));
  const images = Array.from(document.querySelectorAll('img')).map(img => ({
    alt: img.getAttribute('alt'), decorative: !!img.closest('.geomlib-canvas'), src: img.src.slice(0, 40)}));
  const tracks = Array.from(document.querySelectorAll('.widget-slider .noUi-target')).map(
    t => getComputedStyle(t).backgroundColor);
  return {
    skip: skip ? {href: skip.getAttribute('href'), first: focusable[0] === skip,
                  target: !!document.querySelector(skip.getAttribute('href'))} : null,
    main: !!main,
    navs: Array.from(document.querySelectorAll('nav')).map(n => ({label: n.getAttribute('aria-label'),
                                                                  inMain: !!(main && main.contains(n))})),
    formulaStops: Array.from(document.querySelectorAll('.MathJax_CHTML, .MathJax, .mjx-chtml'))
      .filter(m => m.tabIndex >= 0).length,
    live: document.querySelectorAll('[aria-live=polite]').length,
    tabStops: focusable.length,
    beforeSlider: (() => { const i = focusable.findIndex(el => el.getAttribute('role') === 'slider'); return i; })(),
    sliders: sliders, views: views, images: images, tracks: tracks,
  };
}
"""

# WCAG 1.4.12's spacing; then every slider label whose text no longer fits its box
JS_SPACED_LABELS_CUT = """
() => {
  const style = document.createElement('style');
  style.textContent = '* { line-height: 1.5 !important; letter-spacing: 0.12em !important; '
    + 'word-spacing: 0.16em !important; } p { margin-bottom: 2em !important; }';
  document.head.appendChild(style);
  return new Promise(done => requestAnimationFrame(() => {
    const cut = Array.from(document.querySelectorAll('.widget-slider .widget-label'))
      .filter(l => l.scrollWidth > l.clientWidth + 1).map(l => l.textContent);
    style.remove();
    done(cut);
  }));
}
"""


def _contrast(css_colour):
    """Contrast of an ``rgb(r, g, b)`` colour against the white page."""
    rgb = [float(x) / 255 for x in css_colour[css_colour.index("(") + 1 : -1].split(",")[:3]]
    lin = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in rgb]
    lum = 0.2126 * lin[0] + 0.7152 * lin[1] + 0.0722 * lin[2]
    return 1.05 / (lum + 0.05)


def _open(browser, folder, name, views):
    context = axe_audit.offline_context(browser)
    page = context.new_page()
    errors = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto((folder / name).resolve().as_uri(), wait_until="load")
    return context, page, errors


def _problems(name, info, cut, widgets):
    """What the page's structure gets wrong, as sentences."""
    out = []
    skip = info["skip"]
    if not skip or not skip["target"] or not skip["first"]:
        out.append(f"no skip link to the content as its first Tab stop ({skip})")
    if not info["main"]:
        out.append("no <main>")
    for nav in info["navs"]:
        if not nav["label"]:
            out.append("a navigation bar without aria-label")
    if info["formulaStops"]:
        out.append(f"{info['formulaStops']} formulas are Tab stops")
    for img in info["images"]:
        if img["decorative"]:
            if img["alt"] != "":
                out.append(f"a frozen view picture {img['src']} is not marked decorative (alt='')")
        elif not img["alt"] or PLACEHOLDER in img["alt"]:
            out.append(f"an image without a real alt text: {img['alt']!r} ({img['src']}...)")
    for s in info["sliders"]:
        if not s["name"]:
            out.append(f"a slider without a name (read-out {s['readout']!r})")
        if s["disabled"] and (s["tabindex"] >= 0 or s["ariaDisabled"] != "true"):
            out.append(f"disabled slider {s['name']!r} is a Tab stop or not announced disabled")
        if not s["disabled"] and s["readout"] and s["valuetext"] != s["readout"]:
            out.append(f"slider {s['name']!r} announces {s['valuetext']!r}, its read-out shows {s['readout']!r}")
    for v in info["views"]:
        if v["tabindex"] != 0 or not v["label"]:
            out.append(f"a 3D view that cannot take focus or has no label: {v}")
        if " vertices and " not in v["described"] or "arrow keys" not in v["described"]:
            out.append(f"3D view {v['label']!r} not described by its alt text and its keys: {v['described']!r}")
    if widgets and not info["live"]:
        out.append("no polite live region")
    for colour in info["tracks"]:
        if _contrast(colour) < 3.0:
            out.append(f"a slider track {colour} at {_contrast(colour):.2f}:1 against the page")
    if cut:
        out.append(f"slider labels cut under WCAG text spacing: {cut}")
    return [f"{name}: {p}" for p in out]


def test_every_page_meets_wcag_aa_offline(site, browser):
    folder, pages = site
    names = axe_audit.pages_of(folder)
    assert "index.html" in names and len(names) >= len(pages)
    violations, problems, totals = [], [], {}
    for name in names:
        views = pages.get(name, {}).get("views", 0)
        context, page, errors = _open(browser, folder, name, views)
        try:
            found = axe_audit.audit(page, views)
            info = page.evaluate(JS_PAGE)
            cut = page.evaluate(JS_SPACED_LABELS_CUT)
        finally:
            context.close()
        by_impact, _ = axe_audit.counts(found)
        totals[name] = dict(by_impact) | {"tab stops": info["tabStops"], "to the first slider": info["beforeSlider"]}
        for v in found:
            if v["impact"] in ("serious", "critical"):
                where = "; ".join(n["target"] for n in v["nodes"][:3])
                violations.append(f"{name}: {v['id']} ({v['impact']}, {len(v['nodes'])} nodes: {where}) {v['help']}")
        widgets = bool(info["sliders"] or info["views"])
        problems += _problems(name, info, cut, widgets)
        problems += [f"{name}: uncaught {e}" for e in errors]
    print("axe violations per page (nodes by impact), Tab stops:", json.dumps(totals, indent=1))
    assert not (violations or problems), "\n".join(
        ["axe-core, serious or critical:", *violations, "the page's own checks:", *problems]
    )


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
