"""Estimate against exact: notebooks 01 and 03's scatter plots of a discrete curvature at the interior vertices
of a surface whose exact curvature is known, with the diagonal where the two would agree."""

__all__ = ["exact_scatter_figure"]


def exact_scatter_figure(panels):
    """One panel per ``(estimate, exact, title)``: (k,) arrays of the same vertices; returns the figure.

    The diagonal is drawn over the exact values' range, so a point's distance from it is its error. The
    x axis is "exact" and the title's last word (the quantity: "angle-deficit K" -> "exact K").
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(panels), figsize=(4.5 * len(panels), 3.6), squeeze=False)
    for ax, (estimate, exact, title) in zip(axes[0], panels):
        ax.plot(exact, estimate, ".", ms=3, label="interior vertices")
        ax.plot(exact, exact, "k-", lw=0.8, label="exact (the diagonal)")
        ax.set(xlabel=f"exact {title.split()[-1]}", ylabel=title, title=title)
        ax.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    return fig
