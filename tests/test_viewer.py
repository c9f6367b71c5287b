"""Tests of the 3D views (geomlib.teaching.display.viewer, .colours, .stills): colour mapping, in-place updates, normals, the still
picture in the display bundle, linked cameras and input checks.

The browser side (does the canvas really show the mesh, does a slider change
it, do linked cameras turn together) is tested in tests/browser/.
"""

import ast
import base64
import io
import json
import re
from pathlib import Path

import ipywidgets
import matplotlib
import matplotlib.pyplot
import numpy as np
import pytest
import trimesh
from PIL import Image

from geomlib import MeshError
from geomlib.mesh.geometry import vertex_normals
from geomlib.teaching.display.colours import NAN_COLOR, NAN_NAME, colorize, value_range
from geomlib.teaching.display.stills import drawable, render_still, view_normals
from geomlib.teaching.display.viewer import MeshView, side_by_side
from geomlib.teaching.notebook import text_only


@pytest.fixture(scope="module")
def sphere():
    m = trimesh.creation.icosphere(subdivisions=3, radius=1.0)  # 642 vertices
    return np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int64)


@pytest.fixture
def messages(monkeypatch):
    """Every state message the widgets send: (widget class, changed keys)."""
    sent = []
    original = ipywidgets.Widget._send

    def spy(self, msg, buffers=None):
        if msg.get("method") == "update":
            sent.append((type(self).__name__, sorted(msg.get("state", {}))))
        return original(self, msg, buffers)

    monkeypatch.setattr(ipywidgets.Widget, "_send", spy)
    return sent


# --- colour mapping ---------------------------------------------------------


def test_colorize_maps_ends_middle_and_clips():
    cm = matplotlib.colormaps["viridis"]
    values = np.array([0.0, 5.0, 10.0, -3.0, 12.0])
    colors = colorize(values, "viridis", vmin=0.0, vmax=10.0)
    assert colors.shape == (5, 3) and colors.dtype == np.float32
    np.testing.assert_allclose(colors[0], cm(0.0)[:3], atol=1e-6)
    np.testing.assert_allclose(colors[2], cm(1.0)[:3], atol=1e-6)
    np.testing.assert_allclose(colors[1], cm(0.5)[:3], atol=1 / 255 * 2)  # 256-entry table
    np.testing.assert_allclose(colors[3], colors[0])  # clipped below
    np.testing.assert_allclose(colors[4], colors[2])  # clipped above


def test_nan_is_drawn_violet_and_counted(sphere):
    V, F = sphere
    values = V[:, 0].copy()
    values[[3, 7, 11]] = np.nan
    np.testing.assert_allclose(colorize(values, vmin=-1, vmax=1)[[3, 7, 11]], [NAN_COLOR] * 3, atol=1e-6)
    view = MeshView(V, F, values=values)
    np.testing.assert_allclose(view.colors[[3, 7, 11]], [NAN_COLOR] * 3, atol=1e-6)
    assert not np.isnan(view.colors).any()
    lo, hi = view.range
    assert lo == pytest.approx(np.nanmin(values)) and hi == pytest.approx(np.nanmax(values))
    assert f"NaN: {NAN_NAME} (3)" in view._colorbar.value
    assert f"3 NaN drawn {NAN_NAME}" in view.summary()


def _lab(rgb):
    """CIELAB of sRGB colours in [0, 1] (D65)."""
    rgb = np.asarray(rgb, dtype=np.float64)
    lin = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
    XYZ = lin @ np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]]).T
    XYZ = XYZ / np.array([0.9505, 1.0, 1.089])
    f = np.where(XYZ > 0.008856, np.cbrt(XYZ), 7.787 * XYZ + 16 / 116)
    return np.stack([116 * f[..., 1] - 16, 500 * (f[..., 0] - f[..., 1]), 200 * (f[..., 1] - f[..., 2])], -1)


# colour-vision deficiencies at full severity on linear RGB (Machado, Oliveira and Fernandes 2009)
CVD = {
    "protan": [[0.152286, 1.052583, -0.204868], [0.114503, 0.786281, 0.099216], [-0.003882, -0.048116, 1.051998]],
    "deutan": [[0.367322, 0.860646, -0.227968], [0.280085, 0.672501, 0.047413], [-0.011820, 0.042940, 0.968881]],
    "tritan": [[1.255528, -0.076749, -0.178779], [-0.078411, 0.930809, 0.147602], [0.004733, 0.691367, 0.303900]],
}


def _seen(rgb, matrix, shade):
    """sRGB colours as a reader with the deficiency ``matrix`` sees them, shaded by ``shade``."""
    rgb = np.asarray(rgb, dtype=np.float64)
    lin = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
    lin = np.clip(lin @ np.asarray(matrix).T, 0, 1) * shade
    return np.where(lin <= 0.0031308, 12.92 * lin, 1.055 * lin ** (1 / 2.4) - 0.055)


