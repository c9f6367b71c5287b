"""Checks of the exercises of notebook 04: the generalised eigenproblem, and the reconstruction from k eigenvectors.

The cases, each small enough for a dense solve here and for any solver a learner
may choose (``scipy.linalg.eigh`` on dense matrices, ``scipy.sparse.linalg.eigsh``,
which cannot compute all n pairs, so every k is below n):

* a jittered ellipsoid with 42 vertices, closed (vertex areas differing by a
  factor of about 3, so that M matters);
* an open jittered saddle with 49 vertices (a boundary: the natural, Neumann,
  condition of the cotangent operator, whose null mode is still the constant);
* the 42-vertex icosphere, whose eigenvalues repeat: any M-orthonormal basis
  of a repeated eigenvalue's eigenspace is right. Asked for k = 4 (the
  constant and the threefold lam_1), not 9: at k = 9 ``eigsh`` (its Lanczos
  iteration starts from one random vector) missed one of the five copies of
  lam_4 in 44 of 200 runs; at k = 4 it found all three in 200 of 200.

``eigenpairs(fn)`` checks ``fn(M, C, k) -> (lam, E)`` by what defines the answer,
not by comparing with one basis: ``lam`` the k smallest eigenvalues in ascending
order, ``C E = -M E diag(lam)`` and ``E^T M E = I`` (so each eigenvector's sign and
the basis of a repeated eigenspace are free). ``spectral_reconstruction(fn)``
checks ``fn(V, F, k) -> V_k``; the projection onto the first k eigenvectors does
not depend on their signs, so the typical mistakes can be rebuilt from one dense
basis and named when met.
"""

import numpy as np
import scipy.linalg

from ...lessons.laplace import laplacian, vertex_areas
from ...mesh.topology import boundary_vertices
from ..shapes.surfaces import ellipsoid, saddle, sphere
from .result import Mistake, call, close, exercise

__all__ = ["eigenpairs", "spectral_reconstruction"]

_REREAD_EIGEN = "section 2 · The discrete eigenproblem"
_REREAD = "section 4 · Reconstruction from the first k eigenvectors"


def _egg():
    e = ellipsoid(1.0, 0.7, 0.5, subdivisions=1, jitter=0.3, seed=1)
    return "a 42-vertex jittered ellipsoid (closed)", e.V, e.F


def _open():
    s = saddle(n=6, amplitude=0.6, monkey=0.3, jitter=0.25, seed=2)
    return "a 49-vertex jittered saddle (open: a boundary)", s.V, s.F


def _round():
    s = sphere(1.0, subdivisions=1)
    return "the 42-vertex icosphere (lam_1 = lam_2 = lam_3)", s.V, s.F


# --------------------------------------------------------------------------
# the generalised eigenproblem C e = -lam M e


def _dense_pair(V, F):
    M, C = laplacian(V, F)
    return M.toarray(), C.toarray()


def _real(x, what):
    x = np.asarray(x.toarray() if hasattr(x, "toarray") else x)
    if np.iscomplexobj(x):
        if np.abs(x.imag).max(initial=0.0) > 1e-8 * max(np.abs(x.real).max(initial=0.0), 1e-300):
            raise Mistake(
                f"{what} has complex entries: a solver for non-symmetric matrices was used",
                "solve the symmetric generalised problem, e.g. scipy.linalg.eigh(-C, M), whose eigenpairs are real",
            )
        x = x.real
    return x.astype(float)


def _pair(out, n, k):
    if not isinstance(out, (tuple, list)) or len(out) != 2:
        raise Mistake(
            f"the function returned {type(out).__name__}, not the pair (lam, E)",
            "end with `return lam, E`",
            typical=False,
        )
    lam, E = _real(out[0], "lam"), _real(out[1], "E")
    if lam.ndim == 2 and E.ndim == 1:
        raise Mistake("the pair is returned as (E, lam)", "return the eigenvalues first: `return lam, E`")
    lam = lam.reshape(-1) if lam.ndim == 2 and 1 in lam.shape else lam
    if E.shape == (k, n) and k != n:
        raise Mistake(f"E is transposed: shape {E.shape}, expected ({n}, {k})", "the eigenvectors are the columns of E")
    if lam.ndim == 1 and E.ndim == 2 and E.shape[0] == n and len(lam) == E.shape[1] and len(lam) != k:
        raise Mistake(
            f"{len(lam)} eigenpairs were returned where k = {k} were asked for",
            "keep exactly the k smallest: lam[:k], E[:, :k] (eigsh's k, or eigh's subset_by_index=[0, k - 1])",
        )
    if lam.shape != (k,) or E.shape != (n, k):
        raise Mistake(
            f"lam has shape {lam.shape} and E {E.shape}, expected ({k},) and ({n}, {k})",
            "lam holds the k eigenvalues, E the k eigenvectors as columns",
            typical=False,
        )
    return lam, E


