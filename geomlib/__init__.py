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
symbolic module is ``geomlib.symbolic``.
"""

from importlib import import_module

from .errors import MeshError, MeshWarning  # noqa: F401  (public names, listed in __all__)

__version__ = "0.1.0"
import_module(".frontends", __name__).enable_colab_widgets()  # Colab draws the 3D views only after this

# public name -> module that defines it (imported on first use)
_EXPORTS = {
    # input / output and checks
    "load_mesh": "io",
    "save_mesh": "io",
    "check_mesh": "report",
    "MeshReport": "report",
    # topology
    "edges": "topology",
    "boundary_edges": "topology",
    "boundary_vertices": "topology",
    "boundary_loops": "topology",
    "valence": "topology",
    "one_ring": "topology",
    "euler_characteristic": "topology",
    "connected_components": "topology",
    "vertex_face_adjacency": "topology",
    # Laplacians and curvature
    "laplacian": "laplace",
    "cotangent_weights": "laplace",
    "vertex_areas": "laplace",
    "mean_curvature": "curvature",
    "gaussian_curvature": "curvature",
    "principal_curvatures": "curvature",
    "vertex_normals": "geometry",
    # spectral
    "eigenbasis": "spectral",
    "spectral_reconstruction": "spectral",
    "spectral_basis": "spectral",
    "SpectralBasis": "spectral",
    "spectral_cache_dir": "spectral",
    "clear_spectral_cache": "spectral",
    # smoothing
    "explicit_smoothing": "smoothing",
    "implicit_smoothing": "smoothing",
    "explicit_step_limit": "smoothing",
    "highest_frequency_mode": "smoothing",
    "fixed_point": "smoothing",
    "ExplicitSmoother": "smoothing",
    "ImplicitSmoother": "smoothing",
    # noise and evaluation
    "add_noise": "noise",
    "bounding_box_diagonal": "geometry",
    "vertex_rms": "metrics",
    "hausdorff_distance": "metrics",
    "face_normal_angles": "metrics",
    "normal_angle_error": "metrics",
    "area_change": "metrics",
    "volume_change": "metrics",
    "dihedral_angles": "metrics",
    "sharp_edges": "metrics",
    "sharp_edge_error": "metrics",
    "denoising_metrics": "metrics",
    "MeshComparison": "metrics",
    "point_surface_distance": "metrics",
    "smoothing_sweep": "sweep",
}

__all__ = sorted(["MeshError", "MeshWarning", "data_path", *_EXPORTS])


def data_path(name=""):
    """Path of a mesh the workbook ships (``meshes/NAME`` in the repository).

    ``data_path()`` is the folder itself. Raises MeshError naming the file and
    listing what is there when the mesh does not exist.
    """
    from pathlib import Path

    folder = Path(__file__).resolve().parent.parent / "meshes"
    path = folder / name
    if name and not path.exists():
        have = sorted(p.name for p in folder.glob("*") if p.suffix in (".obj", ".off", ".ply", ".stl"))
        raise MeshError(f"no shipped mesh named {name!r} in meshes/; available: {', '.join(have) or 'none'}")
    return path


def __getattr__(name):
    if name in _EXPORTS:
        value = getattr(import_module(f".{_EXPORTS[name]}", __name__), name)
        globals()[name] = value
        return value
    if name in ("symbolic", "surfaces", "viewer", "metrics", "sweep"):
        return import_module(f".{name}", __name__)
    raise AttributeError(f"module 'geomlib' has no attribute {name!r}")


def __dir__():
    return __all__