def test_nan_colour_stands_apart_from_the_maps_for_colour_blind_readers():
    # at every shade the head light gives, for normal vision and the three deficiencies, NaN's
    # colour is at least 20 CIELAB units from every colour of both maps (the old grey: 4.9)
    worst = {}
    for name in ("viridis", "RdBu_r"):
        lut = matplotlib.colormaps[name](np.linspace(0, 1, 256))[:, :3]
        for kind, matrix in {"normal": np.eye(3), **CVD}.items():
            for shade in (0.45, 0.7, 1.0):
                d = np.linalg.norm(_lab(_seen(lut, matrix, shade)) - _lab(_seen(NAN_COLOR, matrix, shade)), axis=1)
                worst[(name, kind, shade)] = float(d.min())
    assert min(worst.values()) > 20, min(worst.items(), key=lambda kv: kv[1])
    grey = (0.62, 0.62, 0.62)
    lut = matplotlib.colormaps["viridis"](np.linspace(0, 1, 256))[:, :3]
    d = np.linalg.norm(_lab(_seen(lut, CVD["deutan"], 1.0)) - _lab(_seen(grey, CVD["deutan"], 1.0)), axis=1)
    assert d.min() < 8  # the test can fail: the grey it replaces sits in viridis for deutan readers


def test_plot_cycle_is_colour_blind_safe_with_a_line_style_per_colour():
    from geomlib.teaching.display.colours import PLOT_COLOURS, PLOT_LINESTYLES, plot_style

    cycle = list(plot_style()["axes.prop_cycle"])
    assert len(cycle) == len(PLOT_COLOURS) == len({str(c["linestyle"]) for c in cycle})  # no style repeats
    white = _lab([1.0, 1.0, 1.0])
    for colour in PLOT_COLOURS:
        rgb = np.asarray(matplotlib.colors.to_rgb(colour))
        lin = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
        luminance = float(lin @ [0.2126, 0.7152, 0.0722])
        assert 1.05 / (luminance + 0.05) >= 3.0, colour  # a line against the white page
        assert np.linalg.norm(_lab(rgb) - white) > 30
    with matplotlib.rc_context(plot_style()):
        fig, ax = matplotlib.pyplot.subplots()
        lines = [ax.plot([0, 1], [k, k])[0] for k in range(3)]
        assert len({line.get_linestyle() for line in lines}) == 3
        assert matplotlib.colors.to_hex(lines[1].get_color()) == PLOT_COLOURS[1].lower()
        matplotlib.pyplot.close(fig)
    assert PLOT_LINESTYLES[0] == "-"


def test_symmetric_range_is_centred_on_zero(sphere):
    V, F = sphere
    values = 3.0 * V[:, 1].clip(0, None) - 1.0 * V[:, 1].clip(None, 0) ** 2  # in [-1, 3]
    assert value_range(values, symmetric=True) == pytest.approx((-3.0, 3.0))
    assert value_range(values, symmetric=True, vmin=-0.5, vmax=2.0) == (-2.0, 2.0)
    view = MeshView(V, F, values=values, symmetric=True)
    assert view.cmap == "RdBu_r"  # diverging by default for signed values
    assert view.range == pytest.approx((-3.0, 3.0))
    middle = matplotlib.colormaps["RdBu_r"](0.5)[:3]
    zero = colorize(np.array([0.0]), "RdBu_r", *view.range)[0]
    np.testing.assert_allclose(zero, middle, atol=2 / 255)
    # opposite values get colours from opposite ends, mirrored in the map
    plus, minus = colorize(np.array([2.0, -2.0]), "RdBu_r", -3.0, 3.0)
    cm = matplotlib.colormaps["RdBu_r"]
    np.testing.assert_allclose(plus, cm(5 / 6)[:3], atol=2 / 255)
    np.testing.assert_allclose(minus, cm(1 / 6)[:3], atol=2 / 255)


def test_constant_values_get_a_defined_range(sphere):
    V, F = sphere
    view = MeshView(V, F, values=np.zeros(len(V)), symmetric=True)
    lo, hi = view.range
    assert lo < 0 < hi
    assert np.isfinite(view.colors).all()


def test_colour_bar_shows_the_range_and_label(sphere):
    V, F = sphere
    view = MeshView(V, F, values=2.0 * V[:, 2], label="height (length)")
    text = view._colorbar.value
    assert "linear-gradient" in text and "height (length)" in text
    assert ">-2<" in text and ">2<" in text
    assert MeshView(V, F)._colorbar.layout.display == "none"  # no values, no colour bar


# --- updates ----------------------------------------------------------------


