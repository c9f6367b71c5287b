"""geomlib.mesh.repair: each cleaning step on a case with a known answer."""

import numpy as np
import pytest

from geomlib import MeshError, surfaces
from geomlib.mesh.repair import largest_component, remove_unreferenced_vertices, remove_zero_area_faces
from geomlib.teaching.notebook import prepare


def _two_spheres():
    a = surfaces.sphere(1.0, subdivisions=1)  # 42 vertices, 80 faces
    b = surfaces.sphere(1.0, subdivisions=2)  # 162 vertices, 320 faces
    return np.vstack([a.V, b.V + 5]), np.vstack([a.F, b.F + len(a.V)]), len(a.V)


def test_unreferenced_vertices_are_dropped_and_faces_renumbered():
    s = surfaces.sphere(1.0, subdivisions=1)
    V = np.vstack([[9.0, 9, 9], s.V, [7.0, 7, 7]])
    F = s.F + 1
    V2, F2, kept = remove_unreferenced_vertices(V, F)
    assert len(V2) == len(s.V) and np.array_equal(kept, np.arange(1, len(s.V) + 1))
    assert np.array_equal(V2[F2], V[F])


def test_largest_component_keeps_the_one_with_most_faces():
    V, F, na = _two_spheres()
    V2, F2, kept = largest_component(V, F)
    assert len(F2) == 320 and kept[0] == na and np.array_equal(V2[F2], V[F[80:]])


def test_zero_area_faces_are_dropped():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0]])
    F = np.array([[0, 1, 2], [0, 1, 3]])  # the second is flat on a line
    _, F2, kept = remove_zero_area_faces(V, F)
    assert np.array_equal(F2, F[:1]) and np.array_equal(kept, [0])


def test_prepare_says_what_it_did(monkeypatch):
    said = []
    monkeypatch.setattr("geomlib.teaching.notebook.note", lambda text, **kw: said.append(text))
    V, F, na = _two_spheres()
    V = np.vstack([V, [[50.0, 0, 0]]])
    V2, F2, kept = prepare(V, F, one_component=True)
    assert len(V2) == 162 and kept[0] == na
    assert len(said) == 2
    assert "1 vertices are not used" in said[0] and "remove_unreferenced_vertices" in said[0]
    assert "2 connected components" in said[1] and "largest_component" in said[1]


def test_prepare_leaves_a_clean_mesh_alone(monkeypatch):
    said = []
    monkeypatch.setattr("geomlib.teaching.notebook.note", lambda text, **kw: said.append(text))
    s = surfaces.sphere(1.0, subdivisions=1)
    V2, F2, kept = prepare(s.V, s.F, one_component=True, closed=True)
    assert said == [] and np.array_equal(V2, s.V) and np.array_equal(kept, np.arange(len(s.V)))


def test_bad_input_is_a_mesh_error():
    with pytest.raises(MeshError):
        remove_unreferenced_vertices(np.zeros((3, 2)), np.array([[0, 1, 2]]))