def _same(a, b, scale):
    return a.shape == b.shape and np.allclose(a, b, rtol=1e-6, atol=1e-7 * scale)


def _eigenvalues(lam, every, plain, k, scale):
    """Name what the eigenvalues are when they are not the k smallest of C e = -lam M e in ascending order."""
    right = every[:k]
    if _same(lam, right, scale):
        return
    if _same(lam, -right, scale) or _same(np.sort(lam), np.sort(-right), scale):
        raise Mistake(
            "the sign of C is flipped: the eigenvalues are <= 0, those of C e = lam M e",
            "C is negative semidefinite; solve -C e = lam M e, e.g. scipy.linalg.eigh(-C, M), so that lam >= 0",
        )
    if _same(np.sort(lam), np.sort(-every[-k:]), scale):
        raise Mistake(
            "the sign of C is flipped and the eigenvalues are the k of largest magnitude (all < 0): "
            "the smallest of C e = lam M e are the most negative",
            "solve -C e = lam M e (lam >= 0); its smallest eigenvalues are the ones near 0",
        )
    if _same(np.sort(lam), every[-k:], scale):
        raise Mistake(
            "the eigenvalues are the k largest, not the k smallest (eigsh's default which='LM')",
            "ask for the smallest: eigh(-C, M, subset_by_index=[0, k - 1]), or eigsh in shift-invert mode "
            "(sigma just below 0)",
        )
    if _same(lam, every[1 : k + 1], scale) or _same(np.sort(lam), every[1 : k + 1], scale):
        raise Mistake(
            "the null mode is lost: lam_0 = 0 (the constant eigenvector) is missing, the values start at lam_1",
            "keep the eigenpair of lam = 0: it is e_0, the constant 1/sqrt(area), and the reconstruction needs it",
        )
    if _same(np.sort(lam), plain[:k], scale):
        raise Mistake(
            "M is left out: these are the eigenvalues of the plain problem -C e = lam e",
            "the problem is C e = -lam M e: pass M as the second matrix, eigh(-C, M) or eigsh(-C, k, M=M, ...)",
        )
    if _same(np.sort(lam), right, scale):
        raise Mistake(
            "the eigenvalues are right but not in ascending order",
            "sort them, and the columns of E with them: order = np.argsort(lam)",
        )
    raise Mistake(
        f"the eigenvalues differ from the k = {k} smallest of C e = -lam M e "
        f"(yours {np.array2string(lam, precision=4)}, expected {np.array2string(right, precision=4)})",
        "-C and M are the pair: scipy.linalg.eigh(-C, M) on dense arrays gives them in ascending order",
        typical=False,
    )


def _eigenvectors(lam, E, M, C):
    """Name what is wrong with E when lam is right: residual, then M-orthonormality."""
    m = M.diagonal()
    scale = np.abs(C).max() * max(np.abs(E).max(), 1e-300)
    if np.abs(C @ E + (m[:, None] * E) * lam).max() > 1e-6 * scale:
        back = E / np.sqrt(m)[:, None]  # if E holds Q's eigenvectors z (section 2), then M^-1/2 z are the e
        back_scale = np.abs(C).max() * max(np.abs(back).max(), 1e-300)
        if np.abs(C @ back + (m[:, None] * back) * lam).max() <= 1e-6 * back_scale:
            raise Mistake(
                "E holds the eigenvectors z of Q = -M^-1/2 C M^-1/2, not transformed back",
                "the eigenvectors of C e = -lam M e are e = M^-1/2 z: E = Z / np.sqrt(m)[:, None], m = M.diagonal()",
            )
        raise Mistake(
            "the columns of E are not eigenvectors of C e = -lam M e for these lam (C E + M E diag(lam) is not zero)",
            "E[:, i] belongs to lam[i]: keep the solver's columns in the order of its eigenvalues",
            typical=False,
        )
    G = E.T @ (m[:, None] * E)
    if np.abs(G - np.eye(len(lam))).max() <= 1e-6:
        return
    if np.allclose(np.einsum("ij,ij->j", E, E), 1.0, rtol=1e-6) or np.allclose(E.T @ E, np.eye(len(lam)), atol=1e-6):
        raise Mistake(
            "the eigenvectors are normalised in the plain dot product (E^T E = I), not in M (E^T M E = I)",
            "divide each column by its M-norm, sqrt(e^T M e); scipy.linalg.eigh(-C, M) does it itself",
        )
    off = G - np.diag(G.diagonal())
    if np.abs(off).max() <= 1e-6 * np.abs(G.diagonal()).max():
        raise Mistake(
            "the eigenvectors are not M-normalised: E^T M E is diagonal but not I",
            "divide each column by its M-norm, sqrt(e^T M e)",
        )
    raise Mistake(
        f"E^T M E is not the identity (largest difference {np.abs(G - np.eye(len(lam))).max():.3g}): "
        "eigenvectors of one repeated eigenvalue are not M-orthogonal",
        "take an M-orthonormal basis of each eigenspace, as eigh(-C, M) returns",
        typical=False,
    )


