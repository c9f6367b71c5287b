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

JS_AXE = """
(tags) => axe.run(document, {runOnly: {type: 'tag', values: tags}, resultTypes: ['violations']})
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
