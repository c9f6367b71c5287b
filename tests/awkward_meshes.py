"""Awkward meshes as readers bring them, written to files for the notebook runs.

Each function writes one file into ``folder`` and returns its path:

* ``scan_with_holes``: a lumpy closed shape with three holes cut out and 12
  vertices that no face uses (as scanners and decimators leave them), written
  the way a Windows tool writes OBJ: byte-order mark, CRLF line ends, a
  material library, groups, and vertex colours after the coordinates;
* ``two_components``: two spheres in one file;
* ``cad_part``: the shipped CAD part (flat faces, sharp edges), without noise;
* ``y_up_millimetres``: the shipped sphere rotated to y-up and scaled to
  millimetres (radius 1000 mm).
"""

import numpy as np

from geomlib import data_path, load_mesh, save_mesh, surfaces


def _write_windows_obj(path, V, F, colours):
    lines = ["# exported by a scanner tool", "mtllib scan.mtl", "o scan", "g body"]
    lines += [f"v {x:.9g} {y:.9g} {z:.9g} {r:.3f} {g:.3f} {b:.3f}" for (x, y, z), (r, g, b) in zip(V, colours)]
    lines += ["usemtl skin", "s 1"]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in F]
    path.write_bytes(("\ufeff" + "\r\n".join(lines) + "\r\n").encode("utf-8"))
    return path


def scan_with_holes(folder):
    blob = surfaces.sphere(1.0, subdivisions=4)
    rng = np.random.default_rng(11)
    V = blob.V * (1 + 0.08 * np.sin(3 * blob.V[:, [0]]) * np.cos(2 * blob.V[:, [1]]))
    centre_dirs = np.array([[0, 0, 1.0], [1, 0, 0], [0, -0.6, -0.8]])
    centres = V[blob.F].mean(axis=1)
    centres /= np.linalg.norm(centres, axis=1, keepdims=True)
    cut = (centres @ centre_dirs.T > 0.97).any(axis=1)
    F = blob.F[~cut]
    used = np.unique(F)
    unused = np.setdiff1d(np.arange(len(V)), used)[:12]
    keep = np.concatenate([used, unused])  # 12 vertices that no face uses stay in the file
    remap = np.full(len(V), -1)
    remap[keep] = np.arange(len(keep))
    colours = rng.uniform(0.3, 0.9, size=(len(keep), 3))
    return _write_windows_obj(folder / "scan_with_holes.obj", V[keep], remap[F], colours)


def two_components(folder):
    a = surfaces.sphere(1.0, subdivisions=3)
    V = np.vstack([a.V, a.V * 0.5 + [3.0, 0, 0]])
    F = np.vstack([a.F, a.F + len(a.V)])
    path = folder / "two_spheres.obj"
    save_mesh(path, V, F)
    return path


def cad_part(folder):
    return data_path("cad_part.obj")


def y_up_millimetres(folder):
    V, F = load_mesh(data_path("sphere.obj"))
    V = 1000.0 * V[:, [0, 2, 1]] * [1, 1, -1]  # z-up -> y-up (a right-handed rotation), metres -> mm
    path = folder / "sphere_y_up_mm.obj"
    save_mesh(path, V, F)
    return path


ALL = {
    "scan_with_holes": scan_with_holes,
    "two_components": two_components,
    "cad_part": cad_part,
    "y_up_millimetres": y_up_millimetres,
}


def make_all(folder):
    """Write every awkward mesh into ``folder``; return {name: path}."""
    return {name: make(folder) for name, make in ALL.items()}
