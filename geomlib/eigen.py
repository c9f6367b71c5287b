"""Eigenpairs of sparse symmetric positive semidefinite matrices: the smallest few, the largest one.

* :func:`smallest_eigenpairs` -- the k smallest eigenpairs of S: dense LAPACK
  (``scipy.linalg.eigh``) for small matrices, else ARPACK's Lanczos iteration
  (``scipy.sparse.linalg.eigsh``) in shift-invert mode around ``-shift``, with
  ``(S + shift I)^-1`` applied by one sparse Cholesky factorisation
  (:mod:`geomlib.factor`) computed once.
* :func:`largest_eigenpair` -- the largest eigenpair, by ARPACK without any
  factorisation (only products with S are needed).

Both run with one BLAS thread (``threadpoolctl``): on 2-core machines shared
with other busy processes, a 2-thread BLAS pool made dense ``eigh`` at 642
vertices 20x slower (2.1 s instead of 0.1 s) and ARPACK's vector work several
times slower, while the sparse factorisation does not use BLAS threads anyway.
"""

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as sla
from threadpoolctl import ThreadpoolController

from .factor import factor_seconds, factorise
from .progress import Stages

__all__ = ["DENSE_MAX", "smallest_eigenpairs", "largest_eigenpair", "one_blas_thread", "solve_seconds"]

#: Matrices of at most this size are solved with dense LAPACK.
DENSE_MAX = 600

_CONTROLLER = None


def one_blas_thread():
    """A context manager that runs its block with one BLAS thread (and restores the setting)."""
    global _CONTROLLER
    if _CONTROLLER is None:  # looking up the loaded BLAS libraries costs milliseconds: once
        _CONTROLLER = ThreadpoolController()
    return _CONTROLLER.limit(limits=1, user_api="blas")


def solve_seconds(n, k):
    """A rough estimate of :func:`smallest_eigenpairs` on an n x n mesh matrix, in seconds.

    From measurements of shift-invert ARPACK (0.4 s at n = 10k, k = 50; time
    about n^1.2 k^0.8); used only to decide whether to show progress.
    """
    return factor_seconds(n) + 0.3 * (n / 10_000) ** 1.2 * (k / 50) ** 0.8


def smallest_eigenpairs(S, k, shift, method="auto", tol=0.0):
    """The k smallest eigenpairs of a sparse symmetric positive semidefinite S (n, n).

    Parameters
    ----------
    S : (n, n) sparse, symmetric positive semidefinite
    k : int, 1 <= k <= n
    shift : float > 0
        ``S + shift I`` is factorised; the Lanczos iteration converges fastest
        to the eigenvalues nearest ``-shift``, i.e. the smallest. Must be far
        below the smallest non-zero eigenvalue and far above rounding.
    method : "auto", "dense" or "sparse"
        "auto": dense when ``n <= DENSE_MAX``, when k > n / 3 or k >= n - 1
        (ARPACK needs k well below n), sparse otherwise.
    tol : float
        ARPACK's relative accuracy of the eigenvalues (0: machine precision).

    Returns
    -------
    lam : (k,) ascending; Y : (n, k) with ``Y^T Y = I``.
    """
    n = S.shape[0]
    dense = method == "dense" or k >= n - 1 or (method == "auto" and (n <= DENSE_MAX or 3 * k > n))
    with one_blas_thread():
        if dense:
            A = S.toarray()
            A = 0.5 * (A + A.T)
            return la.eigh(A, subset_by_index=[0, k - 1], driver="evr") if k < n else la.eigh(A, driver="evd")
        with Stages(["factorising", "Lanczos iterations"], solve_seconds(n, k), f"{k} eigenpairs") as bar:
            shifted = factorise(S + shift * sp.eye(n, format="csr"))
            bar.next()
            OPinv = sla.LinearOperator((n, n), matvec=shifted.solve, dtype=np.float64)
            v0 = np.random.default_rng(0).uniform(0.5, 1.5, n)  # fixed: reproducible results
            lam, Y = sla.eigsh(S, k=k, sigma=-shift, which="LM", OPinv=OPinv, v0=v0, tol=tol)
    order = np.argsort(lam, kind="stable")
    return lam[order], Y[:, order]


def largest_eigenpair(S, tol=1e-8):
    """The largest eigenvalue of a sparse symmetric S (n, n) and its unit eigenvector (n,).

    Dense LAPACK up to ``DENSE_MAX`` rows, else ARPACK (``which="LA"``) from a
    fixed start vector, relative accuracy ``tol``. Lanczos Ritz values approach
    the largest eigenvalue from below, so it is never overestimated.
    """
    n = S.shape[0]
    with one_blas_thread():
        if n <= DENSE_MAX:
            lam, Y = np.linalg.eigh(S.toarray())
            return float(lam[-1]), Y[:, -1]
        v0 = np.random.default_rng(0).standard_normal(n)
        lam, Y = sla.eigsh(S, k=1, which="LA", v0=v0, tol=tol, ncv=min(n - 1, 40))
    return float(lam[0]), Y[:, 0]
