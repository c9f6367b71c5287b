"""The workbook as a static website (tools/build_site.py), in headless Chromium
with the network cut off.

The site is built once per session into a temporary folder (every notebook
executed; a few minutes), or taken from GEOMLIB_SITE_DIR when that names a
folder built by ``python3 workbook.py site``. Every page is opened once, from
``file://``, for both its offline checks and its accessibility audit (below); the
index and the pages with precomputed sliders are opened again from a static file
server on a loopback port. Every request that goes anywhere else is aborted and
recorded, and the tests assert that there was none.

On every notebook's page:
1. no request left the machine, and no file of the site is missing;
2. every 3D view's canvas shows a picture (not one flat colour), as many
   canvases as the build counted live views;
3. an orbit drag on every canvas changes its picture (no kernel involved), or, for a
   shape that looks the same from every side, a pan drag does;
   (without WebGL, the still pictures are shown instead: a separate test);
4. the formulas are typeset by the MathJax served from the site: MathJax
   output is present, no TeX error, no ``$$`` left in the text;
5. every control that needs a kernel is disabled, and a note says so; the sliders whose
   states the build recorded are enabled, with a note that they snap; widget labels use
   JupyterLab's interface font (not the browser's default serif);
6. no still picture shows beside a live view that drew (the stills are for browsers
   without WebGL, and for pythreejs' frozen views, which are drawn too);
7. no console error and no uncaught exception;
8. no cell raised an error while the notebook ran for the site.

On the pages with precomputed sliders (01, 04, 05, 06, 07; the ones the course needs are
listed in LIVE_SLIDERS), every such slider, moved with the keyboard, changes its
cell's 3D view and read-out, and moved back restores the first picture exactly.

The index lists every notebook in reading order.

Every HTML page of the site (core notebooks, appendices, documentation, reference, index,
and whatever other page the folder holds), settled (formulas typeset, views drawn, slider
states wired), against WCAG 2.1 AA (issue 32), before the checks above touch it:

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
   slider tracks at 3:1 against the page; slider labels not cut under WCAG's text spacing;
4. no uncaught exception.

The site as a whole (no browser needed, on the same build): a page for every notebook
(core and appendix), every markdown page (README, docs/) and the reference; previous/next
links between neighbours in reading order, both ways; every relative link and picture of
every page leads to a file of the site (a notebook's ``.ipynb`` link became its ``.html``);
the reference lists every public name of geomlib; the folder within 60 MB.
Screenshots: build/screenshots/site/.
"""

import functools
import http.server
import json
import re
import sys
import threading
from pathlib import Path

import lablib
import nbformat
import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))

import axe_audit  # noqa: E402
import build_site  # noqa: E402

NOTEBOOKS = [p.name for p in build_site.notebook_paths()]  # core and appendix, in reading order
NOTEBOOK_OF = {Path(n).stem + ".html": n for n in NOTEBOOKS}  # page file -> its notebook
SITE_BYTES = 60_000_000  # the whole folder (issue 30)
SCREENSHOTS = ROOT / "build" / "screenshots" / "site"
LOAD_TIMEOUT = 90  # seconds for a page's views and formulas to appear
LOCAL_SCHEMES = ("file:", "data:", "blob:")

pytestmark = [pytest.mark.browser, pytest.mark.slow]

#: sliders that must move their views on the site (their descriptions), per page
LIVE_SLIDERS = {
    "01_uniform_laplace_curvature.html": {"jitter"},
    "04_spectral_reconstruction.html": {"i", "k"},
    "05_explicit_smoothing.html": {"τ / ℓ²", "iterations"},
    "06_implicit_smoothing.html": {"τ / ℓ²", "iterations"},
    "07_denoising_evaluation.html": {"sigma", "iterations"},
}


@pytest.fixture(scope="session")
def site_url(site):
    handler = functools.partial(_QuietHandler, directory=str(site[0]))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_port}/"
    server.shutdown()
    server.server_close()


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass


