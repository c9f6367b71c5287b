#!/usr/bin/env python
"""Slider latency of the 3D viewer in a real browser: key press to final image.

    .venv/bin/python benchmarks/bench_slider_latency.py [--reps 9] [--no-reference]

Starts JupyterLab (a temporary folder, nothing written into the repository) and
headless Chromium (Debian's /usr/bin/chromium, software WebGL), opens a
generated notebook with a slider that deforms a sphere and recolours it, on
meshes of 2,562, 40,962 and 163,842 vertices, and measures the median time
from a key press on the slider to the last frame drawn on that view's canvas
because of it.

How the time is taken: an init script wraps WebGL's drawElements; after each
draw on a canvas it records the time of the next animation frame (the frame
that shows the draw). A keydown listener records the key press. After each
press the script waits until the kernel is idle and the canvas has drawn
nothing for 0.8 s; the latency is the last recorded frame minus the key press.
The arrival of the large websocket messages (the buffer updates) is recorded
too, which splits the time into kernel + transfer and browser-side work
(decoding, upload to the GPU, drawing with software WebGL).

The reference in the same run ("naive") is the straightforward pythreejs
version: three separate BufferAttributes (three messages per update),
trimesh's vertex normals and matplotlib's colour map call in the callback.
Targets: 150 / 300 / 800 ms. The script also prints the Python-side update
time and the time to draw the still picture a view shows where no widget
front-end runs (goal: under 300 ms at 25k faces).
"""

import argparse
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "browser"))

import lablib  # noqa: E402

SIZES = [(4, 2562, 150), (6, 40962, 300), (7, 163842, 800)]  # icosphere level, vertices, target ms

SETUP = r'''
import time
import numpy as np
import ipywidgets
import trimesh
import matplotlib
import pythreejs as three
from geomlib.teaching.display.viewer import MeshView

def deform(V, t):
    """A smooth bump pattern whose amplitude is t; returns positions and the radial offset."""
    x, y, z = V.T
    bump = 0.15 * t * np.sin(4 * x) * np.cos(3 * y) * np.sin(2 * z + 1)
    return V * (1.0 + bump)[:, None], bump

class NaiveView:
    """The straightforward pythreejs viewer: three buffers, trimesh normals, matplotlib colours."""
    def __init__(self, V, F):
        self.F = F
        self.cmap = matplotlib.colormaps["RdBu_r"]
        m = trimesh.Trimesh(V, F, process=False)
        self.pos = three.BufferAttribute(V.astype(np.float32), normalized=False)
        self.nor = three.BufferAttribute(np.asarray(m.vertex_normals, dtype=np.float32), normalized=False)
        self.col = three.BufferAttribute(np.full((len(V), 3), 0.7, dtype=np.float32), normalized=False)
        geo = three.BufferGeometry(index=three.BufferAttribute(F.astype(np.uint32).ravel(), normalized=False),
                                   attributes={"position": self.pos, "normal": self.nor, "color": self.col})
        mesh = three.Mesh(geo, three.MeshLambertMaterial(vertexColors="VertexColors"))
        cam = three.PerspectiveCamera(position=[0, -4, 2], up=[0, 0, 1], aspect=420 / 340, fov=30)
        scene = three.Scene(children=[mesh, cam, three.AmbientLight(intensity=0.5)], background="#ffffff")
        cam.children = [three.DirectionalLight(position=[1, 1, 1], intensity=0.6)]
        self.renderer = three.Renderer(scene=scene, camera=cam, controls=[three.OrbitControls(controlling=cam)], width=420, height=340)
        self.renderer.add_class("geomlib-canvas")
        self.widget = ipywidgets.VBox([self.renderer])
        self.widget.add_class("geomlib-view")

    def update(self, V, values):
        m = trimesh.Trimesh(V, self.F, process=False)
        self.pos.array = V.astype(np.float32)
        self.nor.array = np.asarray(m.vertex_normals, dtype=np.float32)
        self.col.array = self.cmap((values + 0.15) / 0.3)[:, :3].astype(np.float32)

def make(level, naive):
    s = trimesh.creation.icosphere(subdivisions=level)
    V, F = np.asarray(s.vertices), np.asarray(s.faces)
    view = NaiveView(V, F) if naive else MeshView(V, F, values=np.zeros(len(V)), symmetric=True,
                                                  vmin=-0.15, vmax=0.15, label="bump")
    slider = ipywidgets.FloatSlider(0.0, min=-1.0, max=1.0, step=0.1,
                                    description=f"{'naive' if naive else 'geomlib'} {len(V)}")
    def on_change(change):
        W, bump = deform(V, change["new"])
        view.update(V=W, values=bump)
    slider.observe(on_change, "value")
    box = ipywidgets.VBox([slider, view.widget])
    box.add_class(f"bench-{'naive' if naive else 'geomlib'}-{len(V)}")
    return box
'''

