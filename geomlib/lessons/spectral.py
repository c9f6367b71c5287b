"""Eigenvectors of the Laplace-Beltrami operator and spectral reconstruction (notebook 04).

Convention: the eigenpairs ``(lam_i, e_i)`` solve the symmetric generalised
problem ``C e = -lam M e`` with ``(M, C)`` from :func:`geomlib.laplacian`
(``C`` symmetric negative semidefinite, ``M`` diagonal vertex areas), so
``Delta e = M^-1 C e = -lam e`` with ``lam >= 0``: ``lam`` is a squared
spatial frequency in 1/length^2 (on the unit sphere ``lam -> l (l + 1)``).
Eigenvalues come in ascending order; the eigenvectors are orthonormal in the
``M`` inner product, ``E^T M E = I`` (not ``E^T E = I``: they are samples of
functions normalised by the integral ``int e^2 dA = 1``). The first one is the
constant ``1 / sqrt(area)`` with ``lam = 0``; a mesh with ``c`` connected
components has ``c`` zero eigenvalues, one per component, and their
eigenvectors are the normalised indicator functions of the components
(largest area first); each component then has its own spectrum.

How it is solved (:func:`eigenbasis`, which solves on every call, builds
``(M, C)`` and hands them to :func:`eigenpairs`, the solve for a given pair): ``M^-1 C``
is not symmetric, so with ``D = M^1/2`` the problem becomes ``Q z = lam z``,
``Q = -D^-1 C D^-1``, ``e = D^-1 z`` (Vallet and Levy 2008), handed to
:func:`geomlib.numerics.eigen.smallest_eigenpairs` (dense LAPACK for small
meshes, block Lanczos on one sparse Cholesky factorisation otherwise).

Cache (:func:`spectral_basis`, a separate entry that calls :func:`eigenbasis`
on a miss): a basis is kept in memory (the last few meshes) and on disk
(:mod:`geomlib.numerics.eigenbasis_store`), so a slider over ``k`` re-projects without
solving again and a restarted kernel finds it. ``cache=False`` neither reads
nor writes it; :func:`clear_spectral_cache` empties it;
:func:`spectral_cache_dir` says where it is.
"""

import time
import warnings

import numpy as np
import scipy.sparse as sp
from scipy.sparse import csgraph

from ..mesh.errors import MeshError, MeshWarning
from ..mesh.geometry import bounding_box_diagonal
from ..mesh.validate import as_mesh, whole_number
from ..numerics import eigenbasis_store as basis_cache
from ..numerics.eigen import one_blas_thread, smallest_eigenpairs
from .laplace import assemble_laplacian, check_options
from .operator import pair
from .requirements import positive_vertex_areas

__all__ = [
    "eigenbasis",
    "eigenpairs",
    "spectral_reconstruction",
    "spectral_reconstructions",
    "SpectralBasis",
    "spectral_basis",
    "stored_basis",
    "spectral_cache_dir",
    "clear_spectral_cache",
]

_METHODS = {"auto": "auto", "dense": "dense", "sparse": "sparse", "arpack": "sparse"}


