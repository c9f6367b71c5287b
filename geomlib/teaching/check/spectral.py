"""Checks of the exercise of notebook 04 (reconstruction from the first k eigenvectors).

The case: a jittered ellipsoid with 42 vertices (vertex areas differing by a
factor of about 3, so the M inner product matters) and all its eigenpairs
``C e = -lam M e``, ``E^T M E = I``, solved densely here. The learner's
``fn(V, F, k)`` (the signature of ``geomlib.spectral_reconstruction``, built
from ``geomlib.laplacian`` and ``geomlib.eigenbasis``) is run at a small k and
at k = n, where the right answer is V itself. The projection onto the first k
eigenvectors does not depend on their signs, so the typical mistakes can be
rebuilt from this E and named when met.
"""

import numpy as np
import scipy.linalg

from ...lessons.laplace import laplacian
from ..surfaces import ellipsoid
from .result import Mistake, call, close, exercise

__all__ = ["spectral_reconstruction"]

_REREAD = "section 4 · Reconstruction from the first k eigenvectors"


def _case():
    e = ellipsoid(1.0, 0.7, 0.5, subdivisions=1, jitter=0.3, seed=1)
    M, C = laplacian(e.V, e.F)
    _, E = scipy.linalg.eigh(-C.toarray(), M.toarray())
    return e.V, e.F, M.toarray(), C.toarray(), E


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


@exercise(
    "spectral_reconstruction",
    reread=_REREAD,
    forbid=(
        "lessons.spectral.spectral_reconstruction",
        "lessons.spectral.spectral_basis",
        "lessons.spectral.SpectralBasis",
        "lessons.spectral.eigenbasis",
    ),
)
def spectral_reconstruction(fn):
    """Check ``fn(V, F, k) -> V_k``: V_k = E_k E_k^T M V with E_k the first k eigenvectors."""
    V, F, M, C, E = _case()
    n, m = len(V), M.diagonal()
    scale = np.abs(V).max()
    checked = []
    for k in (5, n):
        X = _positions(call(fn, V.copy(), F.copy(), k), n, k)
        Ek = E[:, :k]
        ref = _project(Ek, lambda X: m[:, None] * X, V)
        wrong = {
            "plain": _project(Ek, lambda X: X, V),
            "inverse": _project(Ek, lambda X: X / m[:, None], V),
            "left": m[:, None] * _project(Ek, lambda X: X, V),
            "C": _project(Ek, lambda X: C @ X, V),
            "Delta": _project(Ek, lambda X: (C @ X) / m[:, None], V),
            "no mean": _project(E[:, 1:k], lambda X: m[:, None] * X, V),
            "one less": _project(E[:, : k - 1], lambda X: m[:, None] * X, V),
            "one more": _project(E[:, : k + 1], lambda X: m[:, None] * X, V),
            "shifted": _project(E[:, 1 : k + 1], lambda X: m[:, None] * X, V),
        }

        def is_(name, X=X, wrong=wrong, ref=ref):
            return close(X, wrong[name], rtol=1e-6, atol=1e-9 * scale) and not close(wrong[name], ref)

        if is_("plain"):
            raise Mistake(
                "the plain dot product E_k^T V is used where the M inner product E_k^T M V belongs "
                "(the result is off by a factor of about one over a vertex area)",
                "E is orthonormal in the M inner product, E^T M E = I, so the coefficients are E_k^T M V",
            )
        if is_("inverse"):
            raise Mistake(
                "V is divided by the vertex areas (M^-1 V) instead of weighted by them (M V)",
                "the coefficients are c = E_k^T M V",
            )
        if is_("left"):
            raise Mistake(
                "M multiplies the result (M E_k E_k^T V) instead of V inside the inner product",
                "V_k = E_k (E_k^T (M V))",
            )
        if is_("C") or is_("Delta"):
            raise Mistake(
                "C (or M^-1 C) is used where M belongs in the inner product",
                "the eigenvectors are orthonormal in <f, g>_M = f^T M g: the coefficients are E_k^T M V",
            )
        if is_("no mean"):
            raise Mistake(
                "the constant eigenvector e_0 (the mean, lam = 0) is left out, so the shape is centred at the origin",
                "use the columns 0 .. k-1 of E, e_0 included: E[:, :k]",
            )
        if is_("one less") or is_("one more") or is_("shifted"):
            raise Mistake(
                "k is off by one: the slice of E does not hold exactly the first k columns",
                "E[:, :k] holds e_0 .. e_{k-1}",
            )
        if not close(X, ref, rtol=1e-6, atol=1e-9 * scale):
            raise Mistake(
                f"V_k differs from the M-orthogonal projection at k = {k} "
                f"(largest difference {np.abs(X - ref).max():.3g}, coordinates up to {scale:.3g})",
                "V_k = E_k (E_k^T M V), with E_k = E[:, :k]",
                typical=False,
            )
        checked.append(f"a 42-vertex jittered ellipsoid with k = {k}" + (" (gives V back)" if k == n else ""))
    return checked
