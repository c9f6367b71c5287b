"""Still pictures of the 3D views: a small numpy z-buffer rasteriser, with title and colour bar.

A still is what a page without a live front-end shows (nbval, exported HTML,
repository previews, nbgrader feedback): the mesh drawn from the view's first
camera, shaded by the same light as the live view, with the title above
and the colour bar with its range below. The camera geometry (framing,
distance, orientation) and the vertex normals are shared with the live view
(:mod:`.viewer`), so both show the same picture.
"""

import base64
import functools
import io

import numpy as np

from ...mesh.geometry import bounding_box_diagonal, vertex_normals
from .colours import format_value

__all__ = [
    "VIEWS",
    "UP",
    "VIEW_DIRECTION",
    "FOV",
    "view_normals",
    "bounding_frame",
    "camera_distance",
    "camera_basis",
    "render_still",
    "draw_edges",
    "still_font",
    "drawable",
    "draw_words",
    "still_with_colorbar",
    "in_a_row",
    "png_base64",
]

#: the axis drawn upwards -> (up vector, viewing direction from the bounding-box
#: centre towards the eye): from the front, a little from the right and above
VIEWS = {
    "z": ((0.0, 0.0, 1.0), (0.55, -1.0, 0.5)),
    "y": ((0.0, 1.0, 0.0), (0.55, 0.5, 1.0)),
    "x": ((1.0, 0.0, 0.0), (0.5, 0.55, 1.0)),
}
UP, VIEW_DIRECTION = VIEWS["z"]
#: vertical field of view of the camera in degrees
FOV = 30.0
#: the light comes from the eye raised by this much along the camera's up (tan of about 37 degrees):
#: a surface seen from above at a low angle, as every height field from the default camera, faces
#: it and keeps its colour; a light at the eye made the white of a zero field on a plane a mid-grey
#: (|n . e| = 0.4 there, shade 0.61)
LIGHT_RAISE = 0.75


# ----------------------------------------------------------------------------
# vertex normals of a view
# ----------------------------------------------------------------------------


def view_normals(V, F):
    """(n, 3) float64: :func:`geomlib.mesh.geometry.vertex_normals`, with (0, 0, 1) where it has none.

    A vertex in no face of non-zero area has no normal (a zero row); a picture
    must still shade it, and the shader's ``normalize`` of a zero vector is
    undefined, so the view gives it the normal (0, 0, 1), whose light is as
    good as any. ``F`` must not hold faces that repeat a vertex (they would have added
    nothing).
    """
    N = vertex_normals(V, F)
    N[~N.any(axis=1)] = (0.0, 0.0, 1.0)
    return N


# ----------------------------------------------------------------------------
# camera
# ----------------------------------------------------------------------------


def bounding_frame(V):
    """Bounding-box centre and half diagonal of V."""
    centre = 0.5 * (V.min(axis=0) + V.max(axis=0))
    radius = 0.5 * bounding_box_diagonal(V)
    return centre, (radius if radius > 0 else 1.0)


def camera_distance(radius, width, height, fov=FOV):
    """Distance from which a sphere of ``radius`` fills about 95 % of a ``width`` x ``height`` picture."""
    half_v = np.radians(fov) / 2
    half_h = np.arctan(np.tan(half_v) * width / height)
    return 0.95 * radius / np.sin(min(half_v, half_h))


def camera_basis(direction, up=UP):
    """(right, up, w): orthonormal camera axes for an eye at ``direction`` from the target, ``up`` up."""
    w = np.asarray(direction, dtype=np.float64)
    w = w / np.linalg.norm(w)
    right = np.cross(up, w)
    if np.linalg.norm(right) < 1e-9:
        right = np.cross(np.roll(up, 1), w)
    right /= np.linalg.norm(right)
    return right, np.cross(w, right), w