def eigenbasis(V, F, k, weights="cotan", area="barycentric", *, method="auto", tol=1e-10, operator=None):
    """The k smallest eigenpairs of ``C e = -lam M e``: ``lam`` ascending >= 0, ``E^T M E = I``.

    ``(M, C) = laplacian(V, F, weights, area)``, so ``Delta e_i = -lam_i e_i``.
    Solved in the symmetric form ``Q z = lam z`` with ``Q = -M^-1/2 C M^-1/2``
    and ``e = M^-1/2 z`` (Vallet and Levy 2008): dense LAPACK for small meshes,
    block Lanczos on the inverse of ``Q + shift I``, applied by one sparse
    Cholesky factorisation, otherwise (:mod:`geomlib.numerics.eigen`); the
    solve for the pair is :func:`eigenpairs`. Every call solves;
    :func:`spectral_basis` keeps the result in a cache.

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64
    k : int, 1 <= k <= n
        Number of eigenpairs.
    weights, area : as in :func:`geomlib.laplacian`.
    method : "auto", "dense", "sparse" or "arpack"
        "auto" is "dense" (LAPACK) up to ``geomlib.numerics.eigen.DENSE_MAX`` vertices or
        when k is more than a third of n, "sparse" otherwise; "arpack" is
        another name for "sparse" (kept for old calls).
    tol : float
        Relative residual of the sparse solve, ``||Q z - lam z|| <= tol ||Q||``
        (:func:`geomlib.numerics.eigen.smallest_eigenpairs`).
    operator : (M, C), optional
        A pair built already from this (V, F) (:func:`geomlib.laplacian`), solved instead of
        assembling one, as trimesh's smoothers take a Laplacian operator; (V, F) are then
        taken as checked and ``weights`` and ``area`` are not used.

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
        k not an integer, k < 1 or k > n; unknown method; vertices with zero
        vertex area (used by no face, or only by zero-area faces), named, with
        the call that removes them.

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
    if operator is None:  # a call of its own: its door
        check_options(weights, area)
        V, F = as_mesh(V, F)
        operator = assemble_laplacian(V, F, weights, area)
    M, C = pair(operator, len(V))
    k, method = _check_k(k, len(V)), _check_method(method)
    positive_vertex_areas(M, F, "eigenbasis")  # names the vertices without area, and the call that removes them
    return eigenpairs(M, C, k, method=method, tol=tol)


def eigenpairs(M, C, k, *, method="auto", tol=1e-10):
    """The k smallest eigenpairs of ``C e = -lam M e`` for a given pair (M, C): ``lam`` ascending >= 0, ``E^T M E = I``.

    The solve behind :func:`eigenbasis`, for any pair with the signs of
    :func:`geomlib.laplacian`: ``C`` (n, n) symmetric negative semidefinite
    with rows summing to zero, ``M`` (n, n) diagonal and positive. Solved in the
    symmetric form ``Q z = lam z``, ``Q = -M^-1/2 C M^-1/2``, ``e = M^-1/2 z``
    (Vallet and Levy 2008). The null space is known before the solve: on each
    connected piece of the graph of C (the mesh's components), the constant.

    Parameters
    ----------
    M : (n, n) scipy.sparse or array, diagonal, positive (length^2 for the cotangent pair)
    C : (n, n) scipy.sparse or array, symmetric, negative semidefinite
    k : int, 1 <= k <= n
    method, tol : as in :func:`eigenbasis`.

    Returns
    -------
    lam : (k,) float64, ascending, ``lam[0] == 0``; E : (n, k) float64, ``E^T M E = I``
        (see :func:`eigenbasis` for the null space, signs and repeated eigenvalues).

    Raises
    ------
    MeshError
        M or C not (n, n), M not diagonal or with an entry <= 0, k outside 1..n, unknown method.
    """
    M, C = pair((M, C))
    m = positive_vertex_areas(M, None, "eigenpairs")
    k, method = _check_k(k, len(m)), _check_method(method)
    D_inv = sp.diags(1.0 / np.sqrt(m))  # M^-1/2
    Q = D_inv @ (-C) @ D_inv  # symmetric PSD: Q z = lam z (notebook 04's symbol)
    shift = 1e-4 * 4.0 * np.pi / m.sum()  # far below lam_1 (Weyl: about 4 pi / area)
    count, labels = _components(C, m)
    Z0 = null_vectors(labels, count, m)  # Q (sqrt(A_i) on one component, 0 elsewhere) = 0: known, kept out of the solve
    lam, Z = smallest_eigenpairs(Q.tocsr(), k, shift, _METHODS[method], tol, null=Z0)
    E = D_inv @ Z  # e = M^-1/2 z, so E^T M E = Z^T Z = I
    return _tidy(lam, E, m, count, labels)


def _check_k(k, n):
    return whole_number("k", k, 1, n, why=f" (the mesh has only {n} vertices: at most n = {n} eigenpairs exist)")


def _check_method(method):
    if method not in _METHODS:
        raise MeshError(f"method must be 'auto', 'dense', 'sparse' or 'arpack', not {method!r}")
    return method


def _components(C, m):
    """(count, label per vertex) of the pieces the graph of C links, numbered by area, largest first.

    The graph of C is the mesh's edges, so its pieces are the mesh's connected
    components; ties in area go to the piece with the smallest vertex index.
    """
    count, labels = csgraph.connected_components(C, directed=False)  # numbered by their smallest vertex
    size = np.bincount(labels, weights=m, minlength=count)
    rank = np.empty(count, dtype=np.int64)
    rank[np.lexsort((np.arange(count), -size))] = np.arange(count)
    return count, rank[labels]


def null_vectors(labels, count, m):
    """Orthonormal (n, count) eigenvectors of ``Q = -M^-1/2 C M^-1/2`` for ``lam = 0``, one per connected component.

    Column c is ``sqrt(m)`` on the vertices with label c (components numbered by
    area, largest first, as :func:`eigenbasis` orders them) and 0 elsewhere,
    normalised: ``Q`` maps it to 0 because every row of C sums to 0.
    """
    Z0 = (labels[:, None] == np.arange(count)[None, :]) * np.sqrt(m)[:, None]
    return Z0 / np.linalg.norm(Z0, axis=0)


def _tidy(lam, E, m, count, labels):
    """Exact zeros and indicator functions for the null space, M-normalised columns, fixed signs."""
    lam = np.array(lam, dtype=np.float64)
    E = np.asfortranarray(E)
    E /= np.sqrt(np.einsum("ij,i,ij->j", E, m, E))[None, :]  # Z^T Z = I only to rounding
    if count > 1:
        warnings.warn(
            f"the mesh has {count} connected components: the first {count} eigenvalues are 0 "
            f"and their eigenvectors are the components' indicator functions; each component "
            f"has its own spectrum",
            MeshWarning,
            stacklevel=4,  # _tidy <- eigenpairs <- eigenbasis <- the caller
        )
    c = min(count, len(lam))
    # The solver returns some rotation of the null space (rounding decides which):
    # replace it by the normalised indicator function of each component.
    scale = max(abs(lam[-1]), 4.0 * np.pi / m.sum())
    if np.all(np.abs(lam[:c]) <= 1e-8 * scale):
        areas = np.bincount(labels, weights=m, minlength=count)[:c]
        E[:, :c] = (labels[:, None] == np.arange(c)[None, :]) / np.sqrt(areas)[None, :]
        lam[:c] = 0.0
    lam = np.maximum(lam, 0.0)  # -C is positive semidefinite; rounding can dip below zero
    big = np.argmax(np.abs(E), axis=0)  # sign: the entry of largest magnitude is positive
    E *= np.where(E[big, np.arange(len(lam))] < 0, -1.0, 1.0)[None, :]
    return lam, E


class SpectralBasis:
    """The first k Laplace-Beltrami eigenpairs of a mesh, ready to project onto.

    Convention: ``C e = -lam M e``, ``lam`` ascending >= 0, ``E^T M E = I``.
    Made by :func:`spectral_basis`. Projections use the ``M`` inner product
    ``<f, g>_M = f^T M g`` (the discrete ``int f g dA``).

    Attributes
    ----------
    lam : (k,) float64, 1/length^2
    E : (n, k) float64, Fortran order (the first j columns are one block)
    m : (n,) float64 diagonal of M, length^2
    components : int, zero eigenvalues among the k (the connected components when k reaches them)
    seconds : float, time the solve took (0 when it came from the cache)
    source : "solved", "memory" or "disk"
    """

    def __init__(self, lam, E, m, seconds=0.0, source="solved"):
        self.lam, self.E, self.m = lam, np.asfortranarray(E), m
        self.components, self.seconds, self.source = int((lam == 0).sum()), seconds, source
        self._whole = self  # the basis this one is the first k columns of: it keeps the coefficients
        self._last = (None, None)  # (key of X, E^T M X): a slider over k only multiplies

    @property
    def k(self):
        return len(self.lam)

    def __repr__(self):
        return (
            f"SpectralBasis(n={self.E.shape[0]}, k={self.k}, components={self.components}, "
            f"lam=[{self.lam[0]:.3g} .. {self.lam[-1]:.3g}], source={self.source!r})"
        )

    def first(self, k, source=None):
        """The basis of the first k eigenpairs (views, no copy)."""
        k = self._k(k)
        if k == self.k and source is None:
            return self
        part = SpectralBasis(self.lam[:k], self.E[:, :k], self.m, self.seconds, source or self.source)
        part._whole = self._whole
        return part

    def _k(self, k):
        if k is None:
            return self.k
        return whole_number("k", k, 1, self.k, why=f" (this basis holds the eigenpairs 1..{self.k})")

    def coefficients(self, X):
        """Spectral coefficients ``E^T M X`` (k, ...) of per-vertex values X (n,) or (n, d).

        Those of the last X are remembered (by content), so a slider over k only multiplies.
        """
        X = np.asarray(X, dtype=np.float64)
        if X.shape[0] != self.E.shape[0]:
            raise MeshError(f"X has {X.shape[0]} rows but the basis has {self.E.shape[0]} vertices")
        whole, name = self._whole, basis_cache.key(X)
        if whole._last[0] != name:
            whole._last = (name, whole.E.T @ (self.m.reshape((-1,) + (1,) * (X.ndim - 1)) * X))
        return whole._last[1][: self.k]

    def reconstruct(self, X, k=None):
        """``E_k E_k^T M X``: the M-orthogonal projection of X onto the first k eigenvectors."""
        k = self._k(k)
        with one_blas_thread():  # see geomlib.numerics.eigen: a 2-thread pool on a busy 2-core machine is slower
            return self.E[:, :k] @ self.coefficients(X)[:k]

    def residual_norms(self, X):
        """``||X - X_k||_M`` for k = 1 .. self.k, from the coefficients alone (Parseval).

        X (n,) or (n, d); the norm is ``sqrt(sum_i m_i |x_i - x_k,i|^2)`` in
        length * sqrt(area), summed over the d columns. Returns (k,).
        """
        X = np.asarray(X, dtype=np.float64)
        c = self.coefficients(X).reshape(self.k, -1)
        Xf = X.reshape(len(self.m), -1)
        total = float(np.einsum("i,ij,ij->", self.m, Xf, Xf))
        return np.sqrt(np.maximum(total - np.cumsum((c * c).sum(axis=1)), 0.0))


def spectral_basis(
    V, F, k, weights="cotan", area="barycentric", *, cache=True, cache_dir=None, method="auto", tol=1e-10
):
    """:func:`eigenbasis` behind a cache, as a :class:`SpectralBasis`.

    The basis of a mesh and its options is kept in memory (the last few) and
    on disk (:mod:`geomlib.numerics.eigenbasis_store`, under :func:`spectral_cache_dir`
    or ``cache_dir``), so asking again, with any k up to the stored one, or
    after a kernel restart, does not solve. ``cache=False`` neither reads nor
    writes it. ``basis.reconstruct(X, j)`` then projects per-vertex values X
    onto the first j <= k eigenvectors (what a slider over k needs);
    ``basis.residual_norms(X)`` gives the error for every j at once.
    """
    check_options(weights, area)
    V, F = as_mesh(V, F)
    return stored_basis(V, F, k, weights, area, cache, cache_dir, method, tol)


def stored_basis(V, F, k, weights, area, cache=True, cache_dir=None, method="auto", tol=1e-10):
    """:func:`spectral_basis` of a checked mesh ((V, F) as ``as_mesh`` returns them, options checked)."""
    k, _ = _check_k(k, len(V)), _check_method(method)
    name, folder = basis_cache.key(V, F, "eigenbasis", weights, area), spectral_cache_dir(cache_dir)
    kept = basis_cache.recall(name) if cache else None
    if kept is not None and kept.k >= k:
        return kept.first(k, "memory")
    stored = basis_cache.load(folder, name, k) if cache else None
    if stored is not None:
        basis = SpectralBasis(*stored, source="disk")
    else:
        t0 = time.perf_counter()
        M, C = assemble_laplacian(V, F, weights, area)
        lam, E = eigenbasis(V, F, k, weights, area, method=method, tol=tol, operator=(M, C))
        seconds = time.perf_counter() - t0
        m = M.diagonal()
        basis = SpectralBasis(lam, E, m, seconds)
        if cache:
            basis_cache.store(folder, name, lam, basis.E, m)
    if cache:
        basis_cache.remember(name, basis)
    return basis.first(k)


def spectral_reconstruction(V, F, k, weights="cotan", area="barycentric", *, cache=True, cache_dir=None, method="auto"):
    """``V_k = E (E^T M V)``: the coordinates projected onto the first k eigenvectors.

    The projection is orthogonal in the M inner product (``<f, g>_M = f^T M g``,
    the discrete ``int f g dA``), the one in which the eigenvectors are
    orthonormal; ``k = n`` gives back V to rounding. The basis comes from
    :func:`spectral_basis` (``cache`` and ``cache_dir`` as there), so a
    repeated call with another k only multiplies.

    Returns
    -------
    V_k : (n, 3) float64, in the units of V.
    """
    check_options(weights, area)
    V, F = as_mesh(V, F)
    return stored_basis(V, F, k, weights, area, cache, cache_dir, method).reconstruct(V)


def spectral_reconstructions(V, F, ks, solve=eigenpairs):
    """``V_k = E_k E_k^T M V`` for each count k of ``ks``, from one eigen-solve, and the error of each.

    ``(M, C) = laplacian(V, F)`` (cotangent weights, barycentric areas); ``solve(M, C, max(ks))``
    gives the eigenpairs (:func:`eigenpairs` by default; notebook 04 hands the student's solver,
    or one returning a basis computed already). The error of ``V_k`` is the area-weighted RMS
    distance over the bounding-box diagonal, ``sqrt(||V - V_k||_M^2 / area) / diag`` with
    ``||X||_M^2 = sum_i A_i |x_i|^2``: measured on ``V - V_k`` itself, not by Parseval from the
    coefficients, so it says what the reconstruction is, rounding included.

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64
    ks : sequence of int, each 1 <= k <= n
    solve : callable (M, C, k) -> (lam (k,), E (n, k)), ``E^T M E = I``

    Returns
    -------
    V_ks : (len(ks), n, 3) float64, in the units of V, in the order of ``ks``.
    err : (len(ks),) float64, dimensionless; never growing with k (nested projections).
    """
    V, F = as_mesh(V, F)
    ks = [_check_k(k, len(V)) for k in ks]
    if not ks:
        raise MeshError("ks is empty: give at least one count k")
    M, C = assemble_laplacian(V, F, "cotan", "barycentric")
    m = M.diagonal()
    E = np.asarray(solve(M, C, max(ks))[1])
    coefficients = E.T @ (m[:, None] * V)  # <e_i, x>_M, one row per eigenvector
    V_ks = np.stack([E[:, :k] @ coefficients[:k] for k in ks])
    gap = V_ks - V[None]
    err = np.sqrt(np.einsum("i,kij,kij->k", m, gap, gap) / m.sum()) / bounding_box_diagonal(V)
    return V_ks, err


def spectral_cache_dir(cache_dir=None):
    """The folder holding cached eigenbases (it need not exist yet); see :func:`geomlib.numerics.eigenbasis_store.folder`."""
    return basis_cache.folder(cache_dir)


def clear_spectral_cache(cache_dir=None, memory=True):
    """Delete the cached eigenbases on disk (and in memory); returns the number of files removed."""
    return basis_cache.clear(cache_dir, memory)
