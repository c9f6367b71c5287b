"""Load time of geomlib.load_mesh against trimesh on a ~500k-vertex OBJ.

    python benchmarks/bench_load.py [--vertices 500000] [--repeats 5]

Writes a latitude-longitude sphere (two poles and rings of 1000 vertices,
about 2 triangles per vertex) with ``save_mesh`` into a temporary folder,
then times, alternating so that both see the same machine load:

* ``load_mesh(path)``: parse, validation at the door and the ``check_mesh``
  scan behind its single warning (everything a user pays for);
* ``trimesh.load(path, process=False)``: trimesh's OBJ reader, no processing.

Prints the medians and their ratio. Goal: load_mesh at most 1.5x trimesh.
Also prints where load_mesh spends its time (parse, check_mesh) and checks
that both readers return the same vertices and faces.
"""

import argparse
import statistics
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import trimesh  # noqa: E402

from geomlib import check_mesh, load_mesh, save_mesh  # noqa: E402
from geomlib.mesh.io import parse_obj  # noqa: E402


def latlong_sphere(n_target, n_lon=1000):
    """Unit sphere: north pole, rings of n_lon vertices, south pole; faces CCW from outside."""
    rings = max(2, round((n_target - 2) / n_lon))
    theta = np.arange(1, rings + 1) * np.pi / (rings + 1)  # polar angle of each ring
    phi = np.arange(n_lon) * 2 * np.pi / n_lon
    T, P = np.meshgrid(theta, phi, indexing="ij")
    ring_pts = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], -1).reshape(-1, 3)
    V = np.vstack([[0.0, 0.0, 1.0], ring_pts, [0.0, 0.0, -1.0]])
    south = len(V) - 1
    j = np.arange(n_lon)
    jn = (j + 1) % n_lon
    faces = [np.stack([np.zeros(n_lon, np.int64), 1 + j, 1 + jn], 1)]  # north cap
    r = np.arange(rings - 1)[:, None]
    a = 1 + r * n_lon + j
    b = 1 + (r + 1) * n_lon + j
    c = 1 + (r + 1) * n_lon + jn
    d = 1 + r * n_lon + jn
    faces += [np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)]
    last = 1 + (rings - 1) * n_lon
    faces.append(np.stack([last + j, np.full(n_lon, south), last + jn], 1))  # south cap
    return V, np.concatenate(faces).astype(np.int64)


def median_time(fn, repeats):
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times), times


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--vertices", type=int, default=500_000)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()

    V, F = latlong_sphere(args.vertices)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "sphere.obj"
        t = time.perf_counter()
        save_mesh(path, V, F)
        t_save = time.perf_counter() - t
        size_mb = path.stat().st_size / 1e6
        print(f"mesh: {len(V)} vertices, {len(F)} faces; OBJ {size_mb:.1f} MB written by save_mesh in {t_save:.2f} s")

        with warnings.catch_warnings():
            warnings.simplefilter("error")  # a clean sphere: no warning expected
            V1, F1 = load_mesh(path)
        m = trimesh.load(path, process=False)
        same = np.array_equal(V1, V) and np.array_equal(F1, F)
        same_tm = np.array_equal(V1, m.vertices) and np.array_equal(F1, m.faces)
        print(f"load_mesh returns the saved arrays exactly: {same}; same as trimesh: {same_tm}")

        ours, trim = [], []
        for _ in range(args.repeats):  # alternate, so both see the same machine load
            ours.append(median_time(lambda: load_mesh(path), 1)[0])
            trim.append(median_time(lambda: trimesh.load(path, process=False), 1)[0])
        data = path.read_bytes()
        t_parse, _ = median_time(lambda: parse_obj(data, str(path)), args.repeats)
        t_check, _ = median_time(lambda: check_mesh(V1, F1), args.repeats)

    mo, mt = statistics.median(ours), statistics.median(trim)
    print(f"load_mesh (parse + validation + check_mesh): median {mo:.3f} s  {[round(x, 3) for x in ours]}")
    print(f"trimesh.load(process=False):                 median {mt:.3f} s  {[round(x, 3) for x in trim]}")
    print(f"  of which parse + validation {t_parse:.3f} s, check_mesh {t_check:.3f} s (medians)")
    ratio = mo / mt
    print(f"ratio load_mesh / trimesh = {ratio:.2f}  (goal <= 1.5: {'met' if ratio <= 1.5 else 'MISSED'})")


if __name__ == "__main__":
    main()
