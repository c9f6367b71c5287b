"""The unfolded angle fan of notebook 01: its angles are the mesh's, its gap is the angle deficit."""

import matplotlib
import numpy as np
import pytest

from geomlib import MeshError
from geomlib.lessons.curvature import angle_deficit
from geomlib.teaching.figures.angle_fan import angle_fan_figure, unfolded_fan
from geomlib.teaching.shapes import surfaces

matplotlib.use("Agg")


def test_icosahedron_vertex_leaves_a_sixty_degree_gap():
    ico = surfaces.sphere(1.0, subdivisions=0)
    points, theta, deficit = unfolded_fan(ico.V, ico.F, 0)
    assert len(theta) == 5 and np.allclose(theta, np.pi / 3)
    assert np.isclose(deficit, np.pi / 3)
    # the true edge lengths: every neighbour at the icosahedron's edge length from the vertex
    edge = np.linalg.norm(ico.V[ico.F[0, 1]] - ico.V[ico.F[0, 0]])
    assert np.allclose(np.linalg.norm(points, axis=1), edge)
    # the last point is the first turned by the angle sum: it misses the first by the gap's chord
    assert np.isclose(np.linalg.norm(points[-1] - points[0]), 2 * edge * np.sin(deficit / 2))


@pytest.mark.parametrize("jitter", [0.0, 0.2])
def test_deficit_is_angle_deficit_on_a_torus(jitter):
    T = surfaces.torus(1.0, 0.35, n=12, jitter=jitter, seed=1)
    expected = angle_deficit(T.V, T.F)
    for i in (0, 5, int(np.argmin(np.hypot(T.V[:, 0], T.V[:, 1])))):
        assert np.isclose(unfolded_fan(T.V, T.F, i)[2], expected[i], atol=1e-12)


def test_boundary_vertex_is_refused_and_alt_text_says_the_numbers():
    s = surfaces.saddle(n=4)
    with pytest.raises(MeshError, match="vertex 0 is on the boundary"):
        unfolded_fan(s.V, s.F, 0)
    ico, T = surfaces.sphere(1.0, subdivisions=0), surfaces.torus(1.0, 0.35, n=8)
    inner = int(np.argmin(np.hypot(T.V[:, 0], T.V[:, 1])))
    fig, alt, deficits = angle_fan_figure([("icosahedron", ico.V, ico.F, 0), ("torus", T.V, T.F, inner)])
    assert "sum to 300.0°, leaving a gap of 60.0°" in alt and "overlapping by" in alt and "K < 0" in alt
    assert len(fig.axes) == 2 and deficits[0] > 0 > deficits[1]
