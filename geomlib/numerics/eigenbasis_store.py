"""The eigenbasis cache: the last few bases in memory, all of them on disk.

A basis is stored under a key that hashes the bytes of ``V`` and ``F``, the
operator options and the geomlib version (:func:`key`); a stored basis with
``k' >= k`` eigenpairs serves a request for ``k``. A file holds the
eigenvalues ``lam`` (k,), the eigenvectors ``E`` (n, k) and the vertex
masses ``m`` (n,), so a basis read back needs no operator. Files are ``<key>-k<k'>.npz``
in the folder of :func:`folder`, written to a temporary name and renamed, so a
reader never sees half a file.

Faults on the reader's machine never stop a computation: a damaged file (for
example truncated by a full disk or a sync tool), an unwritable folder, or a
file where the folder should be is detected, reported with a
:class:`~geomlib.mesh.errors.MeshWarning` naming the path and the problem, and the
caller solves again (and, where it can, replaces the damaged file).
"""

import functools
import hashlib
import os
import sys
import time
import warnings
import zipfile
from collections import OrderedDict
from importlib.metadata import version
from pathlib import Path

import numpy as np

from ..mesh.errors import MeshWarning

__all__ = ["CACHE_DIR", "MEMORY_SIZE", "folder", "key", "clear", "forget", "remember", "recall", "load", "store"]

#: Cache folder chosen by the user for this session (None: see :func:`folder`).
CACHE_DIR = None

#: Bases kept in memory (each is n * k float64: 25k vertices, k = 300 is 60 MB).
MEMORY_SIZE = 3

#: Bumped whenever the stored format or the solver's conventions change.
FORMAT = 3

_MEMORY = OrderedDict()


def folder(cache_dir=None):
    """The folder holding cached eigenbases (it need not exist yet).

    Order: the ``cache_dir`` argument, ``geomlib.numerics.eigenbasis_store.CACHE_DIR``, the
    environment variable ``GEOMLIB_CACHE_DIR``, the per-user cache folder
    (``$XDG_CACHE_HOME/geomlib``, default ``~/.cache/geomlib``, on Linux;
    ``~/Library/Caches/geomlib`` on macOS; ``%LOCALAPPDATA%\\geomlib\\Cache`` on
    Windows); the bases go into its ``spectral`` sub-folder.
    """
    root = cache_dir or CACHE_DIR or os.environ.get("GEOMLIB_CACHE_DIR")
    if not root:
        home = Path.home()
        if sys.platform.startswith("win"):
            root = Path(os.environ.get("LOCALAPPDATA") or home / "AppData" / "Local") / "geomlib" / "Cache"
        elif sys.platform == "darwin":
            root = home / "Library" / "Caches" / "geomlib"
        else:
            root = Path(os.environ.get("XDG_CACHE_HOME") or home / ".cache") / "geomlib"
    return Path(root).expanduser() / "spectral"


def key(*parts):
    """Hex digest of ``parts`` (arrays by their bytes, shape and dtype, anything else by its repr),
    the geomlib version and the cache format: the one key of every cache in geomlib."""
    h = hashlib.blake2b(_salt(), digest_size=16)
    for part in parts:
        if isinstance(part, np.ndarray):
            h.update(repr((part.shape, part.dtype.str)).encode())
            h.update(np.ascontiguousarray(part).view(np.uint8))
        else:
            h.update(repr(part).encode())
    return h.hexdigest()


@functools.cache
def _salt():
    # the installed version is read from the package metadata once: 1 ms a call, and
    # the operator and factorisation caches ask for a key at every smoothing call
    return repr((version("geomlib"), FORMAT)).encode()


def clear(cache_dir=None, memory=True):
    """Delete the cached eigenbases on disk (and in memory); returns the number of files removed."""
    if memory:
        _MEMORY.clear()
    where = folder(cache_dir)
    removed = 0
    if where.is_dir():
        for path in where.glob("*.npz"):
            try:
                path.unlink()
                removed += 1
            except OSError:
                pass
    return removed


def forget():
    """Empty the memory cache only (as a restarted kernel finds it)."""
    _MEMORY.clear()


def remember(name, value):
    """Keep ``value`` in memory under ``name`` (the last ``MEMORY_SIZE`` are kept)."""
    _MEMORY[name] = value
    _MEMORY.move_to_end(name)
    while len(_MEMORY) > MEMORY_SIZE:
        _MEMORY.popitem(last=False)


def recall(name):
    """The value kept under ``name``, or None."""
    value = _MEMORY.get(name)
    if value is not None:
        _MEMORY.move_to_end(name)
    return value


def _stored_k(path):
    try:
        return int(path.stem.rsplit("-k", 1)[1])
    except (IndexError, ValueError):
        return None


def _warn(message):
    warnings.warn(message, MeshWarning, stacklevel=4)


def load(where, name, k):
    """``(lam, E, m)`` of the stored basis of ``name`` with the fewest eigenpairs >= k, or None.

    A file that cannot be read, or holds arrays of the wrong shape, gives a
    MeshWarning and None (the caller solves again and overwrites it).
    """
    if where.exists() and not where.is_dir():
        return None  # reported by store(), which cannot write there either
    candidates = (
        sorted((kk, p) for p in where.glob(f"{name}-k*.npz") if (kk := _stored_k(p)) is not None and kk >= k)
        if where.is_dir()
        else []
    )
    if not candidates:
        return None
    kk, path = candidates[0]
    try:
        with np.load(path) as data:
            lam, E, m = data["lam"], data["E"], data["m"]
        if E.ndim != 2 or E.shape[1] != kk or lam.shape != (kk,) or m.shape != E.shape[:1]:
            raise ValueError(
                f"arrays of shape {lam.shape}, {E.shape} and {m.shape}, expected ({kk},), (n, {kk}) and (n,)"
            )
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:
        _warn(f"the cached eigenbasis {path} is damaged ({type(exc).__name__}: {exc}); solving again and replacing it")
        try:
            path.unlink()
        except OSError:
            pass
        return None
    return lam, np.asfortranarray(E), m


def store(where, name, lam, E, m):
    """Write a basis (``lam``, ``E``, ``m``); smaller stored bases of the same key are deleted. Never raises:
    a folder that cannot be written gives a MeshWarning and the basis is just not stored."""
    if where.exists() and not where.is_dir():
        _warn(
            f"the eigenbasis cache folder {where} is a file, not a folder, so the basis "
            f"is not stored (delete or move that file, or set GEOMLIB_CACHE_DIR)"
        )
        return
    path = where / f"{name}-k{len(lam)}.npz"
    tmp = where / f".{name}-{os.getpid()}-{time.monotonic_ns()}.tmp.npz"
    try:
        where.mkdir(parents=True, exist_ok=True)
        np.savez(tmp, lam=lam, E=E, m=m)
        os.replace(tmp, path)  # atomic: a reader never sees half a file
    except OSError as exc:
        _warn(
            f"could not write the eigenbasis cache in {where} ({type(exc).__name__}: {exc}); "
            f"the basis is not stored and will be solved again next time"
        )
        try:
            tmp.unlink(missing_ok=True)
        except OSError:
            pass
        return
    for other in where.glob(f"{name}-k*.npz"):  # smaller bases of the same mesh are now redundant
        kk = _stored_k(other)
        if kk is not None and kk < len(lam):
            try:
                other.unlink()
            except OSError:
                pass