def test_update_overwrites_buffers_in_place_with_one_message(sphere, messages):
    V, F = sphere
    view = MeshView(V, F, values=V[:, 0], vmin=-2.0, vmax=2.0)
    attributes = dict(view.geometry.attributes)
    buffer = view._buffer
    index = view.geometry.index
    colors_before = view.colors
    messages.clear()

    W = 1.5 * V
    view.update(V=W, values=W[:, 1])

    assert messages == [("InterleavedBuffer", ["array"])]  # one message, one widget
    assert view.geometry.index is index
    for name, attribute in view.geometry.attributes.items():
        assert attribute is attributes[name]
        assert attribute.data is buffer
    np.testing.assert_allclose(buffer.array[:, 0:3] + view._centre, W, atol=1e-6)
    np.testing.assert_allclose(view.V, W)
    np.testing.assert_allclose(view.colors, colorize(W[:, 1], "viridis", -2.0, 2.0), atol=1e-6)
    assert not np.allclose(view.colors, colors_before)
    assert buffer.array.dtype == np.float32 and buffer.array.shape == (len(V), 9)


def test_update_values_only_keeps_positions(sphere):
    V, F = sphere
    view = MeshView(V, F, values=V[:, 0])
    positions = view._buffer.array[:, 0:6].copy()
    view.update(values=-V[:, 0])
    np.testing.assert_array_equal(view._buffer.array[:, 0:6], positions)
    np.testing.assert_allclose(view.values, -V[:, 0])
    view.update(vmin=-10.0, vmax=10.0)
    assert view.range == (-10.0, 10.0)


def test_auto_range_follows_values(sphere):
    V, F = sphere
    view = MeshView(V, F, values=V[:, 0])
    view.update(values=5.0 * V[:, 0])
    assert view.range == pytest.approx((5.0 * V[:, 0].min(), 5.0 * V[:, 0].max()))
    assert ">5<" in view._colorbar.value


# --- normals ----------------------------------------------------------------


def test_view_normals_are_geometry_vertex_normals():
    """The view draws with the mesh core's vertex normals, before and after an update (one home)."""
    m = trimesh.creation.icosphere(subdivisions=4, radius=1.0)  # 2562 vertices
    V, F = np.asarray(m.vertices), np.asarray(m.faces)
    view = MeshView(V, F)
    np.testing.assert_allclose(view.normals, vertex_normals(V, F), atol=1e-6)  # float32 buffer
    E = V * [1.0, 2.0, 3.0]
    view.update(V=E)
    np.testing.assert_allclose(view.normals, vertex_normals(E, F), atol=1e-6)
    # and they are the normals of the surface drawn: an ellipsoid's normal is grad(x^2/a^2 + ...)
    g = E / np.array([1.0, 4.0, 9.0])
    g /= np.linalg.norm(g, axis=1, keepdims=True)
    assert np.abs(view.normals - g).max() < 5e-2


def test_a_vertex_without_normal_is_lit_from_up_and_repeated_faces_draw_nothing():
    # two triangles, a face repeating a vertex, an isolated vertex 4 and vertex 5 only in a zero-area face
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.5], [3, 3, 3], [2, 0, 0]], dtype=np.float64)
    F = np.array([[0, 1, 2], [1, 3, 2], [2, 2, 1], [0, 1, 5]])
    view = MeshView(V, F)
    triangles = F[[0, 1, 3]]
    expected = vertex_normals(V, triangles)
    np.testing.assert_array_equal(expected[[4, 5]], 0.0)  # the mesh core gives no normal there
    expected[[4, 5]] = (0.0, 0.0, 1.0)
    np.testing.assert_allclose(view.normals, expected, atol=1e-6)
    np.testing.assert_allclose(view_normals(V, triangles), expected)
    assert view.F.shape == (4, 3)  # the repeated face is kept in the drawing, where it covers no pixel
    assert view.still().shape[1] == view.width
    with pytest.raises(MeshError, match="every face of F repeats a vertex"):
        MeshView(V, F[[2]])


# --- display ----------------------------------------------------------------


def _decode(bundle):
    return np.asarray(Image.open(io.BytesIO(base64.b64decode(bundle["image/png"]))).convert("RGB"))


