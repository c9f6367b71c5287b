"""Checks of notebook 04: the eigenpairs by the reduction to Q, and the reconstructions V_k = E_k E_k^T M V with their errors.

Cases, placed anew each run (``case_rng``), small enough for a dense solve and for ``eigsh`` (every k < n): a
jittered 42-vertex ellipsoid (closed; areas differing by about 2.25, so M matters), an open jittered 49-vertex
saddle (the natural boundary condition: the null mode is still the constant) and the 42-vertex icosphere, whose
eigenvalues repeat. There k = 4 (the constant and the threefold lam_1): at k = 9 ``eigsh`` missed one of the five
copies of lam_4 in 44 of 200 runs, at k = 4 none in 200. ``eigenpairs`` is judged by what defines the answer (lam
ascending, C E = -M E diag(lam), E^T M E = I; signs and bases of repeated eigenspaces free) and refuses a
generalised solver (:mod:`.solvers`). The reconstruction study is handed the check's own dense solve, so its
mistakes are rebuilt from the very basis it got (a student's own solve may differ in signs, which V_k ignores);
the positions are judged first, then the errors, by their definition and not by Parseval.
"""

import numpy as np
import scipy.linalg
import scipy.sparse as sp

from ...lessons.laplace import laplacian
from ...mesh.topology import boundary_vertices
from ..shapes.surfaces import ellipsoid, saddle, sphere
from .catalogue import Case, Wrong, agree, answer, judge, named, positions
from .catalogue import eigenpairs as pair
from .meshes import placed
from .result import Mistake, call, case_rng, exercise
from .solvers import GENERALISED, refusing

__all__ = ["eigenpairs", "spectral_reconstruction"]


def _meshes(rng):
    shapes = (
        ("a 42-vertex jittered ellipsoid (closed)", ellipsoid(1.0, 0.7, 0.5, subdivisions=1, jitter=0.3, seed=1)),
        ("a 49-vertex jittered saddle (open: a boundary)", saddle(n=6, amplitude=0.6, monkey=0.3, jitter=0.25, seed=2)),
        ("the 42-vertex icosphere (lam_1 = lam_2 = lam_3)", sphere(1.0, subdivisions=1)),
    )
    return [(label, *placed(S.V, S.F, rng, jitter=0.0)) for label, S in shapes]


def _eig(C, d):
    """Eigenvalues, ascending, and eigenvectors of -D C D, D = diag(d) (dense: the cases are tiny)."""
    return np.linalg.eigh(-(d[:, None] * C.toarray() * d[None, :]))


# ---------------------------------------------------------------- the eigenpairs of C e = -lam M e, by the reduction


def _residual(E, lam, c):
    return np.abs(c.C @ E + (c.m[:, None] * E) * lam).max() <= 1e-6 * np.abs(c.C).max() * max(np.abs(E).max(), 1e-300)


def _gram(E, c):
    return E.T @ (c.m[:, None] * E)


def _diagonal(E, c):
    return np.allclose(G := _gram(E, c), np.diag(np.diag(G)), atol=1e-6 * np.abs(G).max())


def _some_of(lam, c):
    return np.all(np.abs(lam[:, None] - c.every[None, :]).min(axis=1) <= 1e-6 * c.every[-1])


_Q = "Q = -M^-1/2 C M^-1/2"


# fmt: off
LAM_MISTAKES = [
    Wrong('the sign of C is flipped: the eigenvalues are <= 0, those of M^-1/2 C M^-1/2', _Q, when=lambda lam, right, c: agree(np.sort(lam), np.sort(-right))),
    Wrong('the sign of C is flipped, and the first k of M^-1/2 C M^-1/2 are its most negative', f'{_Q}, whose smallest eigenvalues are the ones near 0', build=lambda c: -c.every[::-1][:c.k]),
    Wrong('the eigenvalues are the k largest, not the k smallest', 'the first k ascending, or eigsh with sigma below 0', build=lambda c: c.every[-c.k:]),
    Wrong('the null mode is lost: lam_0 = 0 (the constant eigenvector) is missing, the values start at lam_1', 'keep the eigenpair of lam = 0: the reconstruction needs it', build=lambda c: c.every[1:c.k + 1]),
    Wrong('M is left out: these are the eigenvalues of -C itself', _Q, build=lambda c: c.plain[:c.k]),
    Wrong('M^-1 stands on both sides (-M^-1 C M^-1), not M^-1/2', f'{_Q}: the square roots of the areas', build=lambda c: c.inverse[:c.k]),
    Wrong('the eigenvalues are not sorted (np.linalg.eig and eigsh return them in no particular order), so the first k taken are not the k smallest', 'sort them, and the columns with them: order = np.argsort(lam)', when=lambda lam, right, c: _some_of(lam, c) and (not agree(lam, right))),
    Wrong('the eigenvalues differ from the k smallest of C e = -lam M e on {label}', f'{_Q} and a symmetric solver', when=lambda lam, right, c: True, typical=False),
]

