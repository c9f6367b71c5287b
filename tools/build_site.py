"""Build the workbook as a static website in build/site/.

    python3 workbook.py site                 # every notebook in notebooks/
    python tools/build_site.py --out DIR 00_getting_started.ipynb ...   # some of them

Every notebook, core (``NN_*``) and appendix (``NNa_dig_deeper_*``), is executed
with its default parameters (nbclient, widget state stored) and rendered as an HTML
page (nbconvert's ``lab`` template). The README and the pages of docs/ (and
benchmarks/README.md) follow, rendered from their markdown by the same template, and a
reference page of geomlib's public names made from their docstrings by pdoc. An index
page lists it all in reading order (00, 01, 01a, 02, ..., then the documentation and
the reference), each page links to the previous and next, and a link to a notebook or
markdown file of the workbook becomes a link to its page (``:func:`site_links```).
The 3D views stay live in the page: the saved widget state is rendered by the
Jupyter widgets HTML manager and pythreejs's browser code, both served from
``assets/`` in the site folder together with require.js and MathJax, so a page
needs no kernel and no network. Links are relative: the folder works from any
static web server and from ``file://``.

Sliders move the 3D views in the page too, with no kernel: their states are
computed when the site is built. After the notebook's last cell has run,
:func:`geomlib.teaching.display.site_states.record` runs in the same kernel for every cell
that showed widgets: it sets each of the cell's sliders, from the value it was left at, one at a time from the others' defaults, to a short list
of values (every integer up to 10, then 15, 20, 30, 50, 100, ...; a long grid
thinned to about 20 positions, both ends kept: past a stability limit for the
step sliders), so the notebook's own observers run as when a reader moves the
slider, and keeps what they changed in the shown widgets (buffer arrays packed
in 16 bits and gzip, read-out text). The page carries those states as JSON, and
a small script of the site's own (tools/site_states.js, loaded after the widget
manager) snaps the slider to the computed values and sets the recorded traits of
the page's widget models; the 3D views redraw from their buffer models. A line
under the slider says it snaps. Why this way: it replays exactly what JupyterLab
shows for those values (the same callbacks, nothing rewritten in JavaScript),
it needs nothing from the notebooks, and it is one page script of about 150
lines to keep. Linking the slider to a keyframe animation (ipywidgets.jslink to
a pythreejs AnimationAction) would also run without a kernel, but a paused
action does not redraw in the HTML widget manager, and keyframes would have to
be built per notebook. A slider whose states are too large (over
``site_states.MAX_BYTES``) or whose moves change nothing the page can replay is
not precomputed.

Other controls (dropdowns, toggles, checkboxes, and sliders not precomputed)
are shown disabled at their default value, with one line saying that they
recompute in JupyterLab. A view whose widget state was not saved keeps its still
picture; so does a live view in a browser without WebGL. A cell that raises (or
whose sliders could not be recorded) does not stop the build: its page shows the
error and the command exits with status 1. The build prints each page's size and
number of live controls, and the site's total size.

The JavaScript comes from the npm registry, pinned by version and by the
registry's sha512 integrity hash (:data:`PACKAGES`); downloads are kept in
build/npm-cache/ so later builds need no network.
"""

import argparse
import base64
import hashlib
import html
import io
import json
import re
import shutil
import sys
import tarfile
import tempfile
import time
import urllib.request
from pathlib import Path

import nbformat

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"
# the notebooks in reading order: each core notebook NN_* followed by its appendix NNa_*
# (file names sort that way: "_" comes before "a")
NOTEBOOK_GLOBS = ("[0-9][0-9]_*.ipynb", "[0-9][0-9]a_*.ipynb")
# the markdown pages after the notebooks, in reading order (source -> page); every other
# docs/*.md follows them (docs/engineering-NN.md, ...), then the reference page
DOC_PAGES = {
    "README.md": "about.html",
    "docs/README.md": "docs.html",
    "docs/assignment.md": "assignment.html",
    "docs/install.md": "install.html",
    "docs/grading.md": "grading.html",
    "docs/experiments.md": "experiments.html",
    "docs/website.md": "website.html",
    "docs/developing.md": "developing.html",
}
DOC_PAGES_AFTER = {"benchmarks/README.md": "benchmarks.html"}
IMAGES = "docs/images"  # pictures of the markdown pages, copied to images/ on the site
REFERENCE = "reference.html"
REFERENCE_TITLE = "geomlib reference: the public functions"
OUT = ROOT / "build" / "site"
CACHE = ROOT / "build" / "npm-cache"
ASSETS = "assets"
REGISTRY = "https://registry.npmjs.org"

