"""The states of a cell's sliders, computed ahead for the static website.

The site builder (``tools/build_site.py``) runs every notebook in a kernel.
After the last cell, it calls :func:`record` in that same kernel, once per cell
that showed widgets, with the ids of the widgets the cell displayed. ``record`` moves each
slider, one at a time from the defaults of the others, through a short list of
values (:func:`slider_values`). Setting ``slider.value`` in the kernel runs the
notebook's own observers exactly as when a reader moves the slider in
JupyterLab, so the recorded states are what JupyterLab shows for those values.
For every value it keeps what the observers changed in the widgets the cell
displayed: numpy arrays of pythreejs buffers (positions, normals, colours) and
plain values such as the text of an HTML read-out. The slider goes back to its
default at the end, so the saved widget state is the default state.

Nothing here knows a notebook or a geomlib view: it reads ipywidgets and
pythreejs models only (their synced traits), so a notebook needs no code of its
own for its sliders to move on the site.

Arrays are stored compactly: only the columns that change during a slider's
sweep, each column of each state quantised to 16 bits over its own range
(``lo + q (hi - lo) / 65535``; little-endian, gzip, base64: the browser unpacks
gzip itself). On the scale of a mesh that is 1.5e-5 of the column's extent: the
picture is the same. Per state of a mesh of n vertices that is at most 18 n
bytes before gzip (positions, normals and colours), against 36 n as float32.
"""

import base64
import gzip
import json
import math
from collections import deque

import numpy as np

__all__ = ["record", "slider_values", "MAX_VALUES", "MAX_BYTES"]

#: at most this many values per slider (a longer grid is thinned, see slider_values)
MAX_VALUES = 21
#: a slider whose recorded states would take more than this many bytes is left out
#: (it stays disabled on the site), so a page stays small enough to load
MAX_BYTES = 15_000_000
#: round numbers a slider snaps to beyond the first ten integers: 15, 20, 30, 50, 100, ...
NICE = (1.0, 1.5, 2.0, 3.0, 5.0)


def _round(x):
    """``x`` to 12 significant digits: the grid's sums (0.1 + 0.2) printed as a reader reads them."""
    return float(f"{x:.12g}")


def _thin(grid, default, keep):
    """At most about ``keep`` points of a sorted ``grid``: every s-th point counted from the
    default (so it stays on), plus both ends."""
    stride = math.ceil(len(grid) / (keep - 1))
    d = int(np.argmin(np.abs(np.asarray(grid) - default)))
    return sorted({grid[i] for i in range(d % stride, len(grid), stride)} | {grid[0], grid[-1]})


def _nice(lo, hi):
    """The round numbers ``m 10^e`` (m in NICE) in [lo, hi], lo > 0."""
    out = []
    for e in range(math.floor(math.log10(lo)) - 1, math.ceil(math.log10(hi)) + 1):
        out += [_round(m * 10.0**e) for m in NICE if lo <= m * 10.0**e <= hi]
    return out


def slider_values(slider):
    """The values ``slider`` is driven through: sorted, with its default, minimum and maximum.

    - a grid of at most MAX_VALUES positions: all of them;
    - an integer slider: every integer up to 10, then 15, 20, 30, 50, 100, 150, ...;
    - a linear float slider from 0 (or above) whose range spans more than three
      decades of its step: 0 and 1, 2, 5 (and 1.5, 3) times powers of ten down to 1/200
      of the maximum;
    - otherwise (log sliders included) every s-th grid position counted from the default.
    """
    import ipywidgets

    lo, hi, step, default = slider.min, slider.max, slider.step, slider.value
    log = isinstance(slider, ipywidgets.FloatLogSlider)
    count = int(round((hi - lo) / step)) + 1 if step else 1
    grid = [lo + j * step for j in range(count)]
    if log:
        grid = [slider.base**e for e in grid]
        lo, hi = grid[0], grid[-1]
    if count <= MAX_VALUES:
        values = grid
    elif isinstance(slider, ipywidgets.IntSlider):
        values = list(range(lo, min(hi, 10) + 1)) + [int(v) for v in _nice(10.5, hi) if v == int(v)]
    elif not log and lo >= 0 and hi / step > 1000:
        values = [lo] + [v for v in _nice(hi / 200, hi) if v >= lo]
    else:
        exponent = math.log(default, slider.base) if log else default
        positions = _thin([slider.min + j * step for j in range(count)], exponent, MAX_VALUES)
        values = [slider.base**e for e in positions] if log else positions
    cast = int if isinstance(slider, ipywidgets.IntSlider) else _round
    return sorted({cast(v) for v in values if lo <= v <= hi} | {cast(lo), cast(hi), default})


