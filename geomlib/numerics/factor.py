"""Sparse symmetric positive definite systems: factorise once, solve many times.

One call, :func:`factorise`, returns an object whose ``solve(B)`` returns
``A^-1 B``. Behind it is CHOLMOD's sparse Cholesky factorisation ``A = L L^T``
(Chen, Davis, Hager and Rajamanickam 2008) through the ``cholespy`` binding,
which ships CHOLMOD with its own fill-reducing ordering inside its wheels.
CHOLMOD chooses the elimination order itself, so no ordering is written here.
The wheels link the reference (single-threaded) BLAS, so a factorisation uses
one core and does not compete with a BLAS thread pool on 2-core machines.

Why not scipy's ``splu``: the matrices here (``M - tau C`` of implicit
smoothing, ``S + s I`` of the shift-invert eigensolver) are symmetric positive
definite, and SuperLU treats them as general matrices with a column ordering.
Measured on icospheres on a 2-core machine (``M - 10 h^2 C``, three
right-hand sides; load average about 3):

=========  ==================  ==================
vertices   cholespy            splu (COLAMD)
           factor / solve      factor / solve
=========  ==================  ==================
10,242     0.15 s / 2 ms       0.20 s / 15 ms
40,962     0.89 s / 18 ms      2.3 s / 53 ms
163,842    7.0 s / 64 ms       19.9 s / 1.2 s
=========  ==================  ==================

The last :data:`CACHE_SIZE` factorisations are kept in memory under a hash of
the matrix's entries, so the same matrix met again costs a hash instead of a
factorisation. Notebook 06 meets it often: the first step of a rebuilt-operator
run has the fixed operator's matrix, a slider's step value was often used by an
earlier cell. On a reader's 200k-vertex mesh a factorisation takes 2-4 s and
the hash 20 ms; there notebook 06 finds 4 of its 24 factorisations in the cache
(benchmarks/bench_large_mesh.py), and 7 of 85 with its own meshes.
"""

from collections import OrderedDict

import numpy as np
import scipy.sparse as sp
from cholespy import CholeskySolverD, MatrixType

from . import eigenbasis_store as cache

__all__ = ["Factor", "factorise", "factor_seconds", "forget_factorisations", "CACHE_SIZE"]

#: Factorisations kept in memory (CHOLMOD's factor of a 200k-vertex mesh is about 100 MB).
CACHE_SIZE = 2

_FACTORS = OrderedDict()


def factor_seconds(n):
    """A rough estimate of the factorisation time of an n-unknown mesh matrix, in seconds.

    Fitted to the table in the module docstring (about n^1.5); used only to
    decide whether a progress message is worth showing.
    """
    return 0.9 * (n / 40_000) ** 1.5


class Factor:
    """The Cholesky factorisation of a sparse symmetric positive definite (n, n) matrix.

    Raises ``numpy.linalg.LinAlgError`` when the matrix is not positive definite.
    """

    def __init__(self, A):
        A = _canonical(A)
        self.n = A.shape[0]
        if self.n == 0:
            self._solver = None
            return
        try:
            self._solver = CholeskySolverD(
                self.n,
                A.indptr.astype(np.int32),
                A.indices.astype(np.int32),
                np.ascontiguousarray(A.data),
                MatrixType.CSR,
            )
        except ValueError as exc:  # cholespy: "Matrix is not positive definite!"
            raise np.linalg.LinAlgError(f"the matrix is not positive definite ({exc})") from None

    def solve(self, B):
        """``A^-1 B`` for B of shape (n,) or (n, r); returns a new array of B's shape."""
        B = np.ascontiguousarray(B, dtype=np.float64)
        X = np.empty_like(B)
        if self.n:
            self._solver.solve(B, X)
        return X


def _canonical(A):
    """A as CSR float64 with sorted, summed entries: equal matrices get equal arrays."""
    A = sp.csr_matrix(A, dtype=np.float64)
    A.sum_duplicates()
    return A


def factorise(A):
    """Factorise the sparse symmetric positive definite matrix A (see :class:`Factor`),
    or hand back the factorisation of an equal matrix kept from before (module docstring)."""
    A = _canonical(A)
    name = cache.key(A.shape, A.indptr, A.indices, A.data)
    factor = _FACTORS.pop(name, None) or Factor(A)
    _FACTORS[name] = factor  # most recently used last
    while len(_FACTORS) > CACHE_SIZE:
        _FACTORS.popitem(last=False)
    return factor


def forget_factorisations():
    """Empty the memory of :func:`factorise`, so that the next call factorises (benchmarks time that)."""
    _FACTORS.clear()