#: npm package -> (version, integrity, files kept, folder in assets/). The files kept are
#: globs inside the package: ``*`` stays within one folder, ``**`` crosses folders.
#: html-manager 1.0.x is the renderer of ipywidgets 8; jupyter-threejs 2.4.1 is the
#: browser side of pythreejs 2.4.2 (its EXTENSION_SPEC_VERSION ^2.4.1),
#: jupyter-datawidgets 5.5.2 that of ipydatawidgets 4.3.5.
PACKAGES = {
    "requirejs": (
        "2.3.7",
        "sha512-DouTG8T1WanGok6Qjg2SXuCMzszOo0eHeH9hDZ5Y4x8Je+9JB38HdTLT4/VA8OaUhBa0JPVHJ0pyBkM1z+pDsw==",
        ["require.js", "LICENSE"],
        "requirejs",
    ),
    "@jupyter-widgets/html-manager": (
        "1.0.15",
        "sha512-5thBIV6ymNgmPVOHvzx+gGy8ZSKmSazhtGw4/c4xJDVzRhG9PTeQsRjF3FUTopvFi//SABeNz1yp47bCrJ3CQA==",
        # its style sheet lists each icon font in several formats; browsers take the woff2
        ["dist/embed-amd.js", "dist/*.woff2", "dist/*.woff", "dist/*.LICENSE.txt", "LICENSE"],
        "html-manager",
    ),
    "jupyter-threejs": (
        "2.4.1",
        "sha512-AFoYllRmV5Hy1Hbyq8NR09KXiFE+9qQ4zPlKW5RAzkRjdvO56rWM4hzSKNSnW/GH/8FcqMVE2SnGHOP/ZmFwSw==",
        ["dist/index.js", "dist/*.LICENSE.txt", "LICENSE"],
        "jupyter-threejs",
    ),
    "jupyter-datawidgets": (
        "5.5.2",
        "sha512-gRNoe9I21veWAr78+4bzjUuhwuI5VmdSphTepUUB5AHNN1etxr9qpql0Gug41CO085HuzqxLUXF4zCMIoXUZpQ==",
        ["dist/index.js", "LICENSE*"],
        "jupyter-datawidgets",
    ),
    "mathjax": (
        "2.7.9",
        "sha512-NOGEDTIM9+MrsqnjPEjVGNx4q0GQxqm61yQwSK+/5S59i26wId5IC5gNu9/bu8+CCVl5p9G2IHcAl/wJa+5+BQ==",
        # what config=TeX-AMS_CHTML-full,Safe loads: TeX in, CommonHTML out with its web fonts
        [
            "MathJax.js",
            "config/TeX-AMS_CHTML-full.js",
            "config/Safe.js",
            "extensions/*.js",
            "extensions/TeX/*",
            "jax/input/TeX/**",
            "jax/output/CommonHTML/**",
            "jax/element/**",
            "fonts/HTML-CSS/TeX/woff/*",
            "LICENSE",
        ],
        "mathjax",
    ),
}

REQUIRE_JS = f"{ASSETS}/requirejs/require.js"
WIDGET_RENDERER = f"{ASSETS}/html-manager/dist/embed-amd.js"
MATHJAX = f"{ASSETS}/mathjax/MathJax.js?config=TeX-AMS_CHTML-full,Safe"
#: the project's own page script that moves precomputed sliders (source: tools/site_states.js)
STATES_JS = f"{ASSETS}/site/site_states.js"
#: the project's own page script that names the widgets, makes the 3D views keyboard-operable and
#: announces what a slider changes (source: tools/site_a11y.js)
A11Y_JS = f"{ASSETS}/site/site_a11y.js"
AMD_PATHS = {
    "jupyter-threejs": f"{ASSETS}/jupyter-threejs/dist/index",
    "jupyter-datawidgets": f"{ASSETS}/jupyter-datawidgets/dist/index",
}

WIDGET_VIEW = "application/vnd.jupyter.widget-view+json"
WIDGET_STATE = "application/vnd.jupyter.widget-state+json"
#: the page's accessibility style (WCAG 2.1 AA): text contrast at least 4.5:1 (the prompts
#: and the code colours of nbconvert's theme on the cells' #f5f5f5 were 2.2 to 4.4:1), slider
#: tracks and handles at least 3:1 against the page, labels that grow instead of cutting
#: their text under wider spacing, a visible focus on the 3D views, the skip link
A11Y_CSS = """
body.jp-Notebook {
  --jp-cell-prompt-opacity: 1; --jp-cell-prompt-not-active-opacity: 1;
  --jp-cell-prompt-not-active-font-color: #5e5e5e; --jp-cell-inprompt-font-color: #2a6eab;
  --jp-cell-outprompt-font-color: #b3522f;
  --jp-mirror-editor-number-color: #007a00; --jp-mirror-editor-operator-color: #9a1ce6;
  --jp-mirror-editor-meta-color: #9a1ce6; --jp-mirror-editor-comment-color: #3a7272;
  --jp-mirror-editor-atom-color: #4d4df0; --jp-mirror-editor-bracket-color: #6b6b50;
  --jp-mirror-editor-error-color: #d40000; --jp-mirror-editor-hr-color: #6b6b6b;
  --jp-mirror-editor-quote-color: #007a00; --jp-mirror-editor-builtin-color: #007a00;
  --jp-mirror-editor-keyword-color: #007a00;
}
body.jp-Notebook .widget-slider .noUi-target { background: #8a8a8a; border-color: #6b6b6b; }
body.jp-Notebook .widget-slider .noUi-handle { border-color: #6b6b6b; }
/* the widgets' style sheet comes after this one (the page adds it when it loads): hence body.jp-Notebook */
body.jp-Notebook .widget-inline-hbox .widget-label { width: auto; min-width: var(--jp-widgets-inline-label-width);
  overflow: visible; text-overflow: clip; }
/* links in running text are told apart by more than their colour (WCAG 1.4.1) */
body.jp-Notebook .jp-RenderedHTMLCommon a, body.jp-Notebook .jp-RenderedHTMLCommon a:link,
body.jp-Notebook .jp-RenderedHTMLCommon a:visited { text-decoration: underline; }
.geomlib-canvas:focus { outline: 3px solid #1a5fb4; outline-offset: 2px; }
p.site-view-keys { font-size: 13px; color: #444; margin: 0.2em 0; }
.site-visually-hidden { position: absolute; width: 1px; height: 1px; overflow: hidden; clip: rect(0 0 0 0);
  white-space: nowrap; }
"""
#: the skip link at the top of every page: hidden until it has focus (the first Tab stop)
SKIP_LINK = '<a class="site-skip" href="#site-content">Skip to the content</a>'
SKIP_CSS = """a.site-skip { position: absolute; left: 0.5em; top: -3em; z-index: 10; padding: 0.4em 0.8em;
  background: #fff; color: #0b57d0; border: 2px solid #0b57d0; }
a.site-skip:focus { top: 0.5em; }
main:focus { outline: none; }"""

