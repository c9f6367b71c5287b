#!/usr/bin/env python3
"""Every notebook on a reader's 200k-vertex mesh: wall time against the 90-second budget.

    python benchmarks/bench_large_mesh.py [--vertices 200000] [--only 04 07]

Builds three meshes of at least ``--vertices`` vertices in a temporary folder,
as a reader would bring them:

* ``scan``: the shipped creature refined until its edges are short enough
  (irregular triangles of a scan, closed, genus 0), with noise of 0.17 mean edge lengths (as the shipped
  cad_part_noisy.obj has) for the smoothing notebooks' ``PART``;
* ``plane``: an open square grid with the same noise (the ``PLANE`` of 05 and 06);
* ``cad``: the shipped CAD part built again by ``tools/make_meshes.py`` with a
  shorter target edge (flat faces meeting at exact sharp edges: ``CAD_MESH`` of 07).

Each notebook then runs top to bottom in a fresh kernel, with every mesh
parameter pointing at these files and every other parameter at its default, and
with an empty eigenbasis cache. For each notebook the script prints the wall
time against the budget of the issue (90 s on 2 cores; 180 s before issue 25), the slowest cells, and
each cell over ``geomlib.numerics.progress.SECONDS`` that showed no progress bar.
"""

import argparse
import sys
import tempfile
from datetime import datetime
from pathlib import Path

import numpy as np
import trimesh

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "tests"), str(ROOT / "tools")]

import make_meshes  # noqa: E402
from notebook_runner import run_notebook  # noqa: E402

import geomlib  # noqa: E402
from geomlib.numerics import progress  # noqa: E402

BUDGET = 90.0
NOISE = 0.17  # mean edge lengths: the noise of the shipped cad_part_noisy.obj against cad_part.obj


def refined(V, F, n):
    """(V, F) with every edge split until the mesh has at least n vertices."""
    ell = geomlib.mesh.geometry.mean_edge_length(V, F)
    lo, hi = 0.05, 1.0  # max edge as a fraction of the mean edge length
    for _ in range(12):
        mid = 0.5 * (lo + hi)
        W, G = trimesh.remesh.subdivide_to_size(V, F, max_edge=mid * ell)
        lo, hi = (mid, hi) if len(W) >= n else (lo, mid)
    return trimesh.remesh.subdivide_to_size(V, F, max_edge=lo * ell)


def noisy(V, F, seed):
    """V with Gaussian noise of NOISE mean edge lengths (standard deviation per coordinate)."""
    sigma = NOISE * geomlib.mesh.geometry.mean_edge_length(V, F) / geomlib.mesh.geometry.bounding_box_diagonal(V)
    return geomlib.add_noise(V, F, sigma, seed=seed)


def build_meshes(folder, n):
    V, F = geomlib.load_mesh(geomlib.data_path("creature.obj"))
    V, F = refined(V, F, n)
    geomlib.save_mesh(folder / "scan.obj", V, F)
    geomlib.save_mesh(folder / "scan_noisy.obj", noisy(V, F, seed=1), F)
    grid = geomlib.teaching.shapes.surfaces.plane(n=int(np.ceil(np.sqrt(n))), size=2.0)
    geomlib.save_mesh(folder / "plane_noisy.obj", noisy(grid.V, grid.F, seed=2), grid.F)
    shipped = len(geomlib.load_mesh(geomlib.data_path("cad_part.obj"))[0])
    make_meshes.CAD_EDGE *= np.sqrt(shipped / (1.05 * n))  # vertices grow as 1 / edge^2
    geomlib.save_mesh(folder / "cad.obj", *make_meshes.cad_part())
    return {name: str(folder / f"{name}.obj") for name in ("scan", "scan_noisy", "plane_noisy", "cad")}


def parameters(paths):
    return {
        "00": {"MESH": paths["scan"]},
        "01": {"MESH": paths["scan"]},
        "02": {"MESH": paths["scan"]},
        "03": {"MESH": paths["scan"]},
        "04": {"MESH": paths["scan"], "UP": "y"},
        "05": {"PLANE": paths["plane_noisy"], "PART": paths["scan_noisy"]},
        "06": {"PLANE": paths["plane_noisy"], "PART": paths["scan_noisy"], "SPHERE": paths["scan"]},
        "07": {"SMOOTH_MESH": paths["scan"], "CAD_MESH": paths["cad"]},
    }


def cell_seconds(cell):
    times = cell.get("metadata", {}).get("execution", {})
    start, end = times.get("iopub.execute_input"), times.get("shell.execute_reply")
    if not (start and end):
        return 0.0
    parse = lambda s: datetime.fromisoformat(s.replace("Z", "+00:00"))
    return (parse(end) - parse(start)).total_seconds()


def showed_progress(cell):
    """Whether the cell displayed a tqdm bar (as a widget or as text: both carry "NN%|")."""
    for out in cell.get("outputs", []):
        text = out.get("data", {}).get("text/plain", "") if "data" in out else out.get("text", "")
        if "%|" in ("".join(text) if isinstance(text, list) else text):
            return True
    return False


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vertices", type=int, default=200_000)
    parser.add_argument("--only", nargs="*", help="notebook numbers, e.g. 04 07")
    parser.add_argument("--top", type=int, default=5, help="how many of the slowest cells to list")
    args = parser.parse_args()
    names = {p.name[:2]: p.name for p in sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))}
    with tempfile.TemporaryDirectory() as tmp:
        paths = build_meshes(Path(tmp), args.vertices)
        sizes = {k: len(geomlib.load_mesh(p)[0]) for k, p in paths.items()}
        print("meshes:", ", ".join(f"{k} {v} vertices" for k, v in sizes.items()))
        failed = []
        for number, values in parameters(paths).items():
            if args.only and number not in args.only:
                continue
            run = run_notebook(names[number], timeout=3600, **values)
            verdict = "within" if run.seconds <= BUDGET and not run.error else "OVER" if not run.error else "RAISED"
            print(
                f"\n{names[number]}: {run.seconds:.0f} s ({verdict} the {BUDGET:.0f} s budget), {len(run.notes)} notes"
            )
            if run.error:
                print(run.error[-2000:])
            code = [(cell_seconds(c), i, c) for i, c in enumerate(run.notebook.cells) if c.cell_type == "code"]
            for seconds, i, cell in sorted(code, key=lambda t: -t[0])[: args.top]:
                bar = "" if seconds <= progress.SECONDS or showed_progress(cell) else "  (no progress bar)"
                first = cell.source.strip().splitlines()[0][:70] if cell.source.strip() else ""
                print(f"  cell {i:3d} {seconds:7.1f} s  {first}{bar}")
            if run.error or run.seconds > BUDGET:
                failed.append(number)
        print("\nover budget or raised:", ", ".join(failed) or "none")
        return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