def test_mimebundle_has_widget_png_and_text(sphere):
    V, F = sphere
    view = MeshView(V, F, values=V[:, 2], symmetric=True, title="sphere", label="z")
    bundle, metadata = view._repr_mimebundle_()
    assert metadata == {"image/png": {"alt": view.alt_text()}}
    assert set(bundle) >= {"application/vnd.jupyter.widget-view+json", "image/png", "text/plain"}
    assert bundle["application/vnd.jupyter.widget-view+json"]["model_id"] == view.widget.model_id
    image = _decode(bundle)
    assert image.shape[1] == view.width and image.shape[0] >= view.height
    pixels = image.reshape(-1, 3)
    not_white = np.any(pixels < 245, axis=1).mean()
    assert not_white > 0.1
    assert len(np.unique(pixels, axis=0)) > 200  # shaded and coloured, not flat
    reds = (pixels[:, 0] > pixels[:, 2] + 60).mean()  # the diverging map shows both ends
    blues = (pixels[:, 2] > pixels[:, 0] + 60).mean()
    assert reds > 0.01 and blues > 0.01
    assert "642 vertices" in bundle["text/plain"] and "1280 faces" in bundle["text/plain"]
    assert not re.search(r"[0-9a-f]{32}", bundle["text/plain"])  # no model ids in text


def test_alt_text_says_mesh_quantity_range_nans_and_what_to_look_for(sphere, messages):
    V, F = sphere
    H = V[:, 2].copy()
    H[[3, 7]] = np.nan
    view = MeshView(
        V,
        F,
        values=H,
        symmetric=True,
        title="mean curvature",
        label="H (1/length)",
        description="The poles are extreme.",
    )
    lo, hi = view.range
    assert view.alt_text() == (
        f"3D view of mean curvature: a mesh of 642 vertices and 1280 faces, coloured by H (1/length) from "
        f"{lo:.3g} to {hi:.3g} (RdBu_r colour map, 0 in the middle). 2 vertices have no value (NaN), drawn "
        f"{NAN_NAME}. The poles are extreme."
    )
    # the text is in the page, under the canvas, and follows updates
    assert view._caption in view.widget.children and "The poles are extreme." in view._caption.value
    messages.clear()
    view.update(values=5.0 * H, description="Five times as curved.")
    assert "from -5 to 5" in view.alt_text() and view.alt_text().endswith("Five times as curved.")
    assert "Five times as curved." in view._caption.value and "from -5 to 5" in view._caption.value
    assert ("HTML", ["value"]) in messages
    messages.clear()
    view.update(values=5.0 * H)  # nothing new in the text: no message for it
    assert all(name != "HTML" for name, _ in messages)
    view.update(description="Only the words change.")
    assert view.alt_text().endswith("Only the words change.") and "Only the words" in view._caption.value
    view.update(description="  the rim   flattens first ")  # a sentence of its own
    assert view.alt_text().endswith("(NaN), drawn bright violet. The rim flattens first.")
    # plain and zero views say so; no description, no trailing words
    assert (
        MeshView(V, F).alt_text() == "3D view of a mesh of 642 vertices and 1280 faces, plain shading (no colour map)."
    )
    zero = MeshView(V, F, values=np.zeros(len(V)), label="K")
    assert "coloured by K: 0 everywhere" in zero.alt_text() and zero.alt_text().endswith("drawn white.")


def test_the_still_of_a_box_of_views_carries_their_alt_text(sphere):
    from IPython.core.formatters import DisplayFormatter

    from geomlib.teaching.display import viewer
    from geomlib.teaching.display.viewer import box_alt

    V, F = sphere
    a, b = MeshView(V, F, title="a", description="look at a"), MeshView(V, F, title="b")
    box = ipywidgets.VBox([ipywidgets.FloatSlider(), ipywidgets.HBox([a.widget, b.widget])])
    assert box_alt(box) == a.alt_text() + " " + b.alt_text()
    formatter = DisplayFormatter()
    formatter.formatters["image/png"].for_type(ipywidgets.Box, viewer._box_png)  # as in IPython
    data, metadata = formatter.format(box)
    assert "image/png" in data and metadata["image/png"]["alt"] == box_alt(box)
    data, metadata = formatter.format(a)
    assert metadata["image/png"]["alt"] == a.alt_text() and a.alt_text().endswith("Look at a.")


def test_still_puts_the_mesh_in_the_middle():
    # a unit square facing the camera direction fills the middle, corners stay background
    from geomlib.teaching.display.stills import UP, VIEW_DIRECTION, camera_basis

    right, up, w = camera_basis(VIEW_DIRECTION, UP)
    corners = np.array([-right - up, right - up, right + up, -right + up])
    F = np.array([[0, 1, 2], [0, 2, 3]])
    colors = np.tile([1.0, 0.0, 0.0], (4, 1))
    image = render_still(corners, F, colors, width=100, height=80)
    assert image.shape == (80, 100, 3)
    assert image[40, 50, 0] > 200 and image[40, 50, 1] < 40  # red, lit head-on
    assert (image[0, 0] == 255).all() and (image[-1, -1] == 255).all()
    # nearer surfaces hide farther ones: a blue square in front covers the red one
    V2 = np.vstack([corners, 0.5 * corners + 0.5 * w])
    F2 = np.vstack([F, F + 4])
    colors2 = np.vstack([colors, np.tile([0.0, 0.0, 1.0], (4, 1))])
    image2 = render_still(V2, F2, colors2, width=100, height=80)
    assert image2[40, 50, 2] > 200 and image2[40, 50, 0] < 40
    # whatever the order of the faces
    image3 = render_still(V2, F2[::-1], colors2, width=100, height=80)
    assert (image3 == image2).all()


