"""Interactive 3D mesh views for the notebooks (pythreejs 2.4 / three.js r97): the widget.

The view's colours come from :mod:`.colours` (colour maps, colour bars) and its
still picture from :mod:`.stills` (a numpy rasteriser); sliders, read-outs,
arrows and markers are wired by :mod:`.controls`.

Convention: a view shows ``V`` (n, 3) float64 and ``F`` (m, 3) int64 as a
smooth-shaded surface, optionally coloured by a per-vertex scalar ``values``
(n,) through a named matplotlib colour map, with a colour bar giving the value
range. Signed quantities (``symmetric=True``) get a diverging map whose centre
is exactly zero; NaN values are drawn bright violet (``colours.NAN_COLOR``, far
from every colour of the maps for colour-blind readers too) and counted under the
colour bar, which names the colour.

    from geomlib.teaching.display.viewer import MeshView, side_by_side
    view = MeshView(V, F, values=H, symmetric=True, label="H (1/length)")
    slider = ipywidgets.FloatSlider(0.0, min=0.0, max=1.0, description="t")
    slider.observe(lambda change: view.update(V=V + change["new"] * D), "value")
    ipywidgets.VBox([slider, view.widget])       # slider and view in one box
    side_by_side(view_a, view_b)                 # cameras linked: orbit one, both turn

Controls in the browser: left drag orbits, the wheel (or middle drag) zooms,
right drag (or ctrl + left drag) pans. The camera starts framed on the mesh's
bounding box, looking at its centre, with z up (``up="y"`` for models stored
y-up).

Marking views and sliders (the browser tests rely on it)
--------------------------------------------------------
Every ``MeshView.widget`` carries the CSS class ``geomlib-view`` and its
canvas the class ``geomlib-canvas``. The browser test moves, in every notebook,
the first slider that sits in the same ipywidgets box as a view (at any depth,
e.g. ``VBox([slider, view.widget])`` or ``VBox([HBox([s1, s2]), side_by_side(a, b).widget])``);
if there is none, the first slider displayed by the same cell as a view
(``display(slider); display(view)``). It checks that the views of that box or
cell change. So a notebook needs at least one slider next to a view in one of
these two ways, and that slider must change the picture whether it is moved to
its maximum (or to its minimum when it starts there). Sliders elsewhere are
not moved by the test (``geomlib.teaching.display.controls.live`` puts its controls and views in one
box). Views shown with ``side_by_side`` are also checked for
linked cameras (an orbit drag in the first view must turn the second).

Many views on one page
----------------------
pythreejs keeps at most 8 live WebGL canvases per page; when a ninth view
appears, the oldest one is frozen into a picture and comes back to life when
the mouse enters it. Keep notebooks to about 8 views, or reuse one view with
``update``.

Updates
-------
``view.update(V=..., values=...)`` overwrites the buffers in place: positions,
normals and colours live in one interleaved float32 buffer, so an update is a
single widget message and the browser never shows a half-updated frame.
Normals are :func:`geomlib.mesh.geometry.vertex_normals` (through
:func:`.stills.view_normals`, which gives a vertex without a normal (0, 0, 1)). The colour bar's text is a second,
small message and is only sent when the printed range changes (pass fixed
``vmin``/``vmax`` for sliders to avoid it).

Lighting
--------
The surface is shaded by a small shader with a light that moves with the camera
(from the viewer's eye, raised a little along the camera's up, so that a
surface seen from above at a low angle faces it; both sides of the surface
lit), not by three.js lights: a
``DirectionalLight`` or ``PointLight`` makes pythreejs log "Error setting state:
t.on is not a function" once per view in the browser console (harmless, nothing
visible is wrong), and a light fixed to the camera cannot be shared by views
whose cameras are linked. The colours on screen are the colour map's own
colours times the shading factor, so they match the colour bar. On a closed,
outward-oriented mesh back faces are skipped (they cannot be seen from
outside; the software WebGL of headless browsers draws large meshes about
twice as fast); open or inconsistently oriented meshes show both sides.

Pictures that must not mislead
------------------------------
* A field that is zero up to rounding (every finite ``|value| <= zero_tol``,
  default :data:`ZERO_TOL`) is drawn in :data:`ZERO_COLOR` (white) and its colour
  bar says "0 everywhere"; it is never stretched over the whole colour map.
* ``MeshView(P, F, frame=V)`` frames the camera on ``V`` (the input before
  smoothing): a result that shrank or collapsed is drawn at the input's scale,
  so the collapse is seen instead of being reframed away. ``update`` never
  moves the camera either.
* ``side_by_side`` links the cameras of views of different sizes without
  shrinking the smaller ones to specks: views of one mesh (the same faces)
  keep their common scale, and a group of views of a mesh smaller than
  :data:`SPECK_RATIO` times the largest is drawn enlarged to its size, with
  "drawn N x larger" under its title.

Text alternative
----------------
``view.alt_text()`` says what the view shows: the mesh (vertices, faces,
title), the quantity with its unit (``label``) and colour range, the NaN count
and ``description`` (what to look for, given to ``MeshView`` and to
``update``). It is in the page as a caption under the colour bar (class
``geomlib-alt``), follows every ``update`` (one more small message, only when
the text changed), and is the alt of the still: the display bundle is
``(data, {"image/png": {"alt": alt_text()}})``.

Without a front-end
-------------------
``display(view)`` gives the widget together with a still picture (image/png,
drawn by a small numpy z-buffer rasteriser from the same camera direction, with
the colour bar) and a one-line text summary, so nbval, exported HTML and
repository previews still show the mesh. (``jupyter nbconvert --to html``
shows the still unless the notebook was saved with its widget state; with the
state it embeds the live widget, which needs the widget scripts from a CDN.)
A view shown inside an ipywidgets box (``VBox([slider, view.widget])``) is
drawn too: after :func:`setup_display` (each notebook's set-up cell calls it, and
so does the first view) every box holding views has a still picture of them
(``box_still``), side by side.

While nbgrader runs a notebook (``autograde``, ``validate``) a view gives its
one-line summary only, without the widget or a still picture, a box of views the
summaries, and other widgets their text (``geomlib.teaching.notebook.text_only``):
the feedback pages are static HTML without widget state, where a widget would be
an empty placeholder, and no grade cell needs a picture.
"""