#: the visible hint after every live 3D view (tools/site_a11y.js makes these keys work)
VIEW_KEYS = (
    "Keys, once the 3D view has focus (Tab to it or click it): arrow keys turn it, Shift + arrow keys pan, "
    "+ and - zoom, 0 resets. Mouse: drag to turn, wheel to zoom, right-drag to pan."
)
KERNEL_NOTE = "In JupyterLab this control recomputes the result; on this page it stays at its default value."
KERNEL_NOTE_MANY = "In JupyterLab these controls recompute the result; on this page they stay at their default values."
KERNEL_NOTE_OTHERS = (
    "In JupyterLab the other controls recompute the result too; on this page they stay at their defaults."
)

# ---------------------------------------------------------------------------
# the pinned JavaScript
# ---------------------------------------------------------------------------


def fetch_tarball(name, version, integrity):
    """The package's tarball (bytes), from the cache or the registry, checked against ``integrity``."""
    algorithm, _, expected = integrity.partition("-")
    path = CACHE / f"{name.replace('/', '+')}-{version}.tgz"
    cached = path.exists()
    if cached:
        data = path.read_bytes()
    else:
        url = f"{REGISTRY}/{name}/-/{name.rsplit('/', 1)[-1]}-{version}.tgz"
        print(f"downloading {url}", flush=True)
        with urllib.request.urlopen(url, timeout=120) as response:
            data = response.read()
    actual = base64.b64encode(hashlib.new(algorithm, data).digest()).decode()
    if actual != expected:
        raise SystemExit(
            f"{name}@{version}: the download does not match its pinned {algorithm} "
            f"hash ({actual} != {expected}); delete {path} and try again"
        )
    if not cached:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
    return data


def glob_pattern(glob):
    """A compiled pattern for ``glob``: ``**`` matches across folders, ``*`` within one."""
    parts = re.split(r"(\*\*|\*)", glob)
    return re.compile("".join({"**": ".*", "*": "[^/]*"}.get(p, re.escape(p)) for p in parts))


def install_assets(site):
    """Unpack the kept files of every package of :data:`PACKAGES` into ``site/assets/``."""
    for name, (version, integrity, keep, folder) in PACKAGES.items():
        target = site / ASSETS / folder
        patterns = [glob_pattern(g) for g in keep]
        with tarfile.open(fileobj=io.BytesIO(fetch_tarball(name, version, integrity)), mode="r:gz") as tar:
            for member in tar.getmembers():
                rel = member.name.split("/", 1)[1]  # members sit under "package/"
                if member.isfile() and any(g.fullmatch(rel) for g in patterns):
                    dest = target / rel
                    dest.parent.mkdir(parents=True, exist_ok=True)
                    dest.write_bytes(tar.extractfile(member).read())
        (target / "VERSION").write_text(f"{name}@{version} ({integrity})\n")


# ---------------------------------------------------------------------------
# executing and preparing a notebook
# ---------------------------------------------------------------------------


def _shown(cell):
    """Model ids of the widgets a cell's outputs display."""
    return [
        out["data"][WIDGET_VIEW]["model_id"] for out in cell.get("outputs", []) if WIDGET_VIEW in out.get("data", {})
    ]


def execute(path, timeout=1200):
    """Run the notebook at ``path`` top to bottom in its folder; the widget state is stored.

    After the last cell, :func:`geomlib.teaching.display.site_states.record` runs in the same
    kernel for every cell that displayed widgets and records the states of its
    sliders, from the values they were left at. Returns
    ``(nb, recorded)`` with ``recorded`` mapping a cell's index to what was recorded
    (``{"sliders": [...], "left_out": [...]}``, or ``{"error": text}``).

    A cell that raises does not stop the run (the page shows the error, like
    JupyterLab would); :func:`cell_errors` lists them.
    """
    from nbclient import NotebookClient

    nb = nbformat.read(path, as_version=4)
    client = NotebookClient(
        nb,
        timeout=timeout,
        kernel_name="python3",
        store_widget_state=True,
        allow_errors=True,
        resources={"metadata": {"path": str(path.parent)}},
    )
    # the sliders are recorded after the last cell, in the state the page is saved in (a
    # later cell may move a slider, and moving one after "Run all" in JupyterLab runs its
    # callback in that final namespace too): a cell added at the end, removed afterwards
    after_all = nbformat.v4.new_code_cell("None  # the site's slider states are recorded after this cell")
    nb.cells.append(after_all)
    last = len(nb.cells) - 1
    shown, recorded = {}, {}
    with tempfile.TemporaryDirectory() as tmp:

        async def record_sliders(cell, cell_index, execute_reply):
            if cell_index != last:
                if _shown(cell):
                    shown[cell_index] = _shown(cell)
                return
            if cell is not after_all:  # one of the calls below
                return
            for i, ids in shown.items():
                target = Path(tmp) / f"{i}.json"
                # a call that leaves no name behind in the reader's namespace
                probe = nbformat.v4.new_code_cell(
                    f"__import__('geomlib.teaching.display.site_states', fromlist=['record']).record({ids!r}, {str(target)!r})"
                )
                await client.async_execute_cell(probe, cell_index, store_history=False)
                errors = [f"{o['ename']}: {o['evalue']}" for o in probe.outputs if o.get("output_type") == "error"]
                recorded[i] = {"error": "; ".join(errors)} if errors else json.loads(target.read_text())

        client.on_cell_executed = record_sliders
        client.execute()
    nb.cells.pop()
    return nb, recorded