def _word_gaps(title):
    """Widths of the blank column runs between the inked columns of a still's title line."""
    from geomlib.teaching.display.stills import still_with_colorbar

    image = still_with_colorbar(np.full((20, 400, 3), 255, np.uint8), None, 0.0, 1.0, "", title)
    ink = (image[:18] < 128).any(axis=(0, 2))  # the title band above the picture
    columns = np.flatnonzero(ink)
    runs = np.diff(columns) - 1
    return runs[runs > 0]


def test_still_titles_keep_their_spaces():
    # Pillow's default font has a 2 px space that hinting can remove ("implicitsmoothing")
    spaced, joined = _word_gaps("implicit smoothing, steps of 0.3"), _word_gaps("implicitsmoothing,stepsof0.3")
    assert (spaced >= 4).sum() == 4  # the four spaces, each at least 4 px wide
    assert (joined >= 4).sum() == 0  # letters within a word are never that far apart (3 px at most)


def test_plain_view_without_values(sphere):
    V, F = sphere
    view = MeshView(V, F, wireframe=True)
    assert view.wireframe is not None
    assert view.wireframe.geometry.attributes["position"] is view.geometry.attributes["position"]
    n_edges = len(view.wireframe.geometry.index.array) // 2
    assert n_edges == 3 * len(F) // 2  # closed mesh: E = 3F/2
    assert "coloured" not in view.summary()
    image = view.still()
    assert np.any(image < 245, axis=2).mean() > 0.1


def _screen(view, X):
    """Pixel (column, row) of the points X (k, 3) in the view's still (no title above it)."""
    from geomlib.teaching.display.stills import FOV, camera_basis

    right, up, w = camera_basis(view._direction, view._up)
    P = X - view._centre
    depth = view._distance - P @ w
    f = (view.height / 2) / np.tan(np.radians(FOV) / 2)
    return (view.width / 2 + f * (P @ right) / depth).astype(int), (view.height / 2 - f * (P @ up) / depth).astype(int)


def test_the_still_of_a_wireframe_view_draws_its_edges(sphere):
    from geomlib.mesh.topology import edges

    V, F = sphere
    wire, plain = MeshView(V, F, wireframe=True).still(), MeshView(V, F).still()
    darker = (plain.astype(int) - wire.astype(int)).sum(axis=2) > 60  # the edge colour at 0.45 over the surface
    covered = np.any(plain < 245, axis=2)
    rim = covered.copy()
    rim[1:] |= covered[:-1]
    rim[:-1] |= covered[1:]
    rim[:, 1:] |= rim[:, :-1].copy()
    rim[:, :-1] |= rim[:, 1:].copy()
    assert not (darker & ~rim).any()  # the lines lie on the drawn surface (the outline's pixels next to it)
    assert 0.05 < darker.sum() / covered.sum() < 0.4  # lines, not a fill
    view = MeshView(V, F)
    toward = np.asarray(view._direction) / np.linalg.norm(view._direction)  # from the centre to the eye
    E = edges(F)
    mid, centre = V[E].mean(axis=1), V[F].mean(axis=1)
    # every edge facing the camera is drawn through its midpoint (within a pixel); the faces' centres stay clean
    x, y = _screen(view, mid[mid @ toward > 0.5])
    assert np.mean([darker[yy - 1 : yy + 2, xx - 1 : xx + 2].any() for xx, yy in zip(x, y)]) == 1.0
    cx, cy = _screen(view, centre[centre @ toward > 0.5])
    assert darker[cy, cx].mean() < 0.02
    # the surface hides the edges behind it: drawn alone, they leave the picture as it was
    colors = np.full((len(V), 3), 0.8)
    behind = E[mid @ toward < -0.2]
    assert np.array_equal(render_still(V, F, colors, edges=behind), render_still(V, F, colors))
    assert not np.array_equal(render_still(V, F, colors, edges=E[mid @ toward > 0.2]), render_still(V, F, colors))


def _notebook_views():
    """(notebook, {keyword: expression}) of every ``MeshView(...)`` call in the notebooks' code cells."""
    for path in sorted((Path(__file__).parents[1] / "notebooks").glob("*.ipynb")):
        for cell in json.loads(path.read_text(encoding="utf-8"))["cells"]:
            if cell["cell_type"] != "code":
                continue
            source = "".join(cell["source"])
            code = "\n".join("" if line.lstrip().startswith(("%", "!")) else line for line in source.splitlines())
            for node in ast.walk(ast.parse(code)):
                if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "MeshView":
                    yield path.name, {kw.arg: kw.value for kw in node.keywords}


