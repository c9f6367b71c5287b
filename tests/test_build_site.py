"""tools/build_site.py without a browser: how an executed notebook is made fit
for a static page, and the check of the pinned downloads."""

import base64
import hashlib
import json
import re
import sys
from pathlib import Path

import nbformat
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))

import build_site  # noqa: E402


def _model(name, module="@jupyter-widgets/controls", **state):
    return {"model_name": name, "model_module": module, "model_module_version": "2.0.0", "state": state}


def _view(model_id, png=True):
    data = {
        build_site.WIDGET_VIEW: {"version_major": 2, "version_minor": 0, "model_id": model_id},
        "text/plain": "MeshView",
    }
    if png:
        data["image/png"] = "iVBORw0KGgo="
    return nbformat.v4.new_output("display_data", data=data)


def _notebook():
    """A slider and a 3D view in one box, a view alone, and a view whose state was not saved."""
    state = {
        "box": _model("VBoxModel", children=["IPY_MODEL_slider", "IPY_MODEL_r1"]),
        "slider": _model("FloatSliderModel", value=0.0, disabled=False),
        "r1": _model("RendererModel", module="jupyter-threejs", scene="IPY_MODEL_scene"),
        "scene": _model("SceneModel", module="jupyter-threejs", children=[]),
        "r2": _model("RendererModel", module="jupyter-threejs", scene="IPY_MODEL_scene"),
        "label": _model("HTMLModel", value="<b>H</b>"),
    }
    nb = nbformat.v4.new_notebook()
    nb.metadata["widgets"] = {build_site.WIDGET_STATE: {"version_major": 2, "version_minor": 0, "state": state}}
    cells = [
        nbformat.v4.new_code_cell("box"),
        nbformat.v4.new_code_cell("view"),
        nbformat.v4.new_code_cell("lost"),
        nbformat.v4.new_markdown_cell("# 03 · A title\n\ntext"),
    ]
    cells[0].outputs = [_view("box")]
    cells[1].outputs = [_view("r2"), _view("label", png=False)]
    cells[2].outputs = [_view("gone")]
    nb.cells = cells
    return nb, nb.metadata["widgets"][build_site.WIDGET_STATE]["state"]


def test_controls_are_disabled_and_noted():
    nb, state = _notebook()
    assert build_site.prepare_for_site(nb) == 2
    assert state["slider"]["state"]["disabled"] is True
    first = nb.cells[0].outputs  # view, its hidden still, the keys that move it, the note
    assert len(first) == 4 and build_site.WIDGET_VIEW in first[0]["data"]
    assert 'class="site-still" hidden' in first[1]["data"]["text/html"]
    assert "base64,iVBORw0KGgo=" in first[1]["data"]["text/html"]
    assert build_site.VIEW_KEYS in first[2]["data"]["text/html"]
    assert build_site.KERNEL_NOTE in first[3]["data"]["text/html"]
    # no control in the second cell: no note; the label has no still
    assert len(nb.cells[1].outputs) == 4
    assert all("site-kernel-note" not in str(o) for o in nb.cells[1].outputs)


def test_stills_and_figures_keep_their_alt_text():
    nb, state = _notebook()
    nb.cells[0].outputs[0]["metadata"] = {"image/png": {"alt": 'A view of "H" & K'}}
    figure = nbformat.v4.new_output(
        "display_data",
        data={"image/png": "iVBORw0KGgo=", "text/plain": "Figure"},
        metadata={"image/png": {"alt": "a plot"}},
    )
    state["out"] = _model("OutputModel", module="@jupyter-widgets/output", outputs=[figure])
    build_site.prepare_for_site(nb)
    assert 'alt="A view of &quot;H&quot; &amp; K"' in nb.cells[0].outputs[1]["data"]["text/html"]
    assert 'alt="still picture of the 3D view"' in nb.cells[1].outputs[1]["data"]["text/html"]  # no metadata
    (shown,) = state["out"]["state"]["outputs"]
    assert shown["data"]["text/html"] == '<img src="data:image/png;base64,iVBORw0KGgo=" alt="a plot">'
    assert "image/png" not in shown["data"]
    # a page's own figures: the template writes the alt of the output's metadata
    page = nbformat.v4.new_notebook()
    page.cells = [nbformat.v4.new_code_cell("fig")]
    page.cells[0].outputs = [figure, nbformat.v4.new_output("display_data", data={"image/png": "iVBORw0KGgo="})]
    body, _ = build_site.exporter().from_notebook_node(page, resources={"site_nav": "", "metadata": {"name": "t"}})
    assert body.count('alt="a plot"') == 1
    assert body.count("No description has been provided") == 1  # the figure without alt is not given one