def render_still(
    V,
    F,
    colors,
    normals=None,
    width=420,
    height=340,
    direction=VIEW_DIRECTION,
    up=UP,
    distance=None,
    fov=FOV,
    background=(1.0, 1.0, 1.0),
    centre=None,
    cull_back=False,
    edges=None,
):
    """Draw the mesh as the viewer's camera first sees it, into an RGB image.

    The camera looks at ``centre`` (default: the centre of V's bounding box)
    from ``distance`` (default: framing V's bounding box). ``cull_back`` skips
    the triangles that face away from the camera, as the live view does on a
    closed, outward-oriented mesh (half the work; nothing visible changes).

    A z-buffer rasteriser in numpy: vertices are projected with the camera of
    the 3D view, shaded by the same light (from the eye, raised by ``LIGHT_RAISE``; both sides lit), and
    every triangle's pixel centres are found row by row (:func:`fragments`);
    the nearest candidate per pixel wins (depth tested with interpolated 1/z).
    Colours are interpolated (Gouraud). ``edges`` (k, 2) int64 vertex pairs are
    drawn over the surface as the live view's wireframe draws them (:func:`draw_edges`).

    Returns
    -------
    (height, width, 3) uint8
    """
    V = np.asarray(V, dtype=np.float64)
    own_centre, radius = bounding_frame(V)
    centre = own_centre if centre is None else np.asarray(centre, dtype=np.float64)
    if distance is None:
        distance = camera_distance(radius, width, height, fov)
    right, up, w = camera_basis(direction, up)
    P = V - centre
    eye = w * distance
    depth = distance - P @ w  # distance along the viewing axis
    depth = np.maximum(depth, 1e-6 * distance)
    f = (height / 2) / np.tan(np.radians(fov) / 2)
    sx = width / 2 + f * (P @ right) / depth
    sy = height / 2 - f * (P @ up) / depth
    if normals is None:
        normals = view_normals(V, F)
    to_eye = eye - P
    to_eye /= np.linalg.norm(to_eye, axis=1, keepdims=True)
    facing = np.einsum("ij,ij->i", normals, to_eye)
    d = np.abs(facing)  # both sides lit: the normal turned towards the eye
    light = to_eye + LIGHT_RAISE * up
    light /= np.linalg.norm(light, axis=1, keepdims=True)
    lit = np.maximum(np.sign(facing) * np.einsum("ij,ij->i", normals, light), 0.0)
    shade = 0.35 + 0.65 * lit
    vc = np.asarray(colors, dtype=np.float64)[:, :3] * shade[:, None] + 0.12 * (d**40)[:, None]
    inv = 1.0 / depth

    pix, face, b0, b1 = fragments(sx[F], sy[F], inv[F], width, height, cull_back)
    image = np.empty((height * width, 3), dtype=np.float64)
    image[:] = background
    nearest = np.full(height * width, -np.inf)  # 1/depth of the surface drawn at each pixel
    if pix.size:
        # colours of the winning fragments only: under the spikes of an unstable run most
        # fragments are hidden, and interpolating their colours took half the time
        ff = F[face]
        b2 = 1.0 - b0 - b1
        image[pix] = b0[:, None] * vc[ff[:, 0]] + b1[:, None] * vc[ff[:, 1]] + b2[:, None] * vc[ff[:, 2]]
        nearest[pix] = b0 * inv[ff[:, 0]] + b1 * inv[ff[:, 1]] + b2 * inv[ff[:, 2]]
    if edges is not None and len(edges):
        draw_edges(image, nearest, sx, sy, inv, np.asarray(edges, dtype=np.int64), width, height, 0.01 * radius)
    return (np.clip(image, 0.0, 1.0) * 255 + 0.5).astype(np.uint8).reshape(height, width, 3)


#: the live view's wireframe: lines of this colour at this opacity over the surface
EDGE_COLOR = (0x1A / 255, 0x1A / 255, 0x1A / 255)
EDGE_OPACITY = 0.45