class OfflinePage:
    """A page in a fresh browser context in which only ``base`` and local URLs load."""

    def __init__(self, browser, base):
        self.base = base
        self.context = browser.new_context(viewport=lablib.VIEWPORT)
        self.outside, self.missing, self.errors = [], [], []
        self.context.route("**/*", self._route)
        self.page = self.context.new_page()
        self.page.on("request", self._request)
        self.page.on("response", lambda r: self.missing.append(f"{r.status} {r.url}") if r.status >= 400 else None)
        # from file:// a missing file is a failed request, not a response with a status
        self.page.on(
            "requestfailed", lambda r: self.missing.append(f"{r.failure} {r.url}") if self._local(r.url) else None
        )
        self.page.on("console", lambda m: self.errors.append(m.text) if m.type == "error" else None)
        self.page.on("pageerror", lambda e: self.errors.append(f"uncaught: {e}"))

    def _local(self, url):
        return url.startswith(self.base) or url.startswith(LOCAL_SCHEMES)

    def _request(self, request):
        if not self._local(request.url):
            self.outside.append(request.url)

    def _route(self, route):
        if self._local(route.request.url):
            route.continue_()
        else:
            route.abort("internetdisconnected")

    def close(self):
        self.context.close()


JS_MATH_DONE = """
() => new Promise(done => {
  if (!window.MathJax || !MathJax.Hub) { done(false); return; }
  MathJax.Hub.Queue(() => done(true));
})
"""

JS_MATH = """
() => {
  const formulas = document.querySelectorAll('script[type^="math/tex"]').length;
  const text = Array.from(document.querySelectorAll('.jp-MarkdownOutput, .jp-RenderedMarkdown'))
    .map(e => e.innerText).join('\\n');
  return {
    formulas: formulas,
    typeset: document.querySelectorAll('.MathJax_CHTML').length,
    errors: document.querySelectorAll('.mjx-merror, .MathJax_Error').length,
    raw: (text.match(/\\$\\$/g) || []).length,
  };
}
"""

JS_CONTROLS = r"""
() => {
  const sliders = Array.from(document.querySelectorAll('.widget-slider, .widget-dropdown, .widget-toggle-buttons, .widget-checkbox, .widget-button'));
  const enabled = sliders.filter(el => {
    const inputs = el.querySelectorAll('input, select, button, .noUi-target, .slider');
    return Array.from(inputs).some(i => !(i.disabled || i.hasAttribute('disabled')));
  });
  const bare = s => s.replace(/["'\s]/g, '');  // the same list of families, however quoted
  const ui = bare(getComputedStyle(document.body).getPropertyValue('--jp-ui-font-family'));
  const labels = Array.from(document.querySelectorAll('.widget-label, .widget-readout, .widget-html-content'));
  const fonts = new Set(labels.map(el => bare(getComputedStyle(el).fontFamily)));
  return {controls: sliders.length, enabled: enabled.length,
          notes: document.querySelectorAll('.site-kernel-note').length,
          snap_notes: document.querySelectorAll('.site-snap-note').length,
          ui: ui, fonts: Array.from(fonts), labels: labels.length};
}
"""


# run the page's own check that reveals a still where its view did not draw (normally
# 30 s after loading); the number of stills then shown
JS_SHOWN_STILLS = """
() => Array.from(document.querySelectorAll('img.site-still')).filter(img => img.getClientRects().length > 0).length
"""
JS_REVEAL_STILLS = "() => { window.siteRevealStills(false); return (" + JS_SHOWN_STILLS + ")(); }"

# mark the element of every precomputed slider (data-site-slider = its model id) and
# its cell's output area (data-site-cell-<model id>); the sliders' descriptions, values and default
JS_MARK_SLIDERS = """
async () => {
  const out = [];
  for (const group of window.siteStates) {
    for (const s of group.sliders) {
      const views = await Promise.all(Object.values(s.model.views));
      const el = views.map(v => v.el).find(el => el.isConnected);
      el.setAttribute('data-site-slider', s.model_id);
      el.closest('.jp-OutputArea-output').setAttribute('data-site-cell-' + s.model_id, '');  // a cell has several
      out.push({id: s.model_id, description: s.description, values: s.values, default: s.default});
    }
  }
  return out;
}
"""


def _not_blank(png):
    distinct, covered = lablib.image_stats(png)
    return distinct >= 20 and covered >= 0.01


def _shot_if(canvas, accept):
    png = lablib.stable_screenshot(canvas)
    return png if accept(png) else None


