"""The Laplacian of one mesh with its options, built once: M, C, the vertex areas, the moving/fixed split.

Notebooks 05 and 06 step ``P' = P + tau M^-1 C P`` and solve ``(M - tau C) P' = M P``
many times with one operator. :class:`LaplaceOperator` holds what every step,
step limit and fixed point of one mesh needs; :func:`laplace_operator` builds it
on first use and keeps the last ``CACHE_SIZE`` in memory under one key,
:func:`geomlib.numerics.eigenbasis_store.key` of the mesh's bytes and the options (for
uniform weights of F and the vertex count only: that operator does not depend on
the positions, so every noisy copy of a mesh shares it). So a smoother, a step
limit and a slider on the same mesh assemble it once.

Boundary condition (open meshes): ``"fixed"`` keeps the boundary vertices B where
they are (a Dirichlet condition), ``"free"`` moves them with the same operator.
Both schemes take the fixed boundary the way notebooks 05 and 06 write it: the
rows of the fixed vertices are replaced by ``P'_B = P_B`` (:attr:`M_step` and
:attr:`C_step`: ``M_BB = 1``, ``C_B* = 0``), so the steps shown there run on the
whole mesh unchanged. In the implicit system the known ``P_B`` then moves to the
right-hand side and the moving block ``M_II - tau C_II`` stays symmetric positive
definite (:meth:`LaplaceOperator.step_solver`).
"""

from collections import OrderedDict
from functools import cached_property

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from ..mesh.errors import MeshError
from ..mesh.topology import boundary_vertices
from ..mesh.validate import as_mesh, check_choice
from ..numerics import eigenbasis_store as cache
from ..numerics.eigen import largest_eigenpair, largest_eigenvalue
from ..numerics.factor import factor_seconds, factorise
from ..numerics.progress import Stages
from .laplace import assemble_laplacian, check_options
from .requirements import positive_vertex_areas

__all__ = ["LaplaceOperator", "laplace_operator", "kept_operator", "BOUNDARY_CONDITIONS", "SOLVERS", "CACHE_SIZE"]

BOUNDARY_CONDITIONS = ("fixed", "free")

#: How an implicit step's system is solved: a sparse Cholesky factorisation, or
#: conjugate gradients with a Jacobi preconditioner. (Desbrun et al. 1999 solved their
#: system with a preconditioned bi-conjugate gradient, as their operator M^-1 C is not
#: symmetric; multiplied by M, as here, the system is symmetric and plain CG applies.)
SOLVERS = ("cholesky", "cg")

#: Operators kept in memory (each about 40 MB at 164k vertices).
CACHE_SIZE = 6

_OPERATORS = OrderedDict()


def laplace_operator(V, F, weights="cotan", area="barycentric", boundary_condition="fixed"):
    """The :class:`LaplaceOperator` of (V, F) with these options: built on first use, then from memory."""
    check_options(weights, area)
    check_choice("boundary_condition", boundary_condition, BOUNDARY_CONDITIONS)
    V, F = as_mesh(V, F)
    return kept_operator(V, F, weights, area, boundary_condition)


def kept_operator(V, F, weights="cotan", area="barycentric", boundary_condition="fixed"):
    """:func:`laplace_operator` of a checked mesh ((V, F) as ``as_mesh`` returns them, options checked)."""
    # the uniform operator is combinatorial (valences and edges): one per F, whatever the positions
    shape = V if weights == "cotan" else len(V)
    name = cache.key(shape, F, weights, area if weights == "cotan" else None, boundary_condition)
    L = _OPERATORS.pop(name, None) or LaplaceOperator.of(V, F, weights, area, boundary_condition)
    _OPERATORS[name] = L  # most recently used last
    while len(_OPERATORS) > CACHE_SIZE:
        _OPERATORS.popitem(last=False)
    return L