def _widget(model_id):
    """The live widget with this model id (ipywidgets' own lookup of ``IPY_MODEL_`` references)."""
    from ipywidgets import widget_serialization

    return widget_serialization["from_json"](f"IPY_MODEL_{model_id}", None)


def _reachable(roots):
    """Every widget reachable from ``roots`` through synced traits (children, scene, buffers, ...)."""
    from ipywidgets import Widget

    seen, order, todo = set(), [], deque(roots)
    while todo:  # breadth first: sliders come in the order a reader sees them
        item = todo.popleft()
        if isinstance(item, Widget):
            if item.model_id in seen:
                continue
            seen.add(item.model_id)
            order.append(item)
            todo.extend(getattr(item, name) for name in item.keys)
        elif isinstance(item, (list, tuple)):
            todo.extend(item)
        elif isinstance(item, dict):
            todo.extend(item.values())
    return order


def _plain(value):
    """True for a JSON value (what a read-out's text, a layout or a colour range is)."""
    if value is None or isinstance(value, (str, bool, int, float)):
        return not isinstance(value, float) or math.isfinite(value)
    if isinstance(value, (list, tuple)):
        return all(_plain(v) for v in value)
    if isinstance(value, dict):
        return all(isinstance(k, str) and _plain(v) for k, v in value.items())
    return False


def _encode(arrays):
    """The states of one array trait: only its changing columns, each 16-bit over its own range.

    ``arrays`` are the trait's values, the default's first. Returns None when they
    are not finite float arrays of one shape (the slider is then left out).
    """
    first = arrays[0]
    if not all(
        isinstance(a, np.ndarray) and a.dtype.kind == "f" and a.shape == first.shape and np.isfinite(a).all()
        for a in arrays
    ):
        return None
    stack = np.stack([a.reshape(len(a), -1) if a.ndim else a.reshape(1, 1) for a in arrays])  # (states, n, c)
    columns = [c for c in range(stack.shape[2]) if not (stack[:, :, c] == stack[0, :, c]).all()]
    states = []
    for S in stack[1:]:
        X = S[:, columns].astype(np.float64)
        lo, hi = X.min(axis=0), X.max(axis=0)
        width = np.where(hi > lo, hi - lo, 1.0)
        q = np.rint((X - lo) / width * 65535.0).astype("<u2")
        data = gzip.compress(q.tobytes(), compresslevel=9, mtime=0)
        states.append({"lo": lo.tolist(), "hi": hi.tolist(), "q": base64.b64encode(data).decode()})
    return {"shape": list(first.shape), "columns": columns, "states": states}


def _replayable(widget):
    """The synced traits of ``widget`` whose values draw it. Not an Output widget's
    ``msg_id``: it only says which kernel messages the front-end captures, and the
    captured outputs themselves never reach the kernel."""
    import ipywidgets

    return [n for n in widget.keys if not (isinstance(widget, ipywidgets.Output) and n == "msg_id")]