def cell_errors(nb):
    """``"cell N: Name: message"`` for every error output of an executed notebook (N from 0)."""
    return [
        f"cell {i}: {out.get('ename', '?')}: {out.get('evalue', '')}".strip()
        for i, cell in enumerate(nb.cells)
        if cell.cell_type == "code"
        for out in cell.get("outputs", [])
        if out.get("output_type") == "error"
    ]


def _references(value):
    """Model ids referred to (``"IPY_MODEL_<id>"``) anywhere inside a widget's state."""
    if isinstance(value, str):
        return [value[10:]] if value.startswith("IPY_MODEL_") else []
    if isinstance(value, dict):
        value = list(value.values())
    if isinstance(value, list):
        return [ref for item in value for ref in _references(item)]
    return []


def _reachable(model_id, state):
    seen, todo = set(), [model_id]
    while todo:
        mid = todo.pop()
        if mid in seen or mid not in state:
            continue
        seen.add(mid)
        todo.extend(_references(state[mid].get("state", {})))
    return seen


def _is_control(model):
    """An ipywidgets control the reader moves (it has a ``disabled`` trait): needs a kernel."""
    return model.get("model_module") == "@jupyter-widgets/controls" and "disabled" in model.get("state", {})


def _html_output(text):
    return nbformat.v4.new_output("display_data", data={"text/html": text})


def snap_note(sliders):
    """The line under precomputed sliders: they snap to the values computed for the page."""
    if len(sliders) == 1:
        return (
            f"On this page the slider snaps to the {len(sliders[0]['values'])} values computed when the page was built."
        )
    names = [f"{s['description']} ({len(s['values'])} values)" for s in sliders]
    listed = ", ".join(names[:-1]) + " and " + names[-1]
    return (
        f"On this page the sliders {listed} snap to values computed when the page was built, "
        "one at a time: moving one puts the others back to their defaults."
    )


def _alt_in_output_widget(outputs):
    """An image with an alt text in its metadata, inside an Output widget, as an ``<img>`` with that
    alt: the widgets' renderer of the page draws a PNG output without it (the page's own
    outputs get theirs from the template)."""
    for output in outputs:
        data = output.get("data", {})
        alt = output.get("metadata", {}).get("image/png", {}).get("alt")
        if "image/png" in data and alt:
            src = f"data:image/png;base64,{data.pop('image/png').strip()}"
            data["text/html"] = f'<img src="{src}" alt="{html.escape(alt)}">'


def prepare_for_site(nb, recorded=None):
    """Make an executed notebook fit for a static page (in place); returns the live view count.

    - a slider whose states were recorded (``recorded``: cell index -> what
      :func:`execute` recorded) stays enabled, and its output gets a line saying it
      snaps to the computed values;
    - every other control is saved disabled (it cannot recompute without a kernel),
      and an output that holds one gets a one-line note after it;
    - an output whose widget was not saved loses its widget part, so its still
      picture (image/png) or text is shown instead;
    - a live 3D view keeps its still picture, hidden, after it: the page shows it
      when the browser has no WebGL or the view did not appear (script in TEMPLATE);
      its alt is the view's text alternative (the output's ``image/png`` metadata);
      a line after the view says which keys turn, zoom and reset it;
    - a figure inside an Output widget keeps the alt text of its metadata.
    """
    recorded = recorded or {}
    state = nb.metadata.get("widgets", {}).get(WIDGET_STATE, {}).get("state", {})
    for model in state.values():
        if model.get("model_name") == "OutputModel":
            _alt_in_output_widget(model.get("state", {}).get("outputs", []))
    live_sliders = {s["model_id"]: s for r in recorded.values() for s in r.get("sliders", [])}
    for mid, model in state.items():
        if _is_control(model) and mid not in live_sliders:
            model["state"]["disabled"] = True
    live = 0
    for cell in nb.cells:
        if cell.cell_type != "code":
            continue
        outputs = []
        for output in cell.get("outputs", []):
            outputs.append(output)
            view = output.get("data", {}).get(WIDGET_VIEW)
            if view is None:
                continue
            models = _reachable(view["model_id"], state)
            if not models:
                del output["data"][WIDGET_VIEW]
                continue
            renderers = sum(state[m].get("model_name") == "RendererModel" for m in models)
            live += renderers
            if renderers and "image/png" in output["data"]:  # right after its view (the reveal script)
                alt = output.get("metadata", {}).get("image/png", {}).get("alt") or "still picture of the 3D view"
                outputs.append(
                    _html_output(
                        f'<img class="site-still" hidden alt="{html.escape(alt)}" '
                        f'src="data:image/png;base64,{output["data"]["image/png"].strip()}">'
                    )
                )
            if renderers:
                outputs.append(_html_output(f'<p class="site-view-keys">{html.escape(VIEW_KEYS)}</p>'))
            snapping = [s for s in live_sliders.values() if s["model_id"] in models]
            if snapping:
                outputs.append(_html_output(f'<p class="site-snap-note">{html.escape(snap_note(snapping))}</p>'))
            controls = sum(_is_control(state[m]) and m not in live_sliders for m in models)
            if controls:
                note = (KERNEL_NOTE if controls == 1 else KERNEL_NOTE_MANY) if not snapping else KERNEL_NOTE_OTHERS
                outputs.append(_html_output(f'<p class="site-kernel-note">{html.escape(note)}</p>'))
        cell.outputs = outputs
    share_repeated_buffers(state)
    return live


