"""Eigenvectors of the Laplace-Beltrami operator and spectral reconstruction.

Convention: the eigenpairs ``(lam_i, e_i)`` solve the symmetric generalised
problem ``C e = -lam M e`` with ``(M, C)`` from :func:`geomlib.laplacian`
(``C`` symmetric negative semidefinite, ``M`` diagonal vertex areas), so
``Delta e = M^-1 C e = -lam e`` with ``lam >= 0``: ``lam`` is a squared
spatial frequency in 1/length^2 (on the unit sphere ``lam -> l (l + 1)``).
Eigenvalues come in ascending order; the eigenvectors are orthonormal in the
``M`` inner product, ``E^T M E = I`` (not ``E^T E = I``: they are samples of
functions normalised by the integral ``int e^2 dA = 1``). The first one is the
constant ``1 / sqrt(area)`` with ``lam = 0``; a mesh with ``c`` connected
components has ``c`` zero eigenvalues, and their eigenvectors are the
normalised indicator functions of the components (largest component first).

How the problem is solved: ``M^-1 C`` is not symmetric, so it is never formed.
With ``D = M^1/2`` the problem becomes the ordinary symmetric eigenproblem
``S y = lam y`` with ``S = -D^-1 C D^-1`` and ``e = D^-1 y``
(Vallet and Levy 2008, "Spectral geometry processing with manifold harmonics").
Small meshes use dense LAPACK (``scipy.linalg.eigh``); larger ones use
Lanczos iteration in shift-invert mode around a small negative shift ``-s``:
the sparse factorisation of ``S + s I`` (symmetric positive definite, in a
nested-dissection order) is computed once, and every step applies
``(S + s I)^-1`` by triangular solves. The Lanczos iteration is a block,
thick-restart one (:func:`block_lanczos`, matrix-matrix products instead of
ARPACK's one vector at a time), with ARPACK (``scipy.sparse.linalg.eigsh``) as
the fallback.

Cache: a basis is stored in memory (the last few meshes) and on disk, so a
slider over ``k`` re-projects without solving again and a restarted kernel
finds it. The key is a hash of the bytes of ``V`` and ``F``, the operator
(``weights``, ``area``) and the geomlib version; a file holding ``k'`` >= ``k``
eigenpairs serves any request for ``k``. The folder is, in this order: the
``cache_dir`` argument, the module attribute ``CACHE_DIR``, the environment
variable ``GEOMLIB_CACHE_DIR``, else the per-user cache folder
(``$XDG_CACHE_HOME/geomlib`` or ``~/.cache/geomlib`` on Linux,
``~/Library/Caches/geomlib`` on macOS, ``%LOCALAPPDATA%\\geomlib\\Cache`` on
Windows), always in a ``spectral`` sub-folder. ``cache=False`` neither reads
nor writes it; :func:`clear_spectral_cache` empties it.
"""

import contextlib
import ctypes
import hashlib
import os
import sys
import time
import warnings
from collections import OrderedDict
from pathlib import Path

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from .errors import MeshError, MeshWarning, format_indices

__all__ = [
    "eigenbasis",
    "spectral_reconstruction",
    "SpectralBasis",
    "spectral_basis",
    "block_lanczos",
    "nested_dissection",
    "spectral_cache_dir",
    "clear_spectral_cache",
]

#: Cache folder chosen by the user for this session (None: see the module docstring).
CACHE_DIR = None

#: Meshes with at most this many vertices are solved with dense LAPACK.
DENSE_MAX_VERTICES = 600

#: Bases kept in memory (each is n * k float64: 25k vertices, k = 300 is 60 MB).
MEMORY_CACHE_SIZE = 3

#: Bumped whenever the stored format or the solver's conventions change.
_CACHE_FORMAT = 1

_MEMORY = OrderedDict()

#: BLAS threads used while solving (None: leave the BLAS library's own setting).
#: One thread, because on the workbook's 2-core machines a 2-thread OpenBLAS
#: pool that competes with other busy processes made dense ``eigh`` at 642
#: vertices 20x slower (2.1 s instead of 0.1 s) and ARPACK's own vector work
#: several times slower; the sparse factorisation and its solves use one
#: thread anyway.
BLAS_THREADS = 1


