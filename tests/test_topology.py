"""Tests for geomlib.mesh.topology: closed-form counts, orientation laws, course meshes."""

import numpy as np
import pytest
import trimesh
from meshdata import COURSE, needs_course

from geomlib import (
    MeshError,
    boundary_edges,
    boundary_loops,
    boundary_vertices,
    connected_components,
    edges,
    euler_characteristic,
    load_mesh,
    one_ring,
    valence,
    vertex_face_adjacency,
)

# ---------------------------------------------------------------- small meshes


def grid(k):
    """k x k vertices on the unit square (z = 0), each cell split along the same diagonal.

    Faces are counter-clockwise seen from +z. Interior vertices have valence 6.
    """
    x, y = np.meshgrid(np.linspace(0, 1, k), np.linspace(0, 1, k), indexing="ij")
    V = np.stack([x.ravel(), y.ravel(), np.zeros(k * k)], axis=1)
    i, j = np.meshgrid(np.arange(k - 1), np.arange(k - 1), indexing="ij")
    a = (i * k + j).ravel()
    b, c, d = a + k, a + k + 1, a + 1
    F = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    return V, F


def torus(nu=12, nv=8, R=1.0, r=0.4):
    u, v = np.meshgrid(np.arange(nu) * 2 * np.pi / nu, np.arange(nv) * 2 * np.pi / nv, indexing="ij")
    V = np.stack([(R + r * np.cos(v)) * np.cos(u), (R + r * np.cos(v)) * np.sin(u), r * np.sin(v)], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    a = i * nv + j
    b = ((i + 1) % nu) * nv + j
    c = ((i + 1) % nu) * nv + (j + 1) % nv
    d = i * nv + (j + 1) % nv
    F = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return V, F


def disk(k=7):
    """A hub vertex 0 and a ring of k vertices: k triangles, counter-clockwise from +z."""
    t = np.arange(k) * 2 * np.pi / k
    V = np.vstack([[0, 0, 0], np.stack([np.cos(t), np.sin(t), np.zeros(k)], 1)])
    ring = np.arange(1, k + 1)
    F = np.stack([np.zeros(k, int), ring, np.roll(ring, -1)], 1)
    return V, F


def icosahedron():
    m = trimesh.creation.icosahedron()
    return np.asarray(m.vertices), np.asarray(m.faces, dtype=np.int64)


def two_tetrahedra_at_a_vertex():
    """Two closed tetrahedra sharing vertex 0 only: a pinch (non-manifold) vertex."""
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [-1, 0, 0], [0, -1, 0], [0, 0, -1]], float)
    tet = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    F = np.concatenate([tet, np.where(tet == 0, 0, tet + 3)])
    return V, F


# ---------------------------------------------------------------- closed forms


def test_icosahedron_counts():
    V, F = icosahedron()
    E = edges(F)
    assert (len(V), len(E), len(F)) == (12, 30, 20)
    assert euler_characteristic(V, F) == 2
    assert np.array_equal(valence(F, 12), np.full(12, 5))
    assert len(boundary_edges(F)) == 0 and boundary_loops(F) == [] and len(boundary_vertices(F)) == 0


def test_edges_sorted_unique_and_match_trimesh():
    V, F = torus(9, 7)
    E = edges(F)
    assert E.dtype == np.int64 and E.shape[1] == 2
    assert (E[:, 0] < E[:, 1]).all()
    assert np.array_equal(E, np.unique(E, axis=0))  # lexicographically sorted, no repeats
    ref = np.unique(np.sort(trimesh.Trimesh(V, F, process=False).edges_unique, axis=1), axis=0)
    assert np.array_equal(E, ref)


def test_edges_invariant_under_face_order_and_rotation():
    V, F = torus(7, 5)
    rng = np.random.default_rng(3)
    G = np.roll(F[rng.permutation(len(F))], 1, axis=1)
    assert np.array_equal(edges(F), edges(G))


def test_grid_boundary_and_valence():
    k = 6
    V, F = grid(k)
    loops = boundary_loops(F)
    assert len(loops) == 1 and len(loops[0]) == 4 * (k - 1)
    assert len(boundary_edges(F)) == 4 * (k - 1)
    bv = boundary_vertices(F)
    assert np.array_equal(bv, np.unique(loops[0]))
    inside = np.setdiff1d(np.arange(k * k), bv)
    assert len(inside) == (k - 2) ** 2
    assert (valence(F, k * k)[inside] == 6).all()
    assert euler_characteristic(V, F) == 1


def test_boundary_edges_are_traversed_by_their_face():
    V, F = grid(5)
    B = boundary_edges(F)
    directed = {tuple(e) for f in F.tolist() for e in zip(f, f[1:] + f[:1])}
    assert all(tuple(e) in directed for e in B.tolist())
    assert all((b, a) not in directed for a, b in B.tolist())


def test_boundary_loop_is_counter_clockwise_for_upward_faces():
    # faces counter-clockwise seen from +z lie to the left of the loop: positive signed area
    for V, F in (grid(5), disk(9)):
        (loop,) = boundary_loops(F)
        x, y = V[loop, 0], V[loop, 1]
        assert 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) > 0
        assert loop[0] == loop.min()
        consecutive = set(zip(loop.tolist(), np.roll(loop, -1).tolist()))
        assert consecutive == {tuple(e) for e in boundary_edges(F).tolist()}