def _check_canvases(page, expected, shots):
    """Every canvas drawn and turned by a drag; returns the number of canvases."""
    canvases = page.locator("canvas")
    assert lablib.wait_for(lambda: canvases.count() >= expected, LOAD_TIMEOUT), (
        f"{canvases.count()} canvases appeared; the build saved {expected} live views"
    )
    for i in range(canvases.count()):
        canvas = canvases.nth(i)
        canvas.scroll_into_view_if_needed()
        canvas.hover()  # a view frozen to a picture comes back to life when the mouse enters
        before = lablib.wait_for(lambda canvas=canvas: _shot_if(canvas, _not_blank), 30)
        assert before, f"canvas {i} stays blank"
        (shots / f"canvas{i}.png").write_bytes(before)
        box = canvas.bounding_box()
        x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
        after = None
        # an orbit drag; a view of a shape that looks the same from every side (a smooth
        # sphere, lit from the camera) shows no change when orbited, so then a pan drag,
        # which moves any shape across the canvas
        for button in ("left", "right"):
            page.mouse.move(x, y)
            page.mouse.down(button=button)
            page.mouse.move(x + 90, y + 25, steps=12)
            page.mouse.up(button=button)
            after = lablib.wait_for(
                lambda canvas=canvas, before=before: _shot_if(
                    canvas, lambda png: lablib.changed_fraction(before, png) > 0.01
                ),
                20 if button == "left" else 10,
            )
            if after:
                break
        assert after, f"neither an orbit nor a pan drag on canvas {i} changes its picture"
        (shots / f"canvas{i}-dragged.png").write_bytes(after)
    return canvases.count()


def _offline_checks(view, notebook, pages):
    """The checks 1-8 above on ``view``, the loaded page of ``notebook``; raises AssertionError."""
    name = Path(notebook).stem + ".html"
    shots = SCREENSHOTS / Path(notebook).stem
    shots.mkdir(parents=True, exist_ok=True)
    page = view.page
    assert page.evaluate(JS_MATH_DONE), "MathJax did not load"
    math = page.evaluate(JS_MATH)
    markdown = "\n".join(
        c.source for c in nbformat.read(build_site.NOTEBOOKS / notebook, 4).cells if c.cell_type == "markdown"
    )
    if re.search(r"\$[^$\s][^$]*\$", markdown):
        assert math["formulas"] > 0, "the notebook has formulas but MathJax found none"
    assert math["typeset"] >= math["formulas"], f"MathJax typeset {math['typeset']} of {math['formulas']} formulas"
    assert math["errors"] == 0, f"{math['errors']} formulas show a TeX error"
    assert math["raw"] == 0, f"{math['raw']} '$$' left untypeset in the text"

    _check_canvases(page, pages[name]["views"], shots)

    assert page.evaluate(JS_REVEAL_STILLS) == 0, "still pictures shown beside 3D views that drew"  # issue 23

    controls = page.evaluate(JS_CONTROLS)
    live = len(pages[name]["sliders"])
    assert controls["enabled"] == live, f"{controls['enabled']} controls usable without a kernel, {live} precomputed"
    if controls["controls"] > live:
        assert controls["notes"] > 0, "controls are shown without the note that they need JupyterLab"
    if live:
        assert controls["snap_notes"] > 0, "precomputed sliders are shown without the note that they snap"
    if controls["labels"]:  # widget text in JupyterLab's interface font, as in the workbook itself
        assert controls["ui"], "the page does not define JupyterLab's --jp-ui-font-family"
        assert controls["fonts"] == [controls["ui"]], f"widget labels in {controls['fonts']}, not {controls['ui']}"
    page.screenshot(path=str(shots / "page.png"))
    assert not view.outside, f"requests to the network: {view.outside}"
    assert not view.missing, f"files missing from the site: {view.missing}"
    assert not view.errors, "console errors:\n" + "\n".join(view.errors)


def _audit(view, name, pages):
    """axe's violations on the settled page, its structure (axe_audit.JS_PAGE) and the slider
    labels cut under WCAG's text spacing."""
    found = axe_audit.audit(view.page, pages.get(name, {}).get("views", 0))
    return found, view.page.evaluate(axe_audit.JS_PAGE), view.page.evaluate(axe_audit.JS_SPACED_LABELS_CUT)


