"""Smoothing as filtering: what one step of each scheme does to one eigenmode.

Write the vertex positions in the eigenbasis of the Laplace-Beltrami operator,
P = sum_i E_i c_i with C E_i = -lam_i M E_i (lam_i >= 0, notebook 04). Every
linear smoothing step below multiplies each coefficient c_i by a factor that
depends only on tau lam_i, tau being the step (length^2 for the cotangent
operator; a pure number for the uniform one):

* exact diffusion for time tau:      exp(-tau lam)
* explicit (forward Euler) step:     1 - tau lam           (|.| < 1 needs tau lam < 2)
* implicit (backward Euler) step:    1 / (1 + tau lam)     (in (0, 1] for every tau)
* Crank-Nicolson step:               (1 - tau lam / 2) / (1 + tau lam / 2)
* Taubin's pass (Taubin 1995):       (1 - tau_shrink lam)(1 - tau_inflate lam),
  tau_shrink > 0 > tau_inflate, |tau_inflate| slightly larger.

With x = tau lam, the signed chain 1 / (1 + x) > exp(-x) > 1 - x holds for
every x > 0: the implicit factor lies above diffusion's, the explicit one below.
In magnitude, which is what decides how much of a mode is left, only half of it
holds: an implicit step damps every mode less than exact diffusion for the same
time, but the explicit step damps more only while |1 - x| < exp(-x), that is
for x < 1.2785 (the root of x - 1 = exp(-x)). For 1.2785 < x < 2 it damps less
(at x = 1.8, a step at 0.9 of the limit, |1 - x| = 0.8 against exp(-x) = 0.165),
past x = 1 it flips the mode's sign, and past x = 2 it amplifies: the limit.
"""

import numpy as np

from ..mesh.errors import MeshError
from ..mesh.validate import check_choice

__all__ = ["SCHEMES", "mode_factor"]

SCHEMES = ("diffusion", "explicit", "implicit", "crank-nicolson", "taubin")


def mode_factor(lam, tau, scheme, tau_inflate=None):
    """Factor applied to the coefficient of eigenmode lam by one step of ``scheme``.

    Parameters
    ----------
    lam : array_like, eigenvalues of -M^-1 C (>= 0; 1/length^2 for cotan).
    tau : float, the step (length^2 for cotan); for "taubin" the shrink factor.
    scheme : one of SCHEMES.
    tau_inflate : float, Taubin's (negative) inflate factor; only for "taubin".

    Returns
    -------
    ndarray of the shape of ``lam``.

    Raises
    ------
    MeshError
        An unknown ``scheme``; Taubin's pass without ``tau > 0 > tau_inflate``.
    """
    check_choice("scheme", scheme, SCHEMES)
    x = tau * np.asarray(lam, dtype=float)
    if scheme == "diffusion":
        return np.exp(-x)
    if scheme == "explicit":
        return 1.0 - x
    if scheme == "implicit":
        return 1.0 / (1.0 + x)
    if scheme == "crank-nicolson":
        return (1.0 - x / 2) / (1.0 + x / 2)
    if tau_inflate is None or not tau_inflate < 0 < tau:
        raise MeshError(
            f"Taubin's pass needs tau > 0 (shrink) and tau_inflate < 0 (inflate), not tau={tau!r}, "
            f"tau_inflate={tau_inflate!r}"
        )
    return (1.0 - x) * (1.0 - tau_inflate * np.asarray(lam, dtype=float))
