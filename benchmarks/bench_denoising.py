#!/usr/bin/env python3
"""Speed of the denoising evaluation (notebook 07 and its appendix 07a): the sweep and the metrics.

    python benchmarks/bench_denoising.py [--repeats 3]

Prints, on the meshes the notebook uses (geomlib/meshes/sphere.obj and geomlib/meshes/cad_part.obj):

* the full sweep of notebook 07a (5 noise levels x 4 schemes x 4 steps x 9
  iteration counts per mesh, one run per setting through the smoothing
  callback, implicit factorised once per step) against the 60 s budget;
* the same sweep done the obvious way for one noise level (one smoothing call
  per iteration count, the function forms of the metrics), as the reference
  measured in the same run: the ratio says what the one-run-per-setting design buys;
* the metrics: ``MeshComparison.evaluate`` against ``denoising_metrics`` (which
  rebuilds the clean mesh's data at each call), and the exact point-to-surface
  distances of the Hausdorff estimate against ``trimesh.proximity.closest_point``
  and libigl's ``point_mesh_squared_distance`` on the same points.

Times are medians of ``--repeats`` runs (wall clock, this machine); the sweep also
reports its processor time, which other programs running at the same time do not inflate.
"""

import argparse
import statistics
import time
import warnings

import numpy as np
import trimesh

import geomlib
from geomlib.lessons.metrics import MeshComparison, denoising_metrics, point_surface_distance, sample_surface
from geomlib.mesh.errors import MeshWarning
from geomlib.teaching.experiments.sweep import (
    EXPLICIT_FRACTIONS,
    IMPLICIT_STEPS,
    SCHEMES,
    SWEEP_ITERATIONS,
    scale_free_step,
    smoothing_sweep,
)

SIGMAS = (0.001, 0.002, 0.005, 0.01, 0.02)
SEED = 7
BUDGET = 60.0


def median_time(fn, repeats):
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def naive_sweep(V, F, sigma):
    """One smoothing call per (scheme, step, iteration count); function-form metrics."""
    W = geomlib.add_noise(V, F, sigma, seed=SEED)
    for method, weights in SCHEMES:
        values = EXPLICIT_FRACTIONS if method == "explicit" else IMPLICIT_STEPS
        run = geomlib.explicit_smoothing if method == "explicit" else geomlib.implicit_smoothing
        for value in values:
            step = scale_free_step(W, F, method, weights, value)
            for iterations in SWEEP_ITERATIONS:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", MeshWarning)
                    P = run(W, F, step, iterations, weights, progress=False)
                geomlib.vertex_rms(P, V)
                geomlib.normal_angle_error(P, V, F)
                geomlib.area_change(P, V, F)
                geomlib.volume_change(P, V, F)
                geomlib.sharp_edge_error(P, V, F)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()

    meshes = {name: geomlib.load_mesh(geomlib.data_path(name + ".obj")) for name in ("sphere", "cad_part")}
    for name, (V, F) in meshes.items():
        print(f"{name}: {len(V)} vertices, {len(F)} faces")

    # --- the full sweep of the notebook ---------------------------------------
    worker = []  # processor time of the sweeps' worker processes, which process_time does not count

    def full():
        for V, F in meshes.values():
            worker.append(smoothing_sweep(V, F, SIGMAS, SEED, progress=False).worker_seconds)

    c0 = time.process_time()
    t_full = median_time(full, args.repeats)
    cpu_full = (time.process_time() - c0 + sum(worker)) / args.repeats
    settings = sum(
        len(SIGMAS) * (len(EXPLICIT_FRACTIONS) + len(IMPLICIT_STEPS)) * 2 * len(SWEEP_ITERATIONS) for _ in meshes
    )
    print(
        f"\nfull sweep, both meshes ({settings} settings): {t_full:.2f} s wall clock "
        f"= {t_full / BUDGET:.2f} of the {BUDGET:.0f} s budget; {cpu_full:.2f} s of processor time per run "
        f"(wall clock above processor time means other programs shared the cores)"
    )

    # --- reference: the obvious way, one noise level -------------------------
    sigma = SIGMAS[len(SIGMAS) // 2]
    V, F = meshes["cad_part"]
    t_one = median_time(lambda: smoothing_sweep(V, F, [sigma], SEED, progress=False), args.repeats)
    t_naive = median_time(lambda: naive_sweep(V, F, sigma), 1)
    print(
        f"one noise level on cad_part: sweep {t_one:.2f} s, one call per setting {t_naive:.2f} s "
        f"-> ratio {t_naive / t_one:.1f}x"
    )

    # --- metrics --------------------------------------------------------------
    V, F = meshes["sphere"]
    W = geomlib.add_noise(V, F, 0.005, seed=SEED)
    cmp = MeshComparison(V, F)
    cmp.hausdorff(W)  # build the clean side once
    t_eval = median_time(lambda: cmp.evaluate(W, hausdorff=False), 20)
    t_func = median_time(lambda: denoising_metrics(W, V, F), 3)
    t_eval_h = median_time(lambda: cmp.evaluate(W), 5)
    print(
        f"\nmetrics on sphere: evaluate without Hausdorff {1e3 * t_eval:.2f} ms, with {1e3 * t_eval_h:.1f} ms; "
        f"denoising_metrics (rebuilds the clean data) {1e3 * t_func:.1f} ms"
    )

    P = np.vstack([W, sample_surface(W, F, 2 * len(F), seed=1)])
    t_ours = median_time(lambda: point_surface_distance(P, V, F), args.repeats)
    d_ours = point_surface_distance(P, V, F)
    line = f"{len(P)} point-to-surface distances: geomlib {1e3 * t_ours:.0f} ms"
    try:  # trimesh's closest_point needs rtree, which the workbook does not install
        mesh = trimesh.Trimesh(V, F, process=False)
        t_tri = median_time(lambda: trimesh.proximity.closest_point(mesh, P), 1)
        d_tri = trimesh.proximity.closest_point(mesh, P)[1]
        line += (
            f", trimesh {1e3 * t_tri:.0f} ms -> ratio {t_tri / t_ours:.1f}x "
            f"(max difference {np.abs(d_ours - d_tri).max():.1e})"
        )
    except ImportError:
        line += "; trimesh's closest_point needs rtree (not installed)"
    try:
        import igl

        t_igl = median_time(lambda: igl.point_mesh_squared_distance(P, V, F), args.repeats)
        d_igl = np.sqrt(igl.point_mesh_squared_distance(P, V, F)[0])
        line += (
            f"; libigl {1e3 * t_igl:.0f} ms -> ratio {t_igl / t_ours:.2f}x "
            f"(max difference {np.abs(d_ours - d_igl).max():.1e})"
        )
    except ImportError:
        line += "; libigl not installed"
    print(line)
    t_max = median_time(lambda: cmp.hausdorff(W), args.repeats)
    print(f"Hausdorff estimate (both directions, vertices + 2 samples per face each): {1e3 * t_max:.0f} ms")


if __name__ == "__main__":
    main()