def _words(expression):
    """The literal text of an expression: its string constants and the fixed parts of its f-strings."""
    return " ".join(n.value for n in ast.walk(expression) if isinstance(n, ast.Constant) and isinstance(n.value, str))


def test_the_stills_font_draws_every_character_of_the_notebooks_titles_and_labels():
    texts = [_words(kw[key]) for _, kw in _notebook_views() for key in ("title", "label") if key in kw]
    assert len(texts) > 40
    assert "²" in "".join(texts)  # the labels write units as 1/length², not 1/length^2
    assert drawable("".join(texts)) == []  # no character drawn as a box
    assert drawable("K (1/length²) λ τ σ κ φ − × ·") == []


def test_every_view_of_the_notebooks_names_what_it_shows():
    # its alt text begins "3D view of" the title: a noun phrase, not a participle ("3D view of coloured by height")
    views = list(_notebook_views())
    assert len(views) > 20
    untitled = [name for name, kw in views if "title" not in kw]
    assert untitled == []
    first = [(name, _words(kw["title"]).split()[:1]) for name, kw in views if isinstance(kw["title"], ast.Constant)]
    not_a_name = {"coloured", "colored", "drawn", "shown", "smoothed", "with", "after", "by", "of"}
    assert [(name, w) for name, w in first if w and w[0] in not_a_name] == []


# --- side by side -----------------------------------------------------------


def test_side_by_side_links_cameras(sphere):
    V, F = sphere
    a = MeshView(V, F, values=V[:, 0], title="a")
    b = MeshView(2.0 * V + 5.0, F, values=V[:, 1], title="b", width=300, height=200)
    c = MeshView(V, F)
    row = side_by_side(a, b, c)
    assert row.views == [a, b, c]
    cameras = {id(v.renderer.camera) for v in row.views}
    controls = {id(v.renderer.controls[0]) for v in row.views}
    assert len(cameras) == 1 and len(controls) == 1
    assert b.renderer.width == a.width and b.renderer.height == a.height
    assert [child for child in row.widget.children] == [a.widget, b.widget, c.widget]
    # the shared camera is framed on the largest mesh
    assert np.linalg.norm(a.camera.position) == pytest.approx(row._distance)
    assert row._distance > MeshView(V, F)._distance  # b is twice as large
    bundle, metadata = row._repr_mimebundle_()
    assert metadata["image/png"]["alt"].startswith("View 1 of 3: 3D view of a: a mesh of 642 vertices")
    assert (
        "View 3 of 3: 3D view of a mesh of 642 vertices and 1280 faces, plain shading" in metadata["image/png"]["alt"]
    )
    image = _decode(bundle)
    assert image.shape[1] == 3 * a.width + 2 * 8
    assert bundle["text/plain"].count("MeshView") == 3


def test_while_nbgrader_runs_a_view_is_its_summary_without_the_widget_or_a_still(sphere, monkeypatch):
    # nbgrader's feedback pages are static HTML (a widget there is an empty placeholder), and a
    # grading run draws no picture: each view gives its one-line summary
    V, F = sphere
    monkeypatch.delenv("NBGRADER_EXECUTION", raising=False)
    assert not text_only()
    view = MeshView(V, F, title="sphere")
    row = side_by_side(view, MeshView(V, F))
    read = [view._repr_mimebundle_()[0], row._repr_mimebundle_()[0]]
    assert all("image/png" in bundle and _decode(bundle).shape[1] >= view.width for bundle in read)
    monkeypatch.setenv("NBGRADER_EXECUTION", "autograde")
    assert text_only()
    graded = [view._repr_mimebundle_(), row._repr_mimebundle_()]
    assert graded == [{"text/plain": bundle["text/plain"]} for bundle in read]
    assert graded[0]["text/plain"].startswith("MeshView: 642 vertices, 1280 faces (sphere)")


def test_side_by_side_without_linking_keeps_cameras(sphere):
    V, F = sphere
    a, b = MeshView(V, F), MeshView(V, F)
    side_by_side(a, b, link_cameras=False)
    assert a.renderer.camera is not b.renderer.camera


# --- bad input --------------------------------------------------------------


@pytest.mark.parametrize(
    "V_bad, message",
    [
        (np.zeros((5, 2)), "shape"),
        (np.zeros(15), "shape"),
    ],
)
def test_bad_vertex_shapes(V_bad, message, sphere):
    _, F = sphere
    with pytest.raises(MeshError, match=message):
        MeshView(V_bad, F[:1] * 0)


