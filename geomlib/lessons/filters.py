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

__all__ = ["SCHEMES", "mode_factor", "plot_mode_factors"]

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


#: How each curve is drawn: line style and marker as well as colour, so that no curve is told
#: apart by its colour alone.
STYLES = {
    "diffusion": dict(color="k", ls="-"),
    "explicit": dict(color="C3", ls="-", marker="o"),
    "implicit": dict(color="C0", ls="--"),
    "crank-nicolson": dict(color="C2", ls="-."),
    "taubin": dict(color="C1", ls=":", marker="s"),
}


def plot_mode_factors(lam_min, lam_max, tau, taubin=None, ax=None, title=None, past=None):
    """Plot the per-mode factor of each scheme against lam, with the mesh's eigenvalue range shaded.

    Parameters
    ----------
    lam_min, lam_max : float, smallest non-zero and largest eigenvalue of the mesh's operator.
    tau : float, the step of the explicit, implicit and Crank-Nicolson schemes and of diffusion.
    taubin : (tau_shrink, tau_inflate), optional, Taubin's pair in the same operator's units.
    ax : matplotlib axes, optional.
    past : float, optional
        A second explicit step, drawn dashed, with a marker where its factor leaves [-1, 1]
        (at lam = 2 / past): a step past the limit 2 / lam_max shows where the scheme breaks.

    Every curve differs from the others by its line style or marker, not by colour alone.
    Returns the axes.
    """
    import matplotlib.pyplot as plt

    ax = ax or plt.subplots(figsize=(7, 3.6))[1]
    lam = np.linspace(0.0, 1.15 * lam_max, 600)
    every = dict(markevery=60, markersize=4)
    for scheme in ("diffusion", "explicit", "implicit", "crank-nicolson"):
        ax.plot(lam, mode_factor(lam, tau, scheme), lw=1.4, label=scheme, **STYLES[scheme], **every)
    if taubin is not None:
        label = f"Taubin ({taubin[0]:.3g}, {taubin[1]:.3g})"
        ax.plot(lam, mode_factor(lam, taubin[0], "taubin", taubin[1]), lw=1.4, label=label, **STYLES["taubin"], **every)
    if past is not None:
        ax.plot(
            lam,
            mode_factor(lam, past, "explicit"),
            color="C3",
            ls="--",
            marker="o",
            fillstyle="none",
            lw=1.2,
            label=rf"explicit, $\tau$ = {past:.3g} (past the limit)",
            **every,
        )
        ax.plot(
            [2.0 / past],
            [-1.0],
            "v",
            color="C3",
            markersize=8,
            label=rf"leaves $[-1, 1]$ at $\lambda$ = {2.0 / past:.3g}",
        )
    ax.axvspan(lam_min, lam_max, color="0.9", zorder=0, label="this mesh's eigenvalues")
    ax.axhline(0, color="0.5", lw=0.6)
    for y in (-1, 1):
        ax.axhline(y, color="0.5", lw=0.6, ls=":")
    ax.set(
        xlabel=r"eigenvalue $\lambda$",
        ylabel="factor per step",
        ylim=(-2.2, 1.2),
        title=title or rf"one step, $\tau$ = {tau:.3g}",
    )
    ax.legend(fontsize=8, loc="lower left")
    return ax