def _visit(browser, folder, pages, name):
    """Open page ``name`` of the site from ``file://`` once, offline, and run on it the WCAG audit
    and, on a notebook's page, the offline checks (after the audit, which sees the page as a
    reader first does): {"audit": (violations, structure, cut labels) or the exception it
    raised, "offline": None or the exception, "uncaught": the page's uncaught exceptions}."""
    view = OfflinePage(browser, folder.resolve().as_uri() + "/")
    outcome = {"offline": None}
    try:
        try:
            view.page.goto((folder / name).resolve().as_uri(), wait_until="load")
            outcome["audit"] = _audit(view, name, pages)
        except Exception as error:  # kept for the tests of this page to raise
            outcome["audit"] = error
        notebook = NOTEBOOK_OF.get(name)
        if notebook:
            try:
                _offline_checks(view, notebook, pages)
            except Exception as error:
                outcome["offline"] = error
        outcome["uncaught"] = [e for e in view.errors if e.startswith("uncaught: ")]
    finally:
        view.close()
    return outcome


def _raised(result):
    """``result``, or what a visit's check raised, raised here."""
    if isinstance(result, BaseException):
        raise result
    return result


@pytest.fixture(scope="module")
def visited(site, browser):
    """``visited(name)``: the outcome of :func:`_visit` of page ``name``, which opens the page the
    first time a test asks for it; so a notebook's page loads once for its offline test and
    its accessibility test, in whatever order they run."""
    folder, pages = site
    done = {}

    def visit(name):
        if name not in done:
            done[name] = _visit(browser, folder, pages, name)
        return done[name]

    return visit


@pytest.mark.parametrize("notebook", NOTEBOOKS)
def test_page_offline(notebook, site, visited):
    _, pages = site
    name = Path(notebook).stem + ".html"
    assert name in pages, f"{name} was not built"
    _raised(visited(name)["offline"])
    assert not pages[name]["errors"], "cells raised errors while the site was built:\n" + "\n".join(
        pages[name]["errors"]
    )


def test_index_lists_pages_in_order(site, site_url, browser):
    folder, pages = site
    view = OfflinePage(browser, site_url)
    try:
        view.page.goto(site_url + "index.html")
        links = view.page.eval_on_selector_all("ol a", "els => els.map(a => a.getAttribute('href'))")
        assert links == [Path(n).stem + ".html" for n in NOTEBOOKS]
        items = view.page.eval_on_selector_all("ol li", "els => els.map(e => e.innerText)")
        for name, item in zip(links, items):  # relative links to files that exist
            assert "/" not in name and (folder / name).is_file()
            assert f"({pages[name]['views']} live 3D view" in item, item
        view.page.goto(site_url + links[0])
        nav = view.page.eval_on_selector_all("nav.site-nav a", "els => els.map(a => a.getAttribute('href'))")
        assert "index.html" in nav and (len(links) == 1 or links[1] in nav)
        assert not view.outside and not view.missing and not view.errors
        # the guard itself: a request to the network is recorded and fails
        reached = view.page.evaluate("() => fetch('https://example.org/').then(() => true, () => false)")
        assert view.outside == ["https://example.org/"] and reached is False
    finally:
        view.close()


def test_page_from_file_url(site, visited):
    """The folder works without any server: the first page with views, opened from file://
    (the visit test_page_offline checks: canvases drawn, nothing fetched from outside)."""
    _, pages = site
    name = next((f for f, p in pages.items() if p["views"]), None)
    assert name, "no page has a live 3D view"
    _raised(visited(name)["offline"])


NO_WEBGL = """
const getContext = HTMLCanvasElement.prototype.getContext;
HTMLCanvasElement.prototype.getContext = function (kind, ...rest) {
  return /webgl/.test(kind) ? null : getContext.call(this, kind, ...rest);
};
"""


def test_stills_show_without_webgl(site, site_url, browser):
    """In a browser without WebGL every 3D view's still picture is shown instead."""
    _, pages = site
    name = next((f for f, p in pages.items() if p["views"]), None)
    assert name, "no page has a live 3D view"
    view = OfflinePage(browser, site_url)
    try:
        view.context.add_init_script(NO_WEBGL)
        view.page.goto(site_url + name, wait_until="load")
        stills = view.page.locator("img.site-still")
        assert stills.count() > 0, "the page holds no still pictures of its views"
        assert lablib.wait_for(lambda: view.page.evaluate(JS_SHOWN_STILLS) == stills.count(), 30), (
            f"{view.page.evaluate(JS_SHOWN_STILLS)} of {stills.count()} stills shown"
        )
        for i in range(stills.count()):
            assert _not_blank(lablib.stable_screenshot(stills.nth(i))), f"still {i} is blank"
        assert not view.outside, f"requests to the network: {view.outside}"
    finally:
        view.close()