def share_repeated_buffers(state):
    """Save each binary buffer of the widget state once (in place); returns the bytes saved.

    Views of one mesh hold the same arrays (its triangles, often its positions) in
    models of their own: notebook 04's eight views of one creature repeated 5.6 MB of
    buffers. A buffer seen before keeps its path and encoding, empty data, and
    ``"site_same_as": [model id, index]`` naming the first copy; a script in the page's
    footer (TEMPLATE) puts the data back before the widget manager reads the state, so
    every model gets exactly the buffer it had.
    """
    first, saved = {}, 0
    for mid, model in state.items():
        for i, buffer in enumerate(model.get("buffers", [])):
            data = buffer.get("data", "")
            if len(data) < 1024:  # small buffers cost less than their reference
                continue
            if data in first:
                buffer["data"] = ""
                buffer["site_same_as"] = first[data]
                saved += len(data)
            else:
                first[data] = [mid, i]
    return saved


def page_states(recorded):
    """What the page's script needs (tools/site_states.js): per cell, its recorded sliders."""
    return [{"sliders": r["sliders"]} for _, r in sorted(recorded.items()) if r.get("sliders")]


def title_of(nb, fallback):
    for cell in nb.cells:
        if cell.cell_type == "markdown":
            m = re.search(r"^#\s+(.+)$", cell.source, re.MULTILINE)
            if m:
                return m.group(1).strip()
    return fallback


# ---------------------------------------------------------------------------
# pages
# ---------------------------------------------------------------------------

TEMPLATE = """{%- extends 'lab/index.html.j2' -%}
{%- block html_head_js_requirejs -%}
{{ super() }}
<script>require.config({paths: %(paths)s});</script>
<style>
nav.site-nav { display: flex; justify-content: space-between; gap: 1em; padding: 0.6em 1em;
  font-family: var(--jp-ui-font-family); font-size: 14px; border-bottom: 1px solid #ddd; }
nav.site-nav.bottom { border-top: 1px solid #ddd; border-bottom: none; margin-top: 2em; }
/* the output area's style sheet shows its images as blocks, which overrides the hidden attribute */
img.site-still[hidden] { display: none !important; }
p.site-kernel-note, p.site-snap-note { font-style: italic; color: #555; margin: 0.2em 0; }
details.site-hidden-input > summary { cursor: pointer; color: #666; font-size: 13px;
  font-family: var(--jp-ui-font-family); margin: 0.3em 0 0.3em 6em; }
/* the widget style sheets take their font from a variable only JupyterLab's own page defines */
.jupyter-widgets, .jupyter-widgets input, .jupyter-widgets select, .jupyter-widgets button {
  font-family: var(--jp-ui-font-family); }
%(a11y_css)s
</style>
<script type="text/x-mathjax-config">
// formulas out of the Tab order (their assistive MathML stays for screen readers)
MathJax.Hub.Config({menuSettings: {inTabOrder: false}});
</script>
{%- endblock html_head_js_requirejs -%}
{%- block html_head_js_mermaidjs -%}{%- endblock html_head_js_mermaidjs -%}
{% block input_group -%}
{%- if cell.metadata.get("jupyter", {}).get("source_hidden") -%}
<details class="site-hidden-input"><summary>Show the code of this cell</summary>
{{ super() }}
</details>
{%- else -%}
{{ super() }}
{%- endif -%}
{% endblock input_group %}
{%- block body_header -%}
<body class="jp-Notebook" data-jp-theme-light="true" data-jp-theme-name="JupyterLab Light">
%(skip_link)s
<div id="site-live" class="site-visually-hidden" aria-live="polite" aria-atomic="true"></div>
{{ resources.site_nav.replace('<nav class="site-nav"', '<nav class="site-nav" aria-label="Pages"') }}
<main id="site-content" tabindex="-1">
{%- endblock body_header -%}
{% block data_png scoped %}
{#- the alt text from the output's metadata (show_figure, the 3D views' stills); nbconvert's own template has none -#}
{%- set alt = output | get_metadata('alt', 'image/png') -%}
<div class="jp-RenderedImage jp-OutputArea-output {{ extra_class }}">
<img src="data:image/png;base64,{{ output.data['image/png'] | escape_html }}"
{%- if alt %} alt="{{ alt | escape_html }}"{% endif %}>
</div>
{%- endblock data_png %}
{% block body_footer %}
</main>
{{ resources.site_nav.replace('<nav class="site-nav"', '<nav class="site-nav bottom" aria-label="Pages (end of page)"') }}
<script>
// buffers the build saved once (share_repeated_buffers) are copied back into the widget
// state before the widget manager reads it (it renders on "load", after this)
document.addEventListener("DOMContentLoaded", function () {
  var script = document.querySelector('script[type="application/vnd.jupyter.widget-state+json"]');
  if (!script || script.textContent.indexOf("site_same_as") < 0) return;
  var saved = JSON.parse(script.textContent), state = saved.state;
  Object.keys(state).forEach(function (id) {
    (state[id].buffers || []).forEach(function (buffer) {
      if (!buffer.site_same_as) return;
      buffer.data = state[buffer.site_same_as[0]].buffers[buffer.site_same_as[1]].data;
      delete buffer.site_same_as;
    });
  });
  script.textContent = JSON.stringify(saved);
});
</script>
{%- if resources.site_states %}
<script type="application/json" id="site-states">{{ resources.site_states }}</script>
<script src="%(states_js)s"></script>
{%- endif %}
<script src="%(a11y_js)s"></script>
<script>
// the still picture of a 3D view replaces nothing; it appears below the view when
// the browser has no WebGL, or when the view has drawn no canvas 30 s after loading
(function () {
  window.siteRevealStills = reveal;  // the site's browser test runs it without the wait
  function reveal(all) {
    document.querySelectorAll("img.site-still").forEach(function (img) {
      var child = img.closest(".jp-OutputArea-child");
      var view = child && child.previousElementSibling;
      // pythreejs keeps 8 canvases per page: an older view is frozen into an <img> of
      // its last frame (live again when the mouse enters), which is drawn too
      var drawn = view && (view.querySelector("canvas") || view.querySelector(".jupyter-widgets img"));
      if (all || !drawn) img.hidden = false;
    });
  }
  var probe = document.createElement("canvas").getContext("webgl");
  if (probe) {
    var lose = probe.getExtension("WEBGL_lose_context");
    if (lose) lose.loseContext();
    window.addEventListener("load", function () { setTimeout(reveal, 30000, false); });
  } else {
    document.addEventListener("DOMContentLoaded", function () { reveal(true); });
  }
})();
</script>
</body>
{% endblock body_footer %}
"""