@exercise(
    "eigenpairs",
    reread=_REREAD_EIGEN,
    forbid=(
        "lessons.spectral.eigenpairs",
        "lessons.spectral.eigenbasis",
        "lessons.spectral.spectral_basis",
        "lessons.spectral.SpectralBasis",
        "lessons.spectral.spectral_reconstruction",
        "numerics.eigen.smallest_eigenpairs",
        "numerics.eigen.shift_invert_lanczos",
    ),
    own=("lessons.spectral.eigenbasis", "lessons.spectral.eigenpairs"),
)
def eigenpairs(fn):
    """Check ``fn(M, C, k) -> (lam, E)``: the k smallest pairs of ``C e = -lam M e``, ascending, ``E^T M E = I``."""
    checked = []
    for (what, V, F), k in ((_egg(), 6), (_open(), 6), (_round(), 4)):
        M, C = _dense_pair(V, F)
        every = scipy.linalg.eigh(-C, M, eigvals_only=True)
        plain = scipy.linalg.eigh(-C, eigvals_only=True)
        lam, E = _pair(call(fn, *laplacian(V, F), k), len(V), k)
        _eigenvalues(lam, every, plain, k, every[-1])
        _eigenvectors(lam, E, M, C)
        checked.append(f"{what} with k = {k}")
    return checked


# --------------------------------------------------------------------------
# the reconstruction V_k = E_k E_k^T M V


def _positions(out, n, k):
    X = np.asarray(out, dtype=float) if not hasattr(out, "toarray") else out.toarray()
    if X.shape == (3, n) and n != 3:
        raise Mistake(
            f"the result is transposed: shape {X.shape}, expected ({n}, 3)",
            "E_k has one row per vertex, so E_k (E_k^T M V) is (n, 3)",
        )
    if X.shape == (k, 3) and k != n:
        raise Mistake(
            f"the function returned the {k} x 3 coefficients E_k^T M V, not the positions",
            "multiply them back: V_k = E_k c",
        )
    if X.shape != (n, 3):
        raise Mistake(
            f"the function returned shape {X.shape}, expected ({n}, 3): one position per vertex",
            "return E_k @ (E_k.T @ (M @ V))",
            typical=False,
        )
    return X


def _project(E, W, V):
    return E @ (E.T @ W(V))


def _basis(C, m):
    return scipy.linalg.eigh(-C, np.diag(m))[1]


def _wrong_reconstructions(V, F, k, M, C, E):
    """The typical wrong V_k of this mesh, by name."""
    m = M.diagonal()
    m_mixed = vertex_areas(V, F, "mixed")
    E_mixed = _basis(C, m_mixed)
    Ek = E[:, :k]
    wrong = {
        "plain": _project(Ek, lambda X: X, V),
        "inverse": _project(Ek, lambda X: X / m[:, None], V),
        "left": m[:, None] * _project(Ek, lambda X: X, V),
        "C": _project(Ek, lambda X: C @ X, V),
        "Delta": _project(Ek, lambda X: (C @ X) / m[:, None], V),
        "no mean": _project(E[:, 1:k], lambda X: m[:, None] * X, V),
        "no mean, plain": _project(E[:, 1:k], lambda X: X, V),
        "one less": _project(E[:, : k - 1], lambda X: m[:, None] * X, V),
        "one more": _project(E[:, : k + 1], lambda X: m[:, None] * X, V),
        "shifted": _project(E[:, 1 : k + 1], lambda X: m[:, None] * X, V),
        "mixed": _project(E_mixed[:, :k], lambda X: m_mixed[:, None] * X, V),
        "mixed inner": _project(Ek, lambda X: m_mixed[:, None] * X, V),
    }
    boundary = boundary_vertices(F, len(V))
    if len(boundary):
        Cz = C.copy()
        Cz[boundary, :] = 0.0  # the rows of boundary vertices zeroed: C is no longer symmetric
        wrong["boundary rows"] = _project(scipy.linalg.eigh(-Cz, M)[1][:, :k], lambda X: m[:, None] * X, V)
    return wrong