def test_pages_have_a_skip_link_a_live_region_and_labelled_navigation():
    nb, _ = _notebook()
    nav = build_site.nav_html([{"file": "a.html", "title": "A"}, {"file": "b.html", "title": "B"}], 0)
    body, _ = build_site.exporter().from_notebook_node(nb, resources={"site_nav": nav, "metadata": {"name": "t"}})
    assert body.index(build_site.SKIP_LINK) < body.index("<main") < body.index("</main>")
    assert '<main id="site-content"' in body and 'aria-live="polite"' in body
    navs = re.findall(r"<nav [^>]*>", body)
    assert len(navs) == 2 and all("aria-label=" in n for n in navs)
    main = body[body.index("<main") : body.index("</main>")]
    assert "<nav" not in main  # both bars outside the content the skip link jumps to
    assert "inTabOrder: false" in body and build_site.A11Y_JS in body


def test_theme_colours_meet_wcag_aa():
    def luminance(hex_colour):
        rgb = [int(hex_colour[i : i + 2], 16) / 255 for i in (1, 3, 5)]
        rgb = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in rgb]
        return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]

    def contrast(a, b):
        hi, lo = sorted((luminance(a), luminance(b)), reverse=True)
        return (hi + 0.05) / (lo + 0.05)

    colours = dict(re.findall(r"--jp-([a-z-]+-color): (#[0-9a-f]{6})", build_site.A11Y_CSS))
    assert len(colours) >= 12
    for name, colour in colours.items():  # code on the cells' grey, prompts on white
        assert contrast(colour, "#f5f5f5" if "mirror" in name else "#ffffff") >= 4.5, (name, colour)
    track = re.search(r"\.noUi-target \{ background: (#[0-9a-f]{6})", build_site.A11Y_CSS)[1]
    assert contrast(track, "#ffffff") >= 3.0  # a slider's track against the page (WCAG 1.4.11)


def test_several_controls_get_one_plural_note():
    nb, state = _notebook()
    state["box"]["state"]["children"].append("IPY_MODEL_drop")
    state["drop"] = _model("DropdownModel", index=0, disabled=False)
    build_site.prepare_for_site(nb)
    notes = [o for o in nb.cells[0].outputs if "site-kernel-note" in str(o)]
    assert len(notes) == 1 and build_site.KERNEL_NOTE_MANY in notes[0]["data"]["text/html"]
    assert state["drop"]["state"]["disabled"] is True


def test_a_view_without_saved_state_keeps_its_still():
    nb, _ = _notebook()
    build_site.prepare_for_site(nb)
    (lost,) = nb.cells[2].outputs
    assert build_site.WIDGET_VIEW not in lost["data"]
    assert lost["data"]["image/png"] == "iVBORw0KGgo="


def test_title_is_the_first_heading():
    nb, _ = _notebook()
    assert build_site.title_of(nb, "fallback") == "03 · A title"
    assert build_site.title_of(nbformat.v4.new_notebook(), "fallback") == "fallback"


def test_navigation_links_neighbours():
    pages = [{"file": f"{i:02d}.html", "title": f"page {i}"} for i in range(3)]
    first, middle, last = (build_site.nav_html(pages, i) for i in range(3))
    assert 'href="01.html"' in first and 'href="00.html"' not in first
    assert 'href="00.html"' in middle and 'href="02.html"' in middle
    assert 'href="01.html"' in last and 'href="02.html"' not in last
    assert all('href="index.html"' in nav for nav in (first, middle, last))


def test_download_must_match_its_pinned_hash(tmp_path, monkeypatch):
    monkeypatch.setattr(build_site, "CACHE", tmp_path)
    data = b"not the package"
    (tmp_path / "pkg-1.0.0.tgz").write_bytes(data)
    good = "sha512-" + base64.b64encode(hashlib.sha512(data).digest()).decode()
    assert build_site.fetch_tarball("pkg", "1.0.0", good) == data
    bad = "sha512-" + base64.b64encode(hashlib.sha512(b"other").digest()).decode()
    with pytest.raises(SystemExit, match="does not match its pinned sha512"):
        build_site.fetch_tarball("pkg", "1.0.0", bad)


def test_every_package_is_pinned_exactly():
    for name, (version, integrity, keep, folder) in build_site.PACKAGES.items():
        assert version.count(".") == 2 and version.replace(".", "").isdigit(), name
        assert integrity.startswith("sha512-") and len(base64.b64decode(integrity[7:])) == 64, name
        assert keep and folder