def exporter():
    from jinja2 import DictLoader
    from nbconvert import HTMLExporter

    template = (
        TEMPLATE.replace("%(paths)s", json.dumps(AMD_PATHS))
        .replace("%(states_js)s", STATES_JS)
        .replace("%(a11y_js)s", A11Y_JS)
        .replace("%(skip_link)s", SKIP_LINK)
        .replace("%(a11y_css)s", A11Y_CSS + SKIP_CSS)
    )
    return HTMLExporter(
        extra_loaders=[DictLoader({"site.html.j2": template})],
        template_file="site.html.j2",
        require_js_url=REQUIRE_JS,
        widget_renderer_url=WIDGET_RENDERER,
        mathjax_url=MATHJAX,
    )


def notebook_paths():
    """Every notebook of the site, in reading order: 00, 01, 01a, 02, 02a, ..."""
    return sorted({p for glob in NOTEBOOK_GLOBS for p in NOTEBOOKS.glob(glob)}, key=lambda p: p.name)


def doc_pages():
    """{repository path of a markdown page: its page file on the site}, in reading order."""
    pages = {src: page for src, page in DOC_PAGES.items() if (ROOT / src).is_file()}
    for path in sorted((ROOT / "docs").glob("*.md")):
        pages.setdefault(path.relative_to(ROOT).as_posix(), path.stem + ".html")
    pages.update({src: page for src, page in DOC_PAGES_AFTER.items() if (ROOT / src).is_file()})
    return pages


MD_LINK = re.compile(r"(!?)\[([^\]]*)\]\(([^)\s]+)\)")
FENCE = re.compile(r"^\s*(```|~~~)")


def site_links(markdown, source, targets):
    """``markdown`` of the file ``source`` (repository path) with its relative links made
    links of the site: a notebook or markdown page that has a page (``targets``: repository
    path -> page file) links to that page (``05_explicit_smoothing.ipynb`` ->
    ``05_explicit_smoothing.html``), a picture of docs/images/ to images/; a link to any other
    file of the repository, which the site does not carry, becomes its text and path.
    Links to the web, anchors on the same page, and code blocks are left as they are."""

    def rewrite(m):
        bang, text, target = m.groups()
        if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith("#"):
            return m.group(0)
        path, hash_, anchor = target.partition("#")
        rel = (ROOT / source).parent.joinpath(path).resolve()
        try:
            rel = rel.relative_to(ROOT).as_posix()
        except ValueError:
            return m.group(0)
        if rel in targets:
            return f"{bang}[{text}]({targets[rel]}{hash_}{anchor})"
        if rel.startswith(IMAGES + "/"):
            return f"{bang}[{text}](images/{rel[len(IMAGES) + 1 :]})"
        return text if text.strip("`") == rel else f"{text} (`{rel}`)"

    out, fenced = [], False
    for line in markdown.split("\n"):
        if FENCE.match(line):
            fenced = not fenced
        out.append(line if fenced else MD_LINK.sub(rewrite, line))
    return "\n".join(out)


def link_targets(notebooks, docs):
    """Repository path -> page file, for :func:`site_links`."""
    targets = {f"notebooks/{p.name}": p.stem + ".html" for p in notebooks}
    targets.update(docs)
    return targets


def markdown_notebook(source, targets):
    """The markdown page ``source`` (repository path) as a notebook of one markdown cell,
    its links made the site's: rendered like the notebooks' own text (the same theme,
    formulas and code blocks), with no network."""
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_markdown_cell(site_links((ROOT / source).read_text(encoding="utf-8"), source, targets))]
    return nb


# a documentation page is mostly links in running text: underlined, so that they are told
# apart from the text by more than their colour (WCAG 1.4.1)
DOC_CSS = ".jp-RenderedMarkdown a:link, .jp-RenderedMarkdown a:visited { text-decoration: underline; }"

# the site's navigation bars on pdoc's page (the notebooks' pages style them in TEMPLATE)
REFERENCE_NAV_CSS = """nav.site-nav { display: flex; justify-content: space-between; gap: 1em; padding: 0.6em 1em;
  font-family: system-ui, sans-serif; font-size: 14px; border-bottom: 1px solid #ddd; }
nav.site-nav.bottom { border-top: 1px solid #ddd; border-bottom: none; margin-top: 2em; }
nav.site-nav { position: static; height: auto; width: auto; overflow: visible; }  /* pdoc fixes every nav */
/* pdoc's greens on its grey signature boxes reach 4.0-4.4:1; this green, 6.4:1 (WCAG AA asks 4.5) */
.pdoc { --def: #006400; }
.pdoc .kc, .pdoc .bp, .pdoc .nb, .pdoc .k, .pdoc .kn, .pdoc .ow { color: #006400; }"""