import html
import weakref

import numpy as np

from ...mesh.errors import MeshError, format_indices
from ...mesh.geometry import enclosed_volume
from ...mesh.topology import Topology, edges
from ...mesh.validate import as_faces, as_vertices, check_choice, repeated_vertex_faces
from ..notebook import text_only
from .colours import (
    NAN_COLOR,
    NAN_NAME,
    PLAIN_COLOR,
    ZERO_COLOR,
    ZERO_TOL,
    colorbar_html,
    colorize,
    colour_table,
    format_value,
    use_plot_style,
    value_range,
    zero_html,
)
from .frontends import enable_colab_widgets
from .stills import (
    FOV,
    LIGHT_RAISE,
    UP,
    VIEWS,
    bounding_frame,
    camera_basis,
    camera_distance,
    in_a_row,
    png_base64,
    render_still,
    still_with_colorbar,
    view_normals,
)

__all__ = [
    "MeshView",
    "ViewRow",
    "side_by_side",
    "box_still",
    "box_alt",
    "box_text",
    "register_still",
    "setup_display",
]

#: in ``side_by_side``, a mesh whose bounding box is smaller than this fraction
#: of the largest one is drawn enlarged to the largest one's size
SPECK_RATIO = 0.25
#: multisampled (smooth) edges: True, False, or "auto" = only for meshes of at
#: most ANTIALIAS_MAX_VERTICES vertices. Without a GPU (software WebGL) the
#: multisampling costs noticeable time per frame on large meshes, whose small
#: triangles need it least.
ANTIALIAS = "auto"
ANTIALIAS_MAX_VERTICES = 20_000

_VERTEX_SHADER = """
varying vec3 vColor;
varying vec3 vNormal;
varying vec3 vEye;
void main() {
    vColor = color;
    vNormal = normalize(normalMatrix * normal);
    vec4 mv = modelViewMatrix * vec4(position, 1.0);
    vEye = -mv.xyz;
    gl_Position = projectionMatrix * mv;
}
"""

# a light at the eye raised along the camera's up (stills.LIGHT_RAISE), diffuse, plus a little
# specular from the eye; back faces lit too
_FRAGMENT_SHADER = """
varying vec3 vColor;
varying vec3 vNormal;
varying vec3 vEye;
void main() {
    vec3 n = normalize(vNormal);
    if (!gl_FrontFacing) n = -n;
    vec3 e = normalize(vEye);
    vec3 l = normalize(e + vec3(0.0, LIGHT_RAISE, 0.0));
    float d = max(dot(n, l), 0.0);
    float s = pow(max(dot(n, e), 0.0), 40.0);
    gl_FragColor = vec4(vColor * (0.35 + 0.65 * d) + vec3(0.12 * s), 1.0);
}
""".replace("LIGHT_RAISE", f"{LIGHT_RAISE:.4f}")


# ----------------------------------------------------------------------------
# input checks
# ----------------------------------------------------------------------------


def _check_count(V, n):
    if len(V) != n:
        raise MeshError(
            f"V has {len(V)} vertices; the view was built with {n} "
            "(the vertex count cannot change in update; make a new MeshView)"
        )
    return V