def _pictures(canvases, drawn=lambda png: True):
    """Screenshots of the cell's canvases, each ``drawn`` (a frozen view comes back when hovered).
    A moved state may be nearly empty: a large implicit step collapses the mesh to a speck."""
    shots = []
    for i in range(canvases.count()):
        canvas = canvases.nth(i)
        canvas.scroll_into_view_if_needed()
        canvas.hover()
        png = lablib.wait_for(lambda canvas=canvas: _shot_if(canvas, drawn), 30)
        assert png, f"canvas {i} of the slider's cell stays blank"
        shots.append(png)
    return shots


def _press(page, handle, key, slider_id, index):
    handle.press(key)
    at = f"() => window.siteStates.flatMap(g => g.sliders).find(s => s.model_id === '{slider_id}').current"
    assert lablib.wait_for(lambda: page.evaluate(at) == index, 20), f"{key}: the slider is at state {page.evaluate(at)}"


@pytest.mark.parametrize("name", sorted(LIVE_SLIDERS))
def test_precomputed_sliders_move_the_views(name, site, site_url, browser):
    """Every precomputed slider: moved, its cell's view and read-out change; moved back, the
    first picture and text return exactly. Offline, no console error."""
    _, pages = site
    assert name in pages, f"{name} was not built"
    recorded = {s["description"] for s in pages[name]["sliders"]}
    assert LIVE_SLIDERS[name] <= recorded, f"not precomputed: {LIVE_SLIDERS[name] - recorded}"
    shots = SCREENSHOTS / (Path(name).stem + "-sliders")
    shots.mkdir(parents=True, exist_ok=True)
    view = OfflinePage(browser, site_url)
    try:
        page = view.page
        page.goto(site_url + name, wait_until="load")
        ready = "() => document.body.getAttribute('data-site-states')"
        assert lablib.wait_for(lambda: page.evaluate(ready) == "ready", LOAD_TIMEOUT), "the sliders were not wired"
        sliders = page.evaluate(JS_MARK_SLIDERS)
        assert len(sliders) == len(pages[name]["sliders"])
        for s in sliders:
            cell = page.locator(f"[data-site-cell-{s['id']}]")
            canvases = cell.locator("canvas")
            assert lablib.wait_for(lambda: canvases.count() > 0, LOAD_TIMEOUT), f"{s['description']}: no view"
            before, text = _pictures(canvases, _not_blank), cell.inner_text()
            handle = page.locator(f'[data-site-slider="{s["id"]}"] .noUi-handle')
            handle.focus()
            last, d = len(s["values"]) - 1, s["default"]
            far, key, back = (last, "End", "ArrowLeft") if d < last else (0, "Home", "ArrowRight")
            _press(page, handle, key, s["id"], far)
            moved = lablib.wait_for(
                lambda: max(lablib.changed_fraction(a, b) for a, b in zip(before, _pictures(canvases))) > 0.002, 20
            )
            assert moved, f"{s['description']} moved to {s['values'][far]}: its view did not change"
            assert cell.inner_text() != text, f"{s['description']} moved: its read-out did not change"
            for i, png in enumerate(_pictures(canvases)):
                (shots / f"{s['description'].replace('/', '')}-{i}-moved.png").write_bytes(png)
            for j in range(abs(far - d)):  # one computed value per key press, back to the default
                _press(page, handle, back, s["id"], far - j - 1 if far > d else far + j + 1)
            after = lablib.wait_for(
                lambda: (
                    (now := _pictures(canvases))
                    and all(lablib.changed_fraction(a, b) == 0 for a, b in zip(before, now))
                    and now
                ),
                20,
            )
            assert after, f"{s['description']} moved back: the first picture did not return"
            assert cell.inner_text() == text, f"{s['description']} moved back: the read-out differs"
        assert not view.outside, f"requests to the network: {view.outside}"
        assert not view.missing, f"files missing from the site: {view.missing}"
        assert not view.errors, "console errors:\n" + "\n".join(view.errors)
    finally:
        view.close()


# ---------------------------------------------------------------------------
# the site as a whole: pages, reading order, links, reference, size
# ---------------------------------------------------------------------------

NAV = re.compile(r'<nav[^>]*class="site-nav[^"]*"[^>]*>(.*?)</nav>', re.S)
HREF = re.compile(r'(?:href|src)="([^"]*)"')


