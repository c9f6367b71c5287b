#!/usr/bin/env python3
"""Strip outputs, execution counts and widget state from notebooks before a commit.

    python tools/strip_notebooks.py                 # every notebooks/*.ipynb
    python tools/strip_notebooks.py path.ipynb ...  # the given notebooks
    python tools/strip_notebooks.py --check         # list what would change; exit 1 if anything

What is removed or set (tests/test_notebooks_clean.py checks the same rules):
* code cells: ``outputs`` emptied, ``execution_count`` set to null, the
  per-cell ``execution`` timing metadata and ``collapsed``/``scrolled`` view
  state dropped;
* notebook metadata: ``widgets`` (the saved widget state, megabytes for a 3D
  view) removed; ``kernelspec`` set to the standard ``python3`` kernel and
  ``language_info`` reduced to the language name.

The file is written the way Jupyter writes it (JSON, one-space indent, sorted
keys, trailing newline), so stripping a clean notebook changes nothing.
"""

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
KERNELSPEC = {"display_name": "Python 3 (ipykernel)", "language": "python", "name": "python3"}
CELL_VIEW_KEYS = ("execution", "collapsed", "scrolled")


def strip(nb):
    """Return the stripped notebook (dict, nbformat 4) and a list of what changed."""
    changes = []
    for i, cell in enumerate(nb.get("cells", [])):
        if cell.get("cell_type") == "code":
            if cell.get("outputs"):
                changes.append(f"cell {i}: outputs")
            cell["outputs"] = []
            if cell.get("execution_count") is not None:
                changes.append(f"cell {i}: execution count")
            cell["execution_count"] = None
        meta = cell.get("metadata", {})
        for key in CELL_VIEW_KEYS:
            if key in meta:
                changes.append(f"cell {i}: metadata.{key}")
                del meta[key]
        jupyter = meta.get("jupyter")
        if isinstance(jupyter, dict) and "outputs_hidden" in jupyter:
            del jupyter["outputs_hidden"]
            if not jupyter:
                del meta["jupyter"]
            changes.append(f"cell {i}: metadata.jupyter.outputs_hidden")
    meta = nb.setdefault("metadata", {})
    if "widgets" in meta:
        changes.append("metadata.widgets (widget state)")
        del meta["widgets"]
    if meta.get("kernelspec") != KERNELSPEC:
        changes.append("metadata.kernelspec")
        meta["kernelspec"] = dict(KERNELSPEC)
    if meta.get("language_info") != {"name": "python"}:
        changes.append("metadata.language_info")
        meta["language_info"] = {"name": "python"}
    return nb, changes


def dumps(nb):
    return json.dumps(nb, sort_keys=True, indent=1, ensure_ascii=False) + "\n"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("paths", nargs="*", type=Path, help="notebooks (default: notebooks/*.ipynb)")
    parser.add_argument("--check", action="store_true", help="change nothing; exit 1 if a notebook is not clean")
    args = parser.parse_args(argv)
    paths = args.paths or sorted((ROOT / "notebooks").glob("*.ipynb"))
    dirty = 0
    for path in paths:
        text = path.read_text(encoding="utf-8")
        nb, changes = strip(json.loads(text))
        new = dumps(nb)
        if new == text:
            continue
        dirty += 1
        what = ", ".join(changes) or "formatting"
        if args.check:
            print(f"{path}: not clean ({what})")
        else:
            path.write_text(new, encoding="utf-8")
            print(f"{path}: stripped ({what})")
    return 1 if (args.check and dirty) else 0


if __name__ == "__main__":
    sys.exit(main())
