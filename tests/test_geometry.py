"""Tests of geomlib.mesh.geometry's vertex normals and volumes against exact answers."""

import numpy as np
import trimesh

from geomlib.mesh.geometry import enclosed_volume, face_cross, face_volumes, vertex_normals, volume_and_centroid


def test_vertex_normals_on_a_sphere_are_radial_and_unit():
    m = trimesh.creation.icosphere(subdivisions=4, radius=1.0)  # 2562 vertices
    V, F = np.asarray(m.vertices), np.asarray(m.faces)
    N = vertex_normals(V, F)
    assert np.abs(N - V / np.linalg.norm(V, axis=1, keepdims=True)).max() < 1e-2
    np.testing.assert_allclose(np.linalg.norm(N, axis=1), 1.0, atol=1e-12)


def test_vertex_normals_flip_with_orientation():
    m = trimesh.creation.icosphere(subdivisions=3, radius=1.0)
    V, F = np.asarray(m.vertices), np.asarray(m.faces)
    np.testing.assert_allclose(vertex_normals(V, F[:, ::-1]), -vertex_normals(V, F), atol=1e-12)


def test_vertex_normals_weigh_faces_by_area():
    # a 2 x 1 rectangle in z = 0 (two halves of area 1, normal +z) and a triangle of area 1/2
    # standing in x = 0 (normal +x) share vertex 0: its normal is (2 (0, 0, 1) + 1/2 (1, 0, 0)) / |...|
    V = np.array([[0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0], [0, 0, 1], [5, 5, 5]], dtype=np.float64)
    F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 4]])
    N = vertex_normals(V, F)
    np.testing.assert_allclose(N[0], np.array([0.5, 0.0, 2.0]) / np.hypot(0.5, 2.0), atol=1e-15)
    np.testing.assert_array_equal(N[5], 0.0)  # in no face: no normal, not NaN


def test_face_volumes_sum_to_the_enclosed_volume_wherever_the_origin_is():
    # a box 2 x 1 x 0.5 centred at (3, -1, 2): volume 1, centroid the centre, for any origin
    m = trimesh.creation.box(extents=(2.0, 1.0, 0.5))
    V, F = np.asarray(m.vertices) + [3.0, -1.0, 2.0], np.asarray(m.faces, dtype=np.int64)
    assert face_volumes(V, F).sum() == enclosed_volume(V, F) == enclosed_volume(V, F, face_cross(V, F))
    assert abs(enclosed_volume(V, F) - 1.0) < 1e-14
    vol, centroid = volume_and_centroid(V, F)
    assert vol == enclosed_volume(V, F)
    np.testing.assert_allclose(centroid, [3.0, -1.0, 2.0], atol=1e-14)
    assert abs(enclosed_volume(V, F[:, ::-1]) + 1.0) < 1e-14  # clockwise faces: the volume's sign flips