E_MISTAKES = [
    Wrong('E holds the eigenvectors z of Q, not transformed back', 'e = M^-1/2 z: E = Z / np.sqrt(m)[:, None]', when=lambda a, right, c: _residual(a[1] / np.sqrt(c.m)[:, None], a[0], c)),
    Wrong('the back-transform uses M^-1 instead of M^-1/2', 'e = M^-1/2 z', when=lambda a, right, c: _residual(a[1] * np.sqrt(c.m)[:, None], a[0], c)),
    Wrong('the columns of E are not eigenvectors for these lam on {label} (C E + M E diag(lam) is not 0)', 'E[:, i] belongs to lam[i]: keep the columns in the order of their eigenvalues', when=lambda a, right, c: not _residual(a[1], a[0], c), typical=False),
    Wrong('the eigenvectors are normalised in the plain dot product (E^T E = I), not in M (E^T M E = I)', 'divide each column by its M-norm, sqrt(e^T M e)', when=lambda a, right, c: np.allclose(np.einsum('ij,ij->j', a[1], a[1]), 1.0, rtol=1e-06)),
    Wrong('the eigenvectors are not M-normalised: E^T M E is diagonal but not I', 'divide each column by sqrt(e^T M e)', when=lambda a, right, c: _diagonal(a[1], c)),
    Wrong('E^T M E is not the identity on {label}: eigenvectors of one repeated eigenvalue are not M-orthogonal', 'take an orthonormal basis Z of each eigenspace of Q, as a symmetric solver returns', when=lambda a, right, c: True, typical=False),
]
# fmt: on

_SPECTRAL = "eigenpairs eigenbasis spectral_basis SpectralBasis spectral_reconstruction spectral_reconstructions"


@exercise(
    "eigenpairs",
    reread="section 2 · The discrete eigenproblem",
    forbid=named("lessons.spectral", _SPECTRAL) + named("numerics.eigen", "smallest_eigenpairs shift_invert_lanczos"),
    own=named("lessons.spectral", "eigenbasis eigenpairs"),
)
def eigenpairs(fn):
    """Check ``fn(M, C, k) -> (lam, E)``: the k smallest pairs of ``C e = -lam M e``, ascending, ``E^T M E = I``."""
    cases = []
    for (label, V, F), k in zip(_meshes(case_rng()), (6, 6, 4)):
        M, C = laplacian(V, F)
        m = M.diagonal()
        every, plain, inverse = (_eig(C, d)[0] for d in (1 / np.sqrt(m), np.ones(len(m)), 1 / m))
        cases.append(Case(label, M=M, C=C, k=k).but(m=m, every=every, plain=plain, inverse=inverse))
    with refusing(GENERALISED, fn, f"reduce to {_Q} and use a symmetric solver on Q"):
        answers = [pair(call(fn, c.M.copy(), c.C.copy(), c.k), len(c.m), c.k) for c in cases]
    judge(LAM_MISTAKES, cases, [lam for lam, _ in answers], right=lambda c: c.every[: c.k])
    ok = lambda a, right, c: _residual(a[1], a[0], c) and np.allclose(_gram(a[1], c), np.eye(c.k), atol=1e-6)  # noqa: E731
    judge(E_MISTAKES, cases, answers, right=lambda c: None, same=ok)
    return [f"{c.label} with k = {c.k}" for c in cases]


# ---------------------------------------------------------------- the study: V_k for each k of ks from one solve, and its error


