"""geomlib: the helper package of the Laplacian mesh-processing workbook.

Conventions that hold everywhere (see notebooks/00_getting_started.ipynb):

* ``V`` is an (n, 3) float64 array of vertex positions, ``F`` an (m, 3) int64
  array of triangles (0-based vertex indices, counter-clockwise seen from
  outside, so face normals point outwards on a closed mesh).
* The Laplace-Beltrami operator is ``Delta = M^-1 C`` with ``C`` symmetric,
  negative semidefinite, rows summing to zero, off-diagonal
  ``1/2 (cot alpha_ij + cot beta_ij)`` (cotan) or 1 (uniform), and ``M``
  diagonal (vertex areas, or valences for the uniform operator).
  With this sign ``Delta x = -2 H n`` where ``n`` is the outward unit normal,
  so ``H > 0`` on a sphere.
* Lengths are in the mesh's own units; curvatures are in 1/length (H) and
  1/length^2 (K); areas in length^2.

Public names are imported lazily so that ``import geomlib`` stays fast; the
symbolic module is ``geomlib.symbolic`` and the exercise checks are
``geomlib.check`` (both also importable by those names).

Layers (one sub-package each; ``tests/test_layers.py`` holds the rule):

* ``geomlib.mesh``: the mesh core (errors, validation, topology, geometry, I/O);
* ``geomlib.numerics``: numerical machinery (factorisations, eigensolvers, caches, progress);
* ``geomlib.lessons``: the formulas the notebooks derive;
* ``geomlib.teaching``: exact shapes, experiment drivers, display, figures, exercise checks, notebook helpers;
* ``geomlib.course``: grading a class, above the teaching aids (no notebook imports it).

The mesh core imports no other layer; numerics imports only the mesh core;
lessons import the mesh core and numerics; teaching aids import those three.
Importing geomlib sets up no display: a notebook's set-up cell calls :func:`setup_display`.
"""

import sys
from importlib import import_module
from importlib.util import spec_from_loader

from .mesh.errors import MeshError, MeshWarning  # noqa: F401  (public names, listed in __all__)

__version__ = "0.1.0"

# public name -> module that defines it (imported on first use)
_EXPORTS = {
    # input / output and checks
    "load_mesh": "mesh.io",
    "save_mesh": "mesh.io",
    "check_mesh": "mesh.report",
    "MeshReport": "mesh.report",
    # topology
    "edges": "mesh.topology",
    "boundary_edges": "mesh.topology",
    "boundary_vertices": "mesh.topology",
    "boundary_loops": "mesh.topology",
    "valence": "mesh.topology",
    "one_ring": "mesh.topology",
    "euler_characteristic": "mesh.topology",
    "connected_components": "mesh.topology",
    "vertex_face_adjacency": "mesh.topology",
    # Laplacians and curvature
    "laplacian": "lessons.laplace",
    "vertex_areas": "lessons.laplace",
    "mean_curvature": "lessons.curvature",
    "gaussian_curvature": "lessons.curvature",
    "principal_curvatures": "lessons.curvature",
    "discrete_principal_curvatures": "lessons.curvature",
    "vertex_normals": "mesh.geometry",
    "mean_edge_length": "mesh.geometry",
    "surface_area": "mesh.geometry",
    "enclosed_volume": "mesh.geometry",
    # spectral
    "eigenbasis": "lessons.spectral",
    "spectral_reconstruction": "lessons.spectral",
    "spectral_basis": "lessons.spectral",
    "SpectralBasis": "lessons.spectral",
    "spectral_cache_dir": "lessons.spectral",
    "clear_spectral_cache": "lessons.spectral",
    # smoothing
    "explicit_smoothing": "lessons.smoothing",
    "implicit_smoothing": "lessons.smoothing",
    "explicit_step_limit": "lessons.smoothing",
    "highest_frequency_mode": "lessons.smoothing",
    "mode_factor": "lessons.filters",
    "plot_mode_factors": "teaching.figures.filter_plots",
    "fixed_point": "lessons.smoothing",
    "volume_rescaled": "lessons.smoothing",
    "ExplicitSmoother": "lessons.smoothing",
    "ImplicitSmoother": "lessons.smoothing",
    "taubin_smoothing": "lessons.smoothing",
    # noise and evaluation
    "add_noise": "lessons.noise",
    "denoising_experiment": "lessons.noise",
    "denoising_spread": "lessons.noise",
    "denoising_sweep": "lessons.noise",
    "bounding_box_diagonal": "mesh.geometry",
    "vertex_rms": "lessons.metrics",
    "hausdorff_distance": "lessons.metrics",
    "face_normal_angles": "lessons.metrics",
    "normal_angle_error": "lessons.metrics",
    "area_change": "lessons.metrics",
    "volume_change": "lessons.metrics",
    "dihedral_angles": "lessons.metrics",
    "sharp_edges": "lessons.metrics",
    "sharp_edge_error": "lessons.metrics",
    "denoising_metrics": "lessons.metrics",
    "MeshComparison": "lessons.metrics",
    "point_surface_distance": "lessons.metrics",
    "smoothing_sweep": "teaching.experiments.sweep",
    # the display: 3D views in Colab, still pictures where no browser draws them, the plots' colours
    "setup_display": "teaching.display.viewer",
    # progress over the notebooks' loops over meshes
    "loop": "numerics.progress",
    "LARGE_MESH": "numerics.progress",
}

