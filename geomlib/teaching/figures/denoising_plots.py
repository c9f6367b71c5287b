"""Notebook 07's experiments, drawn: the comparison's heat maps of a metric over step and iterations, one per
method (:func:`geomlib.teaching.experiments.sweep.denoising_comparison`), and the error curves of a step sweep
(:func:`geomlib.denoising_sweep`)."""

import numpy as np

__all__ = ["COMPARISON_LABELS", "plot_comparison", "plot_sweep"]


#: How the comparison's heat maps name each metric on their colour bar.
COMPARISON_LABELS = {
    "rms": "E: vertex RMS error / d",
    "normal_mean": "mean face-normal error (degrees)",
    "volume_change": "|volume change| (fraction)",
}


def plot_comparison(result, i, key="rms"):
    """Heat maps of :func:`denoising_comparison` at noise level ``i``: one panel per method.

    Each panel: ``key`` over (step, iteration count), in one unit on every panel (y: the step
    as a fraction of the explicit limit of the method's operator; x: iterations, Taubin's
    pairs), on one log colour scale for all panels in the metric's own unit, the unit of the
    number written at each panel's best cell (ringed); the noisy input's value is marked on
    the colour bar, so a cell darker than the mark improved on the input. Returns
    ``(fig, alt)``, the alt text built from the plotted numbers.
    """
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    noisy = float(result.noisy[key][i])
    shown = [np.abs(v[i]) for v in result.values[key]]
    found = np.concatenate([x[np.isfinite(x) & (x > 0)] for x in shown] + [np.array([noisy] if noisy > 0 else [])])
    lo, hi = (float(found.min()), float(found.max())) if found.size else (1.0, 1.0)
    norm = LogNorm(vmin=lo, vmax=max(hi, 10 * lo))
    fig, axes = plt.subplots(1, len(result.methods), figsize=(3.6 * len(result.methods), 3.3), squeeze=False)
    found, edge = [], []
    for ax, (method, weights), values in zip(axes[0], result.methods, shown):
        steps, counts = result.grids[method, weights]
        im = ax.imshow(values, cmap="viridis", norm=norm, aspect="auto", origin="lower")
        b = result.best(i, (method, weights), key)
        k, l = b["index"]
        ax.plot(l, k, "o", ms=14, mfc="none", mec="white", mew=2)
        side = "center" if 0 < l < len(counts) - 2 else ("left" if l == 0 else "right")  # kept inside the panel
        shift = {"center": 0, "left": -8, "right": 8}[side]
        ax.annotate(f"{b[key]:.3g}", (l, k), xytext=(shift, 11), textcoords="offset points", ha=side, color="white")
        ticks = range(0, len(counts), -(-len(counts) // 5))  # at most five labels: they must not run together
        ax.set_xticks(list(ticks), [str(counts[c]) for c in ticks])
        ax.set_yticks(range(len(steps)), [f"{s:g}" for s in steps])
        ax.set_xlabel("shrink/inflate pairs" if method == "taubin" else "iterations")
        ax.set_title(f"{method}, {weights}", fontsize=10)
        found.append(f"{method} {weights} {b[key]:.3g} at {b['fraction']:g} of the limit, {b['iterations']} iterations")
        if not b["inside"]:
            edge.append(f"{method} {weights}")
    axes[0, 0].set_ylabel("step / explicit limit")
    name = COMPARISON_LABELS.get(key, key)
    bar = fig.colorbar(im, ax=axes, label=f"{name} (log scale)", shrink=0.9)
    if noisy > 0:  # the input every setting has to beat, on the same scale
        bar.ax.axhline(noisy, color="black", lw=2)
        bar.ax.annotate("noisy\ninput", (0, noisy), xytext=(-4, 0), textcoords="offset points", ha="right", va="center")
    fig.suptitle(f"noise sigma = {result.sigmas[i]:g}: {name} after smoothing, over step and iterations", y=1.04)
    alt = (
        f"{len(result.methods)} heat maps at noise sigma {result.sigmas[i]:g}, one per method, of {name} over the "
        f"step (as a fraction of the explicit limit) and the iteration count, from {lo:.3g} to {hi:.3g} on one log "
        f"colour scale; the noisy input's {noisy:.3g} is marked on the colour bar. Each method's smallest value ("
        + (f"on its grid's edge for {' and '.join(edge)}" if edge else "inside its grid")
        + "): "
        + "; ".join(found)
        + "."
    )
    return fig, alt


def plot_sweep(E, taus, E_noisy=None, unit="length^2"):
    """The error of a step sweep (:func:`geomlib.denoising_sweep`): one curve per step over the iterations.

    ``E`` (len(taus), N + 1): the error after k = 0..N iterations of each step (log y axis); the
    smallest is ringed, and ``E_noisy`` (the noisy mesh's error, default ``E[0, 0]``) drawn as a
    line every curve starts on. Returns ``(fig, alt)``, the alt text built from the plotted numbers.
    """
    import matplotlib.pyplot as plt

    E = np.asarray(E, dtype=float)
    E_noisy = float(E[0, 0] if E_noisy is None else E_noisy)
    i, k = np.unravel_index(np.argmin(E), E.shape)
    fig, ax = plt.subplots(figsize=(6.4, 3.6))
    for row, tau in zip(E, taus):
        ax.plot(np.arange(len(row)), row, label=f"tau = {tau:.3g}")
    ax.plot(k, E[i, k], "o", ms=12, mfc="none", mec="black", mew=2)
    ax.axhline(E_noisy, color="grey", ls="--", lw=1)
    ax.annotate("noisy input", (len(E[0]) - 1, E_noisy), xytext=(0, 4), textcoords="offset points", ha="right")
    ax.set(yscale="log", xlabel="iterations N", ylabel="error E (vertex RMS / d)")
    ax.set_title(f"implicit smoothing, one curve per step tau ({unit}): the best is ringed", fontsize=10)
    ax.legend(fontsize=8)
    ends = "; ".join(f"tau {tau:.3g}: smallest {row.min():.3g} at N = {int(row.argmin())}" for row, tau in zip(E, taus))
    alt = (
        f"The error E over the iteration count for {len(taus)} steps of implicit smoothing, on a log scale, all "
        f"starting at the noisy mesh's {E_noisy:.3g}. The smallest, {E[i, k]:.3g}, is at tau {taus[i]:.3g} and "
        f"N = {k} (ringed). Per step: {ends}."
    )
    return fig, alt
