"""Smoothing as filtering, drawn: the factor each scheme applies to one eigenmode, over the eigenvalues
(notebooks 05, 06 and 07a; the factors themselves are :func:`geomlib.lessons.filters.mode_factor`)."""

import numpy as np

from ...lessons.filters import mode_factor

__all__ = ["STYLES", "plot_mode_factors", "plot_taubin_factors", "taubin_zoom"]


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
    taubin : (tau_shrink, tau_inflate), optional, Taubin's pair in the same operator's units; its
        label says whether |tau_inflate| > tau_shrink, the pairs whose factor rises above 1 at low
        lam, and such a pair gets a panel zoomed onto that rise (:func:`taubin_zoom`; an inset when
        ``ax`` is given).
    ax : matplotlib axes, optional.
    past : float, optional
        A second explicit step, drawn dashed, with a marker where its factor leaves [-1, 1]
        (at lam = 2 / past): a step past the limit 2 / lam_max shows where the scheme breaks.

    Every curve differs from the others by its line style or marker, not by colour alone.
    Returns the axes.
    """
    import matplotlib.pyplot as plt

    rises = taubin is not None and -taubin[1] > taubin[0]
    if ax is None and rises:  # a panel of its own for the zoom onto Taubin's rise
        ax, zoom = plt.subplots(1, 2, figsize=(9.5, 3.6), gridspec_kw=dict(width_ratios=(3, 1)))[1]
    else:
        ax, zoom = ax or plt.subplots(figsize=(7, 3.6))[1], None
    lam = np.linspace(0.0, 1.15 * lam_max, 600)
    every = dict(markevery=60, markersize=4)
    for scheme in ("diffusion", "explicit", "implicit", "crank-nicolson"):
        ax.plot(lam, mode_factor(lam, tau, scheme), lw=1.4, label=scheme, **STYLES[scheme], **every)
    if taubin is not None:
        shrink, inflate = taubin
        label = (
            rf"Taubin ({shrink:.3g}, {inflate:.3g}): $|\tau_{{inflate}}| > \tau_{{shrink}}$, above 1 at low $\lambda$"
            if rises
            else rf"Taubin ({shrink:.3g}, {inflate:.3g}): $|\tau_{{inflate}}| \leq \tau_{{shrink}}$, at most 1"
        )
        ax.plot(lam, mode_factor(lam, shrink, "taubin", inflate), lw=1.4, label=label, **STYLES["taubin"], **every)
        if rises:
            taubin_zoom(zoom or ax.inset_axes([0.62, 0.52, 0.35, 0.34]), shrink, inflate, lam_min)
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
    if zoom is not None:
        ax.figure.tight_layout()
    return ax


def taubin_zoom(ax, shrink, inflate, lam_min):
    """Draw into ``ax`` Taubin's factor zoomed onto where it exceeds 1; returns ``ax``.

    With ``|inflate| > shrink`` the pair's factor ``1 + (|inflate| - shrink) lam - shrink |inflate| lam^2``
    exceeds 1 for 0 < lam < lam_1 = (|inflate| - shrink) / (shrink |inflate|), by at most
    ``(|inflate| - shrink)^2 / (4 shrink |inflate|)`` at lam_1 / 2 (a 0.0006 rise for 05's -1.05 tau:
    invisible on the axes of all the schemes). The zoom spans [0, 1.25 lam_1] and a band of
    1.8 times the rise about 1; the mesh's eigenvalues from ``lam_min`` are shaded as on the main axes.
    """
    b = -inflate
    lam_1 = (b - shrink) / (shrink * b)
    rise = (b - shrink) ** 2 / (4 * shrink * b)
    lam = np.linspace(0.0, 1.25 * lam_1, 300)
    ax.plot(lam, mode_factor(lam, shrink, "taubin", inflate), lw=1.4, **STYLES["taubin"], markevery=50, markersize=3)
    ax.axhline(1.0, color="0.5", lw=0.6, ls=":")
    ax.axvspan(lam_min, lam[-1], color="0.9", zorder=0)
    ax.set_xlim(0.0, lam[-1])
    ax.set_ylim(1 - 0.5 * rise, 1 + 1.3 * rise)
    ax.set_title(f"Taubin zoomed: above 1 for $\\lambda$ < {lam_1:.3g},\nat most {1 + rise:.5g}", fontsize=8)
    ax.set_xlabel(r"eigenvalue $\lambda$", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.ticklabel_format(axis="y", useOffset=False)
    return ax


def plot_taubin_factors(lam_max, tau_shrink, tau_inflate, low):
    """One Taubin pair against two explicit steps of ``tau_shrink``: the factor per mode over [0, lam_max].

    Lines told apart by style and marker, each labelled; the smooth mode ``low`` marked on both.
    Returns ``(fig, alt)``, the alt text built from the plotted factors.
    """
    import matplotlib.pyplot as plt

    lam = np.linspace(0.0, lam_max, 200)
    pair = mode_factor(lam, tau_shrink, "taubin", tau_inflate)
    two = mode_factor(lam, tau_shrink, "explicit") ** 2
    fig, ax = plt.subplots(figsize=(7, 3.4))
    ax.plot(lam, pair, "-", lw=2, label=f"one Taubin pair ({tau_shrink:g}, {tau_inflate:g})")
    ax.plot(lam, two, "--", lw=2, label=f"two explicit steps of {tau_shrink:g}")
    at = [
        float(mode_factor(low, tau_shrink, "taubin", tau_inflate)),
        float(mode_factor(low, tau_shrink, "explicit")) ** 2,
    ]
    ax.plot([low, low], at, "ko", ms=5)
    for y, text in zip(at, ("pair", "explicit")):
        ax.annotate(
            f"{text}: {y:.3f}", (low, y), xytext=(6, -4 if text == "explicit" else 4), textcoords="offset points"
        )
    ax.axhline(0, color="0.5", lw=0.6)
    ax.set(
        xlabel=r"eigenvalue $\lambda$ (0: smooth shape, right: fine wiggles)", ylabel="factor kept", xlim=(0, lam_max)
    )
    ax.legend(loc="lower left", fontsize=9)
    alt = (
        f"Factor kept per mode over the eigenvalues 0 to {lam_max:.3g}: one Taubin pair ({tau_shrink:g}, {tau_inflate:g}) "
        f"keeps {at[0]:.3f} of the smooth mode at {low:.3g} where two explicit steps keep {at[1]:.3f}; at the top "
        f"mode the pair keeps {float(pair[-1]):.3f} and the explicit steps {float(two[-1]):.3f}."
    )
    return fig, alt
