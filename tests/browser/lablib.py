"""Drive JupyterLab (or Notebook 7) in headless Chromium: shared by the browser tests and
benchmarks/bench_slider_latency.py.

A server is started from this Python environment (``sys.executable -m
jupyterlab``) on a free loopback port, with token authentication, its own
temporary runtime, config, data, settings and workspace folders (so nothing of
the user's Jupyter set-up or earlier sessions leaks in and nothing is written
into the repository), JupyterLab's news pop-up switched off and every notebook
cell attached to the page (windowing off, so canvases of cells below the fold
are rendered too). The app object is exposed in the page as
``window.jupyterapp`` so cells, outputs and kernels can be inspected directly.

Chromium is Debian's (``/usr/bin/chromium``), launched by Playwright with
software WebGL (SwiftShader).
"""

import contextlib
import io
import json
import os
import secrets
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

CHROMIUM = os.environ.get("GEOMLIB_CHROMIUM", "/usr/bin/chromium")
CHROMIUM_ARGS = [
    "--headless=new",
    "--no-sandbox",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--use-gl=angle",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
]
VIEWPORT = {"width": 1400, "height": 1000}

# user settings written for the test server (JupyterLab settings JSON)
LAB_SETTINGS = {
    "@jupyterlab/apputils-extension/notification.jupyterlab-settings": {"fetchNews": "false", "checkForUpdates": False},
    "@jupyterlab/notebook-extension/tracker.jupyterlab-settings": {"windowingMode": "none"},
}


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


# app -> (Python module that starts it, its configuration class, URL of a notebook)
APPS = {
    "lab": ("jupyterlab", "LabApp", "/lab/tree/{name}?reset&token={token}"),
    "notebook": ("notebook", "JupyterNotebookApp", "/notebooks/{name}?token={token}"),
}


class LabServer:
    """A JupyterLab (``app="lab"``) or Notebook 7 (``app="notebook"``) server
    serving a temporary copy of ``notebook_dir``.

    ``user_settings`` replaces LAB_SETTINGS; ``overrides`` replaces the
    installation's ``share/jupyter/lab/settings/overrides.json`` (the file
    workbook.py writes into .venv); ``args`` go to the app.
    """

    def __init__(self, notebook_dir, startup_timeout=90, app="lab", user_settings=None, overrides=None, args=()):
        self.app = app
        self.user_settings = LAB_SETTINGS if user_settings is None else user_settings
        self.overrides = overrides
        self.args = list(args)
        self.source = Path(notebook_dir)
        self.startup_timeout = startup_timeout
        self.tmp = Path(tempfile.mkdtemp(prefix="geomlib-lab-"))
        self.root = self.tmp / "notebooks"
        self.token = secrets.token_hex(16)
        self.port = free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        self.proc = None
        self.log_path = self.tmp / "server.log"

    def start(self):
        shutil.copytree(self.source, self.root, ignore=shutil.ignore_patterns(".ipynb_checkpoints", "__pycache__"))
        settings = self.tmp / "user-settings"
        for rel, value in self.user_settings.items():
            path = settings / rel
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(json.dumps(value))
        env = dict(os.environ)
        for key, sub in (
            ("JUPYTER_CONFIG_DIR", "config"),
            ("JUPYTER_DATA_DIR", "data"),
            ("JUPYTER_RUNTIME_DIR", "runtime"),
            ("IPYTHONDIR", "ipython"),
        ):
            (self.tmp / sub).mkdir()
            env[key] = str(self.tmp / sub)
        env.pop("JUPYTER_PATH", None)
        env["PYTHONNOUSERSITE"] = "1"
        module, app_class, _ = APPS[self.app]
        if self.overrides is not None:
            (self.tmp / "app-settings").mkdir()
            (self.tmp / "app-settings" / "overrides.json").write_text(json.dumps(self.overrides))
            self.args.append(f"--{app_class}.app_settings_dir={self.tmp / 'app-settings'}")
        cmd = [
            sys.executable,
            "-m",
            module,
            "--no-browser",
            "--ServerApp.ip=127.0.0.1",
            f"--ServerApp.port={self.port}",
            "--ServerApp.port_retries=0",
            f"--IdentityProvider.token={self.token}",
            f"--ServerApp.root_dir={self.root}",
            f"--{app_class}.user_settings_dir={settings}",
            f"--{app_class}.workspaces_dir={self.tmp / 'workspaces'}",
            f"--{app_class}.expose_app_in_browser=True",
            "--ServerApp.open_browser=False",
            *self.args,
        ]
        if hasattr(os, "geteuid") and os.geteuid() == 0:
            cmd.append("--allow-root")  # containers and CI machines often run as root
        self._log = open(self.log_path, "wb")
        self.proc = subprocess.Popen(
            cmd, cwd=self.root, env=env, stdout=self._log, stderr=subprocess.STDOUT, start_new_session=True
        )
        deadline = time.monotonic() + self.startup_timeout
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise RuntimeError(f"JupyterLab exited with code {self.proc.returncode}:\n{self.log()}")
            try:
                with urllib.request.urlopen(f"{self.url}/api/status?token={self.token}", timeout=2) as r:
                    if r.status == 200:
                        return self
            except OSError:
                time.sleep(0.3)
        self.stop()
        raise RuntimeError(f"JupyterLab did not answer within {self.startup_timeout} s:\n{self.log()}")

    def log(self):
        try:
            return self.log_path.read_text(errors="replace")[-4000:]
        except OSError:
            return ""

    def notebook_url(self, name):
        return self.url + APPS[self.app][2].format(name=name, token=self.token)

    def stop(self):
        if self.proc is not None and self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=15)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(timeout=5)
        if getattr(self, "_log", None):
            self._log.close()
        shutil.rmtree(self.tmp, ignore_errors=True)

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()


