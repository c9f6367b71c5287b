#!/usr/bin/env python3
"""Run All of every notebook: kernel time against the goal, and the slowest cells.

    python benchmarks/bench_run_all.py [--only 03 07] [--top 5] [--json run.json]

Each notebook runs top to bottom with nbclient in a fresh kernel, with its
default parameters and an empty eigenbasis cache (``tests/notebook_runner.py``).
The kernel time is the sum of the cells' execution times (what a reader waits
for after pressing Run All, kernel start-up left out); the goal of the issue is
at most 5 s for notebooks 00-06 and 8 s for 07 on a quiet 2-core machine. The
load average at the start is printed with the figures, since a busy machine
slows every cell alike.
"""

import argparse
import json
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "tests"), str(ROOT / "benchmarks")]

from bench_large_mesh import cell_seconds  # noqa: E402
from notebook_runner import run_notebook  # noqa: E402

GOAL = {"07": 8.0}  # seconds of kernel time; every other notebook 5 s
DEFAULT_GOAL = 5.0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="*", help="notebook numbers, e.g. 03 07")
    parser.add_argument("--top", type=int, default=5, help="how many of the slowest cells to list")
    parser.add_argument("--json", help="save the run (per notebook: kernel time, wall time, slowest cells)")
    args = parser.parse_args()
    names = {p.name[:2]: p.name for p in sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))}
    load = os.getloadavg()[0]
    print(f"load average at the start: {load:.2f}")
    saved, failed = {"load_average": load, "notebooks": {}}, []
    for number, name in names.items():
        if args.only and number not in args.only:
            continue
        run = run_notebook(name, timeout=1800)
        code = [(cell_seconds(c), i, c) for i, c in enumerate(run.notebook.cells) if c.cell_type == "code"]
        kernel = sum(t for t, _, _ in code)
        goal = GOAL.get(number, DEFAULT_GOAL)
        verdict = "RAISED" if run.error else "within" if kernel <= goal else "OVER"
        print(f"\n{name}: {kernel:.1f} s kernel ({verdict} the {goal:.0f} s goal), {run.seconds:.1f} s wall")
        if run.error:
            print(run.error[-2000:])
        slowest = []
        for seconds, i, cell in sorted(code, key=lambda t: -t[0])[: args.top]:
            first = cell.source.strip().splitlines()[0][:70] if cell.source.strip() else ""
            print(f"  cell {i:3d} {seconds:6.2f} s  {first}")
            slowest.append({"cell": i, "seconds": round(seconds, 3), "source": first})
        saved["notebooks"][number] = {
            "kernel": round(kernel, 3),
            "wall": round(run.seconds, 3),
            "goal": goal,
            "slowest": slowest,
        }
        if run.error or kernel > goal:
            failed.append(number)
    print("\nover the goal or raised:", ", ".join(failed) or "none")
    if args.json:
        Path(args.json).write_text(json.dumps(saved, indent=1) + "\n")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
