"""Stored results of deterministic experiments, reused across the students of one grading run.

While nbgrader grades (:func:`geomlib.teaching.notebook.graded`), every student's notebook
runs the same lesson experiments on the same fixed parameters and shipped meshes; their
numbers are printed in the feedback (the hidden model answers), so they must be computed,
but once is enough. A result is a dict of float64 arrays, stored under :func:`key`: a hash
of every input, the geomlib version and the cache format (:func:`eigenbasis_store.key
<geomlib.numerics.eigenbasis_store.key>`, the one key of every cache in geomlib) and of the
source of geomlib itself (a changed engine under an unchanged version number, as while
developing, never reads a result the old one computed), as
``<key>.npz`` in the ``experiments`` sub-folder next to the eigenbases (same folder rules:
:func:`~geomlib.numerics.eigenbasis_store.folder`). Arrays round-trip bit for bit, so a
stored result prints the numbers a fresh one prints. Files are written to a temporary name
and renamed (a reader never sees half a file); an unreadable file is treated as absent and
an unwritable folder only means nothing is stored: a fault never stops a computation.
"""

import functools
import hashlib
import os
import time
import zipfile
from pathlib import Path

import numpy as np

from . import eigenbasis_store

__all__ = ["folder", "key", "load", "store"]


def folder(cache_dir=None):
    """The folder holding stored experiment results (it need not exist yet)."""
    return eigenbasis_store.folder(cache_dir).parent / "experiments"


def key(*parts):
    """The name of the result of an experiment on ``parts`` (its name and every input)."""
    return eigenbasis_store.key(_source(), *parts)


@functools.cache
def _source():
    # read once per kernel: about 1 MB of source, a few milliseconds
    h = hashlib.blake2b(digest_size=16)
    package = Path(__file__).resolve().parents[1]
    for path in sorted(package.rglob("*.py")):
        h.update(path.relative_to(package).as_posix().encode() + b"\0" + path.read_bytes())
    return h.hexdigest()


def load(name, cache_dir=None):
    """The dict of arrays stored under ``name`` (a :func:`key`), or None."""
    path = folder(cache_dir) / f"{name}.npz"
    try:
        with np.load(path) as data:
            return {k: data[k] for k in data.files}
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):
        return None  # absent or damaged: the caller computes again and store() replaces it


def store(name, arrays, cache_dir=None):
    """Write ``arrays`` (a dict of arrays) under ``name``; never raises."""
    where = folder(cache_dir)
    tmp = where / f".{name}-{os.getpid()}-{time.monotonic_ns()}.tmp.npz"
    try:
        where.mkdir(parents=True, exist_ok=True)
        np.savez(tmp, **arrays)
        os.replace(tmp, where / f"{name}.npz")
    except OSError:
        try:
            tmp.unlink(missing_ok=True)
        except OSError:
            pass