# in-page instrumentation: frame times after draws, per canvas, and the last key press
INIT_SCRIPT = r"""
(() => {
  window.__frames = [];
  window.__key = 0;
  window.__messages = [];
  // arrival of large websocket messages (the buffer updates), before Lab handles them
  const NativeWebSocket = window.WebSocket;
  window.WebSocket = class extends NativeWebSocket {
    constructor(...args) {
      super(...args);
      this.binaryType = 'arraybuffer';
      this.addEventListener('message', (e) => {
        const size = e.data && (e.data.byteLength || e.data.size || e.data.length || 0);
        if (size > 20000) window.__messages.push({t: performance.now(), size});
      });
    }
  };
  document.addEventListener('keydown', () => { window.__key = performance.now(); }, true);
  const pending = new WeakSet();
  for (const proto of [WebGLRenderingContext.prototype,
                       (window.WebGL2RenderingContext || WebGLRenderingContext).prototype]) {
    const draw = proto.drawElements;
    proto.drawElements = function (...args) {
      const canvas = this.canvas;
      if (!pending.has(canvas)) {
        pending.add(canvas);
        requestAnimationFrame(() => {
          pending.delete(canvas);
          window.__frames.push({canvas, t: performance.now()});
        });
      }
      return draw.apply(this, args);
    };
  }
})();
"""

JS_LAST_FRAME = r"""
(sel) => {
  const canvas = document.querySelector(sel + ' .geomlib-canvas canvas');
  const key = window.__key;
  const mine = window.__frames.filter(f => f.canvas === canvas && f.t >= key);
  const msgs = window.__messages.filter(m => m.t >= key);
  return {key, n: mine.length, last: mine.length ? mine[mine.length - 1].t : null,
          messages: msgs.length, first_message: msgs.length ? msgs[0].t : null,
          last_message: msgs.length ? msgs[msgs.length - 1].t : null,
          bytes: msgs.reduce((a, m) => a + m.size, 0), now: performance.now()};
}
"""


def notebook_json(cells):
    return {
        "nbformat": 4,
        "nbformat_minor": 5,
        "metadata": {"kernelspec": {"name": "python3", "display_name": "Python 3", "language": "python"}},
        "cells": [
            {"cell_type": "code", "id": f"c{i}", "metadata": {}, "execution_count": None, "outputs": [], "source": src}
            for i, src in enumerate(cells)
        ],
    }


def python_side(levels):
    """Time of MeshView.update alone (no browser), per size, in ms."""
    import numpy as np
    import trimesh

    from geomlib.teaching.display.viewer import MeshView

    out = {}
    for level, n, _ in levels:
        s = trimesh.creation.icosphere(subdivisions=level)
        V, F = np.asarray(s.vertices), np.asarray(s.faces)
        view = MeshView(V, F, values=np.zeros(len(V)), vmin=-0.15, vmax=0.15)
        times = []
        for k in range(5):
            W = V * (1.0 + 0.01 * k)
            t = time.perf_counter()
            view.update(V=W, values=W[:, 2])
            times.append(1e3 * (time.perf_counter() - t))
        out[n] = statistics.median(times)
    return out


def still_time():
    """Median ms to draw the PNG still (z-buffer rasteriser + colour bar) of a 25,600-face torus."""
    import numpy as np
    import trimesh

    from geomlib.teaching.display.viewer import MeshView

    m = trimesh.creation.torus(1.0, 0.4, major_sections=128, minor_sections=100)
    view = MeshView(np.asarray(m.vertices), np.asarray(m.faces), values=np.asarray(m.vertices)[:, 2])
    times = []
    for _ in range(5):
        t = time.perf_counter()
        view._repr_mimebundle_()
        times.append(1e3 * (time.perf_counter() - t))
    return statistics.median(times)