def _solve(M, C, k):
    """The eigen-solve handed to the function: the k smallest pairs of the (M, C) it is given, dense, by the
    reduction (NaN when M's diagonal is not positive: (M, C) swapped)."""
    m = np.asarray(M.diagonal(), dtype=float)
    if not (m > 0).all():
        return np.full(k, np.nan), np.full((len(m), k), np.nan)
    lam, Z = _eig(sp.csr_matrix(C), 1 / np.sqrt(m))
    return lam[:k], Z[:, :k] / np.sqrt(m)[:, None]


def _basis_of(V, F, weights="cotan", area="barycentric"):
    """(m, lam, E): the vertex areas and every eigenpair of C e = -lam M e, as ``_solve`` gives them."""
    M, C = laplacian(V, F, weights=weights, area=area)
    return M.diagonal(), *_solve(M, C, len(V))


def _project(c, shift=0, first=0, inner=lambda c, X: c.m[:, None] * X, E=None, left=False):
    """[V_k for k in c.ks]: V_k = E_k E_k^T (inner V), k + shift columns from e_first on."""
    E, W = c.E if E is None else E, inner(c, c.V)
    X = np.stack([E[:, first : k + shift] @ (E[:, first : k + shift].T @ W) for k in c.ks])
    return c.m[:, None] * X if left else X


def _boundary_rows(c):
    Cz = laplacian(c.V, c.F)[1].toarray()
    Cz[boundary_vertices(c.F, c.n), :] = 0.0  # C is no longer symmetric: eigh reads its lower triangle
    return _project(c, E=scipy.linalg.eigh(-Cz, np.diag(c.m))[1])


def _in_uniform_span(a, c):
    """Whether each V_k lies in the span of the uniform eigenvectors up to lam_{k-1}'s whole eigenspace, which
    repeats on a subdivided icosahedron's graph: any basis of a cut eigenspace gives another V_k."""
    m, lam, E = _basis_of(c.V, c.F, weights="uniform")
    spans = [E[:, lam <= lam[k - 1] + 1e-9 * lam[-1]] for k in c.ks]
    return all(agree(S @ (S.T @ (m[:, None] * X)), X) for S, X in zip(spans, a))


def _scaled(a, b):
    """Whether a is b times one factor (a normalisation of its own, or none)."""
    return a[-1] != 0 and np.isfinite(a).all() and agree(a * (b[-1] / a[-1]), b)


# fmt: off
POSITION_MISTAKES = [
    Wrong('the plain dot product E_k^T V is used where the M inner product E_k^T M V belongs', 'the basis is orthonormal in the M inner product of section 4: take the coefficients in that inner product', build=lambda c: _project(c, inner=lambda c, X: X)),
    Wrong('V is divided by the vertex areas (M^-1 V) instead of weighted by them (M V)', 'c = E_k^T M V', build=lambda c: _project(c, inner=lambda c, X: X / c.m[:, None])),
    Wrong('M multiplies the result (M E_k E_k^T V) instead of V inside the inner product', 'V_k = E_k (E_k^T (M V))', build=lambda c: _project(c, inner=lambda c, X: X, left=True)),
    Wrong('the constant eigenvector e_0 (lam = 0) is left out, so the shape is centred at the origin', 'use E[:, :k], e_0 included', build=lambda c: _project(c, first=1)),
    Wrong('the mean is taken out twice: V is centred by its plain mean and e_0, which carries the area-weighted mean, is dropped too', 'no centring is needed: e_0 carries the mean', build=lambda c: _project(c, first=1) + c.V.mean(axis=0)),
    Wrong('V is centred by its mean and the mean is not added back: V_k sits at the origin', 'project V itself: e_0 carries the mean', build=lambda c: _project(c) - c.V.mean(axis=0)),
    Wrong('k is off by one: one eigenvector too few', 'V_k holds e_0 .. e_{k-1}, E[:, :k]', build=lambda c: _project(c, shift=-1)),
    Wrong('k is off by one: one eigenvector too many (k + 1 of them)', 'V_k holds e_0 .. e_{k-1}, E[:, :k]', when=lambda a, right, c: agree(a[0], _project(c, shift=1)[0])),
    Wrong('the uniform operator (valences, weights 1) is used where the cotangent one is asked', 'laplacian(V, F) with its default weights', when=lambda a, right, c: _in_uniform_span(a, c)),
    Wrong('the mixed (Voronoi) vertex areas of Meyer et al. 2003 are used where the barycentric M is asked', 'laplacian(V, F) with its default area', build=lambda c: _project(c.but(m=(b := _basis_of(c.V, c.F, area='mixed'))[0]), E=b[2])),
    Wrong('the rows of the boundary vertices are zeroed, so C is not symmetric: wrong on an open mesh', 'keep every row of C: the natural boundary condition needs no rule', build=_boundary_rows),
    Wrong('V_k differs from the M-orthogonal projection on {label}', 'V_k = E_k (E_k^T M V)', typical=False),
]

