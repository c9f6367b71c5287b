"""Checks of the exercises of notebook 01 (the uniform Laplacian)."""

import numpy as np

from ..laplace import laplacian
from .result import Mistake, call, close, exercise, matrix_pair

__all__ = ["uniform_laplacian"]

# a tetrahedron (valence 3 everywhere) and a 3 x 3 vertex grid (valences 2..6)
_TET_V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
_TET_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
_GRID_V = np.array([[x, y, 0.0] for y in range(3) for x in range(3)])
_GRID_F = np.array([[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4], [3, 4, 7], [3, 7, 6], [4, 5, 8], [4, 8, 7]])


@exercise("uniform_laplacian", reread="section 2 · The uniform Laplacian, derived")
def uniform_laplacian(fn):
    """Check ``fn(V, F) -> (M, C)``: C_ij = 1 on edges, C_ii = -valence, M = diag(valence)."""
    checked = []
    for label, V, F in (("a tetrahedron", _TET_V, _TET_F), ("a 3 x 3 grid", _GRID_V, _GRID_F)):
        M, C = matrix_pair(call(fn, V.copy(), F.copy()), n=len(V))
        M_ref, C_ref = (A.toarray() for A in laplacian(V, F, weights="uniform"))
        off = ~np.eye(len(V), dtype=bool)
        if close(C, -C_ref):
            raise Mistake("the sign of C is flipped",
                          "C_ij = +1 for each edge ij and C_ii = -valence, so that C is negative semidefinite")
        if close(C[off], C_ref[off]) and np.allclose(np.diag(C), 0):
            raise Mistake("the diagonal of C is missing (its rows do not sum to zero)",
                          "set C_ii = -(number of neighbours of i)")
        if close(C, C_ref / np.diag(M_ref)[:, None]):
            raise Mistake("C is already divided by the valence: that is M^-1 C, not C",
                          "keep C_ij = 1 and put the valences in M")
        if close(C[off], 2 * C_ref[off]):
            raise Mistake("every edge is counted twice (off-diagonal entries are 2)",
                          "each edge appears in two triangles; set its entry to 1, do not add")
        if not close(C, C.T):
            raise Mistake("C is not symmetric", "set both C_ij and C_ji for every edge")
        if not close(C, C_ref):
            raise Mistake(f"C differs from the uniform Laplacian on {label}",
                          "C_ij = 1 for neighbours, C_ii = -valence, 0 elsewhere")
        if close(M, np.eye(len(V))):
            raise Mistake("M is the identity", "M = diag(valence), the number of neighbours of each vertex")
        if close(M, -M_ref):
            raise Mistake("M has the wrong sign", "M holds positive valences")
        if not close(M, M_ref):
            raise Mistake(f"M differs from diag(valence) on {label}", "M_ii = number of neighbours of i")
        checked.append(label)
    return checked