def test_bad_faces_name_the_faces(sphere):
    V, F = sphere
    with pytest.raises(MeshError, match="shape"):
        MeshView(V, F[:, :2])
    G = F.copy()
    G[[4, 9]] = len(V)
    with pytest.raises(MeshError, match="faces 4, 9"):
        MeshView(V, G)
    with pytest.raises(MeshError, match="no faces"):
        MeshView(V, np.zeros((0, 3), dtype=np.int64))
    with pytest.raises(MeshError, match="integer"):
        MeshView(V, F + 0.5)


def test_non_finite_input(sphere):
    V, F = sphere
    W = V.copy()
    W[[2, 5]] = np.nan
    with pytest.raises(MeshError, match="vertices 2, 5"):
        MeshView(W, F)
    values = V[:, 0].copy()
    values[8] = np.inf
    with pytest.raises(MeshError, match="infinite at vertices 8"):
        MeshView(V, F, values=values)


def test_values_of_wrong_length(sphere):
    V, F = sphere
    with pytest.raises(MeshError, match=r"one number per vertex, shape \(642,\)"):
        MeshView(V, F, values=np.zeros(len(V) - 1))
    view = MeshView(V, F, values=V[:, 0])
    with pytest.raises(MeshError, match="one number per vertex"):
        view.update(values=np.zeros(len(V) + 3))
    with pytest.raises(MeshError, match="642"):
        view.update(V=V[:-1])
    with pytest.raises(MeshError, match="shape"):
        view.update(V=V[:, :2])
    with pytest.raises(MeshError, match="colour map"):
        MeshView(V, F, values=V[:, 0], cmap="no-such-map")
    with pytest.raises(MeshError, match="MeshView"):
        side_by_side(view, "not a view")


def test_closed_outward_takes_the_mesh_cores_volume(sphere, monkeypatch):
    import geomlib.teaching.display.viewer as viewer

    V, F = sphere
    monkeypatch.setattr(viewer, "enclosed_volume", lambda V, F: -1.0)
    assert MeshView(V, F).mesh.material.side == "DoubleSide"


def test_up_is_checked_as_every_option(sphere):
    V, F = sphere
    with pytest.raises(MeshError, match=r"up must be one of 'z', 'y', 'x', not 'w'"):
        MeshView(V, F, up="w")


def test_back_faces_skipped_only_on_closed_outward_meshes(sphere):
    V, F = sphere
    assert MeshView(V, F).mesh.material.side == "FrontSide"
    assert MeshView(V, F[:, ::-1]).mesh.material.side == "DoubleSide"  # inside out
    G = F.copy()
    G[0] = G[0, ::-1]  # one face flipped
    assert MeshView(V, G).mesh.material.side == "DoubleSide"
    assert MeshView(V, F[1:]).mesh.material.side == "DoubleSide"  # a hole


# --- pictures that must not mislead ----------------------------------------


def test_a_field_zero_up_to_rounding_draws_white(sphere):
    from geomlib.teaching.display.colours import ZERO_COLOR

    V, F = sphere
    rounding = 8e-13 * np.sin(7 * V[:, 0])  # a flat mesh's H, say: zero but for rounding
    view = MeshView(V, F, values=rounding, symmetric=True, label="H (1/length)")
    assert view.is_zero
    np.testing.assert_array_equal(view.colors, np.tile(np.float32(ZERO_COLOR), (len(V), 1)))
    assert "0 everywhere" in view._colorbar.value and "linear-gradient" not in view._colorbar.value
    assert "0 everywhere" in view.summary() and "RdBu_r" not in view.summary()
    # a field above the tolerance is coloured as usual, over its own range
    view.update(values=1e-3 * np.sin(7 * V[:, 0]))
    assert not view.is_zero and "linear-gradient" in view._colorbar.value
    assert len(np.unique(view.colors, axis=0)) > 50
    # the tolerance is the caller's to set: 0 colours even rounding noise
    assert not MeshView(V, F, values=rounding, symmetric=True, zero_tol=0.0).is_zero