def test_cell_errors_are_listed():
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_markdown_cell("text"), nbformat.v4.new_code_cell("1 / 0")]
    nb.cells[1].outputs = [
        nbformat.v4.new_output("error", ename="ZeroDivisionError", evalue="division by zero", traceback=[])
    ]
    assert build_site.cell_errors(nb) == ["cell 1: ZeroDivisionError: division by zero"]
    nb.cells[1].outputs = []
    assert build_site.cell_errors(nb) == []


def test_page_loads_nothing_from_a_cdn_and_folds_hidden_code():
    nb, _ = _notebook()
    nb.cells.append(nbformat.v4.new_markdown_cell("A formula $\\Delta = M^{-1} C$."))
    hidden = nbformat.v4.new_code_cell("explain('...')")
    hidden.metadata["jupyter"] = {"source_hidden": True}
    nb.cells.append(hidden)
    build_site.prepare_for_site(nb)
    nav = build_site.nav_html([{"file": "03.html", "title": "03"}], 0)
    body, _ = build_site.exporter().from_notebook_node(nb, resources={"site_nav": nav})
    # no script, style sheet or font from elsewhere (URLs in CSS comments are fine)
    remote = re.findall(r"""(?:src=|href=|url\(|import\()\s*["']?(?:https?:)?//[^"')\s]+""", body)
    assert not remote, remote[:3]
    assert "unpkg.com" not in body and "cdnjs" not in body
    assert f'src="{build_site.REQUIRE_JS}"' in body and build_site.WIDGET_RENDERER in body
    assert build_site.MATHJAX.split("?")[0] in body
    assert body.count('<details class="site-hidden-input">') == 1
    assert body.count('class="site-nav"') == 1 and body.count('class="site-nav bottom"') == 1


def test_glob_patterns_of_kept_files():
    one, deep = build_site.glob_pattern("extensions/*.js"), build_site.glob_pattern("jax/output/CommonHTML/**")
    assert one.fullmatch("extensions/Safe.js") and not one.fullmatch("extensions/a11y/explorer.js")
    assert deep.fullmatch("jax/output/CommonHTML/fonts/TeX/fontdata.js")
    assert not deep.fullmatch("jax/output/SVG/jax.js")