def draw_edges(image, nearest, sx, sy, inv, E, width, height, slack):
    """Blend the edges ``E`` (k, 2) into ``image`` (h * w, 3) float where the surface does not hide them.

    Each edge is sampled about every half pixel between its projected ends
    (``sx``, ``sy``); 1/depth is linear along it on the screen, as on a triangle.
    A sample is drawn when nothing nearer than ``slack`` (length units) in front
    of it was drawn at its pixel: the edges lie on the surface, and the slack
    plays the part of the live view's polygon offset (the faces pushed back a
    little so that their own edges win the depth test). Every covered pixel is
    blended once, ``EDGE_OPACITY`` of ``EDGE_COLOR``, as the live view's lines.
    """
    x0, y0, x1, y1 = sx[E[:, 0]], sy[E[:, 0]], sx[E[:, 1]], sy[E[:, 1]]
    onscreen = (np.maximum(x0, x1) >= 0) & (np.minimum(x0, x1) < width) & (np.maximum(y0, y1) >= 0)
    onscreen &= np.minimum(y0, y1) < height
    E = E[onscreen]
    x0, y0, x1, y1 = x0[onscreen], y0[onscreen], x1[onscreen], y1[onscreen]
    count = np.ceil(2 * np.hypot(x1 - x0, y1 - y0)).astype(np.int64) + 1
    owner, offset = _runs(count)
    t = offset / np.maximum(count[owner] - 1, 1)
    x = x0[owner] + t * (x1 - x0)[owner]
    y = y0[owner] + t * (y1 - y0)[owner]
    key = (1 - t) * inv[E[owner, 0]] + t * inv[E[owner, 1]]
    px, py = np.floor(x).astype(np.int64), np.floor(y).astype(np.int64)
    inside = (px >= 0) & (px < width) & (py >= 0) & (py < height)
    pix, key = py[inside] * width + px[inside], key[inside]
    front = nearest[pix]
    seen = front == -np.inf  # no surface at the pixel
    seen[~seen] = 1.0 / key[~seen] <= 1.0 / front[~seen] + slack
    pix = np.unique(pix[seen])
    image[pix] = (1 - EDGE_OPACITY) * image[pix] + EDGE_OPACITY * np.asarray(EDGE_COLOR)


