"""How many cores this process may run on: its CPU affinity where the system reports one.

The workbook is measured on 2-core machines; the parallel parts (two threads in
:mod:`geomlib.numerics.eigen`, a second process in a smoothing sweep) use two
cores where there are two and fall back to one where there is one.
"""

import os

__all__ = ["CORES"]

#: Cores this process may run on (at least 1).
CORES = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