def measure(page, selector, reps, settle=0.8, timeout=30.0):
    handle = page.locator(f"{selector} .noUi-handle").first
    handle.scroll_into_view_if_needed()
    canvas = page.locator(f"{selector} .geomlib-canvas").first
    before = canvas.screenshot()
    handle.focus()
    latencies, arrivals, messages = [], [], []
    changed = None
    for r in range(reps):
        key = "ArrowRight" if (r // 5) % 2 == 0 else "ArrowLeft"  # stay inside the slider's range
        page.keyboard.press(key)
        deadline = time.monotonic() + timeout
        last_seen, quiet_since = None, time.monotonic()
        while time.monotonic() < deadline:
            time.sleep(0.1)
            info = page.evaluate(JS_LAST_FRAME, selector)
            kernel = page.evaluate(lablib.JS_STATE)["kernel"]
            if info["last"] != last_seen:
                last_seen, quiet_since = info["last"], time.monotonic()
            elif last_seen is not None and kernel == "idle" and time.monotonic() - quiet_since > settle:
                break
        if last_seen is None:
            raise RuntimeError(f"{selector}: no frame drawn after the key press")
        latencies.append(last_seen - info["key"])
        if info["first_message"] is not None:
            arrivals.append(info["last_message"] - info["key"])
            messages.append((info["messages"], info["bytes"]))
        if changed is None:
            changed = lablib.changed_fraction(before, canvas.screenshot())
    return latencies, changed, arrivals, messages


def main():
    parser = argparse.ArgumentParser(description="slider latency of the 3D viewer in headless Chromium")
    parser.add_argument("--reps", type=int, default=9, help="key presses per mesh size (default 9)")
    parser.add_argument("--no-reference", action="store_true", help="skip the naive reference viewer")
    args = parser.parse_args()
    if not Path(lablib.CHROMIUM).exists():
        sys.exit(f"{lablib.CHROMIUM} is missing: apt-get install chromium")

    variants = ["geomlib"] + ([] if args.no_reference else ["naive"])
    cells = [SETUP]
    for variant in variants:
        for level, n, _ in SIZES:
            cells.append(f"make({level}, naive={variant == 'naive'})")

    print(
        "python side, MeshView.update alone (median ms):",
        ", ".join(f"{n}: {t:.0f}" for n, t in python_side(SIZES).items()),
        flush=True,
    )
    print(f"still picture of the display fallback, 25,600 faces: {still_time():.0f} ms (goal < 300)", flush=True)

    with tempfile.TemporaryDirectory(prefix="bench-slider-") as tmp:
        (Path(tmp) / "bench.ipynb").write_text(json.dumps(notebook_json(cells)))
        with lablib.LabServer(tmp) as server, lablib.chromium_browser() as browser:
            page = browser.new_page(viewport=lablib.VIEWPORT)
            page.add_init_script(INIT_SCRIPT)
            lablib.open_notebook(page, server, "bench.ipynb")
            state = lablib.run_all(page, timeout_s=300)
            if state.get("errors") or state.get("timeout"):
                sys.exit(f"the benchmark notebook failed: {state}")
            time.sleep(2.0)
            results = {}
            for variant in variants:
                for level, n, target in SIZES:
                    sel = f".bench-{variant}-{n}"
                    lat, changed, arrivals, messages = measure(page, sel, args.reps)
                    results[(variant, n)] = statistics.median(lat)
                    arrive = f"{statistics.median(arrivals):.0f}" if arrivals else "?"
                    count, size = messages[len(messages) // 2] if messages else (0, 0)
                    print(
                        f"{variant:8s} {n:7d} vertices: median {statistics.median(lat):6.0f} ms "
                        f"(min {min(lat):.0f}, max {max(lat):.0f}, {len(lat)} presses); "
                        f"last update message in the browser after {arrive} ms "
                        f"({count} large message(s), {size / 1e6:.1f} MB); "
                        f"{changed:.0%} of the canvas changed",
                        flush=True,
                    )
            lablib.shutdown_kernel(page)

    print("\nkey press -> final image, median ms")
    header = f"{'vertices':>9s} {'geomlib':>8s} {'target':>7s}"
    if not args.no_reference:
        header += f" {'naive':>7s} {'naive/geomlib':>14s}"
    print(header)
    for level, n, target in SIZES:
        g = results[("geomlib", n)]
        line = f"{n:9d} {g:8.0f} {target:7d}"
        if not args.no_reference:
            r = results[("naive", n)]
            line += f" {r:7.0f} {r / g:14.2f}"
        print(line + ("" if g <= target else "   <- above target"))


if __name__ == "__main__":
    main()