def test_a_zero_field_in_a_given_range_shows_that_ranges_colour_bar(sphere):
    V, F = sphere
    view = MeshView(V, F, values=np.zeros(len(V)), symmetric=True, vmin=-2.0, vmax=2.0, label="H (1/length)", title="H")
    assert view.is_zero and "linear-gradient" in view._colorbar.value and "0 everywhere" in view._colorbar.value
    still = view.still()
    bar = still[18 + view.height + 6 + 5, 40:-40].astype(int)  # the bar's middle row, inside its frame
    assert bar[:, 2].max() - bar[:, 0].min() > 100  # blue to red, with white between: the bar is drawn
    middle = bar[len(bar) // 2 - 3 : len(bar) // 2 + 3]
    assert (middle > 235).all()  # its middle, 0, is the white of the surface
    # a flat grid seen from the default camera (a plane's H in notebook 01): its white reads as white,
    # not the mid-grey (156 of 255) of a light at the eye
    from geomlib.teaching.shapes import surfaces

    grid = surfaces.plane(n=8)
    flat = MeshView(grid.V, grid.F, values=np.zeros(len(grid.V)), symmetric=True, vmin=-1.0, vmax=1.0, title="plane")
    surface = flat.still()[18 : 18 + flat.height]
    assert np.median(surface[np.any(surface < 250, axis=2)]) > 220


def test_zero_field_keeps_nan_violet(sphere):
    V, F = sphere
    values = np.zeros(len(V))
    values[:5] = np.nan
    view = MeshView(V, F, values=values)
    assert view.is_zero
    np.testing.assert_allclose(view.colors[:5], [NAN_COLOR] * 5, atol=1e-6)
    np.testing.assert_allclose(view.colors[5:], 1.0)


def test_frame_keeps_a_collapsed_mesh_at_the_input_scale(sphere):
    V, F = sphere
    collapsed = 0.01 * V + 0.3  # what a collapsing flow leaves
    own = MeshView(collapsed, F)
    framed = MeshView(collapsed, F, frame=V)
    assert framed._distance == pytest.approx(MeshView(V, F)._distance)
    assert own._distance == pytest.approx(0.01 * framed._distance)

    # in the still, the collapsed mesh covers a small fraction of what the input covers
    def covered(view):
        return np.any(view.still()[: view.height] < 245, axis=2).mean()

    assert covered(framed) < 0.01 * covered(MeshView(V, F))
    assert covered(own) > 0.5 * covered(MeshView(V, F))
    # updating to the collapsed positions does not reframe either
    view = MeshView(V, F)
    distance = view._distance
    view.update(V=collapsed)
    assert view._distance == distance and covered(view) < 0.01 * covered(MeshView(V, F))


def test_fit_draws_a_collapse_or_an_explosion_at_the_frames_size_and_says_so(sphere):
    V, F = sphere
    view = MeshView(V, F, title="smoothing", fit=True)

    def covered():
        return np.any(view.still()[18 : 18 + view.height] < 245, axis=2).mean()

    full = covered()
    view.update(V=0.5 * V + 0.1)  # shrunk to half: drawn as it is, so the shrinkage is seen
    assert view._title.value == "<b>smoothing</b>" and 0.15 * full < covered() < 0.35 * full
    view.update(V=1e-6 * V + 0.3)  # collapsed: a speck, drawn a million times larger at the frame's centre
    assert "drawn 1e+06 x larger" in view._title.value and "drawn 1e+06 times larger" in view.alt_text()
    assert covered() == pytest.approx(full, rel=0.02)
    stretched = V * [30.0, 1.0, 1.0]  # a volume kept by a large stretch: out of the frame, drawn smaller
    view.update(V=stretched)
    assert "drawn 17.3 x smaller" in view._title.value  # the bounding boxes' diagonals: sqrt(902 / 3)
    picture = np.any(view.still()[18 : 18 + view.height] < 245, axis=2)
    assert picture.any() and not (picture[0].any() or picture[-1].any() or picture[:, 0].any() or picture[:, -1].any())
    view.update(V=V)
    assert view._title.value == "<b>smoothing</b>" and covered() == pytest.approx(full)
    assert MeshView(1e-6 * V, F, frame=V)._fitted == 1.0  # without fit: the frame's scale, always


def test_linked_views_of_very_different_sizes_are_not_specks(sphere):
    V, F = sphere
    big = 28.0 * V  # fandisk_ns is 28 times plane_ns
    small_V, small_F = V[:, :], F[:, ::-1].copy()  # another mesh (other faces)
    a, b = MeshView(big, F, title="large"), MeshView(small_V, small_F, title="small")
    row = side_by_side(a, b)
    assert a._scale == 1.0 and b._scale == pytest.approx(28.0)
    assert b.mesh.scale == pytest.approx((28.0, 28.0, 28.0))
    assert "28 x larger" in b._title.value and "larger" not in a._title.value
    assert "28 x larger" in b.summary()
    covered = [np.any(v.still(distance=row._distance)[18 : 18 + v.height] < 245, axis=2).mean() for v in row.views]
    assert covered[1] > 0.5 * covered[0]


def test_linked_views_of_one_mesh_keep_their_common_scale(sphere):
    V, F = sphere
    before, after = MeshView(V, F), MeshView(0.05 * V, F)  # the same mesh before and after shrinking
    side_by_side(before, after)
    assert before._scale == after._scale == 1.0
    # similar sizes are never rescaled
    c, d = MeshView(V, F), MeshView(0.5 * V, F[:, ::-1].copy())
    side_by_side(c, d)
    assert c._scale == d._scale == 1.0
