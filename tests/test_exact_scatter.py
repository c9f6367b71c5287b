"""Notebook 01's estimate-against-exact scatter: each panel plots exactly the values it is given."""

import matplotlib

matplotlib.use("agg")
import numpy as np  # noqa: E402

from geomlib.teaching.figures.exact_scatter import exact_scatter_figure  # noqa: E402


def test_each_panel_holds_its_points_and_the_diagonal():
    exact = np.array([0.0, 1.0, 2.0])
    fig = exact_scatter_figure([(exact + 0.1, exact, "scaled H"), (2 * exact, exact, "angle-deficit K")])
    assert [ax.get_title() for ax in fig.axes] == ["scaled H", "angle-deficit K"]
    for ax, factor, shift in zip(fig.axes, (1.0, 2.0), (0.1, 0.0)):
        points, diagonal = ax.lines
        assert np.allclose(points.get_xdata(), exact) and np.allclose(points.get_ydata(), factor * exact + shift)
        assert np.allclose(diagonal.get_xdata(), diagonal.get_ydata())
    assert fig.axes[1].get_xlabel() == "exact K"
    assert exact_scatter_figure([(exact, exact, "your κ₁")]).axes[0].get_xlabel() == "exact κ₁"
