"""Colour maps of the 3D views and their stills: values to colours, and the colour bars.

Convention: a per-vertex scalar ``values`` (n,) float64 is mapped linearly from
``[vmin, vmax]`` onto a named matplotlib colour map (clipped beyond). Signed
quantities get a range symmetric about zero (:func:`value_range`), so zero is
the map's middle colour; NaN values are drawn in :data:`NAN_COLOR`; a field
that is zero up to rounding is drawn in :data:`ZERO_COLOR` and its colour bar
says so (:func:`zero_html`). The colour bar under a live view is HTML
(:func:`colorbar_html`); the still picture draws its own (:mod:`.stills`).
"""

import html

import numpy as np

from ...mesh.errors import MeshError

__all__ = [
    "NAN_COLOR",
    "NAN_NAME",
    "ZERO_COLOR",
    "ZERO_TOL",
    "PLAIN_COLOR",
    "PLOT_COLOURS",
    "PLOT_LINESTYLES",
    "plot_style",
    "use_plot_style",
    "colour_table",
    "value_range",
    "colorize",
    "format_value",
    "colorbar_html",
    "zero_html",
]

#: colour of vertices whose value is NaN (RGB in [0, 1]): a bright violet, the colour
#: farthest from every colour of viridis and RdBu_r (at every shade the views draw) for
#: readers with normal vision and with protan, deutan or tritan colour blindness (CIELAB
#: distance at least 24 under Machado et al.'s simulation, against 4.9 for the mid grey it
#: replaces, which deutan readers saw as viridis's middle)
NAN_COLOR = (0.62, 0.0, 1.0)
#: the name of NAN_COLOR, as the colour bar and the text alternatives say it
NAN_NAME = "bright violet"
#: colour of a field that is zero up to rounding (white: nothing to see)
ZERO_COLOR = (1.0, 1.0, 1.0)
#: default ``zero_tol``: a field whose finite values all satisfy |v| <= ZERO_TOL
#: (in its own units) is zero up to rounding and drawn in ZERO_COLOR
ZERO_TOL = 1e-10
#: colour of a surface without values
PLAIN_COLOR = (0.74, 0.78, 0.86)


#: the line colours of the workbook's plots: Okabe and Ito's colour-blind-safe set without
#: its light colours, each at least 3:1 against a white page (WCAG 1.4.11): blue,
#: vermillion, bluish green, reddish purple, black
PLOT_COLOURS = ("#0072B2", "#D55E00", "#009E73", "#AA4499", "#000000")
#: one line style per colour, so that no two series of a plot differ by colour alone
PLOT_LINESTYLES = ("-", "--", "-.", ":", (0, (6, 2, 1, 2, 1, 2)))


def plot_style():
    """Matplotlib settings of the workbook's plots: the colour cycle :data:`PLOT_COLOURS`
    with a line style of its own per colour (:data:`PLOT_LINESTYLES`), ``C0``-``C4`` being
    those colours. Use as ``with matplotlib.rc_context(plot_style()):``."""
    from matplotlib import cycler  # matplotlib re-exports its own dependency: nothing more to install

    return {"axes.prop_cycle": cycler(color=list(PLOT_COLOURS), linestyle=list(PLOT_LINESTYLES))}


def use_plot_style():
    """Make :func:`plot_style` matplotlib's default for this session (:func:`geomlib.setup_display`,
    which each notebook's set-up cell calls, does it)."""
    import matplotlib

    matplotlib.rcParams.update(plot_style())


def _get_cmap(cmap):
    import matplotlib

    try:
        return matplotlib.colormaps[cmap] if isinstance(cmap, str) else cmap
    except KeyError:
        raise MeshError(f"unknown matplotlib colour map {cmap!r}") from None


def colour_table(cmap, size=256):
    """(size, 3) float32: the colour map ``cmap`` sampled at ``size`` evenly spaced points."""
    cm = _get_cmap(cmap)
    return cm(np.linspace(0.0, 1.0, size))[:, :3].astype(np.float32)