def test_build_never_replaces_a_folder_it_did_not_make(tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(SystemExit, match="holds no earlier build"):
        build_site.build(tmp_path, names=["00_getting_started.ipynb"])
    assert (tmp_path / "notes.txt").read_text() == "mine"


def test_a_precomputed_slider_stays_enabled_and_says_it_snaps():
    nb, state = _notebook()
    state["box"]["state"]["children"].append("IPY_MODEL_drop")
    state["drop"] = _model("DropdownModel", index=0, disabled=False)
    slider = {"model_id": "slider", "description": "t", "values": [0.0, 0.5, 1.0], "default": 0, "traits": []}
    recorded = {0: {"sliders": [slider], "left_out": []}}
    assert build_site.prepare_for_site(nb, recorded) == 2
    assert state["slider"]["state"]["disabled"] is False and state["drop"]["state"]["disabled"] is True
    notes = [o["data"]["text/html"] for o in nb.cells[0].outputs if "note" in str(o)]
    assert notes == [
        '<p class="site-snap-note">On this page the slider snaps to the 3 values computed when the page was built.</p>',
        f'<p class="site-kernel-note">{build_site.KERNEL_NOTE_OTHERS}</p>',
    ]
    assert build_site.page_states(recorded) == [{"sliders": [slider]}]
    assert build_site.page_states({0: {"error": "boom"}, 1: {"sliders": [], "left_out": []}}) == []


def test_the_states_are_on_the_page_and_cannot_end_their_script():
    nb, _ = _notebook()
    build_site.prepare_for_site(nb)
    states = [{"sliders": [{"model_id": "slider", "traits": [{"states": ["<b>1</b></script>"]}]}]}]
    text = json.dumps(states, separators=(",", ":")).replace("</", "<\\/")
    body, _ = build_site.exporter().from_notebook_node(nb, resources={"site_nav": "", "site_states": text})
    assert body.count("</script>") == body.count("<script")
    assert f'<script src="{build_site.STATES_JS}">' in body
    (inside,) = re.findall(r'<script[^>]*id="site-states"[^>]*>(.*?)</script>', body, re.S)
    assert json.loads(inside) == states


def test_links_become_the_sites_pages():
    targets = {
        "notebooks/05_explicit_smoothing.ipynb": "05_explicit_smoothing.html",
        "docs/install.md": "install.html",
        "README.md": "about.html",
    }
    text = (
        "See [05](05_explicit_smoothing.ipynb#The-limit), [install](../docs/install.md), "
        "[home](../README.md), ![a view](../docs/images/front.png), [the tool](../tools/build_site.py), "
        "[`tools/run_notebook.py`](../tools/run_notebook.py), [web](https://example.org/x.md), [here](#top)\n"
        "```bash\n[05](05_explicit_smoothing.ipynb)\n```"
    )
    assert build_site.site_links(text, "notebooks/04_spectral_reconstruction.ipynb", targets) == (
        "See [05](05_explicit_smoothing.html#The-limit), [install](install.html), "
        "[home](about.html), ![a view](images/front.png), the tool (`tools/build_site.py`), "
        "`tools/run_notebook.py`, [web](https://example.org/x.md), [here](#top)\n"
        "```bash\n[05](05_explicit_smoothing.ipynb)\n```"
    )


def test_reading_order_puts_each_appendix_after_its_core(tmp_path, monkeypatch):
    for name in ("01a_dig_deeper_x.ipynb", "00_start.ipynb", "01_one.ipynb", "02_two.ipynb", "notes.ipynb"):
        (tmp_path / name).write_text("{}")
    monkeypatch.setattr(build_site, "NOTEBOOKS", tmp_path)
    assert [p.name for p in build_site.notebook_paths()] == [
        "00_start.ipynb",
        "01_one.ipynb",
        "01a_dig_deeper_x.ipynb",
        "02_two.ipynb",
    ]
    pages = list(build_site.doc_pages())
    assert pages[:4] == ["README.md", "docs/README.md", "docs/assignment.md", "docs/install.md"]
    assert pages[-1] == "benchmarks/README.md"
    assert {p.relative_to(build_site.ROOT).as_posix() for p in (build_site.ROOT / "docs").glob("*.md")} <= set(pages)


def test_repeated_buffers_are_saved_once_and_name_their_first_copy():
    big, other = "A" * 2000, "B" * 2000
    state = {
        "a": {"buffers": [{"path": ["array"], "encoding": "base64", "data": big}]},
        "b": {"buffers": [{"path": ["x"], "encoding": "base64", "data": other}, {"path": ["y"], "data": big}]},
        "c": {"buffers": [{"path": ["array"], "encoding": "base64", "data": "small"}]},
        "d": {"buffers": [{"path": ["array"], "encoding": "base64", "data": "small"}]},
    }
    assert build_site.share_repeated_buffers(state) == 2000
    assert state["a"]["buffers"][0]["data"] == big and state["b"]["buffers"][0]["data"] == other
    assert state["b"]["buffers"][1] == {"path": ["y"], "data": "", "site_same_as": ["a", 0]}
    assert state["d"]["buffers"][0]["data"] == "small"  # a small one costs less than its reference


def test_the_reference_page_lists_the_public_names_with_the_sites_navigation():
    import geomlib

    nav = build_site.nav_html([{"file": "developing.html", "title": "Developing"}, {"file": "reference.html"}], 1)
    page = build_site.reference_html(nav)
    assert all(f'id="{name}"' in page for name in geomlib.__all__)
    assert page.count('class="site-nav"') == 1 and page.count('class="site-nav bottom"') == 1
    assert 'href="developing.html"' in page and "<title>geomlib reference" in page
    assert '<a class="headerlink" href="#load_mesh" aria-label="link to load_mesh"></a>' in page
    assert all("aria-label=" in a for a in re.findall(r"<a [^>]*>\s*</a>", page))  # every empty link named
    assert not re.search(r"""(?:src=|href=)["'](?:https?:)?//[^"']+\.(?:js|css)""", page)


def test_large_style_sheets_are_shared_files(tmp_path):
    theme = "body { color: #111; }\n" * 1000
    page = (
        f'<html><head><style type="text/css">{theme}</style><style type="text/css">p {{ }}</style>'
        f'<style type="text/css">{theme}.x {{ background: url(img.png); }}</style></head>'
        f'<body><style type="text/css">{theme}</style></body></html>'
    )
    shared = build_site.share_styles(page, tmp_path)
    (css,) = (tmp_path / "assets" / "site").glob("style-*.css")
    assert css.read_text() == theme
    link = f'<link rel="stylesheet" href="assets/site/{css.name}">'
    assert shared.startswith(f"<html><head>{link}<style")  # in the same place, the small sheet kept
    assert "url(img.png)" in shared and shared.count(theme) == 2  # a relative url(), and the body, untouched
    assert build_site.share_styles(page, tmp_path) == shared
