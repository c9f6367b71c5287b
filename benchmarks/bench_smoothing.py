#!/usr/bin/env python
"""Speed of implicit smoothing with a reused factorisation, as a ratio to spsolve.

Run from the repository root:

    python benchmarks/bench_smoothing.py                 # 40k, 160k, 655k vertices + slider
    python benchmarks/bench_smoothing.py --levels 6 7    # only 40k and 160k
    python benchmarks/bench_smoothing.py --no-slider

What is timed (wall clock, the same run, alternating, best of ``--repeat``):

* ``implicit_smoothing(V, F, step, 10)`` with the operator kept fixed (cotan
  weights, barycentric areas): the operator is built once, ``M - step C`` is
  factorised once (sparse Cholesky, CHOLMOD through cholespy:
  ``geomlib.numerics.factor``) and the factorisation solves the 10 iterations.
* the baseline: the same operator built once (``geomlib.laplacian``), then
  ``scipy.sparse.linalg.spsolve(M - step C, M P)`` called every iteration, 10
  times, as a straightforward implementation does.
* optionally (``--cg``) ``solver="cg"``: warm-started Jacobi-preconditioned CG.

The meshes are icospheres (levels 6, 7, 8: 40,962, 163,842 and 655,362
vertices) with seeded Gaussian noise of 0.2 mean edge lengths along the normal;
the step is 10 mean edge lengths squared (scale-free value 10). The results of
ours and the baseline are compared (max difference printed). Target: ratio at
most 0.2 at 160k vertices.

Step limit (``--limit``): ``explicit_step_limit`` for cotan and uniform
weights on the 25,000-vertex torus and the 163,842-vertex icosphere, first
call and cached call (what notebook 05's sliders pay), against scipy's
``eigsh(S, k=1, which="LA", tol=1e-8)`` on the same symmetric matrix.

Slider: the callback behind notebook 06's step and iteration sliders on a
25,000-vertex torus (200 x 125 sections), and on the course's 25,193-vertex
armadillo when ``../shared/meshes`` is present: ``ImplicitSmoother.smooth(step,
5)`` followed by ``MeshView.update(V=...)`` (its buffer packing and normals; no
browser attached). As in the notebook, the operator is built and every slider
step value factorised before the sliders are shown (``ImplicitSmoother.prepare``,
and their first 5 iterates computed, timed separately). Printed: moving the
step slider (a look-up), moving the iteration slider one past the prepared
iterates (one solve), returning to a setting seen before, and, for comparison,
a factorised step without prepared iterates (5 solves) and a step value never
factorised. Target: 150 ms.
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
SLIDER_ITERATIONS = 5  # iterations behind each slider setting (notebook 06 starts at 3)
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


def ours(V, F, step, iterations, solver="cholesky"):
    from geomlib import implicit_smoothing

    return implicit_smoothing(V, F, step, iterations, solver=solver, progress=False)


def timed(fn, *args, **kw):
    from geomlib.numerics.factor import forget_factorisations

    forget_factorisations()  # a repeat must factorise again, as the reference does
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
        line = (
            f"{len(V):>8,d} vertices  ours {best['ours']:8.2f} s  spsolve x{ITERATIONS} "
            f"{best['spsolve']:8.2f} s  ratio {best['ours'] / best['spsolve']:.3f}  "
            f"max diff {diff:.1e} edge lengths"
        )
        if cg:
            line += f"  | cg {best['cg']:.2f} s ratio {best['cg'] / best['spsolve']:.3f}"
        print(line, flush=True)
        rows.append((len(V), best))
    return rows


def slider_meshes():
    import trimesh

    m = trimesh.creation.torus(major_radius=1.0, minor_radius=0.35, major_sections=200, minor_sections=125)
    yield "torus", np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)
    course = ROOT.parent / "shared" / "meshes" / "decomposition" / "armadillo.obj"
    if course.exists():
        from geomlib import load_mesh

        V, F = load_mesh(course)
        yield "armadillo (course)", V, F


def bench_slider(repeat):
    """The callback of notebook 06's sliders on a 25k-vertex mesh, timed."""
    from geomlib import ImplicitSmoother
    from geomlib.teaching.display.viewer import MeshView

    slider = 10.0 ** np.arange(-1.0, 3.01, 0.25)  # the notebook's FloatLogSlider positions (step / h^2)
    for name, V, F in slider_meshes():
        h2 = np.linalg.norm(V[F[:, 0]] - V[F[:, 1]], axis=1).mean() ** 2
        steps = slider * h2
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            view = MeshView(V, F)
        t = time.perf_counter()
        smoother = ImplicitSmoother(V, F)
        t_operator = time.perf_counter() - t
        t = time.perf_counter()
        smoother.prepare(steps)
        t_prepare = time.perf_counter() - t
        t = time.perf_counter()
        smoother.prepare(steps, SLIDER_ITERATIONS)
        t_iterates = time.perf_counter() - t

        def callback(step, iterations):
            t = time.perf_counter()
            view.update(V=smoother.smooth(step, iterations, progress=False))
            return time.perf_counter() - t

        rng = np.random.default_rng(0)
        step_moves, iteration_moves, revisits = [], [], []
        for _ in range(repeat):
            for s in rng.permutation(steps)[:6]:
                step_moves.append(callback(s, SLIDER_ITERATIONS))  # iterates prepared
                iteration_moves.append(callback(s, SLIDER_ITERATIONS + 1))  # iteration slider +1
                revisits.append(callback(s, SLIDER_ITERATIONS + 1))  # a setting seen before
            smoother._history.clear()
            smoother.prepare(steps, SLIDER_ITERATIONS)
        unprepared = []
        for s in rng.permutation(steps)[:6]:
            smoother._history.pop((float(s), False), None)  # factorised, iterates not kept
            unprepared.append(callback(s, SLIDER_ITERATIONS))
        fresh = ImplicitSmoother(V, F)
        t = time.perf_counter()
        view.update(V=fresh.smooth(steps[5], SLIDER_ITERATIONS, progress=False))
        t_cold = time.perf_counter() - t

        def ms(x):
            return f"median {np.median(x) * 1e3:.0f} ms (max {np.max(x) * 1e3:.0f})"

        print(
            f"slider, {name}, {len(V):,d} vertices, {SLIDER_ITERATIONS} iterations (target 150 ms):\n"
            f"  outside the callback: operator {t_operator * 1e3:.0f} ms, factorising the "
            f"{len(steps)} slider step values {t_prepare:.2f} s, their first {SLIDER_ITERATIONS} "
            f"iterates {t_iterates:.2f} s\n"
            f"  step slider moved: {ms(step_moves)}\n"
            f"  iteration slider moved one past the prepared iterates: {ms(iteration_moves)}\n"
            f"  setting seen before: {ms(revisits)}\n"
            f"  for comparison: step factorised but iterates not prepared {ms(unprepared)}; "
            f"a step never factorised {t_cold * 1e3:.0f} ms",
            flush=True,
        )