_ERROR = 'sqrt(||V - V_k||_M^2 / area) / diag'
ERROR_MISTAKES = [
    Wrong('the errors are not relative: ||V - V_k||_M itself', f'{_ERROR}, area = sum of the A_i', build=lambda c: c.norms),
    Wrong('the errors are not divided by the bounding-box diagonal', f'{_ERROR}, diag = |max - min| of the coordinates', build=lambda c: c.norms / np.sqrt(c.m.sum())),
    Wrong('the square root is missing: squared distances', _ERROR, when=lambda a, right, c: _scaled(a, right**2) and not agree(a, right)),
    Wrong('the vertices are weighted equally (the Euclidean norm), not by their areas A_i', f'||X||_M^2 = sum_i A_i |x_i|^2, so {_ERROR}', when=lambda a, right, c: _scaled(a, c.plain)),
    Wrong('the errors are right up to one factor on {label}: another normalisation', _ERROR, when=lambda a, right, c: _scaled(a, right) and not agree(a, right)),
    Wrong(f'the errors differ from {_ERROR} on {{label}}', 'measure V - V_k itself, in the M-norm', typical=False),
]
# fmt: on


def _study(fn, c):
    """(V_ks (len(ks), n, 3), err (len(ks),)) the function returned on case c, as float arrays."""
    out, count = answer(fn, c), len(c.ks)
    if not isinstance(out, (tuple, list)) or len(out) != 2 or len(out[0]) != count or np.shape(out[1]) != (count,):
        diagnosis = f"the function returned {type(out).__name__}, not the pair (V_ks, err) for the {count} counts in ks"
        raise Mistake(diagnosis, "return the list of V_k and the array of errors, one each per k of ks", typical=False)
    if not np.isfinite(np.asarray(out[0], dtype=float)).all():
        diagnosis = "the positions are NaN, as when (M, C) are swapped: C's diagonal, negative, went in as the "
        raise Mistake(diagnosis + "vertex areas and under a square root", "M, C = laplacian(V, F): M first")
    return np.stack([positions(X, c.n, "V_k") for X in out[0]]), np.asarray(out[1], dtype=float)


@exercise(
    "spectral_reconstruction",
    reread="section 4 · Reconstruction from the first k eigenvectors",
    forbid=named("lessons.spectral", "spectral_reconstructions spectral_reconstruction spectral_basis SpectralBasis"),
    allow=("lessons.laplace.laplacian", "lessons.spectral.eigenpairs"),
)
def spectral_reconstruction(fn):
    """Check ``fn(V, F, ks, solve) -> (V_ks, err)``: V_k = E_k E_k^T M V for each k, the eigenpairs from the
    check's ``solve`` (any number of calls), and the error sqrt(||V - V_k||_M^2 / area) / diag of each."""
    meshes, cases = _meshes(case_rng()), []
    for (label, V, F), ks in ((meshes[0], [1, 4, 12]), (meshes[1], [3, 8])):
        m, _, E = _basis_of(V, F)
        c = Case(label, V=V, F=F, ks=ks, solve=_solve).but(m=m, E=E, diag=np.linalg.norm(np.ptp(V, axis=0)))
        gap = _project(c) - V
        norms = np.sqrt(np.einsum("i,kij,kij->k", m, gap, gap))
        plain = np.sqrt(np.einsum("kij,kij->k", gap, gap) / len(m)) / c.diag
        cases.append(c.but(norms=norms, err=norms / np.sqrt(m.sum()) / c.diag, plain=plain))
    answers = [_study(fn, c) for c in cases]
    judge(POSITION_MISTAKES, cases, [a[0] for a in answers], right=_project)
    judge(ERROR_MISTAKES, cases, [a[1] for a in answers], right=lambda c: c.err)
    return [f"{c.label} with ks = {c.ks}" for c in cases]