# --------------------------------------------------------------------------
# input


def _as_mesh(V, F):
    from .validate import as_mesh

    return as_mesh(V, F)


def _check_k(k, n):
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)):
        raise MeshError(f"k must be an integer number of eigenpairs, not {k!r}")
    k = int(k)
    if k < 1:
        raise MeshError(f"k must be at least 1, not {k}")
    if k > n:
        raise MeshError(
            f"k = {k} eigenpairs asked for, but the mesh has only {n} vertices "
            f"(at most n = {n} eigenpairs exist)"
        )
    return k


def _operator(V, F, weights, area):
    from .laplace import laplacian

    M, C = laplacian(V, F, weights=weights, area=area)
    m = np.asarray(M.diagonal(), dtype=np.float64)
    isolated = np.flatnonzero(m <= 0)
    if len(isolated):
        raise MeshError(
            f"{len(isolated)} vertex/vertices belong to no triangle of non-zero area, so the "
            f"mass matrix M is singular there and no eigenbasis exists: vertices "
            f"{format_indices(isolated)} (remove them, e.g. with trimesh's remove_unreferenced_vertices)"
        )
    return m, sp.csr_matrix(C)


def _components(F, m, n):
    """Number of connected components (vertices linked by faces) and a label per vertex, largest area first."""
    from scipy.sparse.csgraph import connected_components

    if len(F):
        I = np.concatenate([F[:, 0], F[:, 1], F[:, 2]])
        J = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])
        G = sp.csr_matrix((np.ones(len(I)), (I, J)), shape=(n, n))
    else:
        G = sp.csr_matrix((n, n))
    count, labels = connected_components(G, directed=False)
    # order: by total area, largest first (ties: smallest vertex index)
    size = np.bincount(labels, weights=m, minlength=count)
    first = np.full(count, n)
    np.minimum.at(first, labels, np.arange(n))
    order = np.lexsort((first, -size))
    rank = np.empty(count, dtype=np.int64)
    rank[order] = np.arange(count)
    return count, rank[labels]


# --------------------------------------------------------------------------
# cache