@contextlib.contextmanager
def chromium_browser():
    """Playwright's Chromium driver on Debian's binary; yields the browser."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)
        try:
            yield browser
        finally:
            browser.close()


# ---------------------------------------------------------------------------
# page helpers (JavaScript evaluated in the JupyterLab page)
# ---------------------------------------------------------------------------

JS_PANEL = """
() => {
  const app = window.jupyterapp;
  const w = app && app.shell.currentWidget;
  return !!(w && w.content && w.content.widgets && w.sessionContext);
}
"""

JS_KERNEL_READY = """
async () => {
  const panel = window.jupyterapp.shell.currentWidget;
  await panel.sessionContext.ready;
  const k = panel.sessionContext.session && panel.sessionContext.session.kernel;
  return !!k && k.status === 'idle';
}
"""

JS_STATE = """
() => {
  const panel = window.jupyterapp.shell.currentWidget;
  const cells = panel.content.widgets;
  let code = 0, done = 0, pending = 0;
  const errors = [];
  cells.forEach((cell, i) => {
    if (cell.model.type !== 'code') return;
    code += 1;
    if (cell.model.executionCount !== null && cell.model.executionCount !== undefined) done += 1;
    const prompt = cell.node.querySelector('.jp-InputPrompt');
    if (prompt && prompt.textContent.includes('*')) pending += 1;
    const outputs = cell.model.outputs.toJSON();
    for (const o of outputs) {
      if (o.output_type === 'error') {
        errors.push({cell: i, ename: o.ename, evalue: o.evalue,
                     traceback: (o.traceback || []).join('\\n').replace(/\\u001b\\[[0-9;]*m/g, '')});
      }
    }
  });
  const k = panel.sessionContext.session && panel.sessionContext.session.kernel;
  return {code, done, pending, errors, kernel: k ? k.status : 'none'};
}
"""

JS_SHUTDOWN = """
async () => {
  const panel = window.jupyterapp.shell.currentWidget;
  if (panel && panel.sessionContext) { await panel.sessionContext.shutdown(); }
  return true;
}
"""

# find the first slider that shares an ipywidgets box with a geomlib view, or
# failing that, the first slider displayed by the same cell as a view; mark it
# (data-geomlib-slider) and the box or output area (data-geomlib-box)
JS_FIND_SLIDER = """
() => {
  const sliders = [...document.querySelectorAll('.jp-Notebook .widget-slider')];
  const mark = (s, el, how) => {
    document.querySelectorAll('[data-geomlib-slider]').forEach(e => e.removeAttribute('data-geomlib-slider'));
    document.querySelectorAll('[data-geomlib-box]').forEach(e => e.removeAttribute('data-geomlib-box'));
    s.setAttribute('data-geomlib-slider', '1');
    el.setAttribute('data-geomlib-box', '1');
    const h = s.querySelector('.noUi-handle');
    return {found: true, how, count: el.querySelectorAll('.geomlib-view').length,
            now: h ? Number(h.getAttribute('aria-valuenow')) : null,
            max: h ? Number(h.getAttribute('aria-valuemax')) : null,
            min: h ? Number(h.getAttribute('aria-valuemin')) : null,
            description: (s.querySelector('.widget-label') || {}).textContent || ''};
  };
  for (const s of sliders) {
    let el = s.parentElement;
    while (el && !el.classList.contains('jp-OutputArea-output')) {
      if (el.classList.contains('widget-box') && el.querySelector('.geomlib-view')) return mark(s, el, 'box');
      el = el.parentElement;
    }
  }
  for (const s of sliders) {
    const area = s.closest('.jp-OutputArea');
    if (area && area.querySelector('.geomlib-view')) return mark(s, area, 'cell');
  }
  return {found: false};
}
"""


def open_notebook(page, server, name, timeout_s=120):
    """Open NAME in a fresh Lab page and wait for its kernel."""
    page.goto(server.notebook_url(name), wait_until="domcontentloaded", timeout=timeout_s * 1000)
    page.wait_for_function(JS_PANEL, timeout=timeout_s * 1000, polling=250)
    page.wait_for_function(JS_KERNEL_READY, timeout=timeout_s * 1000, polling=250)


def run_all(page, timeout_s=180):
    """Run every cell; return the final state dict (code, done, errors, kernel)."""
    page.evaluate("() => window.jupyterapp.commands.execute('runmenu:run-all')")
    deadline = time.monotonic() + timeout_s
    state = None
    idle_since = None
    while time.monotonic() < deadline:
        state = page.evaluate(JS_STATE)
        finished = state["done"] == state["code"] and state["pending"] == 0 and state["kernel"] == "idle"
        if finished or (state["errors"] and state["pending"] == 0 and state["kernel"] == "idle"):
            idle_since = idle_since or time.monotonic()
            if time.monotonic() - idle_since > 1.0:  # stay idle for a moment: widgets render
                return state
        else:
            idle_since = None
        time.sleep(0.25)
    state = dict(state or {}, timeout=True)
    return state


def shutdown_kernel(page):
    try:
        page.evaluate(JS_SHUTDOWN)
    except Exception:  # the page may already be gone; the server's exit ends the kernel too
        pass


def stable_screenshot(locator, tries=20, pause=0.15):
    """Screenshot of an element once its position stopped moving (Lab keeps
    laying out while MathJax typesets and outputs above it grow)."""
    locator.scroll_into_view_if_needed()
    box = locator.bounding_box()
    png = None
    for _ in range(tries):
        time.sleep(pause)
        again = locator.bounding_box()
        if again == box:
            png = locator.screenshot()
            if locator.bounding_box() == box:
                return png
            again = locator.bounding_box()
        box = again
    return png if png is not None else locator.screenshot()


def image_stats(png_bytes, background=(255, 255, 255)):
    """(distinct colours, fraction of pixels differing from the background)."""
    import numpy as np
    from PIL import Image

    im = np.asarray(Image.open(io.BytesIO(png_bytes)).convert("RGB")).reshape(-1, 3)
    distinct = len(np.unique(im.view([("", im.dtype)] * 3)))
    off = np.any(np.abs(im.astype(int) - background) > 8, axis=1).mean()
    return distinct, float(off)


def changed_fraction(png_a, png_b):
    """Fraction of pixels that differ between two screenshots of equal size."""
    import numpy as np
    from PIL import Image

    a = np.asarray(Image.open(io.BytesIO(png_a)).convert("RGB")).astype(int)
    b = np.asarray(Image.open(io.BytesIO(png_b)).convert("RGB")).astype(int)
    if a.shape != b.shape:
        return 1.0
    return float(np.any(np.abs(a - b) > 8, axis=2).mean())


def find_slider(page, timeout):
    """JS_FIND_SLIDER's answer, waited for: widget views attach to the page asynchronously,
    after their cell has reported that it ran, so a slider may come a moment after its view."""
    return wait_for(lambda: (found := page.evaluate(JS_FIND_SLIDER))["found"] and found, timeout) or {"found": False}


def views(page, timeout):
    """The page's 3D views (``.geomlib-canvas``), once at least one is there and their
    number held still for a moment: like sliders, views attach after their cell ran."""
    canvases = page.locator(".geomlib-canvas")
    seen = []

    def settled():
        seen.append(canvases.count())
        return len(seen) > 1 and seen[-1] >= 1 and seen[-1] == seen[-2]

    wait_for(settled, timeout, interval=0.5)
    return canvases


def wait_for(predicate, timeout, interval=0.3):
    """Call ``predicate`` until it returns something true or ``timeout`` seconds pass; return its last value."""
    deadline = time.monotonic() + timeout
    value = predicate()
    while not value and time.monotonic() < deadline:
        time.sleep(interval)
        value = predicate()
    return value
