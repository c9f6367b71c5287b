"""Front-ends that need a word from the kernel before they draw the 3D views.

Google Colab renders ipywidgets' own controls out of the box, but loads a
third-party widget's JavaScript (here pythreejs, ``jupyter-threejs``) only
after ``google.colab.output.enable_custom_widget_manager()`` was called in the
session. :func:`geomlib.setup_display` makes that call when it runs inside Colab;
every notebook's set-up cell calls it, and so does the first 3D view. Colab is recognised by its
module ``google.colab``; everywhere else nothing happens.

JupyterLab, Notebook 7 and VS Code need nothing from the kernel (VS Code
needs its ``jupyter.widgetScriptSources`` setting; see the README).
"""

import importlib
import importlib.util
import sys

__all__ = ["enable_colab_widgets", "in_colab"]

COLAB = "google.colab"

# the call is made once per kernel, however often geomlib is imported or reloaded
_state = {"enabled": False}


def in_colab():
    """True when the module ``google.colab`` is imported or importable."""
    if COLAB in sys.modules:
        return True
    try:
        return importlib.util.find_spec(COLAB) is not None
    except (ImportError, ValueError):  # no 'google' package at all, or a broken one
        return False


def enable_colab_widgets():
    """In Colab, enable its custom widget manager (once); elsewhere do nothing.

    Returns
    -------
    bool
        True when this call enabled it, False when it was already enabled
        or this is not Colab.
    """
    if _state["enabled"] or not in_colab():
        return False
    output = importlib.import_module(COLAB + ".output")
    output.enable_custom_widget_manager()
    _state["enabled"] = True
    return True
