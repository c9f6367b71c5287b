"""The convergence plot of notebook 03: relative errors against the mean edge length, slopes in the legend.

``results`` maps a family of meshes ("regular", "jittered") to rows, one per refinement level:
``{"ell": mean edge length, (quantity, method): (median, maximum) relative error, ...}``;
``slopes`` maps ``(family, (quantity, method), "median" | "max")`` to the fitted log-log slope.
The slopes are shown once, in the legend; the methods are told apart by marker and the two
statistics by line style, so no series depends on colour alone. An area rule keeps its marker and
colour across panels ("cotan, mixed" for H and "mixed" for K).
"""

import numpy as np

__all__ = ["error_figure", "error_alt"]

MARKERS = ("o", "s", "^", "D", "v")


def _slope(p):
    """A slope to two decimals, without a minus sign on zero."""
    text = f"{p:.2f}"
    return "0.00" if text == "-0.00" else text


def _rule(method):
    """The last word of a method's name: "cotan, mixed" and "mixed" share a marker."""
    return method.split(", ")[-1]


def _keys(results):
    first = next(iter(results.values()))[0]
    return [k for k in first if isinstance(k, tuple)]


def error_figure(results, slopes):
    """(fig, alt): one log-log panel per quantity and family, median solid, maximum dashed."""
    import matplotlib.pyplot as plt

    keys = _keys(results)
    quantities = list(dict.fromkeys(q for q, _ in keys))
    # one marker and colour per rule, named by the method's last word, so that "barycentric" and "mixed"
    # look the same in the H and in the K panels
    rules = list(dict.fromkeys(_rule(name) for _, name in keys))
    fig, axes = plt.subplots(
        len(quantities), len(results), figsize=(10, 3.8 * len(quantities)), sharex=True, squeeze=False
    )
    for col, (family, rows) in enumerate(results.items()):
        ell = np.array([r["ell"] for r in rows])
        for row, q in enumerate(quantities):
            ax = axes[row, col]
            for key in (k for k in keys if k[0] == q):
                m = rules.index(_rule(key[1]))
                for i, (stat, style) in enumerate((("median", "-"), ("max", "--"))):
                    ax.loglog(
                        ell,
                        [r[key][i] for r in rows],
                        style,
                        marker=MARKERS[m % len(MARKERS)],
                        color=f"C{m}",
                        mfc="white" if i else None,
                        label=f"{key[1]}, {stat}: slope {_slope(slopes[family, key, stat])}",
                    )
            ax.loglog(ell, 1e-2 * (ell / ell[0]) ** 2, "k:", lw=1, label="slope 2, for reference")
            ax.set(title=f"{q}, {family} meshes", ylabel="relative error")
            ax.xaxis.set_minor_formatter(plt.NullFormatter())
            ax.legend(fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel(r"mean edge length $\ell$")
    fig.tight_layout()
    return fig, error_alt(results, slopes)


def error_alt(results, slopes):
    """The figure's alt text: what is plotted, and every slope it shows."""
    keys = _keys(results)
    families = list(results)
    parts = []
    for stat in ("median", "max"):
        per_key = "; ".join(
            f"{q} {name} " + " / ".join(_slope(slopes[f, (q, name), stat]) for f in families) for q, name in keys
        )
        parts.append(
            f"slopes of the {'median' if stat == 'median' else 'maximum'} error ({' / '.join(families)}): {per_key}"
        )
    n = [r["n"] for r in next(iter(results.values()))] if "n" in next(iter(results.values()))[0] else []
    size = f" over meshes of {n[0]} to {n[-1]} vertices" if n else ""
    return (
        f"Log-log plots of the relative error of each curvature estimate against the mean edge length{size}, "
        f"median (solid) and maximum (dashed), for {' and '.join(families)} meshes, with a dotted line of slope 2. "
        + ". ".join(parts)
        + "."
    )