def test_two_boundary_loops_of_an_annulus():
    V, F = grid(6)
    # punch a hole: drop every face at the four centre vertices; the hole's rim is
    # their ring of neighbours, the 4 x 4 block around them minus the two corners the
    # diagonals (i, j)-(i+1, j+1) do not reach: 10 vertices
    keep = ~np.isin(F, [14, 15, 20, 21]).any(axis=1)
    loops = boundary_loops(F[keep])
    assert sorted(len(l) for l in loops) == [10, 20]
    assert euler_characteristic(V, F[keep]) == 0


def test_torus_and_disk_euler():
    assert euler_characteristic(*torus()) == 0
    assert euler_characteristic(*disk()) == 1
    V, F = disk(5)
    assert len(boundary_loops(F)[0]) == 5


def test_euler_counts_only_referenced_vertices():
    V, F = icosahedron()
    V2 = np.vstack([V, [[5.0, 5.0, 5.0]]])
    assert euler_characteristic(V2, F) == 2


def test_one_ring_interior_counter_clockwise_around_outward_normal():
    V, F = icosahedron()
    for i in range(12):
        ring = one_ring(F, i)
        assert len(ring) == 5
        assert set(ring.tolist()) == set(np.unique(F[(F == i).any(1)]).tolist()) - {i}
        d = V[ring] - V[i]
        turn = np.cross(d, np.roll(d, -1, axis=0)).sum(axis=0)
        assert turn @ V[i] > 0  # counter-clockwise about the outward direction


def test_one_ring_boundary_vertex():
    k = 5
    V, F = grid(k)
    i = 2  # middle of the edge x = 0
    ring = one_ring(F, i)
    assert len(ring) == valence(F, k * k)[i] == len(np.flatnonzero((F == i).any(1))) + 1
    # starts and ends on the boundary, counter-clockwise seen from +z
    B = boundary_edges(F)
    assert (i, ring[0]) in set(map(tuple, B.tolist()))
    assert (ring[-1], i) in set(map(tuple, B.tolist()))
    d = V[ring] - V[i]
    assert (np.cross(d[:-1], d[1:])[:, 2] > 0).all()


def test_one_ring_of_hub_and_unreferenced_vertex():
    V, F = disk(6)
    assert np.array_equal(one_ring(F, 0), np.arange(1, 7))
    assert len(one_ring(F, 99)) == 0


def test_one_ring_refuses_a_pinch_vertex():
    V, F = two_tetrahedra_at_a_vertex()
    with pytest.raises(MeshError, match=r"vertex 0 is non-manifold.*more than one fan"):
        one_ring(F, 0)
    assert len(one_ring(F, 1)) == 3


def test_one_ring_refuses_two_open_fans():
    # two triangles touching only at vertex 0 (a bow tie)
    F = np.array([[0, 1, 2], [0, 3, 4]])
    with pytest.raises(MeshError, match=r"vertex 0 is non-manifold.*2 separate fans"):
        one_ring(F, 0)


def test_one_ring_refuses_inconsistent_orientation():
    V, F = icosahedron()
    F = F.copy()
    f = np.flatnonzero((F == 0).any(1))[0]
    F[f] = F[f, ::-1]
    with pytest.raises(MeshError, match="consistent orientation"):
        one_ring(F, 0)


def test_one_ring_negative_index():
    with pytest.raises(MeshError, match="negative"):
        one_ring(np.array([[0, 1, 2]]), -1)


def test_connected_components_labels():
    V1, F1 = icosahedron()
    F = np.concatenate([F1 + 1, F1 + 14])  # vertex 0 and 13 unused
    labels = connected_components(F, 26)
    assert labels[0] == -1 and labels[13] == -1
    assert (labels[1:13] == 0).all() and (labels[14:26] == 1).all()
    assert labels.max() + 1 == 2


def test_valence_sums_to_twice_edges():
    V, F = torus(10, 6)
    assert valence(F).sum() == 2 * len(edges(F))
    assert (valence(F) == 6).all()


def test_vertex_face_adjacency():
    V, F = disk(6)
    A = vertex_face_adjacency(F)
    assert A.shape == (7, 6)
    assert np.array_equal(np.asarray(A.sum(axis=1)).ravel(), [6, 2, 2, 2, 2, 2, 2])


def test_functions_validate_faces():
    with pytest.raises(MeshError, match=r"shape \(m, 3\)"):
        edges(np.zeros((4, 4), int))
    with pytest.raises(MeshError, match=r"face 1 has index -2"):
        valence(np.array([[0, 1, 2], [0, -2, 1]]))
    with pytest.raises(MeshError, match=r"valid: 0..2 for 3 vertices.*face 0 has index 3"):
        boundary_vertices(np.array([[0, 1, 3]]), n=3)
    with pytest.raises(MeshError, match=r"1 face repeats a vertex.*face 0 = \[1, 1, 2\]"):
        boundary_loops(np.array([[1, 1, 2]]))