def _order():
    """The page files the site must have, in reading order."""
    docs = list(build_site.doc_pages().values())
    return [Path(n).stem + ".html" for n in NOTEBOOKS] + docs + [build_site.REFERENCE]


def test_a_page_for_every_notebook_docs_page_and_the_reference(site):
    folder, pages = site
    assert list(pages) == _order()
    assert [p for p in _order() if not (folder / p).is_file()] == []


def test_previous_and_next_link_neighbours_both_ways(site):
    folder, _ = site
    order = _order()
    for i, name in enumerate(order):
        navs = NAV.findall((folder / name).read_text(encoding="utf-8"))
        assert len(navs) == 2, f"{name}: {len(navs)} navigation bars, not one above and one below"
        for nav in navs:
            links = HREF.findall(nav)
            want = [order[j] for j in (i - 1, i + 1) if 0 <= j < len(order)]
            assert "index.html" in links and all(w in links for w in want), f"{name}: {links}, wanted {want}"
            assert set(links) <= {"index.html", *want}, f"{name}: {links}"


def test_every_link_of_every_page_leads_into_the_site(site):
    folder, _ = site
    for page in sorted(folder.glob("*.html")):
        text = page.read_text(encoding="utf-8")
        broken = set()
        for target in HREF.findall(text):
            if not target or re.match(r"^([a-z][a-z0-9+.-]*:|#|//)", target):
                continue
            path = target.partition("#")[0].partition("?")[0]
            if path and not (folder / path).is_file():
                broken.add(target)
        assert not broken, f"{page.name} links to files the site does not have: {sorted(broken)[:5]}"
        assert not re.search(r'href="[^"#:]*\.(ipynb|md)(#[^"]*)?"', text), f"{page.name} links to a notebook or .md"


def test_the_reference_lists_every_public_name(site):
    folder, _ = site
    import geomlib

    text = (folder / build_site.REFERENCE).read_text(encoding="utf-8")
    missing = [name for name in geomlib.__all__ if f'id="{name}"' not in text]
    assert not missing, f"the reference has no entry for {missing}"
    assert "<html lang=" in text and not re.search(r'(?:src|href)="(?:https?:)?//[^"]*\.(js|css)', text)


def test_the_site_stays_within_60_mb(site):
    folder, pages = site
    size = build_site.folder_size(folder)
    biggest = sorted(pages.values(), key=lambda p: -p.get("bytes", 0))[:3]
    assert size <= SITE_BYTES, f"the site is {size / 1e6:.1f} MB; largest pages: " + ", ".join(
        f"{p['file']} {p['bytes'] / 1e6:.1f} MB" for p in biggest
    )


# ---------------------------------------------------------------------------
# every page against WCAG 2.1 AA, on the page the offline test loads
# ---------------------------------------------------------------------------

AUDITED = [*_order(), "index.html"]  # the pages named by a test of their own


def _assert_accessible(name, outcome):
    found, info, cut = _raised(outcome["audit"])
    by_impact, _ = axe_audit.counts(found)
    totals = dict(by_impact) | {"tab stops": info["tabStops"], "to the first slider": info["beforeSlider"]}
    print(f"{name}: axe violations (nodes by impact), Tab stops:", json.dumps(totals))
    violations = [
        f"{name}: {v['id']} ({v['impact']}, {len(v['nodes'])} nodes: "
        + "; ".join(n["target"] for n in v["nodes"][:3])
        + f") {v['help']}"
        for v in found
        if v["impact"] in ("serious", "critical")
    ]
    problems = axe_audit.problems(name, info, cut, bool(info["sliders"] or info["views"]))
    problems += [f"{name}: {e}" for e in outcome["uncaught"]]
    assert not (violations or problems), "\n".join(
        ["axe-core, serious or critical:", *violations, "the page's own checks:", *problems]
    )


@pytest.mark.parametrize("name", AUDITED)
def test_page_meets_wcag_aa_offline(name, site, visited):
    folder, _ = site
    assert (folder / name).is_file(), f"{name} was not built"
    _assert_accessible(name, visited(name))


def test_every_other_page_meets_wcag_aa_offline(site, visited):
    """Whatever other HTML page the folder holds is audited too."""
    folder, pages = site
    names = axe_audit.pages_of(folder)
    assert "index.html" in names and len(names) >= len(pages)
    for name in sorted(set(names) - set(AUDITED)):
        _assert_accessible(name, visited(name))