_NAMED = (
    (
        ("plain",),
        "the plain dot product E_k^T V is used where the M inner product E_k^T M V belongs "
        "(the result is off by a factor of about one over a vertex area)",
        "E is orthonormal in the M inner product, E^T M E = I, so the coefficients are E_k^T M V",
    ),
    (("inverse",), "V is divided by the vertex areas (M^-1 V) instead of weighted by them (M V)", "c = E_k^T M V"),
    (
        ("left",),
        "M multiplies the result (M E_k E_k^T V) instead of V inside the inner product",
        "V_k = E_k (E_k^T (M V))",
    ),
    (
        ("C", "Delta"),
        "C (or M^-1 C) is used where M belongs in the inner product",
        "the eigenvectors are orthonormal in <f, g>_M = f^T M g: the coefficients are E_k^T M V",
    ),
    (
        ("no mean, plain",),
        "the constant eigenvector e_0 is dropped and the plain inner product E^T V is used: two mistakes",
        "use E[:, :k], e_0 included (it carries the position), and the coefficients E_k^T M V",
    ),
    (
        ("no mean",),
        "the constant eigenvector e_0 (the mean, lam = 0) is left out, so the shape is centred at the origin",
        "use the columns 0 .. k-1 of E, e_0 included: E[:, :k]",
    ),
    (
        ("one less", "one more", "shifted"),
        "k is off by one: the slice of E does not hold exactly the first k columns",
        "E[:, :k] holds e_0 .. e_{k-1}",
    ),
    (
        ("mixed", "mixed inner"),
        "the mixed (Voronoi) vertex areas of Meyer et al. 2003 are used where the barycentric M is asked "
        "(libigl's massmatrix gives the Voronoi ones by default)",
        "take M from geomlib.laplacian(V, F), barycentric: A_i is a third of the areas of the triangles at i",
    ),
    (
        ("boundary rows",),
        "the rows of the boundary vertices are zeroed, so C is not symmetric and the eigensolver "
        "reads one triangle of it: wrong on an open mesh",
        "keep every row of C: the cotangent operator of an open mesh has the natural (Neumann) boundary "
        "condition and needs no boundary rule",
    ),
)


@exercise(
    "spectral_reconstruction",
    reread=_REREAD,
    forbid=(
        "lessons.spectral.spectral_reconstruction",
        "lessons.spectral.spectral_basis",
        "lessons.spectral.SpectralBasis",
    ),
    allow=("lessons.laplace.laplacian", "lessons.spectral.eigenpairs"),
)
def spectral_reconstruction(fn):
    """Check ``fn(V, F, k) -> V_k``: V_k = E_k E_k^T M V with E_k the first k eigenvectors (every k < n)."""
    checked = []
    for (what, V, F), k in ((_egg(), 5), (_egg(), 12), (_open(), 8)):
        n = len(V)
        M, C = _dense_pair(V, F)
        m, E = M.diagonal(), _basis(C, M.diagonal())
        scale = np.abs(V).max()
        X = _positions(call(fn, V.copy(), F.copy(), k), n, k)
        ref = _project(E[:, :k], lambda X: m[:, None] * X, V)
        if not close(X, ref, rtol=1e-6, atol=1e-7 * scale):
            wrong = _wrong_reconstructions(V, F, k, M, C, E)
            for names, diagnosis, hint in _NAMED:
                if any(
                    name in wrong
                    and close(X, wrong[name], rtol=1e-6, atol=1e-7 * scale)
                    and not close(wrong[name], ref)
                    for name in names
                ):
                    raise Mistake(f"{diagnosis} ({what}, k = {k})", hint)
            raise Mistake(
                f"V_k differs from the M-orthogonal projection on {what} at k = {k} "
                f"(largest difference {np.abs(X - ref).max():.3g}, coordinates up to {scale:.3g})",
                "V_k = E_k (E_k^T M V), with E_k = E[:, :k] from C e = -lam M e, (M, C) = laplacian(V, F); "
                "on an open mesh keep every row of C",
                typical=False,
            )
        checked.append(f"{what} with k = {k}")
    return checked