class LaplaceOperator:
    """``Delta = M^-1 C`` of one mesh (:func:`geomlib.laplacian`) with the moving and fixed vertices.

    Attributes
    ----------
    weights, area, boundary_condition : the options it was built with.
    M : (n, n) scipy.sparse DIA, C : (n, n) scipy.sparse CSR
        As :func:`geomlib.laplacian` returns them (C symmetric NSD, rows summing to zero).
    m : (n,) float64
        The vertex areas, the diagonal of M (length^2 for cotan, valences for uniform).
    moving : (n,) bool
        The vertices the schemes move: all, or all but the boundary ones (``"fixed"``).
    I, B : int64 arrays
        The moving and the fixed vertices.
    M_step, C_step : sparse (n, n)
        M and C with the fixed vertices' rows replaced by ``P'_B = P_B`` (``M_BB = 1``,
        ``C_B* = 0``); M and C themselves when nothing is fixed. The steps of notebooks 05
        and 06 take these.

    ``operator=(M, C)``: a pair built already (signs and shapes of :func:`geomlib.laplacian`),
    taken instead of assembling one from V, as trimesh's smoothers take a Laplacian operator;
    ``weights`` and ``area`` then only name it.
    """

    def __init__(self, V, F, weights="cotan", area="barycentric", boundary_condition="fixed", *, operator=None):
        check_options(weights, area)
        check_choice("boundary_condition", boundary_condition, BOUNDARY_CONDITIONS)
        V, F = as_mesh(V, F)
        self._build(V, F, weights, area, boundary_condition, operator)

    @classmethod
    def of(cls, V, F, weights="cotan", area="barycentric", boundary_condition="fixed", operator=None):
        """The operator of a checked mesh ((V, F) as ``as_mesh`` returns them, options checked)."""
        L = cls.__new__(cls)
        L._build(V, F, weights, area, boundary_condition, operator)
        return L

    def _build(self, V, F, weights, area, boundary_condition, operator):
        self.weights, self.area, self.boundary_condition = weights, area, boundary_condition
        self.M, C = assemble_laplacian(V, F, weights, area) if operator is None else pair(operator, len(V))
        self.C = C.tocsr()
        self.m = self.M.diagonal()
        self.moving = np.ones(len(V), dtype=bool)
        if boundary_condition == "fixed":
            self.moving[boundary_vertices(F, len(V))] = False
        self.I, self.B = np.flatnonzero(self.moving), np.flatnonzero(~self.moving)
        self.M_step, self.C_step = self.M, self.C
        if len(self.B):
            self.M_step = sp.diags(np.where(self.moving, self.m, 1.0))
            self.C_step = (sp.diags(self.moving.astype(np.float64)) @ self.C).tocsr()
            self.C_step.eliminate_zeros()

    def require_positive_areas(self, F, what):
        """Raise MeshError (naming ``what`` and the vertices) unless every vertex area is positive."""
        positive_vertex_areas(self.M, F, what)

    @cached_property
    def blocks(self):
        """``(C_II, C_IB)``: C's rows of the moving vertices, split into moving and fixed columns."""
        if not len(self.B):
            return self.C, sp.csr_matrix((len(self.I), 0))  # nothing fixed: no copy of C
        C_I = self.C[self.I]
        return C_I[:, self.I].tocsr(), C_I[:, self.B].tocsr()

    def symmetric_block(self):
        """``S = -M^-1/2 C M^-1/2`` on the moving vertices: symmetric PSD, the spectrum of ``-Delta`` there."""
        D = sp.diags(1.0 / np.sqrt(self.m[self.I]))
        return (D @ (-self.blocks[0]) @ D).tocsr()

    @cached_property
    def lam_max(self):
        """The largest eigenvalue of ``-Delta`` on the moving vertices (0 when none move)."""
        return largest_eigenvalue(self.symmetric_block()) if len(self.I) else 0.0

    @cached_property
    def top_mode(self):
        """``(lam_max, y)``: the largest eigenpair of :meth:`symmetric_block` (ARPACK, relative accuracy 1e-8)."""
        return largest_eigenpair(self.symmetric_block()) if len(self.I) else (0.0, np.zeros(0))

    def factorise(self, tau):
        """The Cholesky factorisation of the moving block ``M_II - tau C_II`` (symmetric positive definite)."""
        A = sp.diags(self.m[self.I]) - tau * self.blocks[0]
        with Stages(["factorising M - tau C"], factor_seconds(len(self.I)), "implicit smoothing"):
            try:
                return factorise(A)
            except np.linalg.LinAlgError as exc:
                raise MeshError(f"implicit smoothing: M - {tau:.6g} C is not positive definite ({exc})") from None

    def step_solver(self, tau, factor=None, solver="cholesky"):
        """``solve(R)``: the X with ``(M_step - tau C_step) X = R``, the system of one implicit step.

        The fixed rows read ``X_B = R_B``; moving the known values to the right
        leaves ``(M_II - tau C_II) X_I = R_I + tau C_IB X_B``, solved by its
        Cholesky factor (``factor``, or factorised now) or, with ``solver="cg"``,
        by Jacobi-preconditioned conjugate gradients started from ``R_I / m_I``
        (which is ``P_I`` when ``R = M P``), relative residual 1e-10.
        """
        check_choice("solver", solver, SOLVERS)
        I, B = self.I, self.B
        C_II, C_IB = self.blocks
        if solver == "cholesky":
            factor = self.factorise(tau) if factor is None else factor
            if not len(B):
                return factor.solve  # nothing fixed: the moving block is the whole system
            solve_block = factor.solve
        else:
            A = (sp.diags(self.m[I]) - tau * C_II).tocsr()
            jacobi = sp.diags(1.0 / A.diagonal())

            def solve_block(rhs, x0):
                X = np.empty_like(rhs)
                for j in range(rhs.shape[1]):
                    X[:, j], info = sla.cg(
                        A, rhs[:, j], x0=x0[:, j], rtol=1e-10, atol=0.0, M=jacobi, maxiter=20 * len(I) + 100
                    )
                    if info != 0:
                        raise MeshError(f"implicit smoothing: CG did not converge (info {info}); use solver='cholesky'")
                return X

        def solve(R):
            X = np.array(R, dtype=np.float64)  # the fixed rows: X_B = R_B
            rhs = R[I] + tau * (C_IB @ R[B])
            X[I] = solve_block(rhs) if solver == "cholesky" else solve_block(rhs, R[I] / self.m[I, None])
            return X

        return solve


def pair(operator, n=None):
    """``(M, C)`` of a built operator handed to a smoother or a solve, as (DIA, CSR) matrices.

    Raises MeshError unless it is a pair of square matrices of one size (n, when given) and M is diagonal.
    """
    try:
        M, C = operator
    except (TypeError, ValueError):
        raise MeshError("the operator must be a pair (M, C) as geomlib.laplacian returns it") from None
    M, C = sp.csr_matrix(M), sp.csr_matrix(C)
    size = M.shape[0] if n is None else n
    if M.shape != (size, size) or C.shape != (size, size):
        raise MeshError(f"M and C must be square and of one size ({size}): M is {M.shape}, C is {C.shape}")
    m = M.diagonal()
    if abs(M - sp.diags(m)).max() > 0:
        raise MeshError("M must be diagonal (the lumped vertex areas): its off-diagonal entries are not all zero")
    return sp.diags(m), C
