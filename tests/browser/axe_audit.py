"""axe-core over the pages of the built website, offline, from ``file://``.

axe-core comes from the npm registry, pinned by version and by the registry's
sha512 integrity hash, through the site builder's own download and cache
(``tools/build_site.py``: build/npm-cache/), so a machine that built the site
once runs the audit without network.

    python tests/browser/axe_audit.py build/site      # a table: violations per page

The rules are axe's WCAG 2.0 and 2.1 level A and AA rules (tags ``wcag2a``,
``wcag2aa``, ``wcag21a``, ``wcag21aa``). A page is audited once it has settled:
the formulas typeset, the 3D views drawn, the slider script ready.
"""

import io
import sys
import tarfile
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import build_site  # noqa: E402
import lablib  # noqa: E402

AXE = (
    "axe-core",
    "4.14.1",
    "sha512-FHfa+lmNjQZfJz1q8wKqIDwC6DExcHt/pkjNQb09a3NPjCKg2rhu5qb2S4r76ASyFNNtuFooJpZe37OgudVGtQ==",
)
TAGS = ["wcag2a", "wcag2aa", "wcag21a", "wcag21aa"]
SETTLE_TIMEOUT = 90  # seconds for a page's formulas, views and sliders

JS_SETTLED = """
(views) => new Promise(done => {
  const drawn = () => document.querySelectorAll('canvas').length >= views;
  const states = () => !document.getElementById('site-states')
    || document.body.getAttribute('data-site-states') === 'ready';
  const math = () => new Promise(ok => (window.MathJax && MathJax.Hub) ? MathJax.Hub.Queue(() => ok(true)) : ok(true));
  math().then(() => {
    const t0 = Date.now();
    (function wait() {
      if ((drawn() && states()) || Date.now() - t0 > 60000) done(drawn() && states());
      else setTimeout(wait, 250);
    })();
  });
})
"""

# preload: false, because from file:// axe's fetch of the stylesheets (for css-orientation-lock) is
# refused as a cross-origin request, which logs console errors and leaves axe without them anyway
JS_AXE = """
(tags) => axe.run(document, {runOnly: {type: 'tag', values: tags}, resultTypes: ['violations'], preload: false})
  .then(r => r.violations.map(v => ({id: v.id, impact: v.impact, help: v.help,
    nodes: v.nodes.map(n => ({target: n.target.join(' '), html: n.html.slice(0, 200),
                             summary: (n.failureSummary || '').slice(0, 300)}))})))
"""


def axe_script():
    """Path of axe.min.js, unpacked once from the pinned tarball (downloaded once, then cached)."""
    name, version, integrity = AXE
    path = build_site.CACHE / f"{name}-{version}" / "axe.min.js"
    if not path.exists():
        data = build_site.fetch_tarball(name, version, integrity)
        with tarfile.open(fileobj=io.BytesIO(data), mode="r:gz") as tar:
            script = tar.extractfile("package/axe.min.js").read()
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(script)
    return path


def offline_context(browser):
    """A browser context in which only file:, data: and blob: URLs load."""
    context = browser.new_context(viewport=lablib.VIEWPORT)
    context.route(
        "**/*",
        lambda route: (
            route.continue_()
            if route.request.url.startswith(("file:", "data:", "blob:"))
            else route.abort("internetdisconnected")
        ),
    )
    return context


def audit(page, views=0):
    """axe's violations on the settled ``page`` (a Playwright page showing a site page with
    ``views`` live 3D views): a list of ``{id, impact, help, nodes: [{target, html, summary}]}``."""
    page.evaluate(JS_SETTLED, views)
    page.add_script_tag(path=str(axe_script()))
    return page.evaluate(JS_AXE, TAGS)


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


def contrast(css_colour):
    """Contrast of an ``rgb(r, g, b)`` colour against the white page."""
    rgb = [float(x) / 255 for x in css_colour[css_colour.index("(") + 1 : -1].split(",")[:3]]
    lin = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in rgb]
    lum = 0.2126 * lin[0] + 0.7152 * lin[1] + 0.0722 * lin[2]
    return 1.05 / (lum + 0.05)


def problems(name, info, cut, widgets):
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
        if contrast(colour) < 3.0:
            out.append(f"a slider track {colour} at {contrast(colour):.2f}:1 against the page")
    if cut:
        out.append(f"slider labels cut under WCAG text spacing: {cut}")
    return [f"{name}: {p}" for p in out]


def pages_of(folder):
    """Every HTML page of the site folder (its assets left out), relative paths, sorted."""
    folder = Path(folder)
    return sorted(
        str(p.relative_to(folder))
        for p in folder.rglob("*.html")
        if build_site.ASSETS not in p.relative_to(folder).parts
    )


def counts(violations):
    """{impact: nodes} and {rule: nodes} of one page's violations."""
    by_impact, by_rule = Counter(), Counter()
    for v in violations:
        by_impact[v["impact"]] += len(v["nodes"])
        by_rule[v["id"]] += len(v["nodes"])
    return by_impact, by_rule


def main(folder):
    import json

    folder = Path(folder).resolve()
    views = {}
    if (folder / "pages.json").exists():
        views = {p["file"]: p["views"] for p in json.loads((folder / "pages.json").read_text())}
    total = Counter()
    report = {}
    with lablib.chromium_browser() as browser:
        for name in pages_of(folder):
            context = offline_context(browser)
            page = context.new_page()
            page.goto((folder / name).as_uri(), wait_until="load")
            violations = audit(page, views.get(name, 0))
            context.close()
            by_impact, by_rule = counts(violations)
            total += by_impact
            report[name] = violations
            rules = ", ".join(f"{r} {n}" for r, n in by_rule.most_common())
            print(
                f"{name:45s} critical {by_impact['critical']:4d}  serious {by_impact['serious']:4d}  "
                f"moderate {by_impact['moderate']:3d}  minor {by_impact['minor']:3d}  {rules}",
                flush=True,
            )
    print(
        f"{'total':45s} critical {total['critical']:4d}  serious {total['serious']:4d}  "
        f"moderate {total['moderate']:3d}  minor {total['minor']:3d}"
    )
    (folder.parent / f"{folder.name}-axe.json").write_text(json.dumps(report, indent=1))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else build_site.OUT)