def fragments(X, Y, inv, width, height, cull_back=False, budget=2_000_000):
    """The pixels the triangles cover, nearest first: ``(pix, face, b0, b1)`` of the visible fragments.

    ``X``, ``Y`` (m, 3) are the screen corners of the triangles and ``inv`` (m, 3)
    their 1/depth. A pixel is covered when its centre has barycentric
    coordinates b0, b1, b2 = 1 - b0 - b1 all >= 0; of the fragments of one
    pixel the largest interpolated 1/depth wins (a z-buffer). Returns the pixel
    index (row * width + column), the face and b0, b1 of each winner. With
    ``cull_back`` the triangles facing away are left out: those whose corners
    run clockwise as seen from the camera (positive ``area`` here, the screen's y
    pointing down).

    Why row by row: a triangle's box can be many times its area (a long sliver;
    the spikes of an unstable run cover a picture 17 times over), and testing
    every pixel centre of the boxes took 0.7 s for one such picture. Along a
    pixel row the barycentric coordinates and 1/depth are linear in x, so the
    covered centres form one interval (:func:`_row_lines`) and each fragment
    costs one multiply-add for its depth; only the winners get their
    barycentric coordinates. Faces go in groups of about ``budget`` box pixels,
    which bounds the memory.
    """
    area = (X[:, 1] - X[:, 0]) * (Y[:, 2] - Y[:, 0]) - (X[:, 2] - X[:, 0]) * (Y[:, 1] - Y[:, 0])
    x0 = np.maximum(np.floor(X.min(axis=1) - 0.5), 0).astype(np.int64)
    y0 = np.maximum(np.floor(Y.min(axis=1) - 0.5), 0).astype(np.int64)
    x1 = np.minimum(np.floor(X.max(axis=1) - 0.5) + 1, width - 1).astype(np.int64)
    y1 = np.minimum(np.floor(Y.max(axis=1) - 0.5) + 1, height - 1).astype(np.int64)
    drawn = (area < -1e-12) if cull_back else (np.abs(area) > 1e-12)
    faces = np.flatnonzero((x1 >= x0) & (y1 >= y0) & drawn)
    group = np.cumsum((x1[faces] - x0[faces] + 1) * (y1[faces] - y0[faces] + 1)) // budget
    nearest = np.full(height * width, -np.inf)
    kept = []
    for g in np.unique(group):
        fi = faces[group == g]
        owner, offset = _runs(y1[fi] - y0[fi] + 1)  # every face with every pixel row of its box
        rows, py = fi[owner], y0[fi][owner] + offset
        lo, hi, k0, k1 = _row_lines(X[rows], Y[rows], inv[rows], area[rows], py + 0.5)
        lo = np.maximum(np.ceil(lo - 0.5), x0[rows])  # the pixel centres px + 0.5 in [lo, hi]
        hi = np.minimum(np.floor(hi - 0.5), x1[rows])
        owner, offset = _runs(np.where(hi >= lo, hi - lo + 1, 0).astype(np.int64))
        px = lo.astype(np.int64)[owner] + offset
        pix = py[owner] * width + px
        key = k0[owner] + k1[owner] * (px + 0.5)  # 1/depth at the pixel centre
        np.maximum.at(nearest, pix, key)  # the largest 1/z of every pixel: a z-buffer (50x a sort at 1M fragments)
        front = key >= nearest[pix]  # what is already hidden is dropped now
        kept.append((pix[front], rows[owner[front]], key[front]))
    if not kept:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0), np.zeros(0)
    pix, face, key = (np.concatenate(k) for k in zip(*kept))
    front = key == nearest[pix]
    pix, face = pix[front], face[front]
    cx, cy, Xf, Yf, a = pix % width + 0.5, pix // width + 0.5, X[face], Y[face], area[face]
    b0 = ((Xf[:, 1] - cx) * (Yf[:, 2] - cy) - (Xf[:, 2] - cx) * (Yf[:, 1] - cy)) / a
    b1 = ((Xf[:, 2] - cx) * (Yf[:, 0] - cy) - (Xf[:, 0] - cx) * (Yf[:, 2] - cy)) / a
    return pix, face, b0, b1


def _runs(counts):
    """``(owner, offset)`` of ``counts.sum()`` items in runs of ``counts``: the run of each item and its place in it."""
    owner = np.repeat(np.arange(len(counts)), counts)
    return owner, np.arange(owner.size) - np.repeat(np.cumsum(counts) - counts, counts)


def _row_lines(X, Y, inv, area, cy):
    """Triangles (screen corners X, Y (r, 3), 1/depth ``inv``, signed ``area``) on the rows y = cy:
    ``(lo, hi, k0, k1)``, the interval [lo, hi] of x inside the triangle (lo > hi: none) and
    1/depth there, ``k0 + k1 x``.

    Corner i's barycentric coordinate is linear in x along the row, ``(p + c x) / area`` with
    the edge opposite i; it is >= 0 on a half-line, or everywhere or nowhere when that edge
    is horizontal (c = 0).
    """
    lo, hi = np.full(len(cy), -np.inf), np.full(len(cy), np.inf)
    k0, k1 = np.zeros(len(cy)), np.zeros(len(cy))
    s = np.sign(area)
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        p = X[:, j] * (Y[:, k] - cy) - X[:, k] * (Y[:, j] - cy)
        c = Y[:, j] - Y[:, k]
        with np.errstate(divide="ignore", invalid="ignore"):
            bound = -p / c
        lo = np.where(s * c > 0, np.maximum(lo, bound), lo)
        hi = np.where(s * c < 0, np.minimum(hi, bound), hi)
        hi = np.where((c == 0) & (s * p < 0), -np.inf, hi)
        k0 += p * inv[:, i]
        k1 += c * inv[:, i]
    return lo, hi, k0 / area, k1 / area


# ----------------------------------------------------------------------------
# title, colour bar, rows of stills, PNG
# ----------------------------------------------------------------------------


