"""Autograde seconds per student of the seven exercise notebooks, against the floor.

    python benchmarks/bench_autograde.py [--students 10] [--workers 2] [--json out.json] [--no-judge]

Builds a course folder in a temporary directory (notebooks 01-07 as one assignment,
``nbgrader generate_assignment``), configured as docs/grading.md configures a course (the
grading judge's preprocessor included; ``--no-judge`` leaves it out, as the figures before
it were measured), hands in ``--students`` full solutions, and measures in one run, so that
the machine's load moves every figure alike. Each grading run starts with an empty cache
folder (``GEOMLIB_CACHE_DIR``), so what a class pays once (the model answers from one run of
the solution notebooks, ``geomlib.course.model_answers``) is in its figure, shared by the
class: the default of 10 students is a small class.

* the floor: for each notebook, a fresh kernel started by nbclient (as nbgrader's Execute
  does) running one cell with every import the notebook makes, summed over the seven;
  measured before and after the grading, the mean of the two;
* serial: ``nbgrader autograde ASSIGNMENT``, the whole class one student after another;
* parallel: ``geomlib-course autograde COURSE ASSIGNMENT --workers N`` on a fresh copy.

Prints seconds per student and the ratio serial / floor, and the same in processor seconds
(this process's and its ended children's: kernels, nbgrader, the judge), which a busy machine
moves less than the wall clock. Goal: at most 2x (2.9x when issue 37 was filed, without
the judge; benchmarks/README.md has the figures since).
"""

import argparse
import ast
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import nbformat  # noqa: E402
from nbclient import NotebookClient  # noqa: E402

from geomlib.course.autograde import autograde_class  # noqa: E402
from geomlib.course.grading import CONFIG_LINE  # noqa: E402

NOTEBOOKS = sorted((ROOT / "notebooks").glob("0[1-7]_*.ipynb"))
ASSIGNMENT = "bench"
GOAL = 2.0


def imports_of(path):
    """Every import statement of a notebook's code cells, in order, once each (magics kept out)."""
    found = []
    for cell in nbformat.read(path, as_version=4).cells:
        if cell.cell_type != "code":
            continue
        lines = [line for line in cell.source.splitlines() if not line.lstrip().startswith(("%", "!"))]
        try:
            tree = ast.parse("\n".join(lines))
        except SyntaxError:
            continue
        for node in ast.walk(tree):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                statement = ast.unparse(node)
                if statement not in found:
                    found.append(statement)
    return found


def cpu_seconds():
    """Processor seconds of this process and of its children that have ended (kernels, nbgrader, the judge)."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def floor_seconds():
    """(wall, processor) seconds to start a kernel and run each notebook's imports, summed over the notebooks."""
    total, cpu = 0.0, cpu_seconds()
    for path in NOTEBOOKS:
        nb = nbformat.v4.new_notebook()
        nb.cells = [nbformat.v4.new_code_cell("%matplotlib inline\n" + "\n".join(imports_of(path)))]
        began = time.perf_counter()
        NotebookClient(nb, timeout=600, kernel_name="python3").execute()
        total += time.perf_counter() - began
    return total, cpu_seconds() - cpu


def nbgrader(course, *args):
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}")
    env.pop("GEOMLIB_STRICT_CLAIMS", None)
    subprocess.run([str(Path(sys.executable).parent / "nbgrader"), *args], cwd=course, env=env, check=True,
                   capture_output=True)  # fmt: skip


def make_course(folder, students, judge=True):
    folder.mkdir()
    (folder / "nbgrader_config.py").write_text(
        "c = get_config()\n"
        f"c.CourseDirectory.root = {str(folder)!r}\n"
        "c.CourseDirectory.course_id = 'bench'\n"
        "c.Execute.timeout = 600\n" + (f"{CONFIG_LINE}\n" if judge else "")
    )
    source = folder / "source" / ASSIGNMENT
    source.mkdir(parents=True)
    for path in NOTEBOOKS:
        shutil.copy(path, source)
    nbgrader(folder, "generate_assignment", ASSIGNMENT)
    for k in range(students):  # full solutions: the graded run does all the work a class's does
        out = folder / "submitted" / f"student{k}" / ASSIGNMENT
        out.mkdir(parents=True)
        for path in NOTEBOOKS:
            shutil.copy(path, out)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--students", type=int, default=10)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--json", type=Path)
    parser.add_argument("--no-judge", action="store_true", help="grade without the grading judge (docs/grading.md)")
    args = parser.parse_args(argv)
    os.environ.pop("GEOMLIB_STRICT_CLAIMS", None)
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="bench-autograde-") as scratch:
        serial, parallel = Path(scratch) / "serial", Path(scratch) / "parallel"
        make_course(serial, args.students, judge=not args.no_judge)
        shutil.copytree(serial, parallel)
        (parallel / "nbgrader_config.py").write_text(
            (serial / "nbgrader_config.py").read_text().replace(str(serial), str(parallel))
        )
        floor_before, floor_cpu_before = floor_seconds()
        os.environ["GEOMLIB_CACHE_DIR"] = str(Path(scratch) / "cache-serial")
        began, cpu = time.perf_counter(), cpu_seconds()
        nbgrader(serial, "autograde", ASSIGNMENT)
        serial_s = (time.perf_counter() - began) / args.students
        serial_cpu = (cpu_seconds() - cpu) / args.students
        os.environ["GEOMLIB_CACHE_DIR"] = str(Path(scratch) / "cache-parallel")
        began = time.perf_counter()
        graded = autograde_class(parallel, ASSIGNMENT, workers=args.workers, out=print)
        parallel_s = (time.perf_counter() - began) / args.students
        assert all(g.ok for g in graded), [g.log[-2000:] for g in graded if not g.ok]
        floor_after, floor_cpu_after = floor_seconds()
    floor, floor_cpu = (floor_before + floor_after) / 2, (floor_cpu_before + floor_cpu_after) / 2
    ratio = serial_s / floor
    print(f"load average at the start: {load:.1f} (2 cores); the grading judge {'left out' if args.no_judge else 'on'}")
    print(
        f"floor (kernel start + imports, 7 notebooks): {floor:.1f} s ({floor_before:.1f} s before, {floor_after:.1f} s after)"
    )
    print(f"nbgrader autograde, serial:                 {serial_s:.1f} s per student")
    print(f"geomlib-course autograde --workers {args.workers}:        {parallel_s:.1f} s per student (wall clock)")
    print(f"serial / floor: {ratio:.2f}x (goal at most {GOAL:.1f}x): {'met' if ratio <= GOAL else 'NOT met'}")
    print(
        f"processor seconds (the load moves them little): floor {floor_cpu:.1f} s, serial {serial_cpu:.1f} s per "
        f"student, {serial_cpu / floor_cpu:.2f}x"
    )
    if args.json:
        figures = {"load": load, "floor_s": floor, "serial_s": serial_s, "parallel_s": parallel_s, "ratio": ratio}
        figures |= {"floor_cpu_s": floor_cpu, "serial_cpu_s": serial_cpu}
        setting = {"workers": args.workers, "students": args.students, "judge": not args.no_judge}
        args.json.write_text(json.dumps(figures | setting, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
