"""Speed and peak memory of geomlib's Laplacian and Gaussian curvature, as ratios to libigl.

Run from the repository root:

    python benchmarks/bench_laplace.py              # icospheres of 40k, 160k, 655k vertices
    python benchmarks/bench_laplace.py --levels 6 7 --repeat 3

For each size and each operation it prints the best-of-``repeat`` wall time of
geomlib and of libigl (measured in the same run, interleaved), their ratio,
and the peak-memory increase of one call in a fresh subprocess (the peak
resident set size during the call minus the resident size before it, from
/proc/self/status after resetting the high-water mark; this counts libigl's
C++ allocations, which tracemalloc cannot see), with their ratio. Ratios below 1 mean geomlib is
faster / leaner.

Operations:

* ``cotan+M``: ``laplacian(V, F, "cotan", "barycentric")`` against
  ``igl.cotmatrix`` + ``igl.massmatrix(BARYCENTRIC)``.
* ``cotan+Mmixed``: ``area="mixed"`` against ``massmatrix(VORONOI)``.
* ``K``: ``gaussian_curvature(V, F)`` (pointwise, with boundary detection and
  vertex areas) against ``igl.gaussian_curvature`` (integrated deficit only).
* ``K-deficit``: ``gaussian_curvature(V, F, boundary="deficit", integrated=True)``,
  the same quantity libigl returns.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

OPS = ("cotan+M", "cotan+Mmixed", "K", "K-deficit")


def ours(op):
    from geomlib.lessons.curvature import gaussian_curvature
    from geomlib.lessons.laplace import laplacian

    return {
        "cotan+M": lambda V, F: laplacian(V, F, "cotan", "barycentric"),
        "cotan+Mmixed": lambda V, F: laplacian(V, F, "cotan", "mixed"),
        "K": lambda V, F: gaussian_curvature(V, F),
        "K-deficit": lambda V, F: gaussian_curvature(V, F, boundary="deficit", integrated=True),
    }[op]


def libigl(op):
    import igl

    return {
        "cotan+M": lambda V, F: (igl.cotmatrix(V, F), igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_BARYCENTRIC)),
        "cotan+Mmixed": lambda V, F: (igl.cotmatrix(V, F), igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI)),
        "K": lambda V, F: igl.gaussian_curvature(V, F),
        "K-deficit": lambda V, F: igl.gaussian_curvature(V, F),
    }[op]


def _peak_child(path, who, op):
    """Run in a fresh interpreter: print the peak-RSS increase (bytes) of one call."""
    import resource

    data = np.load(path)
    V, F = np.ascontiguousarray(data["V"]), np.ascontiguousarray(data["F"])
    fn = ours(op) if who == "geomlib" else libigl(op)
    small = V[:4].copy(), np.array([[0, 1, 2], [0, 2, 3]])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fn(*small)  # import and warm up everything before the baseline
    try:
        # Linux: reset the high-water mark (VmHWM) to the current RSS, so the
        # peak of this one call is measured even if loading peaked higher
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")
        before = _status_kb("VmRSS")
        out = fn(V, F)
        after = _status_kb("VmHWM")
    except OSError:  # elsewhere: ru_maxrss (a lower bound when loading peaked higher)
        before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        out = fn(V, F)
        after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    del out
    print(json.dumps({"peak_bytes": (after - before) * 1024}))


def _status_kb(field):
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith(field + ":"):
                return int(line.split()[1])
    raise OSError(field)


def peak_memory(path, who, op):
    cmd = [sys.executable, __file__, "--child", str(path), who, op]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, cwd=ROOT).stdout
    return json.loads(out.strip().splitlines()[-1])["peak_bytes"]


def best_time(fn, V, F, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn(V, F)
        times.append(time.perf_counter() - t0)
    return min(times)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument(
        "--levels",
        type=int,
        nargs="+",
        default=[6, 7, 8],
        help="icosphere subdivision levels (6, 7, 8: 40962, 163842, 655362 vertices)",
    )
    parser.add_argument("--repeat", type=int, default=5, help="timed repetitions (best is kept)")
    parser.add_argument("--ops", nargs="+", default=list(OPS), choices=OPS)
    parser.add_argument("--no-memory", action="store_true", help="skip the subprocess memory measurement")
    parser.add_argument(
        "--json", metavar="PATH", help="also save the results as JSON (notebook 03 reads benchmarks/bench_laplace.json)"
    )
    parser.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        _peak_child(*args.child)
        return

    import platform

    from geomlib.teaching.shapes.surfaces import icosphere

    results = []

    print(
        f"{'vertices':>9} {'operation':<13} {'geomlib s':>10} {'libigl s':>9} {'time':>6} "
        f"{'geomlib MB':>10} {'libigl MB':>9} {'memory':>6}"
    )
    with tempfile.TemporaryDirectory() as tmp:
        for level in args.levels:
            V, F = icosphere(level)
            V = np.ascontiguousarray(V, dtype=np.float64)
            F = np.ascontiguousarray(F, dtype=np.int64)
            path = os.path.join(tmp, f"ico{level}.npz")
            np.savez(path, V=V, F=F)
            for op in args.ops:
                a, b = ours(op), libigl(op)
                a(V, F), b(V, F)  # warm-up
                ta = tb = np.inf
                for _ in range(args.repeat):  # interleaved, so both see the same machine load
                    ta = min(ta, best_time(a, V, F, 1))
                    tb = min(tb, best_time(b, V, F, 1))
                if args.no_memory:
                    ma = mb = float("nan")
                else:
                    ma, mb = peak_memory(path, "geomlib", op), peak_memory(path, "libigl", op)
                mr = ma / mb if mb > 0 else float("nan")
                print(
                    f"{len(V):>9} {op:<13} {ta:>10.3f} {tb:>9.3f} {ta / tb:>5.2f}x "
                    f"{ma / 2**20:>10.1f} {mb / 2**20:>9.1f} {mr:>5.2f}x",
                    flush=True,
                )
                results.append(
                    dict(
                        vertices=len(V),
                        operation=op,
                        geomlib_s=ta,
                        libigl_s=tb,
                        time_ratio=ta / tb,
                        geomlib_peak_mb=ma / 2**20,
                        libigl_peak_mb=mb / 2**20,
                        memory_ratio=mr,
                    )
                )
    if args.json:
        import igl
        import scipy

        meta = dict(
            python=platform.python_version(),
            numpy=np.__version__,
            scipy=scipy.__version__,
            libigl=getattr(igl, "__version__", "unknown"),
            machine=platform.machine(),
            cpus=os.cpu_count(),
            repeat=args.repeat,
        )
        Path(args.json).write_text(json.dumps(dict(meta=meta, results=results), indent=1) + "\n")


if __name__ == "__main__":
    main()
