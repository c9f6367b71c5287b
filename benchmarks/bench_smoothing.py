#!/usr/bin/env python
"""Speed of implicit smoothing with a reused factorisation, as a ratio to spsolve.

Run from the repository root:

    python benchmarks/bench_smoothing.py                 # 40k, 160k, 655k vertices + slider
    python benchmarks/bench_smoothing.py --levels 6 7    # only 40k and 160k
    python benchmarks/bench_smoothing.py --no-slider

What is timed (wall clock, the same run, alternating, best of ``--repeat``):

* ``implicit_smoothing(V, F, step, 10)`` with the operator kept fixed (cotan
  weights, barycentric areas): the operator is built once, ``M - step C`` is
  factorised once (scipy ``splu``) and the factorisation solves the 10
  iterations.
* the baseline: the same operator built once (``geomlib.laplacian``), then
  ``scipy.sparse.linalg.spsolve(M - step C, M P)`` called every iteration, 10
  times, as a straightforward implementation does.
* optionally (``--cg``) ``solver="cg"``: warm-started Jacobi-preconditioned CG.

The meshes are icospheres (levels 6, 7, 8: 40,962, 163,842 and 655,362
vertices) with seeded Gaussian noise of 0.2 mean edge lengths along the normal;
the step is 10 mean edge lengths squared (scale-free value 10). The results of
ours and the baseline are compared (max difference printed). Target: ratio at
most 0.2 at 160k vertices.

Slider: the recomputation behind a step / iterations slider of notebook 06 on a
25,000-vertex torus (200 x 125 sections), and on the course's 25,193-vertex
armadillo when ``../shared/meshes`` is present: ``ImplicitSmoother.smooth(step,
10)`` followed by ``MeshView.update(V=...)`` (its buffer packing and normals; no
browser attached). Printed: a step value seen before (factorisation cached) and
a new step value (one factorisation, then the solves). Target: 150 ms.
"""

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import scipy.sparse.linalg as sla

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

ITERATIONS = 10
STEP_SCALE_FREE = 10.0


def noisy_icosphere(level, seed=0):
    import trimesh

    m = trimesh.creation.icosphere(subdivisions=level)
    V, F = np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)
    edge = np.linalg.norm(V[F[:, 0]] - V[F[:, 1]], axis=1).mean()
    rng = np.random.default_rng(seed)
    V = V + (0.2 * edge * rng.standard_normal(len(V)))[:, None] * V  # along the normal
    return V, F, edge


def baseline(V, F, step, iterations):
    from geomlib import laplacian

    M, C = laplacian(V, F)
    A = (M - step * C).tocsc()
    P = V.copy()
    for _ in range(iterations):
        P = sla.spsolve(A, M @ P)
    return P


def ours(V, F, step, iterations, solver="lu"):
    from geomlib import implicit_smoothing

    return implicit_smoothing(V, F, step, iterations, solver=solver, progress=False)


def timed(fn, *args, **kw):
    t = time.perf_counter()
    out = fn(*args, **kw)
    return time.perf_counter() - t, out


def bench_sizes(levels, repeat, cg):
    rows = []
    for level in levels:
        V, F, edge = noisy_icosphere(level)
        step = STEP_SCALE_FREE * edge**2
        best = {"ours": np.inf, "spsolve": np.inf, "cg": np.inf}
        for r in range(repeat):
            t, P_ours = timed(ours, V, F, step, ITERATIONS)
            best["ours"] = min(best["ours"], t)
            t, P_base = timed(baseline, V, F, step, ITERATIONS)
            best["spsolve"] = min(best["spsolve"], t)
            if cg:
                t, P_cg = timed(ours, V, F, step, ITERATIONS, solver="cg")
                best["cg"] = min(best["cg"], t)
        diff = np.abs(P_ours - P_base).max() / edge
        line = (f"{len(V):>8,d} vertices  ours {best['ours']:8.2f} s  spsolve x{ITERATIONS} "
                f"{best['spsolve']:8.2f} s  ratio {best['ours'] / best['spsolve']:.3f}  "
                f"max diff {diff:.1e} edge lengths")
        if cg:
            line += f"  | cg {best['cg']:.2f} s ratio {best['cg'] / best['spsolve']:.3f}"
        print(line, flush=True)
        rows.append((len(V), best))
    return rows


def slider_meshes():
    import trimesh

    m = trimesh.creation.torus(major_radius=1.0, minor_radius=0.35, major_sections=200,
                               minor_sections=125)
    yield "torus", np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)
    course = ROOT.parent / "shared" / "meshes" / "decomposition" / "armadillo.obj"
    if course.exists():
        from geomlib import load_mesh

        V, F = load_mesh(course)
        yield "armadillo (course)", V, F


def bench_slider(repeat):
    from geomlib import ImplicitSmoother
    from geomlib.viewer import MeshView

    for name, V, F in slider_meshes():
        edge = np.linalg.norm(V[F[:, 0]] - V[F[:, 1]], axis=1).mean()
        t0 = time.perf_counter()
        smoother = ImplicitSmoother(V, F)
        setup = time.perf_counter() - t0
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            view = MeshView(V, F)
        steps = [s * edge**2 for s in (0.5, 2.0, 8.0, 32.0, 128.0)]
        cold, warm = [], []
        for s in steps:  # first visit of each step value: factorise, then solve
            t = time.perf_counter()
            view.update(V=smoother.smooth(s, ITERATIONS))
            cold.append(time.perf_counter() - t)
        for _ in range(repeat):
            for s in steps:  # slider moved back to a value seen before
                t = time.perf_counter()
                view.update(V=smoother.smooth(s, ITERATIONS))
                warm.append(time.perf_counter() - t)
        print(f"slider, {name} ({len(V):,d} vertices, {ITERATIONS} iterations): operator set-up "
              f"{setup * 1e3:.0f} ms once; step seen before median {np.median(warm) * 1e3:.0f} ms "
              f"(max {max(warm) * 1e3:.0f}); new step median {np.median(cold) * 1e3:.0f} ms "
              f"(max {max(cold) * 1e3:.0f}); target 150 ms", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--levels", type=int, nargs="+", default=[6, 7, 8])
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--cg", action="store_true", help="also time solver='cg'")
    parser.add_argument("--no-slider", action="store_true")
    args = parser.parse_args()
    print(f"implicit smoothing, {ITERATIONS} iterations, operator fixed, step = "
          f"{STEP_SCALE_FREE:g} mean edge length^2; ratio = ours / spsolve every iteration")
    bench_sizes(args.levels, args.repeat, args.cg)
    if not args.no_slider:
        bench_slider(max(args.repeat, 3))


if __name__ == "__main__":
    main()