# ---------------------------------------------------------------- course meshes

# (file, Euler characteristic, boundary loop lengths) from shared/meshes/PROVENANCE.md
COURSE_TOPOLOGY = [
    ("camel.obj", 1, []),
    ("cow_manifold2.obj", 1, [16]),
    ("cow_small_manifold2.obj", 1, [6]),
    ("curvatures/lilium_s.obj", 1, [70]),
    ("curvatures/plane.obj", 1, [36]),
    ("decompose/armadillo.obj", 2, []),
    ("decomposition/terrain.obj", 1, [157]),
    ("bunny.obj", 2, []),
]


@needs_course
@pytest.mark.parametrize("name, chi, loops", COURSE_TOPOLOGY)
def test_course_mesh_topology(name, chi, loops):
    V, F = load_mesh(COURSE / name, report=True)[:2]
    assert euler_characteristic(V, F) == chi
    assert sorted(len(l) for l in boundary_loops(F)) == loops
    assert len(boundary_edges(F)) == sum(loops)


@needs_course
def test_camel_pinch_vertex_one_ring():
    V, F = load_mesh(COURSE / "camel.obj", report=True)[:2]
    with pytest.raises(MeshError, match="vertex 946 is non-manifold"):
        one_ring(F, 946)
    assert len(one_ring(F, 0)) == valence(F)[0]


def test_loop_chaining_vectorised_matches_walk():
    from geomlib.mesh.topology import _loops_vectorised, _loops_walk

    V, F = grid(7)
    holed = F[~np.isin(F, [16, 17, 23, 24]).any(axis=1)]
    separate = np.arange(3 * 50).reshape(-1, 3)[np.random.default_rng(2).permutation(50)]
    for faces in (F, holed, separate, disk(11)[1]):
        B = boundary_edges(faces)
        fast, slow = _loops_vectorised(B), _loops_walk(B)
        assert fast is not None and len(fast) == len(slow)
        assert all(np.array_equal(a, b) for a, b in zip(fast, slow))
    # a bow tie: vertex 0 has two outgoing boundary edges, so the walk decides
    bow = np.array([[0, 1, 2], [0, 3, 4]])
    assert _loops_vectorised(boundary_edges(bow)) is None
    loops = boundary_loops(bow)
    assert sorted(len(l) for l in loops) == [3, 3]


def test_edge_face_counts_boundary_counts_and_face_pairs():
    from geomlib.mesh.topology import Topology, boundary_edge_counts, edge_face_counts

    # a square of two triangles, and a third triangle on edge (0, 1) below it
    F = np.array([[0, 1, 2], [0, 2, 3], [1, 0, 4]])
    E, count = edge_face_counts(F)
    assert E.tolist() == [[0, 1], [0, 2], [0, 3], [0, 4], [1, 2], [1, 4], [2, 3]]
    assert count.tolist() == [2, 2, 1, 1, 1, 1, 1]
    assert boundary_edge_counts(F).tolist() == [2, 2, 2, 2, 2]
    E2, f1, f2 = Topology(F, 5).face_pairs()
    assert E2.tolist() == [[0, 1], [2, 0]] and f1.tolist() == [0, 0] and f2.tolist() == [2, 1]
    # a bow-tie vertex has four boundary edges
    assert boundary_edge_counts(np.array([[0, 1, 2], [0, 3, 4]]))[0] == 4


def test_unreferenced_vertices_and_non_manifold_edges():
    from geomlib.mesh.topology import non_manifold_edges, unreferenced_vertices

    F = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 5]])
    assert unreferenced_vertices(F, 7).tolist() == [4, 6]
    assert non_manifold_edges(F).tolist() == [[0, 1]]
    assert non_manifold_edges(F[:2]).shape == (0, 2)


def test_boundary_counts_through_unpaired_vertices_match_the_full_edge_count():
    """The half-edge probes only skip work: on open, flipped, bow-tie and non-manifold meshes
    the boundary counts equal those of the full edge table."""
    from geomlib.mesh.topology import boundary_edge_counts, edge_face_counts, unpaired_vertices
    from geomlib.teaching.shapes.surfaces import icosphere, plane

    _, closed = icosphere(2)
    grid = plane(n=12).F
    flipped = grid.copy()
    flipped[::3] = flipped[::3, ::-1]  # inconsistent orientation: interior edges, unpaired half-edges
    rng = np.random.default_rng(3)
    holes = closed[rng.permutation(len(closed))[:-25]]  # an open sphere with holes
    bowtie = np.array([[0, 1, 2], [0, 3, 4], [0, 5, 6], [1, 2, 7]])
    fin = np.vstack([closed, [[0, 1, 200]]])  # an edge of three faces
    assert not unpaired_vertices(closed).any()
    for F in (closed, grid, flipped, holes, bowtie, fin):
        E, count = edge_face_counts(F)
        exact = np.bincount(E[count == 1].ravel(), minlength=F.max() + 1)
        np.testing.assert_array_equal(boundary_edge_counts(F), exact)
