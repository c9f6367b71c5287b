"""Run All of every notebook, as a reader's kernel sees it: time per notebook and its slowest cells.

    python benchmarks/bench_run_all.py                   # every notebook (a few minutes)
    python benchmarks/bench_run_all.py 04 07             # only those
    python benchmarks/bench_run_all.py --json run_all.json

Each notebook runs top to bottom with nbclient's defaults in a fresh kernel
started in the notebooks folder, with ``GEOMLIB_CACHE_DIR`` pointing at an
empty folder (so notebook 04 solves its eigenbasis as on a first visit). The
kernel time of a notebook is the sum of its cells' execution times (from the
kernel's own timestamps, ``execute_input`` to ``execute_reply``); kernel start
and shutdown are reported apart. The goal (issue 25) is at most 5 s for
notebooks 00-06 and 8 s for 07 on 2 cores; the slowest cells are listed so the
next speed-up can aim at them. Timings on a shared machine vary with its load,
which is printed.
"""

import argparse
import json
import os
import sys
import tempfile
import time
from datetime import datetime
from pathlib import Path

import nbformat
from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"
GOAL_S = {"07": 8.0}  # every other notebook: 5 s
DEFAULT_GOAL_S = 5.0


def _seconds(cell):
    timing = cell.get("metadata", {}).get("execution", {})
    start, end = timing.get("iopub.execute_input"), timing.get("shell.execute_reply")
    if not (start and end):
        return 0.0
    parse = lambda stamp: datetime.fromisoformat(stamp.replace("Z", "+00:00"))  # noqa: E731
    return (parse(end) - parse(start)).total_seconds()


def run(path, cache_dir):
    nb = nbformat.read(path, as_version=4)
    os.environ["GEOMLIB_CACHE_DIR"] = str(cache_dir)  # the kernel inherits it
    client = NotebookClient(nb, resources={"metadata": {"path": str(path.parent)}})
    t0 = time.perf_counter()
    client.execute()
    wall = time.perf_counter() - t0
    cells = [
        (i, _seconds(c), "".join(c["source"]).strip().splitlines()[0][:70] if c["source"] else "")
        for i, c in enumerate(nb.cells)
        if c.cell_type == "code"
    ]
    kernel = sum(s for _, s, _ in cells)
    return dict(
        notebook=path.name,
        kernel_s=kernel,
        wall_s=wall,
        start_and_stop_s=wall - kernel,
        goal_s=GOAL_S.get(path.name[:2], DEFAULT_GOAL_S),
        slowest=sorted(cells, key=lambda c: -c[1])[:4],
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("only", nargs="*", help="notebook number prefixes, e.g. 04 07")
    parser.add_argument("--json", type=Path, help="save the results here")
    args = parser.parse_args()
    paths = sorted(p for p in NOTEBOOKS.glob("[0-9][0-9]_*.ipynb") if not args.only or p.name[:2] in args.only)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"{len(paths)} notebooks, {os.cpu_count()} CPUs, load average {load:.1f}", flush=True)
    rows = []
    for path in paths:
        with tempfile.TemporaryDirectory() as cache_dir:
            row = run(path, cache_dir)
        rows.append(row)
        met = "met" if row["kernel_s"] <= row["goal_s"] else "NOT met"
        print(
            f"{row['notebook']:<40s} kernel {row['kernel_s']:6.1f} s (goal <= {row['goal_s']:g} s, {met}); "
            f"kernel start and stop {row['start_and_stop_s']:.1f} s",
            flush=True,
        )
        for i, s, first in row["slowest"]:
            print(f"    cell {i:3d}  {s:6.2f} s  {first}", flush=True)
    if args.json:
        load_after = os.getloadavg()[0] if hasattr(os, "getloadavg") else None
        args.json.write_text(json.dumps(dict(load_average=[load, load_after], notebooks=rows), indent=1) + "\n")
        print(f"saved {args.json}")
    return 0 if all(r["kernel_s"] <= r["goal_s"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