def reference_html(nav):
    """The reference page: geomlib's public names (``geomlib.__all__``) with their
    docstrings, rendered by pdoc from the installed package (no network), with the
    site's navigation."""
    import pdoc.doc
    import pdoc.render

    import geomlib

    pdoc.render.configure(docformat="numpy", search=False, show_source=False, math=False, mermaid=False)
    module = pdoc.doc.Module(geomlib)
    page = pdoc.render.html_module(module, all_modules={"geomlib": module})
    page = re.sub(r"<title>[^<]*</title>", f"<title>{html.escape(REFERENCE_TITLE)}</title>", page, count=1)
    # pdoc's anchor beside each entry is an empty link: it gets a name a screen reader can say
    page = re.sub(
        r'<a class="headerlink" href="#([^"]+)"></a>',
        lambda m: f'<a class="headerlink" href="#{m[1]}" aria-label="link to {m[1]}"></a>',
        page,
    )
    style = f"<style>{REFERENCE_NAV_CSS}\n{SKIP_CSS}</style>"
    # inside pdoc's main column: its module list is a fixed column on the left of a wide window
    top = nav.replace('<nav class="site-nav"', '<nav class="site-nav" aria-label="Pages"')
    bottom = nav.replace('<nav class="site-nav"', '<nav class="site-nav bottom" aria-label="Pages (end of page)"')
    page = re.sub(r"(<body[^>]*>)", lambda m: m[1] + "\n" + SKIP_LINK, page, count=1)
    page = page.replace('<nav class="pdoc">', '<nav class="pdoc" aria-label="Contents of the reference">', 1)
    return (
        page.replace("</head>", style + "\n</head>", 1)
        .replace('<main class="pdoc">', '<main class="pdoc" id="site-content" tabindex="-1">\n' + top, 1)
        .replace("</main>", bottom + "\n</main>", 1)
    )


def nav_html(pages, i):
    def link(j, label):
        if 0 <= j < len(pages):
            return f'<a href="{pages[j]["file"]}">{label} {html.escape(pages[j]["title"])}</a>'
        return "<span></span>"

    return (
        f'<nav class="site-nav">{link(i - 1, "&larr;")}<a href="index.html">Contents</a>{link(i + 1, "&rarr;")}</nav>'
    )


def write_page(nb, out, name):
    """Write the executed notebook ``nb`` as ``out/<name>.html``, a page as the site's (its
    3D views live, the pinned JavaScript in ``out/assets/``) without the site's links;
    returns the page's path. Used for one run of a notebook (tools/run_notebook.py)."""
    out = Path(out)
    install_assets(out)
    prepare_for_site(nb)
    body, _ = exporter().from_notebook_node(nb, resources={"site_nav": "", "metadata": {"name": title_of(nb, name)}})
    page = out / f"{name}.html"
    page.write_text(body, encoding="utf-8")
    (out / A11Y_JS).parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(Path(__file__).with_name("site_a11y.js"), out / A11Y_JS)
    return page


INDEX = """<!DOCTYPE html>
<html lang="en">
<head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1.0">
<title>{title}</title>
<style>
body {{ font-family: system-ui, sans-serif; max-width: 50em; margin: 2em auto; padding: 0 1em; line-height: 1.5; }}
li {{ margin: 0.4em 0; }}
.views {{ color: #595959; font-size: 0.9em; }}
{skip_css}
</style></head>
<body>
{skip_link}
<main id="site-content" tabindex="-1">
<h1>{title}</h1>
<p>Every notebook of the workbook, run with its default parameters. The 3D views
turn in the page: drag to orbit, scroll to zoom, right-drag to pan; or Tab to a view and
use the arrow keys to turn it, Shift + arrow keys to pan, + and - to zoom, 0 to reset. The main
sliders move the views here too: they snap to values computed when the site was
built. Other controls recompute only in JupyterLab; here they show their default value.</p>
<ol>
{items}
</ol>
<h2>About the workbook, and its reference</h2>
<p>How to install it, grade with it, run its experiments and work on it; and
geomlib's public functions with their docstrings.</p>
<ul>
{documents}
</ul>
</main>
</body>
</html>
"""