def _sweep(slider, values, watched):
    """Set ``slider`` to each value (the default first and last); the changed traits per value.

    Returns ``{(model_id, trait): [value at each of values]}`` for every synced trait of
    ``watched`` that changed.
    """
    seen = {}  # (model id, trait) -> list of values so far
    current = {"j": 0}

    def note(change):
        key = (change["owner"].model_id, change["name"])
        if key not in seen:  # unchanged until now: its earlier states are the old value
            seen[key] = [change["old"]] * current["j"]
        column = seen[key]
        del column[current["j"] :]
        column.append(change["new"])

    default = slider.value
    names = {w.model_id: _replayable(w) for w in watched}
    for w in watched:
        w.observe(note, names=names[w.model_id])
    try:
        for j, v in enumerate(values):
            current["j"] = j
            slider.value = v
            for key, column in seen.items():  # traits that did not change at this value keep theirs
                column.extend([column[-1]] * (j + 1 - len(column)))
    finally:
        for w in watched:
            w.unobserve(note, names=names[w.model_id])
        slider.value = default  # the observers put the default state back
    return seen


def record(model_ids, path):
    """Record the states of every slider shown by a cell; write them to ``path`` (JSON).

    Parameters
    ----------
    model_ids : list of str
        Model ids of the widgets the cell displayed.
    path : str
        File written: ``{"sliders": [...], "left_out": [...]}``; per slider its model id,
        its values, the index of its default, and per changed trait of a shown
        model its values (plain JSON) or encoded arrays (see the module docstring).

    A slider whose moves change nothing the cell shows (a plot drawn by an Output
    widget, for instance, is drawn by the front-end) or something that cannot be
    stored (not JSON, not a finite float array) is left out, and so is one whose
    states would exceed MAX_BYTES; ``left_out`` names them with the reason.
    """
    import ipywidgets

    shown = _reachable([_widget(m) for m in model_ids])
    sliders = [
        w
        for w in shown
        if isinstance(w, (ipywidgets.IntSlider, ipywidgets.FloatSlider, ipywidgets.FloatLogSlider)) and not w.disabled
    ]
    watched = [w for w in shown if w not in sliders]
    out, left_out = [], []
    for slider in sliders:
        values = slider_values(slider)
        d = values.index(slider.value)
        order = [d] + [j for j in range(len(values)) if j != d]  # from the default, and back to it
        seen = _sweep(slider, [values[j] for j in order], watched)
        name = slider.description or slider.model_id
        traits, reason = [], None
        for (mid, trait), column in seen.items():
            by_value = [None] * len(values)
            for j, v in zip(order, column):
                by_value[j] = v
            if isinstance(column[0], np.ndarray):
                encoded = _encode([by_value[d]] + [v for j, v in enumerate(by_value) if j != d])
                if encoded is None:
                    reason = f"{trait} of a {type(_widget(mid)).__name__} is not a finite float array"
                    break
                # per value: the default is the page's own array; the others in order
                it = iter(encoded.pop("states"))
                states = [None if j == d else next(it) for j in range(len(values))]
                traits.append({"model_id": mid, "trait": trait, "array": encoded, "states": states})
            elif all(_plain(v) for v in by_value):
                traits.append({"model_id": mid, "trait": trait, "states": by_value})
            else:
                reason = f"{trait} of a {type(_widget(mid)).__name__} is not plain data"
                break
        if reason is None and not traits:
            reason = "moving it changes nothing the cell shows"
        size = len(json.dumps(traits))
        if reason is None and size > MAX_BYTES:
            reason = f"its {len(values)} states take {size / 1e6:.1f} MB"
        if reason:
            left_out.append({"model_id": slider.model_id, "description": name, "reason": reason})
            continue
        out.append(
            {
                "model_id": slider.model_id,
                "description": name,
                "log": isinstance(slider, ipywidgets.FloatLogSlider),
                "values": values,
                "default": d,
                "traits": traits,
            }
        )
    with open(path, "w") as f:
        json.dump({"sliders": out, "left_out": left_out}, f)
