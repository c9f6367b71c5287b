"""Teaching aids: 3D views and stills, exercise checks, notebook helpers, experiment drivers.

May import the mesh core, numerics and lessons; only the course tools import it. Its parts:
``shapes/`` (the exact surfaces tests and checks rely on), ``experiments/`` (the step unit,
the sweeps of notebook 07), ``display/`` (views, stills, controls), ``figures/`` (the
notebooks' matplotlib figures), ``check/`` (exercise checks), ``notebook`` (claims, notes).

The names a lesson notebook uses are importable from here, so that a notebook's
teaching aids come in one line (``from geomlib.teaching import claim, live, MeshView``).
They are imported on first use: the 3D viewer is not loaded by a notebook that only checks.
"""

from importlib import import_module

# public name -> module that defines it (imported on first use)
_EXPORTS = {
    **dict.fromkeys(["reveal", "use"], "check"),
    **dict.fromkeys(["live", "live_figure", "mesh_warnings"], "display.controls"),
    **dict.fromkeys(["clipped", "explicit_explorer", "implicit_explorer"], "display.smoothing_controls"),
    **dict.fromkeys(["claim", "explain", "note", "prepare", "show_figure", "show_source"], "notebook"),
    **dict.fromkeys(["MeshSteps", "absolute_step", "log_positions", "log_slider", "step_label"], "experiments.steps"),
    **dict.fromkeys(
        [
            "EXPLICIT_FRACTIONS",
            "IMPLICIT_STEPS",
            "denoising_comparison",
            "smoothing_sweep",
        ],
        "experiments.sweep",
    ),
    **dict.fromkeys(["MeshView", "setup_display", "side_by_side"], "display.viewer"),
    **dict.fromkeys(["plot_comparison", "plot_sweep"], "figures.denoising_plots"),
}

__all__ = sorted(_EXPORTS)


def __getattr__(name):
    if name not in _EXPORTS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(import_module(f".{_EXPORTS[name]}", __name__), name)
    globals()[name] = value  # later look-ups skip this hook
    return value


def __dir__():
    return __all__