def build(out=OUT, names=None, log=print):
    """Build the site into ``out``; returns a list of pages in reading order (file, title,
    kind: notebook, appendix, doc or reference; live views, live sliders, bytes, seconds,
    cell errors); the list is also written to ``out/pages.json``. ``names`` (file names in
    notebooks/) builds those notebooks only, with every documentation page."""
    out = Path(out)
    paths = [NOTEBOOKS / Path(n).name for n in names] if names else notebook_paths()
    docs = doc_pages()
    targets = link_targets(paths, docs)
    if out.exists() and any(out.iterdir()):
        if not (out / "pages.json").exists():
            raise SystemExit(
                f"{out} is not empty and holds no earlier build of the site; choose an empty or new folder"
            )
        shutil.rmtree(out)
    out.mkdir(parents=True, exist_ok=True)
    install_assets(out)
    (out / STATES_JS).parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(Path(__file__).with_name("site_states.js"), out / STATES_JS)
    shutil.copyfile(Path(__file__).with_name("site_a11y.js"), out / A11Y_JS)
    pages = []
    executed = []
    for path in paths:
        start = time.perf_counter()
        log(f"executing {path.name} ...")
        nb, recorded = execute(path)
        live = prepare_for_site(nb, recorded)
        source = f"notebooks/{path.name}"
        for cell in nb.cells:
            if cell.cell_type == "markdown":
                cell.source = site_links(cell.source, source, targets)
            for output in cell.get("outputs", []):  # text a cell shows as markdown (explain, notes)
                if "text/markdown" in output.get("data", {}):
                    output["data"]["text/markdown"] = site_links(output["data"]["text/markdown"], source, targets)
        sliders = [s for r in recorded.values() for s in r.get("sliders", [])]
        pages.append(
            {
                "file": path.stem + ".html",
                "title": title_of(nb, path.stem),
                "views": live,
                "sliders": [
                    {"model_id": s["model_id"], "description": s["description"], "states": len(s["values"])}
                    for s in sliders
                ],
                "left_out": [s for r in recorded.values() for s in r.get("left_out", [])],
                "seconds": round(time.perf_counter() - start, 1),
                "errors": cell_errors(nb)
                + [f"cell {i}: recording its sliders: {r['error']}" for i, r in recorded.items() if "error" in r],
            }
        )
        executed.append((nb, page_states(recorded)))
        pages[-1]["kind"] = "appendix" if re.match(r"\d\da_", path.name) else "notebook"
        log(f"  {pages[-1]['seconds']} s, {live} live 3D views, {len(sliders)} precomputed sliders")
        for s in sliders:
            log(f"    {s['description']}: {len(s['values'])} states")
        for s in pages[-1]["left_out"]:
            log(f"    {s['description']}: not precomputed ({s['reason']})")
        for error in pages[-1]["errors"]:
            log(f"  ERROR in {error}")
    for source, file in docs.items():
        nb = markdown_notebook(source, targets)
        pages.append(
            {"file": file, "title": title_of(nb, Path(source).stem), "kind": "doc", "source": source}
            | {"views": 0, "sliders": [], "left_out": [], "seconds": 0, "errors": []}
        )
        executed.append((nb, []))
    if (ROOT / IMAGES).is_dir():
        shutil.copytree(ROOT / IMAGES, out / "images")
    pages.append(
        {"file": REFERENCE, "title": REFERENCE_TITLE, "kind": "reference"}
        | {"views": 0, "sliders": [], "left_out": [], "seconds": 0, "errors": []}
    )
    page_exporter = exporter()
    (out / REFERENCE).write_text(reference_html(nav_html(pages, len(pages) - 1)), encoding="utf-8")
    pages[-1]["bytes"] = (out / REFERENCE).stat().st_size
    for i, (page, (nb, states)) in enumerate(zip(pages, executed)):
        resources = {"site_nav": nav_html(pages, i), "metadata": {"name": page["title"]}}
        if states:  # JSON inside <script>: "</" written as "<\/" so no text in it ends the element
            resources["site_states"] = json.dumps(states, separators=(",", ":")).replace("</", "<\\/")
        body, _ = page_exporter.from_notebook_node(nb, resources=resources)
        if page["kind"] == "doc":
            body = body.replace("</head>", f"<style>{DOC_CSS}</style>\n</head>", 1)
        (out / page["file"]).write_text(share_styles(body, out), encoding="utf-8")
        page["bytes"] = (out / page["file"]).stat().st_size
    items = "\n".join(
        f'<li><a href="{p["file"]}">{html.escape(p["title"])}</a> '
        f'<span class="views">({p["views"]} live 3D view{"" if p["views"] == 1 else "s"}'
        f"{live_sliders_text(len(p['sliders']))})</span></li>"
        for p in pages
        if p["kind"] in ("notebook", "appendix")
    )
    documents = "\n".join(
        f'<li><a href="{p["file"]}">{html.escape(p["title"])}</a></li>'
        for p in pages
        if p["kind"] in ("doc", "reference")
    )
    (out / "index.html").write_text(
        INDEX.format(
            title="Discrete curvature and Laplacian mesh processing",
            items=items,
            documents=documents,
            skip_link=SKIP_LINK,
            skip_css=SKIP_CSS,
        ),
        encoding="utf-8",
    )
    (out / "pages.json").write_text(json.dumps(pages, indent=1))
    return pages


SHARED_STYLE = 8192  # bytes: a style sheet of the page's head this large goes to a file of its own


def share_styles(page, site):
    """``page`` (HTML text) with each large style sheet of its head moved to a file in
    ``site/assets/site/`` named by its hash, the ``<style>`` element replaced by a
    ``<link>`` to it in the same place. nbconvert writes JupyterLab's theme (about
    260 KB) into every page; shared, a browser reads it once, and the site is that much
    smaller per page. Sheets that refer to other files (``url()`` or ``@import`` other than
    ``data:``) stay in the page, where their relative addresses hold."""
    end = page.find("</head>")

    def move(m):
        css = m.group(1)
        if len(css) < SHARED_STYLE or re.search(r"@import|url\(\s*['\"]?(?!data:)", css):
            return m.group(0)
        name = f"{ASSETS}/site/style-{hashlib.sha256(css.encode()).hexdigest()[:12]}.css"
        path = Path(site) / name
        if not path.exists():
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(css, encoding="utf-8")
        return f'<link rel="stylesheet" href="{name}">'

    head = re.sub(r'<style type="text/css">(.*?)</style>', move, page[:end], flags=re.S)
    return head + page[end:]


def live_sliders_text(n):
    return "" if not n else f", {n} slider{'' if n == 1 else 's'} that move{'s' if n == 1 else ''} the view"


def folder_size(path):
    return sum(f.stat().st_size for f in Path(path).rglob("*") if f.is_file())


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("notebooks", nargs="*", help="file names in notebooks/ (default: all)")
    parser.add_argument("--out", default=str(OUT), help="output folder (default: build/site)")
    args = parser.parse_args(argv)
    start = time.perf_counter()
    pages = build(args.out, args.notebooks or None)
    size = folder_size(args.out)
    print(f"\nbuilt {args.out} in {time.perf_counter() - start:.0f} s, {size / 1e6:.1f} MB:")
    for p in pages:
        errors = f", {len(p['errors'])} cell errors" if p["errors"] else ""
        print(
            f"  {p['file']:45s} {p['bytes'] / 1e6:5.1f} MB, {p['views']:2d} live 3D views, "
            f"{len(p['sliders'])} live controls{errors}"
        )
    print(f"open {Path(args.out) / 'index.html'} in a browser, or copy the folder to any static web host")
    failed = [p["file"] for p in pages if p["errors"]]
    if failed:
        print(f"\ncells raised errors in {', '.join(failed)} (the pages show them); see above")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