def spectral_cache_dir(cache_dir=None):
    """The folder holding cached eigenbases (it need not exist yet).

    Order: the ``cache_dir`` argument, ``geomlib.spectral.CACHE_DIR``, the
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


def clear_spectral_cache(cache_dir=None, memory=True):
    """Delete the cached eigenbases on disk (and in memory); returns the number of files removed."""
    if memory:
        _MEMORY.clear()
    folder = spectral_cache_dir(cache_dir)
    removed = 0
    if folder.is_dir():
        for path in folder.glob("*.npz"):
            try:
                path.unlink()
                removed += 1
            except OSError:
                pass
    return removed


def _key(V, F, weights, area):
    from . import __version__

    h = hashlib.blake2b(digest_size=16)
    h.update(repr((V.shape, F.shape, weights, area, __version__, _CACHE_FORMAT)).encode())
    h.update(np.ascontiguousarray(V, dtype=np.float64).view(np.uint8))
    h.update(np.ascontiguousarray(F, dtype=np.int64).view(np.uint8))
    return h.hexdigest()


def _disk_lookup(folder, key, k):
    """The cached file for ``key`` with the fewest eigenpairs >= k, or None."""
    best = None
    if folder.is_dir():
        for path in folder.glob(f"{key}-k*.npz"):
            try:
                kk = int(path.stem.rsplit("-k", 1)[1])
            except ValueError:
                continue
            if kk >= k and (best is None or kk < best[0]):
                best = (kk, path)
    if best is None:
        return None
    try:
        with np.load(best[1]) as data:
            lam, E = data["lam"], data["E"]
    except (OSError, ValueError, KeyError):  # unreadable or half-written file: solve again
        return None
    if E.ndim != 2 or E.shape[1] != best[0] or lam.shape != (best[0],):
        return None
    return lam, np.asfortranarray(E)


def _disk_store(folder, key, lam, E):
    path = folder / f"{key}-k{len(lam)}.npz"
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tmp = folder / f".{key}-{os.getpid()}-{time.monotonic_ns()}.tmp.npz"
        np.savez(tmp, lam=lam, E=E)
        os.replace(tmp, path)  # atomic: a reader never sees half a file
        for other in folder.glob(f"{key}-k*.npz"):  # smaller bases of the same mesh are now redundant
            if other != path:
                try:
                    kk = int(other.stem.rsplit("-k", 1)[1])
                except ValueError:
                    continue
                if kk < len(lam):
                    other.unlink(missing_ok=True)
    except OSError as err:
        warnings.warn(f"could not write the eigenbasis cache in {folder}: {err}", RuntimeWarning, stacklevel=4)


# --------------------------------------------------------------------------
# BLAS threads


_HANDLES = {}


def _openblas_handles():
    """(set, get) function pairs of every OpenBLAS loaded in this process (Linux only; else []).

    The loaded libraries are listed again only when modules were imported since
    the last look (an import may load another BLAS), so a slider callback does
    not pay for reading /proc/self/maps."""
    stamp = len(sys.modules)
    if _HANDLES.get("stamp") == stamp:
        return _HANDLES["handles"]
    try:
        with open("/proc/self/maps") as maps:
            paths = tuple(sorted({line.split()[-1] for line in maps
                                  if "openblas" in line.rsplit("/", 1)[-1].lower()}))
    except OSError:
        paths = ()
    if _HANDLES.get("paths") != paths:
        _HANDLES.update(paths=paths, handles=_load_handles(paths))
    _HANDLES["stamp"] = stamp
    return _HANDLES["handles"]


def _load_handles(paths):
    handles = []
    for path in paths:
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        for prefix, suffix in (("openblas", ""), ("scipy_openblas", ""), ("scipy_openblas", "64_")):
            setter = getattr(lib, f"{prefix}_set_num_threads{suffix}", None)
            getter = getattr(lib, f"{prefix}_get_num_threads{suffix}", None)
            if setter is not None and getter is not None:
                getter.restype = ctypes.c_int
                handles.append((setter, getter))
                break
    return handles


@contextlib.contextmanager
def _blas_threads(count):
    """Run the block with ``count`` OpenBLAS threads and restore the previous setting."""
    if not count:
        yield
        return
    saved = []
    try:
        for setter, getter in _openblas_handles():
            saved.append((setter, int(getter())))
            setter(int(count))
    except Exception:  # an unexpected BLAS build: leave it alone
        pass
    try:
        yield
    finally:
        for setter, old in saved:
            try:
                setter(old)
            except Exception:
                pass


# --------------------------------------------------------------------------
# solvers


def _dense(m, C, k):
    d = 1.0 / np.sqrt(m)
    S = -(C.toarray() * d[:, None] * d[None, :])
    S = 0.5 * (S + S.T)
    if k < len(m):
        lam, Y = la.eigh(S, subset_by_index=[0, k - 1], driver="evr")
    else:
        lam, Y = la.eigh(S, driver="evd")
    return lam, Y


def _shift(m, C):
    """A small positive shift s: S + s I is positive definite and well scaled.

    s is 1e-4 of the Weyl estimate 4 pi / area of the first non-zero
    eigenvalue of a closed surface: far below every non-zero eigenvalue of a
    reasonable mesh, far above rounding.
    """
    return 1e-4 * 4.0 * np.pi / m.sum()


def nested_dissection(A, X, leaf=64):
    """Fill-reducing vertex order for a sparse symmetric matrix on a mesh (geometric nested dissection).

    The vertices are split at the median along the principal axis of their
    positions X (n, 3); the vertices on the smaller side of the cut that have
    a neighbour across it form the separator, which is numbered last; both
    halves are split again, down to ``leaf`` vertices. Eliminating in this
    order keeps the fill of a factorisation small (George 1973). Returns the
    permutation p (n,) int64: ``A[p][:, p]`` is the reordered matrix.
    """
    A = sp.csr_matrix(A)
    n = A.shape[0]
    indptr, indices = A.indptr, A.indices
    X = np.asarray(X, dtype=np.float64)
    order = np.empty(n, dtype=np.int64)
    end = n
    owner = np.full(n, -1, dtype=np.int64)  # which part a vertex is in right now
    local = np.zeros(n, dtype=np.int64)
    stack = [np.arange(n)]
    part = 0
    while stack:
        idx = stack.pop()
        m = len(idx)
        if m <= leaf:
            order[end - m:end] = idx
            end -= m
            continue
        part += 1
        owner[idx] = part
        local[idx] = np.arange(m)
        P = X[idx] - X[idx].mean(axis=0)
        axis = np.linalg.eigh(P.T @ P)[1][:, -1]
        c = P @ axis
        left = c <= np.median(c)
        if left.all() or not left.any():  # all on one point: split by index
            left = np.zeros(m, dtype=bool)
            left[: m // 2] = True
        # the edges of this part, as local (row, col) pairs
        starts, counts = indptr[idx], indptr[idx + 1] - indptr[idx]
        rows = np.repeat(np.arange(m), counts)
        pos = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts) + np.repeat(starts, counts)
        cols = indices[pos]
        inside = owner[cols] == part
        rows, cols = rows[inside], local[cols[inside]]
        cross = left[rows] & ~left[cols]
        sep_left = np.zeros(m, dtype=bool)
        sep_left[rows[cross]] = True
        sep_right = np.zeros(m, dtype=bool)
        sep_right[cols[cross]] = True
        sep = sep_left if sep_left.sum() <= sep_right.sum() else sep_right
        S = idx[sep]
        order[end - len(S):end] = S
        end -= len(S)
        stack.append(idx[left & ~sep])
        stack.append(idx[~left & ~sep])
    return order


def _orthonormalise(W, norm0):
    """Q, R with W = Q R, Q^T Q = I: Cholesky QR twice (BLAS 3), Householder QR when W is nearly rank deficient.

    Returns (Q, R, bad) with ``bad`` the columns whose remainder vanished (None when none did)."""
    try:
        R1 = la.cholesky(W.T @ W, lower=False)
        Q = la.solve_triangular(R1, W.T, trans="T", lower=False).T
        R2 = la.cholesky(Q.T @ Q, lower=False)
        Q = la.solve_triangular(R2, Q.T, trans="T", lower=False).T
        R = R2 @ R1
        if np.all(np.abs(np.diag(R)) > 1e-8 * norm0):
            return Q, R, None
    except la.LinAlgError:
        pass
    Q, R = np.linalg.qr(W)
    bad = np.abs(np.diag(R)) <= 1e-10 * np.maximum(norm0, 1e-300)
    return Q, R, bad


def block_lanczos(apply_T, n, k, block=8, ncv=None, tol=1e-12, max_restarts=100, seed=0):
    """Largest k eigenpairs of a symmetric positive definite operator T, thick-restart block Lanczos.

    ``apply_T(X)`` maps an (n, b) block to T X. The Krylov basis grows by blocks
    of ``block`` vectors up to ``ncv``, fully re-orthogonalised (a local pass
    against the neighbouring blocks, then one pass against the whole basis,
    both as matrix-matrix products); then the Rayleigh-Ritz values of the
    projected matrix H = V^T T V are checked and the best Ritz vectors kept
    (thick restart, Wu and Simon 2000; block form as in Zhou and Saad 2008).
    A Ritz pair (theta, y) has converged when its residual ``||T y - theta y||``,
    read off the last block of the Krylov relation, is at most
    ``tol * theta``. Returns (theta (k,) descending, Y (n, k) orthonormal);
    raises RuntimeError when ``max_restarts`` restarts do not suffice.

    Why blocks: ARPACK's single-vector Lanczos re-orthogonalises one vector at a
    time (matrix-vector products that stream the whole basis through memory
    for every step) and its restarts and final Ritz vectors are level-2 BLAS
    too; with blocks of b vectors the same work is done by matrix-matrix
    products, and the sparse triangular solves run on b right-hand sides at once.
    """
    b = int(block)
    if ncv is None:
        ncv = b * int(np.ceil((2 * k + 2 * b) / b))
    ncv = min(ncv, n - b)
    ncv -= ncv % b
    if ncv < k + b:
        raise RuntimeError(f"block Lanczos needs ncv >= k + block, got ncv = {ncv} for k = {k}, block = {b}")
    rng = np.random.default_rng(seed)
    V = np.empty((n, ncv + b), order="F")
    H = np.zeros((ncv, ncv))
    V[:, :b] = np.linalg.qr(rng.standard_normal((n, b)))[0]
    j, cur = 0, b
    keep = ncv - max(1, ((ncv - k) // b) // 2) * b  # Ritz vectors kept at a restart
    after_restart = False
    for _ in range(max_restarts):
        while j < ncv:
            Wb = np.asfortranarray(apply_T(V[:, j:j + b]))
            norm0 = np.sqrt(np.einsum("ij,ij->j", Wb, Wb))
            # local pass: in exact arithmetic T V_j couples only to the neighbouring
            # blocks (after a restart, the first new block couples to every kept vector)
            lo = 0 if (after_restart or j == 0) else j - b
            after_restart = False
            Vl = V[:, lo:cur]
            hl = Vl.T @ Wb
            W = Wb - Vl @ hl
            # full pass: re-orthogonalisation against the whole basis
            Vc = V[:, :cur]
            h = Vc.T @ W
            W -= Vc @ h
            h[lo:cur] += hl
            H[:cur, j:j + b] = h
            H[j:j + b, :cur] = h.T
            sq = H[j:j + b, j:j + b]
            H[j:j + b, j:j + b] = 0.5 * (sq + sq.T)
            Q, R, bad = _orthonormalise(W, norm0)
            if bad is not None and bad.any():
                # an invariant subspace was found: continue with random directions
                for i in np.flatnonzero(bad):
                    x = rng.standard_normal(n)
                    good = Q[:, ~bad]
                    for _ in range(2):
                        x -= Vc @ (Vc.T @ x)
                        x -= good @ (good.T @ x)
                    Q[:, i] = x / np.linalg.norm(x)
                    R[i, :] = 0.0
            V[:, cur:cur + b] = Q
            cur += b
            j += b
        theta, Y = la.eigh(H[:j, :j])
        theta, Y = theta[::-1], Y[:, ::-1]
        residual = np.linalg.norm(R @ Y[j - b:j, :k], axis=0)
        if np.all(residual <= tol * np.abs(theta[:k])):
            return theta[:k], V[:, :j] @ Y[:, :k]
        Yk = np.asfortranarray(Y[:, :keep])
        V_next = V[:, j:j + b].copy()
        V[:, :keep] = V[:, :j] @ Yk
        V[:, keep:keep + b] = V_next
        H[:] = 0.0
        H[np.arange(keep), np.arange(keep)] = theta[:keep]
        j, cur = keep, keep + b
        after_restart = True
    raise RuntimeError(f"block Lanczos: {k} eigenpairs not converged after {max_restarts} restarts")


def _block_size(k):
    """Block size of the block Lanczos solver: 4 for small k, up to 16 for k >= 200 (measured)."""
    return int(min(16, max(4, round(k / 12))))


def _sparse(m, C, k, tol, X, method="sparse"):
    n = len(m)
    d = 1.0 / np.sqrt(m)
    D = sp.diags(d)
    S = (D @ (-C) @ D).tocsc()
    S = (0.5 * (S + S.T)).tocsc()
    s = _shift(m, C)
    # The one factorisation: every Lanczos step is a pair of triangular solves.
    # S + s I is symmetric positive definite, so no pivoting is needed and a
    # symmetric fill-reducing order (nested dissection) can be imposed:
    # measured at 41k vertices, 5.2M instead of 7.0M non-zeros in L + U
    # (scipy's default COLAMD with partial pivoting) and solves about 1.4x faster.
    p = nested_dissection(S, X)
    K = (S + s * sp.eye(n, format="csc"))[p][:, p].tocsc()
    lu = sla.splu(K, permc_spec="NATURAL", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
    ip = np.empty_like(p)
    ip[p] = np.arange(n)

    def solve(x):
        return lu.solve(np.asfortranarray(x[p]))[ip]

    if method == "sparse":
        try:
            theta, Y = block_lanczos(solve, n, k, block=_block_size(k), tol=tol or 1e-12)
            lam = 1.0 / theta - s
            # guard: the residual of S y = lam y itself, relative to the size of S
            R = S @ Y - Y * lam[None, :]
            if np.abs(R).max() <= 1e-9 * np.abs(S).max():
                return lam, Y
        except RuntimeError:
            pass
    # ARPACK (single-vector implicitly restarted Lanczos) with the same factorisation
    OPinv = sla.LinearOperator((n, n), matvec=solve, dtype=np.float64)
    v0 = np.sqrt(m) * (1.0 + 0.1 * np.random.default_rng(0).standard_normal(n))
    lam, Y = sla.eigsh(S, k=k, sigma=-s, which="LM", OPinv=OPinv, v0=v0, tol=tol or 0.0)
    return lam, Y


def _finish(m, lam, Y, labels, count):
    """Sort, M-normalise, fix signs, put the exact null space first."""
    order = np.argsort(lam, kind="stable")
    lam = np.array(lam[order], dtype=np.float64)
    E = Y[:, order] / np.sqrt(m)[:, None]
    # re-normalise in the M inner product (the solvers give Y^T Y = I to rounding)
    E /= np.sqrt(np.einsum("ij,i,ij->j", E, m, E))[None, :]
    k = len(lam)
    c = min(count, k)
    # the null space: one constant per component; the solver returns some
    # rotation of it, replace it by the normalised indicator functions
    scale = max(abs(lam[-1]), 4.0 * np.pi / m.sum())
    zero = np.abs(lam[:c]) <= 1e-8 * scale
    if zero.all():
        idx = np.arange(c)
        areas = np.bincount(labels, weights=m, minlength=count)[:c]
        Z = (labels[:, None] == idx[None, :]) / np.sqrt(areas)[None, :]
        E[:, :c] = Z
        lam[:c] = 0.0
    # rounding can push tiny eigenvalues below zero; -C is positive semidefinite
    lam = np.maximum(lam, 0.0)
    # sign: the entry of largest magnitude is positive (deterministic output)
    big = np.argmax(np.abs(E), axis=0)
    E *= np.where(E[big, np.arange(k)] < 0, -1.0, 1.0)[None, :]
    return lam, np.asfortranarray(E)


# --------------------------------------------------------------------------
# the basis


class SpectralBasis:
    """The first k Laplace-Beltrami eigenpairs of a mesh, ready to project onto.

    Convention: ``C e = -lam M e``, ``lam`` ascending >= 0, ``E^T M E = I``.
    Made by :func:`spectral_basis` (or :func:`eigenbasis`, which returns its
    ``(lam, E)``). Projections use the ``M`` inner product
    ``<f, g>_M = f^T M g`` (the discrete ``int f g dA``).

    Attributes
    ----------
    lam : (k,) float64, 1/length^2
    E : (n, k) float64, Fortran order (the first j columns are one block)
    m : (n,) float64 diagonal of M, length^2
    components : int, connected components (= number of zero eigenvalues)
    seconds : float, time the solve took (0 when it came from the cache)
    source : "solved", "memory" or "disk"
    """

    def __init__(self, lam, E, m, components=1, seconds=0.0, source="solved"):
        self.lam = lam
        self.E = E
        self.m = m
        self.components = components
        self.seconds = seconds
        self.source = source
        self._coefficients = {}

    @property
    def k(self):
        return len(self.lam)

    def __repr__(self):
        return (f"SpectralBasis(n={self.E.shape[0]}, k={self.k}, components={self.components}, "
                f"lam=[{self.lam[0]:.3g} .. {self.lam[-1]:.3g}], source={self.source!r})")

    def _k(self, k):
        if k is None:
            return self.k
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 1 <= k <= self.k:
            raise MeshError(f"k must be an integer in 1..{self.k} (the eigenpairs in this basis), not {k!r}")
        return int(k)

    def coefficients(self, X):
        """Spectral coefficients ``E^T M X`` (k, ...) of per-vertex values X (n,) or (n, d).

        Remembered for the last few X (by identity and content), so a slider
        over k only multiplies.
        """
        X = np.asarray(X, dtype=np.float64)
        if X.shape[0] != self.E.shape[0]:
            raise MeshError(f"X has {X.shape[0]} rows but the basis has {self.E.shape[0]} vertices")
        h = hashlib.blake2b(np.ascontiguousarray(X).view(np.uint8), digest_size=16).hexdigest()
        c = self._coefficients.get((h, X.shape))
        if c is None:
            c = self.E.T @ (self.m.reshape((-1,) + (1,) * (X.ndim - 1)) * X)
            if len(self._coefficients) >= 4:
                self._coefficients.pop(next(iter(self._coefficients)))
            self._coefficients[(h, X.shape)] = c
        return c

    def reconstruct(self, X, k=None):
        """``E_k E_k^T M X``: the M-orthogonal projection of X onto the first k eigenvectors."""
        k = self._k(k)
        with _blas_threads(BLAS_THREADS):
            c = self.coefficients(X)
            return self.E[:, :k] @ c[:k]

    def residual_norms(self, X):
        """``||X - X_k||_M`` for k = 1 .. self.k, from the coefficients alone (Parseval).

        X (n,) or (n, d); the norm is ``sqrt(sum_i m_i |x_i - x_k,i|^2)`` in
        length * sqrt(area), summed over the d columns. Returns (k,).
        """
        X = np.asarray(X, dtype=np.float64)
        c = self.coefficients(X).reshape(self.k, -1)
        total = float(np.einsum("i,ij,ij->", self.m, X.reshape(len(self.m), -1), X.reshape(len(self.m), -1)))
        left = total - np.cumsum((c * c).sum(axis=1))
        return np.sqrt(np.maximum(left, 0.0))


def _stored_basis(V, F, k, weights, area, cache, cache_dir, method, tol):
    """The cached or freshly solved basis with at least k eigenpairs (V, F validated)."""
    n = len(V)
    k = _check_k(k, n)
    if method not in ("auto", "dense", "sparse", "arpack"):
        raise MeshError(f"method must be 'auto', 'dense', 'sparse' or 'arpack', not {method!r}")
    key = _key(V, F, weights, area) if cache else None
    if cache:
        hit = _MEMORY.get(key)
        if hit is not None and hit.k >= k:
            _MEMORY.move_to_end(key)
            return hit
    m, C = _operator(V, F, weights, area)
    count, labels = _components(F, m, n)
    if count > 1:
        warnings.warn(
            f"the mesh has {count} connected components: the first {count} eigenvalues are 0 and their "
            f"eigenvectors are the components' indicator functions; each component has its own spectrum",
            MeshWarning,
            stacklevel=4,
        )
    if cache:
        folder = spectral_cache_dir(cache_dir)
        stored = _disk_lookup(folder, key, k)
        if stored is not None:
            basis = SpectralBasis(stored[0], stored[1], m, count, 0.0, "disk")
            _remember(key, basis)
            return basis
    t0 = time.perf_counter()
    # ARPACK and the block solver need k well below n; near k = n only LAPACK makes sense
    dense = method == "dense" or k >= n - 1 or (method == "auto" and (n <= DENSE_MAX_VERTICES or 3 * k > n))
    with _blas_threads(BLAS_THREADS):
        if dense:
            lam, Y = _dense(m, C, k)
        else:
            lam, Y = _sparse(m, C, k, tol, V, "arpack" if method == "arpack" else "sparse")
        lam, E = _finish(m, lam, Y, labels, count)
    basis = SpectralBasis(lam, E, m, count, time.perf_counter() - t0, "solved")
    if cache:
        _disk_store(folder, key, lam, E)
        _remember(key, basis)
    return basis


def spectral_basis(V, F, k, weights="cotan", area="barycentric", *, cache=True, cache_dir=None,
                   method="auto", tol=None):
    """The first k eigenpairs as a :class:`SpectralBasis` (cached; see :func:`eigenbasis`).

    ``basis.reconstruct(X, j)`` then projects per-vertex values X onto the
    first j <= k eigenvectors without solving again (what a slider over k
    needs); ``basis.residual_norms(X)`` gives the error for every j at once.
    """
    V, F = _as_mesh(V, F)
    basis = _stored_basis(V, F, k, weights, area, cache, cache_dir, method, tol)
    if basis.k == k:
        return basis
    return SpectralBasis(basis.lam[:k], basis.E[:, :k], basis.m, basis.components, 0.0, basis.source)


def _remember(key, basis):
    _MEMORY[key] = basis
    _MEMORY.move_to_end(key)
    while len(_MEMORY) > MEMORY_CACHE_SIZE:
        _MEMORY.popitem(last=False)


def eigenbasis(V, F, k, weights="cotan", area="barycentric", *, cache=True, cache_dir=None,
               method="auto", tol=None):
    """The k smallest eigenpairs of ``C e = -lam M e``: ``lam`` ascending >= 0, ``E^T M E = I``.

    ``(M, C) = laplacian(V, F, weights, area)``; ``Delta e_i = -lam_i e_i``.
    The symmetric form ``M^-1/2 (-C) M^-1/2 y = lam y``, ``e = M^-1/2 y`` is
    solved (``M^-1 C`` itself is not symmetric): dense LAPACK for small meshes,
    sparse shift-invert Lanczos (ARPACK) with one LU factorisation otherwise
    (Vallet and Levy 2008). Eigenvectors are M-orthonormal, not orthonormal.

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64
    k : int, 1 <= k <= n
        Number of eigenpairs.
    weights, area : as in :func:`geomlib.laplacian`.
    cache : bool
        Read and write the memory and disk cache (module docstring). With
        ``cache=False`` the basis is always solved for and not stored.
    cache_dir : str or Path, optional
        Cache folder for this call (default: :func:`spectral_cache_dir`).
    method : "auto", "dense", "sparse" or "arpack"
        "auto" is "dense" (LAPACK) up to ``DENSE_MAX_VERTICES`` vertices or
        when k is more than a third of n, "sparse" otherwise: shift-invert
        block Lanczos (:func:`block_lanczos`) on one sparse factorisation,
        falling back to ARPACK if it does not converge; "arpack" uses
        ``scipy.sparse.linalg.eigsh`` with the same factorisation.
    tol : float or None
        Converged when the shift-inverted Ritz residual is at most ``tol``
        times the Ritz value (default 1e-12; eigenvalues then agree with
        ARPACK at full accuracy to about 1e-11 relative).

    Returns
    -------
    lam : (k,) float64
        Eigenvalues in 1/length^2, ascending; ``lam[0] == 0`` exactly (one
        zero per connected component).
    E : (n, k) float64
        Eigenvectors as columns, ``E^T M E = I``; the first is the constant
        ``1/sqrt(area)``; on several components the first ones are the
        components' normalised indicator functions, largest area first. Each
        other column's entry of largest magnitude is positive. Within a
        repeated eigenvalue (e.g. a sphere's 2l + 1 fold ones) any M-orthonormal
        basis of the eigenspace is a correct answer.

    Raises
    ------
    MeshError
        k not an integer, k < 1 or k > n; vertices in no triangle (M singular).

    Warns
    -----
    MeshWarning
        Several connected components (several zero eigenvalues).

    Notes
    -----
    Boundaries need nothing special: the cotangent operator of an open mesh
    gives the natural (Neumann) boundary condition, so the constant is still
    the first eigenvector.
    """
    V, F = _as_mesh(V, F)
    basis = _stored_basis(V, F, k, weights, area, cache, cache_dir, method, tol)
    k = int(k)
    return basis.lam[:k].copy(), basis.E[:, :k].copy(order="F")


def spectral_reconstruction(V, F, k, weights="cotan", area="barycentric", *, cache=True, cache_dir=None,
                            method="auto"):
    """``V_k = E_k E_k^T M V``: the coordinates projected onto the first k eigenvectors.

    The projection is orthogonal in the M inner product (``<f, g>_M = f^T M g``,
    the discrete ``int f g dA``), which is the one in which the eigenvectors
    are orthonormal; ``k = n`` gives back V to rounding. The basis comes from
    :func:`eigenbasis` (cached: a repeated call with another k only
    multiplies).

    Returns
    -------
    V_k : (n, 3) float64, in the units of V.
    """
    V, F = _as_mesh(V, F)
    basis = _stored_basis(V, F, k, weights, area, cache, cache_dir, method, 0.0)
    return basis.reconstruct(V, int(k))