def value_range(values, symmetric=False, vmin=None, vmax=None):
    """Colour range ``(vmin, vmax)`` for ``values``: the finite min and max, or
    ``(-a, a)`` with ``a = max |values|`` when ``symmetric``; given bounds are
    kept. A range of zero width is widened slightly so the colours stay defined
    (all values then get the middle colour)."""
    finite = values[np.isfinite(values)] if values is not None else np.zeros(0)
    if symmetric:
        if vmin is not None or vmax is not None:
            a = max(abs(vmin or 0.0), abs(vmax or 0.0))
        else:
            a = float(np.abs(finite).max()) if finite.size else 1.0
        lo, hi = -a, a
    else:
        lo = float(finite.min()) if vmin is None and finite.size else (0.0 if vmin is None else float(vmin))
        hi = float(finite.max()) if vmax is None and finite.size else (1.0 if vmax is None else float(vmax))
    if not hi > lo:
        eps = max(abs(lo), abs(hi), 1.0) * 1e-9
        lo, hi = lo - eps, hi + eps
    return lo, hi


def colorize(values, cmap="viridis", vmin=0.0, vmax=1.0, lut=None):
    """Per-vertex RGB colours in [0, 1]: ``cmap((values - vmin) / (vmax - vmin))``.

    Parameters
    ----------
    values : (n,) float64; NaN entries get :data:`NAN_COLOR`.
    cmap : matplotlib colour map name (or object); ignored when ``lut`` is given.
    vmin, vmax : the values mapped to the ends of the map (clipped beyond).
    lut : optional (k, 3) float32 table of the map sampled at k points.

    Returns
    -------
    (n, 3) float32
    """
    values = np.asarray(values, dtype=np.float64)
    if lut is None:
        lut = colour_table(cmap)
    k = lut.shape[0]
    with np.errstate(invalid="ignore"):
        t = (values - vmin) * ((k - 1) / (vmax - vmin)) + 0.5
    nan = np.isnan(t)
    idx = np.clip(np.where(nan, 0.0, t), 0, k - 1).astype(np.intp)
    colors = lut[idx]
    if nan.any():
        colors[nan] = NAN_COLOR
    return colors


def format_value(x):
    """A value as a colour bar prints it: three significant digits, and 0 as "0"."""
    return f"{x:.3g}" if x != 0 else "0"


def colorbar_html(lut, vmin, vmax, label, n_nan, width):
    """The colour bar under a live view: the map ``lut`` from ``vmin`` to ``vmax``, ``label``, the NaN count."""
    # 17 stops sampled from the map
    samples = lut[:: max(1, len(lut) // 16)]
    samples = np.vstack([samples, lut[-1:]])
    stops = ", ".join(
        f"rgb({int(r * 255)},{int(g * 255)},{int(b * 255)}) {100 * i / (len(samples) - 1):.1f}%"
        for i, (r, g, b) in enumerate(samples.tolist())
    )
    nan_text = ""
    if n_nan:
        swatch = "rgb({},{},{})".format(*(int(c * 255) for c in NAN_COLOR))
        nan_text = (
            f'<span style="display:inline-block;width:10px;height:10px;background:{swatch};'
            f'margin:0 3px 0 8px"></span>NaN: {NAN_NAME} ({n_nan})'
        )
    label_html = (
        f"<div style='text-align:center'><span class='geomlib-label'>{html.escape(label)}</span>{nan_text}</div>"
        if (label or nan_text)
        else ""
    )
    return (
        f"<div class='geomlib-colorbar' style='width:{width}px;font:12px sans-serif;color:#222'>"
        "<div style='display:flex;align-items:center;gap:6px'>"
        f"<span class='geomlib-vmin'>{format_value(vmin)}</span>"
        f"<div style='flex:1;height:12px;border:1px solid #888;background:linear-gradient(to right, {stops})'></div>"
        f"<span class='geomlib-vmax'>{format_value(vmax)}</span></div>{label_html}</div>"
    )


def zero_html(text, label, width):
    """The colour bar of a field that is zero up to rounding: ``text`` in a white box, ``label`` under it."""
    label_html = f"<div style='text-align:center'>{html.escape(label)}</div>" if label else ""
    return (
        f"<div class='geomlib-colorbar geomlib-zero' style='width:{width}px;font:12px sans-serif;"
        f"color:#222'><div style='border:1px solid #888;background:#fff;text-align:center'>"
        f"{html.escape(text)}</div>{label_html}</div>"
    )