# modules reachable by their short public names (geomlib.symbolic, geomlib.check, ...)
_MODULES = {
    "symbolic": "lessons.symbolic",
    "check": "teaching.check",
    "surfaces": "teaching.shapes.surfaces",
    "viewer": "teaching.display.viewer",
    "metrics": "lessons.metrics",
    "sweep": "teaching.experiments.sweep",
}


class _ShortNames:
    """Lets ``import geomlib.symbolic`` (and the other short names) find the module in its layer.

    The module object is the layer's own, so ``geomlib.symbolic is geomlib.lessons.symbolic``.
    """

    @staticmethod
    def find_spec(name, path=None, target=None):
        short = name.rpartition(".")[2]
        if not name.startswith(__name__ + ".") or name.count(".") != 1 or short not in _MODULES:
            return None
        module = import_module(f".{_MODULES[short]}", __name__)
        return spec_from_loader(name, _ShortNames, origin=module.__spec__.origin)

    @staticmethod
    def create_module(spec):
        return import_module(f".{_MODULES[spec.name.rpartition('.')[2]]}", __name__)

    @staticmethod
    def exec_module(module):
        pass


sys.meta_path.append(_ShortNames)

__all__ = sorted(["MeshError", "MeshWarning", "data_path", *_EXPORTS])


def data_path(name=""):
    """Path of a mesh the workbook ships (``geomlib/meshes/NAME``, package data of the wheel).

    ``data_path()`` is the folder itself. Raises MeshError naming the file and
    listing what is there when the mesh does not exist.
    """
    from pathlib import Path

    folder = Path(__file__).resolve().parent / "meshes"
    path = folder / name
    if name and not path.exists():
        have = sorted(p.name for p in folder.glob("*") if p.suffix in (".obj", ".off", ".ply", ".stl"))
        raise MeshError(f"no shipped mesh named {name!r} in geomlib/meshes/; available: {', '.join(have) or 'none'}")
    return path


def __getattr__(name):
    if name in _EXPORTS:
        value = getattr(import_module(f".{_EXPORTS[name]}", __name__), name)
        globals()[name] = value
        return value
    if name in _MODULES:
        return import_module(f".{_MODULES[name]}", __name__)
    raise AttributeError(f"module 'geomlib' has no attribute {name!r}")


def __dir__():
    return __all__