@functools.lru_cache(maxsize=1)
def still_font():
    """The font of the stills' titles and colour bars: DejaVu Sans at 11 px, from matplotlib's own files.

    Pillow's default font (Aileron) has no superscript two, no Greek and no minus
    sign: "K (1/length²)" came out with a box for the "²". DejaVu Sans covers
    Latin, Greek and the mathematical signs the labels use, and every install of
    the workbook has it (matplotlib ships it).
    """
    from matplotlib import font_manager
    from PIL import ImageFont

    path = font_manager.findfont(font_manager.FontProperties(family="DejaVu Sans"), fallback_to_default=True)
    return ImageFont.truetype(path, 11)


def drawable(text, font=None):
    """The characters of ``text`` that ``font`` (default :func:`still_font`) has no glyph for (drawn as boxes)."""
    font = still_font() if font is None else font
    box = np.asarray(font.getmask("\uffff"))  # what a character without a glyph becomes
    return sorted({ch for ch in text if not ch.isspace() and np.array_equal(np.asarray(font.getmask(ch)), box)})


def draw_words(draw, xy, text, font, fill=(20, 20, 20)):
    """Draw ``text`` word by word, a third of the font size apart.

    Pillow's default font (Aileron at 10 px) has a space 2 px wide, which its
    hinting can shrink to nothing: "implicit smoothing" came out as
    "implicitsmoothing". Drawing the words with an explicit gap keeps them apart
    in any font.
    """
    x, y = xy
    gap = max(font.getlength(" "), getattr(font, "size", 10) / 3)
    for word in text.split(" "):
        if word:
            draw.text((x, y), word, fill=fill, font=font)
            x += font.getlength(word)
        x += gap
    return x - gap


def still_with_colorbar(image, lut, vmin, vmax, label, title):
    """Add the title above and a colour bar with its range below the still picture."""
    from PIL import Image, ImageDraw

    h, w = image.shape[:2]
    top = 18 if title else 0
    bottom = 38 if lut is not None else 0
    canvas = Image.new("RGB", (w, h + top + bottom), "white")
    canvas.paste(Image.fromarray(image), (0, top))
    draw = ImageDraw.Draw(canvas)
    font = still_font()
    if title:
        draw_words(draw, (4, 3), title, font)
    if lut is not None:
        lo, hi = format_value(vmin), format_value(vmax)
        x0, x1 = 10 + round(font.getlength(lo)), w - 10 - round(font.getlength(hi))
        y = h + top + 6
        if x1 > x0:
            t = np.linspace(0, 1, x1 - x0)
            strip = (lut[np.round(t * (len(lut) - 1)).astype(int)] * 255).astype(np.uint8)
            canvas.paste(Image.fromarray(np.repeat(strip[None], 10, axis=0)), (x0, y))
            draw.rectangle([x0 - 1, y - 1, x1, y + 10], outline=(120, 120, 120))
        draw.text((4, y - 1), lo, fill=(20, 20, 20), font=font)
        draw.text((x1 + 4, y - 1), hi, fill=(20, 20, 20), font=font)
        if label:
            draw_words(draw, (max(4, (w - font.getlength(label)) // 2), y + 13), label, font)
    return np.asarray(canvas)


def png_base64(image):
    """The (h, w, 3) uint8 image as base64 PNG text (the image/png entry of a display bundle)."""
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(image).save(buf, format="PNG", optimize=False, compress_level=3)
    return base64.b64encode(buf.getvalue()).decode("ascii")


def in_a_row(images):
    """(h, w, 3) uint8: the images next to each other on white, 8 pixels apart, aligned at the top."""
    h = max(im.shape[0] for im in images)
    gap = np.full((h, 8, 3), 255, dtype=np.uint8)
    parts = []
    for im in images:
        pad = np.full((h - im.shape[0], im.shape[1], 3), 255, dtype=np.uint8)
        parts += [np.vstack([im, pad]), gap]
    return np.hstack(parts[:-1])