def bench_limit():
    """explicit_step_limit, first and cached call, against ARPACK on the same matrix."""
    import scipy.sparse as sp

    from geomlib import explicit_step_limit, laplacian

    meshes = [next(slider_meshes()), ("icosphere",) + noisy_icosphere(7)[:2]]
    for name, V, F in meshes:
        for weights in ("cotan", "uniform"):
            t_first, limit = timed(explicit_step_limit, V, F, weights, boundary_condition="free")
            t_cached, _ = timed(explicit_step_limit, V, F, weights, boundary_condition="free")
            M, C = laplacian(V, F, weights=weights)
            d = sp.diags(1.0 / np.sqrt(M.diagonal()))
            S = (d @ (-C) @ d).tocsr()
            v0 = np.random.default_rng(0).standard_normal(len(V))
            t_ref, lam = timed(sla.eigsh, S, k=1, which="LA", v0=v0, tol=1e-8)
            print(
                f"step limit, {name} {len(V):,d} vertices, {weights}: first call {t_first:.2f} s, "
                f"cached {t_cached * 1e3:.2f} ms; eigsh {t_ref:.2f} s; ratio {t_first / t_ref:.2f}; "
                f"2 / lam_max agree to {abs(limit * lam[0][0] / 2 - 1):.1e}",
                flush=True,
            )


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--levels", type=int, nargs="+", default=[6, 7, 8])
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--cg", action="store_true", help="also time solver='cg'")
    parser.add_argument("--no-slider", action="store_true")
    parser.add_argument("--limit", action="store_true", help="also time explicit_step_limit")
    args = parser.parse_args()
    print(
        f"implicit smoothing, {ITERATIONS} iterations, operator fixed, step = "
        f"{STEP_SCALE_FREE:g} mean edge length^2; ratio = ours / spsolve every iteration"
    )
    bench_sizes(args.levels, args.repeat, args.cg)
    if not args.no_slider:
        bench_slider(max(args.repeat, 3))
    if args.limit:
        bench_limit()


if __name__ == "__main__":
    main()