def _check_values(values, n):
    try:
        values = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise MeshError(f"values must be a per-vertex array of numbers: {exc}") from None
    if values.ndim == 2 and 1 in values.shape:
        values = values.ravel()
    if values.ndim != 1 or values.shape[0] != n:
        raise MeshError(f"values must have one number per vertex, shape ({n},); got {values.shape}")
    bad = np.flatnonzero(np.isinf(values))
    if bad.size:
        raise MeshError(f"values are infinite at vertices {format_indices(bad)}")
    return values


# ----------------------------------------------------------------------------
# camera orientation of the live view
# ----------------------------------------------------------------------------


def _closed_outward(V, F):
    """True when every edge has two faces traversing it in opposite directions (a closed,
    consistently oriented mesh) and the enclosed volume is positive (faces counter-clockwise
    from outside). Then back faces can never be seen from outside and the renderer may skip them."""
    T = Topology(F, len(V))
    closed = (T.edge_face_count == 2).all() and len(T.inconsistent_edges()) == 0
    return bool(closed) and enclosed_volume(V, F) > 0


def _look_at_quaternion(direction, up=UP):
    """Quaternion (x, y, z, w) of a camera at ``direction`` looking at the origin, ``up`` up."""
    right, up, w = camera_basis(direction, up)
    R = np.column_stack([right, up, w])  # camera looks along -w
    tr = np.trace(R)
    if tr > 0:
        s = 2.0 * np.sqrt(tr + 1.0)
        q = [(R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s, 0.25 * s]
    else:
        i = int(np.argmax(np.diag(R)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * np.sqrt(1.0 + R[i, i] - R[j, j] - R[k, k])
        q = [0.0, 0.0, 0.0, (R[k, j] - R[j, k]) / s]
        q[i] = 0.25 * s
        q[j] = (R[j, i] + R[i, j]) / s
        q[k] = (R[k, i] + R[i, k]) / s
    return tuple(float(x) for x in q)


# ----------------------------------------------------------------------------
# the view
# ----------------------------------------------------------------------------


class MeshView:
    """An interactive 3D view of a triangle mesh, optionally coloured by a per-vertex scalar.

    Convention: V (n, 3) float64, F (m, 3) int64 counter-clockwise from outside;
    ``values`` (n,) in their own units, mapped linearly from ``[vmin, vmax]``
    onto the colour map (clipped outside), NaN drawn in ``NAN_COLOR`` (bright violet).

    Parameters
    ----------
    V : (n, 3) float64
        Vertex positions.
    F : (m, 3) int64
        Triangles (0-based vertex indices); a face that repeats a vertex draws nothing.
    values : (n,) float64 or None
        Per-vertex scalar to colour by; None gives plain shading and no colour bar.
    cmap : str or None
        Matplotlib colour map name; default "viridis", or "RdBu_r" when ``symmetric``.
    symmetric : bool
        Signed quantity: range ``[-a, a]`` with ``a = max |values|`` (or the larger
        of ``|vmin|``, ``|vmax|`` when given), so zero is the map's middle colour.
    vmin, vmax : float or None
        Fixed colour range; None takes it from the values (at every update).
    wireframe : bool
        Draw the edges over the surface.
    width, height : int
        Canvas size in pixels.
    title : str or None
        Heading shown above the canvas: what the view shows, a noun ("signed mean
        curvature", "the mesh coloured by height"); its text alternative begins
        "3D view of" the title (without one: "3D view of a mesh of n vertices").
    label : str or None
        Name and unit of the values, shown under the colour bar, e.g. "H (1/length)".
    up : {"z", "y", "x"}
        The axis drawn upwards. "z" suits the workbook's meshes and height
        fields such as the course's plane; scanned models (bunny, armadillo)
        usually want "y". The camera looks from the front, a little from the
        right and above; orbit from there.
    frame : (k, 3) float64 or None
        Positions whose bounding box frames the camera, e.g. the input mesh when
        V is its smoothed result: a mesh that shrank or collapsed is then drawn
        at the input's scale. Default: V itself.
    fit : bool
        Keep the mesh readable whatever an update does to its size: a mesh
        smaller than ``SPECK_RATIO`` times its frame (a collapse), or one that
        leaves the frame's bounding sphere (an explosion, a volume kept by a
        large stretch), is drawn scaled about its own centre to the frame's size,
        put at the frame's centre, and its title says "drawn N x larger" (or
        smaller). In between it is drawn as it is, so shrinkage is seen.
    zero_tol : float >= 0
        A field whose finite values all lie within ``zero_tol`` of zero (in the
        values' units) is zero up to rounding: drawn in ``ZERO_COLOR`` (white),
        its colour bar saying so. 0 switches this off.
    description : str or None
        What to look for in the view, in a sentence ("the rim flattens first");
        the end of its text alternative :meth:`alt_text`.

    Attributes
    ----------
    widget : ipywidgets.VBox
        Title, canvas and colour bar, for layouts (CSS class ``geomlib-view``).
    renderer, camera, controls, geometry : the pythreejs objects.

    Raises
    ------
    MeshError
        V not (n, 3) or not finite, F not (m, 3) integer indices in 0..n-1,
        values not of length n or infinite, unknown colour map.
    """

    def __init__(
        self,
        V,
        F,
        values=None,
        cmap=None,
        symmetric=False,
        vmin=None,
        vmax=None,
        wireframe=False,
        width=420,
        height=340,
        title=None,
        label=None,
        up="z",
        frame=None,
        zero_tol=ZERO_TOL,
        description=None,
        fit=False,
    ):
        import ipywidgets as widgets
        import pythreejs as three

        setup_display()
        V = as_vertices(V)
        self._n = V.shape[0]
        # a face that repeats a vertex is drawn as nothing, not refused: a view shows any mesh
        # that can be drawn; the normals, edges and volume come from the real triangles
        self._F = as_faces(F, self._n, allow_repeated=True)
        repeated = repeated_vertex_faces(self._F)
        self._triangles = np.delete(self._F, repeated, axis=0) if len(repeated) else self._F
        if len(self._triangles) == 0:
            raise MeshError("every face of F repeats a vertex: there is no triangle to draw")
        self._V = V
        self._values = None if values is None else _check_values(values, self._n)
        self.symmetric = bool(symmetric)
        self.cmap = cmap if cmap is not None else ("RdBu_r" if symmetric else "viridis")
        self._lut = colour_table(self.cmap)
        self._fixed = (vmin, vmax)
        self.width, self.height = int(width), int(height)
        self.title, self.label = title, label
        self.description = None if description is None else str(description)
        self.up = check_choice("up", up, tuple(VIEWS))
        self._up, self._direction = VIEWS[up]
        self.zero_tol = float(zero_tol)
        self._centre, self._radius = bounding_frame(V if frame is None else as_vertices(frame, where="frame"))
        self._scale = 1.0  # drawn this many times larger (side_by_side enlarges specks)
        self.fit = bool(fit)
        self._fitted = self._fit_factor(V)  # and this many times larger about its own centre (``fit``)
        self._distance = camera_distance(self._radius, self.width, self.height)

        # one interleaved float32 buffer: position (0:3), normal (3:6), colour (6:9)
        self._buffer = three.InterleavedBuffer(array=self._pack())
        position = three.InterleavedBufferAttribute(data=self._buffer, itemSize=3, offset=0, normalized=False)
        normal = three.InterleavedBufferAttribute(data=self._buffer, itemSize=3, offset=3, normalized=False)
        color = three.InterleavedBufferAttribute(data=self._buffer, itemSize=3, offset=6, normalized=False)
        index = three.BufferAttribute(array=self._F.astype(np.uint32).ravel(), normalized=False)
        self.geometry = three.BufferGeometry(
            index=index, attributes={"position": position, "normal": normal, "color": color}
        )
        # closed outward meshes: back faces are hidden anyway and skipping them
        # halves the software rasteriser's work; open or inconsistently oriented
        # meshes show both sides
        self.closed = _closed_outward(V, self._triangles)
        material = three.ShaderMaterial(
            vertexShader=_VERTEX_SHADER,
            fragmentShader=_FRAGMENT_SHADER,
            vertexColors="VertexColors",
            side="FrontSide" if self.closed else "DoubleSide",
            lights=False,
            fog=False,
            polygonOffset=True,
            polygonOffsetFactor=1.0,
            polygonOffsetUnits=1.0,
        )
        self.mesh = three.Mesh(geometry=self.geometry, material=material)
        children = [self.mesh]
        if wireframe:
            E = edges(self._triangles)
            lines = three.BufferGeometry(
                index=three.BufferAttribute(array=E.astype(np.uint32).ravel(), normalized=False),
                attributes={"position": position},
            )
            self.wireframe = three.LineSegments(
                geometry=lines, material=three.LineBasicMaterial(color="#1a1a1a", transparent=True, opacity=0.45)
            )
            children.append(self.wireframe)
        else:
            self.wireframe = None
        self.scene = three.Scene(children=children, background="#ffffff")
        self.camera = three.PerspectiveCamera(
            fov=FOV,
            aspect=self.width / self.height,
            near=self._distance * 0.01,
            far=self._distance * 100.0,
            position=tuple(float(x) for x in camera_basis(self._direction, self._up)[2] * self._distance),
            quaternion=_look_at_quaternion(self._direction, self._up),
            up=self._up,
        )
        self.controls = three.OrbitControls(controlling=self.camera, target=(0.0, 0.0, 0.0))
        antialias = (self._n <= ANTIALIAS_MAX_VERTICES) if ANTIALIAS == "auto" else bool(ANTIALIAS)
        self.renderer = three.Renderer(
            camera=self.camera,
            scene=self.scene,
            controls=[self.controls],
            width=self.width,
            height=self.height,
            antialias=antialias,
        )
        self.renderer.add_class("geomlib-canvas")

        self._title = widgets.HTML(self._title_text(), layout=widgets.Layout(display=None if title else "none"))
        self._colorbar = widgets.HTML(
            self._colorbar_text(), layout=widgets.Layout(display=None if self._values is not None else "none")
        )
        # the text alternative, in the page as a caption under the colour bar (the site ties it
        # to the canvas with aria-describedby and announces its changes)
        self._caption = widgets.HTML(self._caption_text(), layout=widgets.Layout(width=f"{self.width}px"))
        self._caption.add_class("geomlib-alt")
        self.widget = widgets.VBox(
            [self._title, self.renderer, self._colorbar, self._caption],
            layout=widgets.Layout(width="auto", align_items="flex-start"),
        )
        self.widget.add_class("geomlib-view")
        _SHOWN[self.widget.model_id] = self

    # -- state ---------------------------------------------------------------

    @property
    def V(self):
        """(n, 3) float64 vertex positions shown (a copy)."""
        return self._V.copy()

    @property
    def F(self):
        """(m, 3) int64 faces (a copy)."""
        return self._F.copy()

    @property
    def values(self):
        """(n,) float64 values shown, or None (a copy)."""
        return None if self._values is None else self._values.copy()

    @property
    def range(self):
        """(vmin, vmax) of the colour map as currently drawn."""
        return value_range(self._values, self.symmetric, *self._fixed)

    @property
    def positions(self):
        """(n, 3) float32 positions as sent to the browser (relative to the first bounding-box centre)."""
        return self._buffer.array[:, 0:3].copy()

    @property
    def colors(self):
        """(n, 3) float32 vertex colours in [0, 1] as sent to the browser."""
        return self._buffer.array[:, 6:9].copy()

    @property
    def normals(self):
        """(n, 3) float32 unit vertex normals as sent to the browser."""
        return self._buffer.array[:, 3:6].copy()

    @property
    def is_zero(self):
        """True when the values are zero up to rounding (every finite |value| <= zero_tol)."""
        if self._values is None:
            return False
        finite = self._values[np.isfinite(self._values)]
        return bool(finite.size) and float(np.abs(finite).max()) <= self.zero_tol

    def _fit_factor(self, V):
        """How many times larger V is drawn under ``fit``: 1 while it is at least ``SPECK_RATIO`` of
        its frame and inside the frame's bounding sphere (which the camera shows whole), else the
        frame's size over V's."""
        if not self.fit:
            return 1.0
        centre, radius = bounding_frame(V)
        reach = float(np.linalg.norm(V - self._centre, axis=1).max())
        if radius < SPECK_RATIO * self._radius or reach > self._radius:
            return self._radius / radius
        return 1.0

    def _shown(self):
        """(n, 3) float64: the positions as drawn (V, or V scaled by ``fit`` about its centre onto the frame's)."""
        if self._fitted == 1.0:
            return self._V
        return self._centre + self._fitted * (self._V - bounding_frame(self._V)[0])

    def _size_note(self):
        """ "drawn N x larger" (or smaller) when the picture is not to the frame's scale, else ""."""
        scale = self._scale * self._fitted
        if scale == 1.0:
            return ""
        if scale < 1.0:
            return f"drawn {1 / scale:.3g} x smaller"
        return f"drawn {scale:.3g} x larger"

    def _title_text(self):
        text = f"<b>{html.escape(self.title)}</b>" if self.title else ""
        if self._size_note():
            text += f" <i>({self._size_note()})</i>"
        return text

    def _colors(self):
        if self._values is None:
            return np.broadcast_to(np.asarray(PLAIN_COLOR, dtype=np.float32), (self._n, 3))
        if self.is_zero:
            colors = np.empty((self._n, 3), dtype=np.float32)
            colors[:] = ZERO_COLOR
            colors[np.isnan(self._values)] = NAN_COLOR
            return colors
        lo, hi = self.range
        return colorize(self._values, vmin=lo, vmax=hi, lut=self._lut)

    def _pack(self, V=True, colors=True, old=None):
        buf = np.empty((self._n, 9), dtype=np.float32)
        if V:
            # positions relative to the first bounding-box centre (float32 keeps
            # its precision near the origin)
            buf[:, 0:3] = self._shown() - self._centre
            buf[:, 3:6] = view_normals(self._V, self._triangles)
        else:
            buf[:, 0:6] = old[:, 0:6]
        if colors:
            buf[:, 6:9] = self._colors()
        else:
            buf[:, 6:9] = old[:, 6:9]
        return buf

    def _set_scale(self, scale):
        """Draw the mesh ``scale`` times larger (about its frame's centre), saying so in the title."""
        self._scale = float(scale)
        for obj in (self.mesh, self.wireframe):
            if obj is not None:
                obj.scale = (self._scale,) * 3
        self._title.value = self._title_text()
        self._title.layout.display = None if self._title.value else "none"
        self._refresh_caption()

    def _colorbar_text(self):
        if self._values is None:
            return ""
        n_nan = int(np.isnan(self._values).sum())
        lo, hi = self.range
        if self.is_zero and not self._zero_on_a_bar():
            return zero_html(self._zero_text(), self.label or "", self.width)
        label = f"{self.label or 'values'}: {self._zero_text()}" if self.is_zero else self.label or ""
        return colorbar_html(self._lut, lo, hi, label, n_nan, self.width)

    def _zero_on_a_bar(self):
        """A zero field with a colour range given (vmin and vmax, as for a row of views sharing one) shows
        that range's colour bar, so that its white reads as the bar's middle, 0."""
        return self.is_zero and None not in self._fixed and self.range[1] > self.range[0]

    def _zero_text(self):
        largest = float(np.nanmax(np.abs(self._values)))
        return (
            f"0 everywhere, up to rounding (largest |value| {format_value(largest)} <= {format_value(self.zero_tol)})"
        )

    def alt_text(self):
        """The view's text alternative: the mesh, the quantity with its unit and colour range, NaNs, the description.

        Shown under the canvas, given to the still as its alt and to the canvas on the website.
        """
        mesh = f"a mesh of {self._n} vertices and {self._F.shape[0]} faces"
        text = f"3D view of {self.title}: {mesh}" if self.title else f"3D view of {mesh}"
        if self._size_note():
            text += f", {self._size_note().replace(' x ', ' times ')}"
        name = self.label or "the values"
        if self._values is None:
            text += ", plain shading (no colour map)."
        elif self.is_zero:
            text += f", coloured by {name}: {self._zero_text()}, drawn white."
        else:
            lo, hi = self.range
            text += f", coloured by {name} from {format_value(lo)} to {format_value(hi)} ({self.cmap} colour map"
            text += ", 0 in the middle)." if self.symmetric else ")."
        n_nan = 0 if self._values is None else int(np.isnan(self._values).sum())
        if n_nan:
            text += f" {n_nan} {'vertex has' if n_nan == 1 else 'vertices have'} no value (NaN), drawn {NAN_NAME}."
        words = " ".join((self.description or "").split())
        if words:  # a sentence of its own, however the notebook wrote it
            text += f" {words[0].upper()}{words[1:]}" + ("" if words.endswith((".", "!", "?")) else ".")
        return text

    def _caption_text(self):
        return f"<div class='geomlib-alt-text' style='font:12px sans-serif;color:#222'>{html.escape(self.alt_text())}</div>"

    def _refresh_caption(self):
        text = self._caption_text()
        if text != self._caption.value:
            self._caption.value = text

    # -- updates ---------------------------------------------------------------

    def update(self, V=None, values=None, vmin=None, vmax=None, description=None):
        """Overwrite positions and/or colours in place: one message to the browser.

        Parameters
        ----------
        V : (n, 3) float64 or None
            New positions (same vertex count); normals are recomputed.
        values : (n,) float64 or None
            New per-vertex values (colours recomputed).
        vmin, vmax : float or None
            New fixed colour range (kept for later updates).
        description : str or None
            New sentence saying what to look for (the end of :meth:`alt_text`).

        None leaves that part unchanged. The text alternative under the canvas is
        sent again only when its text changed. The buffer objects stay the same; only
        their contents are replaced. Raises MeshError for wrong shapes.
        """
        new_V = V is not None
        if new_V:
            self._V = _check_count(as_vertices(V), self._n)
            fitted, self._fitted = self._fitted, self._fit_factor(self._V)
            if fitted != self._fitted:
                self._title.value = self._title_text()
                self._title.layout.display = None if self._title.value else "none"
        new_colors = False
        if values is not None:
            self._values = _check_values(values, self._n)
            new_colors = True
        if vmin is not None or vmax is not None:
            lo, hi = self._fixed
            self._fixed = (lo if vmin is None else float(vmin), hi if vmax is None else float(vmax))
            new_colors = new_colors or self._values is not None
        if description is not None:
            self.description = str(description)
        if new_V or new_colors:
            self._buffer.array = self._pack(V=new_V, colors=new_colors, old=self._buffer.array)
        if new_colors:
            text = self._colorbar_text()
            if text != self._colorbar.value:
                self._colorbar.value = text
            if self._colorbar.layout.display == "none":
                self._colorbar.layout.display = None
        self._refresh_caption()

    # -- display ---------------------------------------------------------------

    def still(self, distance=None):
        """(h, w, 3) uint8 still picture: the first camera view, title and colour bar."""
        buf = self._buffer.array
        image = render_still(
            self._shown(),
            self._F,
            buf[:, 6:9],
            buf[:, 3:6].astype(np.float64),
            self.width,
            self.height,
            direction=self._direction,
            up=self._up,
            distance=(distance or self._distance) / self._scale,
            centre=self._centre,
            cull_back=self.closed,
            edges=None if self.wireframe is None else edges(self._triangles),
        )
        lo, hi = self.range
        bar = self._values is not None and (not self.is_zero or self._zero_on_a_bar())
        lut = self._lut if bar else None
        title = self.title
        if title and self._size_note():
            title = f"{title} ({self._size_note()})"
        if self.is_zero:
            title = f"{title or ''}  [{self.label or 'values'}: 0 everywhere]".strip()
        return still_with_colorbar(image, lut, lo, hi, self.label or "", title)

    def summary(self):
        """One line of text describing the view (the text/plain display)."""
        text = f"MeshView: {self._n} vertices, {self._F.shape[0]} faces"
        if self.title:
            text = f"{text} ({self.title})"
        if self._size_note():
            text += f", {self._size_note()}"
        if self._values is not None and self.is_zero:
            text += f"; {self.label or 'values'}: {self._zero_text()}, drawn white"
        elif self._values is not None:
            lo, hi = self.range
            name = self.label or "values"
            text += f"; {name} coloured by {self.cmap} over [{format_value(lo)}, {format_value(hi)}]"
            n_nan = int(np.isnan(self._values).sum())
            if n_nan:
                text += f", {n_nan} NaN drawn {NAN_NAME}"
        return text

    def _repr_mimebundle_(self, include=None, exclude=None, **kwargs):
        if text_only():
            return {"text/plain": self.summary()}
        bundle = self.widget._repr_mimebundle_(include=include, exclude=exclude) or {}
        bundle["text/plain"] = self.summary()
        bundle["image/png"] = png_base64(self.still())
        return bundle, {"image/png": {"alt": self.alt_text()}}

    def __repr__(self):
        return f"<{self.summary()}>"


class ViewRow:
    """Views shown in a row (``side_by_side``); ``.views``, ``.widget``; displayable."""

    def __init__(self, views, widget, distance):
        self.views = list(views)
        self.widget = widget
        self._distance = distance
        _SHOWN[widget.model_id] = self

    def still(self):
        """(h, w, 3) uint8: the still pictures of the views next to each other."""
        return in_a_row([v.still(distance=self._distance) for v in self.views])

    def summary(self):
        """The views' one-line summaries, left to right, one per line."""
        return "\n".join(v.summary() for v in self.views)

    def alt_text(self):
        """The text alternatives of the views, left to right, in one text."""
        return " ".join(f"View {k} of {len(self.views)}: {v.alt_text()}" for k, v in enumerate(self.views, 1))

    def _repr_mimebundle_(self, include=None, exclude=None, **kwargs):
        if text_only():
            return {"text/plain": self.summary()}
        bundle = self.widget._repr_mimebundle_(include=include, exclude=exclude) or {}
        bundle["text/plain"] = self.summary()
        bundle["image/png"] = png_base64(self.still())
        return bundle, {"image/png": {"alt": self.alt_text()}}

    def __repr__(self):
        return "<ViewRow of " + "; ".join(v.summary() for v in self.views) + ">"


# widget model id -> the MeshView or ViewRow that made the widget (weak: a
# view the notebook dropped is not kept alive for its picture)
_SHOWN = weakref.WeakValueDictionary()


def register_still(widget, shown):
    """Let a box holding ``widget`` be drawn as ``shown.still()`` ((h, w, 3) uint8), described by
    ``shown.alt_text()`` and summed up by ``shown.summary()``: what :func:`box_still`,
    :func:`box_alt` and :func:`box_text` find for it, as for a view."""
    _SHOWN[widget.model_id] = shown


def _shown_in(box):
    """The views (registered with their still, text and summary) inside an ipywidgets box, at any depth, in order."""
    shown = _SHOWN.get(getattr(box, "model_id", None))
    if shown is not None:
        yield shown
        return
    for child in getattr(box, "children", ()):
        yield from _shown_in(child)


def box_still(box):
    """Still picture of the views inside an ipywidgets box, or None if it holds none.

    Every MeshView or side_by_side row found in ``box`` (at any depth) gives
    its still picture; they are placed next to each other, (h, w, 3) uint8.
    Sliders and other controls are not drawn.
    """
    images = [shown.still() for shown in _shown_in(box)]
    return in_a_row(images) if images else None


def box_alt(box):
    """The text alternatives of the views inside an ipywidgets box, in one text ("" if it holds none)."""
    return " ".join(shown.alt_text() for shown in _shown_in(box))


def box_text(box):
    """The summaries of the views (and figures) inside an ipywidgets box, one per line ("" if it holds none)."""
    return "\n".join(shown.summary() for shown in _shown_in(box))


def _box_png(box):
    if text_only():
        return None
    image = box_still(box)
    return None if image is None else (png_base64(image), {"alt": box_alt(box)})


def _widget_as_text(widget):
    # a box of views: their summaries; a slider, a progress bar, an Output widget: its text, as without a front-end
    return {"text/plain": box_text(widget) or repr(widget)}


def setup_display():
    """Set up this session's display for the workbook; each notebook's set-up cell calls it.

    In Colab, enables its custom widget manager (:func:`.frontends.enable_colab_widgets`),
    without which the 3D views are not drawn. In IPython, displays every ipywidgets box
    with the still of its views as image/png (with ``text_only``, every widget as text
    alone: a box as the summaries of its views, any other as its text), and draws
    plots in :func:`.colours.plot_style`. Calling it again changes nothing; a
    :class:`MeshView` calls it when it is made, so a view is drawn in a reader's own
    notebook too.
    """
    from IPython import get_ipython

    enable_colab_widgets()
    shell = get_ipython()
    if shell is not None:
        import ipywidgets

        shell.display_formatter.formatters["image/png"].for_type(ipywidgets.Box, _box_png)
        if text_only():
            shell.display_formatter.mimebundle_formatter.for_type(ipywidgets.DOMWidget, _widget_as_text)
        # a notebook's own plots: colour-blind-safe colours, each with its own line style
        use_plot_style()


def side_by_side(*views, link_cameras=True):
    """Show MeshViews next to each other; with ``link_cameras`` they share one camera.

    Linked views share the first view's camera and orbit controls, so orbiting,
    zooming or panning in any of them turns all of them together (every mesh is
    centred on its bounding box, or its ``frame``; the camera is framed on the
    largest). Views are resized to the first view's canvas size (one camera,
    one aspect ratio).

    Sizes: views of the same mesh (equal faces ``F``) keep their common scale,
    so a result that shrank is seen shrunk next to its input. A group of views
    of another, much smaller mesh (bounding box below ``SPECK_RATIO`` of the
    largest) would be a speck under the shared camera: it is drawn enlarged to
    the largest size, and its title says by how much.

    Returns
    -------
    ViewRow with ``.views`` and ``.widget`` (an HBox); display it directly.
    """
    import ipywidgets as widgets

    if len(views) == 1 and isinstance(views[0], (list, tuple)):
        views = tuple(views[0])
    if not views or not all(isinstance(v, MeshView) for v in views):
        raise MeshError("side_by_side takes one or more MeshView objects")
    distance = None
    if link_cameras and len(views) > 1:
        first = views[0]
        groups = []  # views of one mesh: (radius, [views])
        for v in views:
            for group in groups:
                if np.array_equal(group[1][0]._F, v._F):
                    group[1].append(v)
                    break
            else:
                groups.append([0.0, [v]])
        for group in groups:
            group[0] = max(v._radius for v in group[1])
        radius = max(r for r, _ in groups)
        for r, members in groups:
            scale = radius / r if r < SPECK_RATIO * radius else 1.0
            for v in members:
                v._set_scale(scale)
        distance = camera_distance(radius, first.width, first.height)
        cam = first.camera
        cam.position = tuple(float(x) for x in camera_basis(first._direction, first._up)[2] * distance)
        cam.near, cam.far = distance * 0.01, distance * 100.0
        for v in views:
            v._distance = distance
        for v in views[1:]:
            v._up, v._direction, v.up = first._up, first._direction, first.up
            v.width, v.height = first.width, first.height
            v.renderer.width, v.renderer.height = first.width, first.height
            v._colorbar.value = v._colorbar_text()
            v.renderer.camera = cam
            v.renderer.controls = [first.controls]
            v.camera, v.controls = cam, first.controls
    box = widgets.HBox([v.widget for v in views], layout=widgets.Layout(flex_flow="row wrap"))
    box.add_class("geomlib-row")
    return ViewRow(views, box, distance)
