"""The "turn the knobs" cells of notebooks 05 and 06: smoothing runs under sliders, one call each.

``explicit_explorer(meshes, steps, limits, iterations)`` shows the meshes of notebook 05
under one step slider and one iteration slider, each mesh coloured by how far its vertices
moved; ``implicit_explorer(V, F, steps, name, iterations, limit)`` shows one mesh of notebook
06 under a step slider (positions prepared ahead, a factorisation each), an iteration slider,
the volume switch and the fixed or rebuilt operator. Both advance by the lessons' engines
(:class:`geomlib.lessons.smoothing.ExplicitSmoother`, :class:`ImplicitSmoother`,
:func:`implicit_smoothing`), which call the very steps the notebooks show, and both return
the :class:`geomlib.teaching.display.controls.Live` box.
"""

import numpy as np

from ...lessons.smoothing import ExplicitSmoother, ImplicitSmoother, implicit_smoothing
from ...mesh.geometry import bounding_box_diagonal, enclosed_volume
from ...mesh.topology import boundary_vertices
from ...numerics.progress import LARGE_MESH
from ..experiments.steps import log_positions, log_slider, step_label
from ..notebook import graded, note
from .controls import live, mesh_warnings
from .viewer import MeshView

__all__ = ["explicit_explorer", "implicit_explorer", "clipped"]


def clipped(P, V, fraction=0.25):
    """P with every displacement from V clipped to ``fraction`` of V's bounding-box diagonal (for the views)."""
    d, cap = P - V, fraction * bounding_box_diagonal(V)
    return V + d * np.minimum(1.0, cap / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-300))


def explicit_explorer(meshes, steps, limits, iterations):
    """Notebook 05's meshes under a step slider (``steps.slider``) and an iteration slider.

    ``meshes``: name -> (V, F); ``steps``: their :class:`MeshSteps`; ``limits``: name -> the
    cotangent limit (length²). A run past a mesh's limit is drawn clipped to a quarter of its
    diagonal and stopped when it diverges; the read-out says which fraction of its limit each
    mesh gets and what happened.
    """
    import ipywidgets

    step_slider = steps.slider(limits)
    count = ipywidgets.IntSlider(
        value=iterations, min=0, max=max(300, iterations), description="iterations", continuous_update=False
    )
    views = [
        MeshView(
            V,
            F,
            values=np.zeros(len(V)),
            vmin=0.0,
            vmax=0.05,
            width=300,
            height=280,
            title=name,
            label="|displacement| / diagonal",
            description="how far smoothing moved each vertex",
        )
        for name, (V, F) in meshes.items()
    ]
    smoothers = {name: ExplicitSmoother(V, F) for name, (V, F) in meshes.items()}  # M and C once, not per move

    def update(step, iterations):
        lines = []
        for view, (name, (V, F)) in zip(views, meshes.items()):
            tau, limit = steps.at(name, step), limits[name]
            P, caught = mesh_warnings(smoothers[name].smooth, tau, iterations, on_failure="stop", progress=False)
            fate = (
                "diverged, stopped at the last finite iterate"
                if any("diverged" in w for w in caught)
                else ("past the limit: the top mode grows" if tau >= limit else "stable")
            )
            moved = np.linalg.norm(P - V, axis=1) / bounding_box_diagonal(V)
            view.update(
                V=clipped(P, V),
                values=moved,
                description=f"{iterations} steps of {tau / limit:.3g} x the "
                f"limit: {fate}; moved up to {moved.max():.2g} of the diagonal",
            )
            lines.append(f"{name}: tau = {tau:.3g} = {tau / limit:.3g} x limit, {fate}")
        return lines

    return live(update, {"step": step_slider, "iterations": count}, views)  # three meshes: three cameras


def implicit_explorer(V, F, steps, name, iterations, limit):
    """Notebook 06's mesh ``name`` under a step slider from STEP / 100 to 10 STEP, an iteration
    slider, the volume switch (closed meshes only) and the operator, fixed (built once) or rebuilt every step.

    The step slider's positions are factorised ahead (13 of them, or 4 above ``LARGE_MESH`` vertices, said in a
    note); ``limit`` is the mesh's explicit limit, for the read-out. The view keeps the input's framing until the
    result is smaller than a quarter of the input or leaves the frame; then it is drawn scaled (``fit``).
    """
    import ipywidgets

    grid = 0.25 if len(V) <= LARGE_MESH else 1.0  # slider positions: the step x 10^(grid k)
    if len(V) > LARGE_MESH:
        note(
            "{name} has {n} vertices: the step slider gets 4 positions (STEP / 100 to 10 STEP, a decade apart) "
            "instead of 13, each a factorisation prepared now.",
            name=name.upper(),
            n=len(V),
        )
    value = steps.values[name]
    # up to 10 STEP, not 100 STEP: 50 steps of that leave a needle too thin to draw
    step_slider = log_slider(value, value / 100, value * 10, step_label(steps.unit), grid)
    positions = log_positions(step_slider)

    def prepared(step):  # the slider position nearest to ``step``, as an absolute step
        return steps.absolute(name, positions[np.argmin(np.abs(np.log10(positions / step)))])

    # while nbgrader grades nobody moves the slider: only its starting position is prepared
    taus = [prepared(step_slider.value)] if graded() else [steps.absolute(name, s) for s in positions]
    smoother = ImplicitSmoother(V, F).prepare(taus, iterations)
    closed = len(boundary_vertices(F, len(V))) == 0
    vol0, diag = enclosed_volume(V, F), bounding_box_diagonal(V)
    controls = {
        "step": step_slider,
        "iterations": ipywidgets.IntSlider(
            value=iterations, min=0, max=max(50, iterations), description="iterations", continuous_update=False
        ),
        "keep_volume": ipywidgets.Checkbox(value=False, description="keep volume", disabled=not closed),
        "operator": ipywidgets.ToggleButtons(options=["fixed", "rebuilt"], value="fixed", description="operator"),
    }
    view = MeshView(
        V,
        F,
        values=np.zeros(len(V)),
        vmin=0.0,
        vmax=0.05,
        title="implicit smoothing",
        fit=True,
        label="|displacement| / diagonal",
        description="how far smoothing moved each vertex; sharp edges move most",
    )

    def update(step, iterations, keep_volume, operator):
        tau = prepared(step)
        if operator == "fixed":
            P = smoother.smooth(tau, iterations, keep_volume=keep_volume, progress=False)
        else:
            P = implicit_smoothing(
                V, F, tau, iterations, rebuild=True, keep_volume=keep_volume, on_failure="stop", progress=False
            )
        volume = f"volume {enclosed_volume(P, F) / vol0:.4f} of the input" if closed else "an open mesh"
        view.update(
            V=P,
            values=np.linalg.norm(P - V, axis=1) / diag,
            description=f"{iterations} {operator}-operator steps of tau = {tau:.3g}; {volume}",
        )
        return f"tau = {tau:.3g} ({tau / limit:.3g} x the explicit limit); {volume}"

    knobs = live(update, controls, view)
    knobs.view, knobs.positions, knobs.value = view, positions, value  # for a test that walks every position
    return knobs
