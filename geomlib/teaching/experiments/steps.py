"""The smoothing step as a reader gives it: its unit, and one step per mesh.

Notebooks 05-07 take the step tau in one of two units (``STEP_UNIT``):

* ``"length^2"``: tau itself, as the assignment gives it (1e-5 on ``fandisk_ns.obj``);
* ``"ell^2"``: tau / ell^2 with ell the mean edge length of the mesh, scale-free:
  one value means a comparable step on meshes of any size.

With uniform weights the Laplacian has no units and tau is a plain number in
either unit. :func:`absolute_step` is the one conversion; :class:`MeshSteps`
holds a notebook's ``STEP``, which is one number for every mesh or a dict by
mesh name (``{"PLANE": 1e-6, "PART": 1e-4}``, the names of the parameters that
hold the meshes), and gives each mesh its tau. :func:`log_slider` is a step
slider on which the value a reader typed is a position.
"""

import numpy as np

from ...mesh.errors import MeshError
from ...mesh.geometry import mean_edge_length

__all__ = ["STEP_UNITS", "absolute_step", "step_label", "log_slider", "log_positions", "MeshSteps"]

#: the units a notebook's STEP_UNIT may name
STEP_UNITS = ("ell^2", "length^2")


def absolute_step(step, unit, V, F, weights="cotan"):
    """The step tau of the smoothing functions for a ``step`` given in ``unit``.

    ``"length^2"``: tau = step. ``"ell^2"``: tau = step * ell^2, ell the mean
    edge length of (V, F), for cotangent weights; uniform weights have no
    units, so there tau = step in either unit.
    """
    if unit not in STEP_UNITS:
        raise MeshError(f"the step unit must be one of {STEP_UNITS}; got {unit!r}")
    if unit == "ell^2" and weights == "cotan":
        return float(step) * mean_edge_length(V, F) ** 2
    return float(step)


def step_label(unit):
    """A slider's label for a step in ``unit``: "τ / ℓ²" or "τ (length²)"."""
    return "τ / ℓ²" if unit == "ell^2" else "τ (length²)"


def log_slider(value, lo, hi, description, grid=0.05):
    """A logarithmic slider at ``value`` whose positions ``value * 10^(grid k)`` reach from ``lo`` to ``hi``.

    ``value`` itself is a position, so the number a reader typed is on the
    slider. It updates when released (``continuous_update=False``): one run per move.
    """
    import ipywidgets

    if not (value > 0 and lo > 0 and hi > 0):
        raise MeshError(f"a logarithmic slider needs positive numbers; got value {value}, range {lo}..{hi}")
    centre = np.log10(value)
    low = centre - grid * np.ceil((centre - np.log10(min(lo, value))) / grid)
    high = centre + grid * np.ceil((np.log10(max(hi, value)) - centre) / grid)
    return ipywidgets.FloatLogSlider(
        value=value,
        base=10,
        min=low,
        max=high,
        step=grid,
        readout_format=".3g",
        description=description,
        continuous_update=False,
    )


def log_positions(slider):
    """Every position of a logarithmic slider, lowest first: ``base ** (min + step k)``."""
    count = int(round((slider.max - slider.min) / slider.step)) + 1
    return slider.base ** (slider.min + slider.step * np.arange(count))


class MeshSteps:
    """The step of every mesh of a notebook, from its ``STEP`` and ``STEP_UNIT``.

    Parameters
    ----------
    step : float > 0, or dict parameter name -> float > 0
        One step for every mesh, or one per mesh keyed by the parameter that
        holds it ("PLANE", "PART"; any case). A mesh the dict leaves out gets
        the smallest step it gives (the safest of them).
    unit : one of :data:`STEP_UNITS`
    meshes : dict name -> (V, F)
        The notebook's meshes by their names in the notebook ("plane", "part").

    Raises
    ------
    MeshError
        An unknown unit, a step that is not a positive number, a dict key that
        names no mesh.
    """

    def __init__(self, step, unit, meshes):
        if unit not in STEP_UNITS:
            raise MeshError(f"STEP_UNIT must be one of {STEP_UNITS}; got {unit!r}")
        self.per_mesh = isinstance(step, dict)
        given = {str(k).lower(): v for k, v in step.items()} if self.per_mesh else {}
        unknown = sorted(set(given) - set(meshes))
        if unknown:
            names = ", ".join(name.upper() for name in meshes)
            raise MeshError(f"STEP names {', '.join(k.upper() for k in unknown)}, which is not a mesh here ({names})")
        values = list(given.values()) if self.per_mesh else [step]
        if not values or not all(isinstance(v, (int, float)) and np.isfinite(v) and v > 0 for v in values):
            raise MeshError(f"STEP must be a number > 0 or a dict of them by mesh; got {step!r}")
        self.unit, self.meshes, self.step = unit, meshes, step
        self.values = {name: float(given.get(name, min(values))) for name in meshes}
        # a slider for every mesh at once shows STEP itself, or with one step per mesh a factor on each
        self.reference = 1.0 if self.per_mesh else float(step)
        self._unit_steps = {}  # name -> the tau of a step of 1 in the unit (ell^2 costs 85 ms at 200k vertices)

    def tau(self, name):
        """The absolute step tau of mesh ``name`` (length^2 with cotangent weights)."""
        return self.absolute(name, self.values[name])

    def absolute(self, name, value):
        """The absolute step of mesh ``name`` for a step ``value`` given in the unit (:func:`absolute_step`).

        The conversion is linear, so the mesh's step of 1 is measured once and scaled
        (a slider callback converts at every move).
        """
        if name not in self._unit_steps:
            V, F = self.meshes[name]
            self._unit_steps[name] = absolute_step(1.0, self.unit, V, F)
        return float(value) * self._unit_steps[name]

    def at(self, name, position):
        """The absolute step of mesh ``name`` at a ``position`` of :meth:`slider`."""
        return self.absolute(name, self.values[name] * position / self.reference)

    def slider(self, limits, below=20.0, above=1.5):
        """A log slider for the step of every mesh, from 1/``below`` of the smallest limit to ``above`` x the largest.

        ``limits`` : dict name -> the mesh's stability limit (length^2). With one
        STEP the slider shows it in its unit; with a dict, a factor on every mesh's step.
        """
        at_limit = [self.reference * limits[name] / self.tau(name) for name in limits]  # positions of the limits
        label = "× STEP" if self.per_mesh else step_label(self.unit)
        return log_slider(self.reference, min(at_limit) / below, max(at_limit) * above, label)

    def describe(self, name):
        """The step of mesh ``name`` as the parameter cell gives it: "STEP = 0.03 ell^2"."""
        return f"STEP = {self.values[name]:g} {self.unit}"

    def __format__(self, spec):
        """STEP's value(s) formatted with ``spec``: "0.03", or "{PLANE: 1e-06, PART: 0.0001}"."""
        if not self.per_mesh:
            return format(self.values[next(iter(self.values))], spec or "g")
        return "{" + ", ".join(f"{name.upper()}: {value:{spec or 'g'}}" for name, value in self.values.items()) + "}"

    def __str__(self):
        return f"STEP = {self:g} {self.unit}"
