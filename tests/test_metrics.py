"""Denoising metrics on cases with known answers, identities and laws."""

import numpy as np
import pytest
import trimesh

from geomlib import MeshError
from geomlib.lessons.metrics import (
    MeshComparison,
    area_change,
    bounding_box_diagonal,
    denoising_metrics,
    dihedral_angles,
    enclosed_volume,
    face_normal_angles,
    hausdorff_distance,
    interior_edges,
    normal_angle_error,
    point_surface_distance,
    point_triangle_distance,
    sample_surface,
    sharp_edge_error,
    sharp_edges,
    surface_area,
    vertex_rms,
    volume_change,
)
from geomlib.lessons.noise import add_noise


def icosphere(subdivisions=3, radius=1.0):
    mesh = trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius)
    return np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)


def grid(n=11, size=2.0):
    """Flat n x n grid in z = 0, [0, size]^2, counter-clockwise seen from +z."""
    x = np.linspace(0, size, n)
    X, Y = np.meshgrid(x, x, indexing="ij")
    V = np.column_stack([X.ravel(), Y.ravel(), np.zeros(n * n)])
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    F = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])]).astype(np.int64)
    return V, F


def rotation(axis, degrees):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    return trimesh.transformations.rotation_matrix(np.radians(degrees), axis)[:3, :3]


def cube():
    mesh = trimesh.creation.box(extents=(2.0, 2.0, 2.0))
    return np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)


# --- identical meshes -------------------------------------------------------


def test_identical_meshes_give_zero_everywhere():
    V, F = icosphere(2)
    out = denoising_metrics(V.copy(), V, F)
    for key in ("rms", "normal_mean", "normal_p95", "area_change", "volume_change"):
        assert out[key] == 0.0, key
    # samples inside faces are interpolated, so they sit on the other surface to rounding
    assert out["hausdorff"] < 1e-15
    V, F = cube()
    assert denoising_metrics(V.copy(), V, F)["sharp_edge_error"] == 0.0


# --- vertex RMS -----------------------------------------------------------


def test_translated_copy_has_rms_equal_to_the_shift():
    V, F = icosphere(2)
    shift = np.array([0.03, -0.04, 0.12])  # length 0.13
    assert vertex_rms(V + shift, V, relative=False) == pytest.approx(0.13, rel=1e-12)
    assert vertex_rms(V + shift, V) == pytest.approx(0.13 / bounding_box_diagonal(V), rel=1e-12)


def test_rms_of_a_scaled_sphere_is_the_radius_change():
    V, F = icosphere(2, radius=1.0)  # every vertex at radius 1
    assert vertex_rms(1.07 * V, V, relative=False) == pytest.approx(0.07, rel=1e-12)


def test_relative_metrics_do_not_depend_on_units_or_position():
    # relative lengths are divided by the (axis-aligned) bounding-box diagonal:
    # invariant under scaling and translation; angles and relative changes are
    # invariant under rotation too, and so are the absolute distances
    V, F = icosphere(2)
    W = add_noise(V, F, 0.01, seed=5)
    a = denoising_metrics(W, V, F)
    b = denoising_metrics(13.0 * W + [5.0, -1.0, 2.0], 13.0 * V + [5.0, -1.0, 2.0], F)
    for key in a:
        assert b[key] == pytest.approx(a[key], rel=1e-6, abs=1e-12, nan_ok=True), key
    R = rotation([1, 2, 3], 40)
    c = denoising_metrics(W @ R.T, V @ R.T, F)
    for key in ("normal_mean", "normal_p95", "area_change", "volume_change"):
        assert c[key] == pytest.approx(a[key], rel=1e-6, abs=1e-12), key
    assert vertex_rms(W @ R.T, V @ R.T, relative=False) == pytest.approx(vertex_rms(W, V, relative=False))
    assert hausdorff_distance(W @ R.T, V @ R.T, F, relative=False) == pytest.approx(
        hausdorff_distance(W, V, F, relative=False), rel=1e-9
    )


# --- normals -----------------------------------------------------------


@pytest.mark.parametrize("degrees", [0.5, 10.0, 37.0, 120.0])
def test_rotated_patch_has_every_normal_off_by_the_angle(degrees):
    # a flat patch in z = 0 turned about the x axis: every normal (0, 0, 1)
    # is perpendicular to the axis and turns by exactly the angle
    V, F = grid(6)
    W = V @ rotation([1.0, 0.0, 0.0], degrees).T
    mean, p95 = normal_angle_error(W, V, F)
    assert mean == pytest.approx(degrees, abs=1e-9)
    assert p95 == pytest.approx(degrees, abs=1e-9)


def test_rotated_sphere_normals_turn_by_the_angle_times_sine_law():
    # a normal n turned by theta about the unit axis a moves through the angle
    # 2 asin(sin(theta / 2) |a x n|)
    V, F = icosphere(2)
    a = np.array([0.3, -1.0, 0.2]) / np.linalg.norm([0.3, -1.0, 0.2])
    theta = 50.0
    W = V @ rotation(a, theta).T
    N = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    N /= np.linalg.norm(N, axis=1)[:, None]
    expected = np.degrees(2 * np.arcsin(np.sin(np.radians(theta) / 2) * np.linalg.norm(np.cross(a, N), axis=1)))
    np.testing.assert_allclose(face_normal_angles(W, V, F), expected, atol=1e-9)


def test_one_tilted_face_has_the_known_angle():
    # lift one corner of a right triangle in the plane z = 0 so that the face
    # tilts by exactly theta about the opposite edge
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    F = np.array([[0, 1, 2]])
    theta = 23.0
    W = V.copy()
    # tilt about the edge 0-1 (the x axis): vertex 2 rotates in the y-z plane
    W[2] = [0, np.cos(np.radians(theta)), np.sin(np.radians(theta))]
    assert face_normal_angles(W, V, F)[0] == pytest.approx(theta, abs=1e-12)
    # a flipped face is 180 degrees off, a collapsed one counts as 90
    assert face_normal_angles(V[[0, 2, 1]], V, F)[0] == pytest.approx(180.0)
    assert face_normal_angles(np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]]), V, F)[0] == 90.0


def test_normal_percentile_counts_faces():
    # tilt exactly one face of a flat grid: the mean is angle / m, the 95th percentile 0
    V, F = grid(5)
    W = V.copy()
    corner = int(np.flatnonzero(np.bincount(F.ravel()) == 1)[0])  # a corner in one face only
    W[corner, 2] = 0.1
    angles = face_normal_angles(W, V, F)
    assert np.count_nonzero(angles) == 1
    mean, p95 = normal_angle_error(W, V, F)
    assert mean == pytest.approx(angles.max() / len(F))
    assert p95 == 0.0


# --- area and volume -------------------------------------------------------


@pytest.mark.parametrize("s", [0.5, 1.0, 1.3])
def test_scaling_changes_area_by_s2_and_volume_by_s3(s):
    V, F = icosphere(3)
    assert area_change(s * V, V, F) == pytest.approx(s**2 - 1, abs=1e-12)
    assert volume_change(s * V, V, F) == pytest.approx(s**3 - 1, abs=1e-12)


def test_cube_area_and_volume_are_exact():
    V, F = cube()
    assert surface_area(V, F) == pytest.approx(24.0)
    assert enclosed_volume(V, F) == pytest.approx(8.0)
    assert enclosed_volume(V + 10.0, F) == pytest.approx(8.0)  # closed: origin-free


def test_volume_of_an_open_mesh_raises_and_the_report_says_nan():
    V, F = grid(4)
    W = V + [0, 0, 0.1]
    with pytest.raises(MeshError, match="closed meshes only"):
        volume_change(W, V, F)
    out = denoising_metrics(W, V, F)
    assert np.isnan(out["volume_change"])
    assert out["area_change"] == pytest.approx(0.0, abs=1e-12)


# --- point to surface distance and Hausdorff ---------------------------------


def test_point_triangle_distance_in_each_region():
    A, B, C = np.array([0.0, 0, 0]), np.array([1.0, 0, 0]), np.array([0.0, 1, 0])
    P = np.array(
        [
            [0.2, 0.2, 0.7],  # above the interior: the height
            [0.5, -0.3, 0.4],  # beside edge AB: distance to the edge
            [-0.3, -0.4, 0.0],  # beyond corner A
            [1.0, 1.0, 0.0],  # beyond edge BC, in the plane
            [2.0, -1.0, 2.0],  # beyond corner B
        ]
    )
    expected = [0.7, 0.5, 0.5, np.sqrt(2) / 2, np.sqrt(1 + 1 + 4)]
    k = len(P)
    d = point_triangle_distance(P, np.tile(A, (k, 1)), np.tile(B, (k, 1)), np.tile(C, (k, 1)))
    np.testing.assert_allclose(d, expected, rtol=1e-14)
    # a degenerate triangle is a segment
    d = point_triangle_distance(np.array([[0.5, 1.0, 0.0]]), A[None], B[None], (A + B)[None] / 2)
    assert d[0] == pytest.approx(1.0)


def test_point_surface_distance_agrees_with_libigl():
    igl = pytest.importorskip("igl")
    V, F = icosphere(3)
    W = add_noise(V, F, 0.02, seed=1)
    rng = np.random.default_rng(0)
    P = np.vstack(
        [
            rng.normal(size=(500, 3)) * 0.8,  # inside and around
            sample_surface(V, F, 500, seed=2),
            rng.normal(size=(50, 3)) * 10,
        ]
    )  # far away
    d = point_surface_distance(P, W, F)
    d2, _, _ = igl.point_mesh_squared_distance(P, W, F)
    np.testing.assert_allclose(d, np.sqrt(d2), rtol=1e-12, atol=1e-14)


def test_hausdorff_of_a_plane_patch_lifted_by_d_is_d():
    V, F = grid(9, size=1.0)
    for d in (1e-4, 0.05, 0.4):
        W = V + [0, 0, d]
        assert hausdorff_distance(W, V, F, relative=False) == pytest.approx(d, rel=1e-12)
        assert hausdorff_distance(W, V, F) == pytest.approx(d / np.sqrt(2), rel=1e-12)


def test_hausdorff_of_an_offset_sphere_is_the_offset():
    # the polyhedral sphere of radius 1 + d around the one of radius 1: the
    # big mesh's vertices are exactly d away (the small convex polyhedron lies
    # in the unit ball and touches it along their rays), nothing is further
    V, F = icosphere(3)
    for d in (0.01, 0.2):
        h = hausdorff_distance((1 + d) * V, V, F, relative=False, seed=3)
        assert h == pytest.approx(d, rel=1e-12)
        h = hausdorff_distance(V, (1 + d) * V, F, relative=False, seed=3)
        assert h == pytest.approx(d, rel=1e-12)  # symmetric


def test_hausdorff_of_a_translated_convex_mesh_is_the_translation_length():
    # for convex polyhedra K and K + t the supporting planes in the direction
    # of t are |t| apart, and a vertex of K + t attains it
    V, F = icosphere(2)
    t = np.array([0.02, 0.05, -0.01])
    h = hausdorff_distance(V + t, V, F, relative=False)
    assert h == pytest.approx(np.linalg.norm(t), rel=1e-12)


def test_hausdorff_is_an_estimate_from_below_and_sees_between_vertices():
    # a sphere mesh against a finer one: the coarse faces cut inside the
    # sphere, deepest at the face centres, which no vertex sees
    V, F = icosphere(1)
    fine = trimesh.creation.icosphere(subdivisions=4)
    Vf, Ff = np.asarray(fine.vertices), np.asarray(fine.faces, dtype=np.int64)
    vertices_only = hausdorff_distance(V, Vf, F, Ff, relative=False, samples_per_face=0)
    sampled = hausdorff_distance(V, Vf, F, Ff, relative=False, samples_per_face=20)
    # true value: about 1 - (inradius of the coarse mesh's deepest face)
    centres = V[F].mean(axis=1)
    depth = 1 - np.linalg.norm(centres, axis=1).min()
    assert vertices_only < sampled <= depth + 1e-3
    assert sampled > 0.9 * depth


def test_hausdorff_samples_are_seeded():
    V, F = icosphere(2)
    W = add_noise(V, F, 0.01, seed=4)
    a = hausdorff_distance(W, V, F, seed=9)
    assert hausdorff_distance(W, V, F, seed=9) == a
    C = MeshComparison(V, F, seed=9)
    assert C.hausdorff(W) == C.hausdorff(W)


def test_hausdorff_shortcuts_measure_the_same_points():
    # with one connectivity the bounds come from corresponding points, and MeshComparison keeps the
    # clean side: both only save work, so the estimate is the general one (meshes told apart by F_clean)
    V, F = icosphere(3)
    for sigma in (0.002, 0.02):
        W = add_noise(V, F, sigma, seed=5)
        general = hausdorff_distance(W, V, F, F.copy(), seed=9)
        assert hausdorff_distance(W, V, F, seed=9) == pytest.approx(general, rel=1e-12)
        C = MeshComparison(V, F, seed=9)
        assert C.hausdorff(W) == pytest.approx(general, rel=1e-12)
        assert C.hausdorff(W, seed=3) == pytest.approx(hausdorff_distance(W, V, F, F.copy(), seed=3), rel=1e-12)


def test_hausdorff_is_at_least_the_vertex_to_vertex_lower_bound_and_at_most_max_displacement():
    V, F = icosphere(3)
    W = add_noise(V, F, 0.005, seed=8)
    h = hausdorff_distance(W, V, F, relative=False)
    # each point of one surface has a partner (same barycentric coordinates)
    # on the other no further than the largest vertex displacement
    assert h <= np.linalg.norm(W - V, axis=1).max() + 1e-12
    assert h > 0


# --- dihedral angles and sharp edges -----------------------------------------


def test_cube_edges_bend_by_90_degrees_and_face_diagonals_by_0():
    V, F = cube()
    E, angle = dihedral_angles(V, F)
    assert len(E) == 18  # 12 cube edges + 6 face diagonals
    assert np.sum(np.isclose(angle, 90.0)) == 12
    assert np.sum(np.isclose(angle, 0.0, atol=1e-12)) == 6
    Es, sharp_angle = sharp_edges(V, F, threshold=30)
    assert len(Es) == 12
    # turned inside out every fold is concave
    _, angle_in = dihedral_angles(V, F[:, ::-1])
    assert np.sum(np.isclose(angle_in, -90.0)) == 12


@pytest.mark.parametrize("delta", [-15.0, 5.0, 20.0])
def test_opening_a_hinge_by_delta_gives_sharp_edge_error_delta(delta):
    # two triangles on the edge 0-1 (the x axis) folded by 60 degrees (convex)
    def hinge(bend):
        b = np.radians(bend)
        return np.array([[0.0, 0, 0], [1, 0, 0], [0.5, -1, 0], [0.5, np.cos(b), -np.sin(b)]])

    F = np.array([[0, 2, 1], [0, 1, 3]])
    E, angle = dihedral_angles(hinge(60.0), F)
    assert angle == pytest.approx([60.0])
    assert sharp_edge_error(hinge(60.0 + delta), hinge(60.0), F) == pytest.approx(abs(delta))
    # a fold below the threshold is not a feature
    assert np.isnan(sharp_edge_error(hinge(20.0 + delta), hinge(20.0), F))


def test_the_sharp_edge_error_is_of_the_signed_bend_so_a_fold_turned_over_counts_whole():
    """The text of 07a defines theta_e as the signed bend: +90 at a cube's (convex) edge, -90 in a notch, 0 flat.
    A concave 60-degree fold turned into a convex one is off by 120 degrees, more than any unsigned angle
    between normals could be off (at most 60 here): the error can exceed 90 degrees."""

    def hinge(bend):  # the fold of the test above; a negative bend folds the other way (concave)
        b = np.radians(bend)
        return np.array([[0.0, 0, 0], [1, 0, 0], [0.5, -1, 0], [0.5, np.cos(b), -np.sin(b)]])

    F = np.array([[0, 2, 1], [0, 1, 3]])
    assert dihedral_angles(hinge(-60.0), F)[1] == pytest.approx([-60.0])
    assert sharp_edge_error(hinge(60.0), hinge(-60.0), F) == pytest.approx(120.0)
    assert sharp_edge_error(hinge(-100.0), hinge(100.0), F) == pytest.approx(200.0)


def test_interior_edges_of_an_open_grid():
    V, F = grid(4)  # 3 x 3 squares
    E, f1, f2, boundary, other = interior_edges(F)
    assert len(boundary) == 12 and len(other) == 0
    assert len(E) + len(boundary) == 33  # edges of a 3 x 3 triangulated grid
    # f1 holds i -> j, f2 holds j -> i
    for (i, j), a, b in zip(E, f1, f2):
        ra, rb = list(F[a]), list(F[b])
        assert ra[(ra.index(i) + 1) % 3] == j and rb[(rb.index(j) + 1) % 3] == i


def test_smoothing_a_cube_rounds_its_sharp_edges():
    # moving every vertex towards its neighbours' mean flattens the folds
    V, F = cube()
    from geomlib.lessons.laplace import uniform_adjacency

    A = uniform_adjacency(len(V), F)
    W = 0.5 * V + 0.5 * (A @ V) / A.sum(axis=1)
    assert sharp_edge_error(W, V, F) > 10.0


def test_every_method_of_the_comparison_gives_its_function():
    """The class keeps the clean side computed once; the numbers are the functions' own."""
    mesh = trimesh.creation.box(extents=(2.0, 1.0, 0.5)).subdivide().subdivide()
    V, F = np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)
    W = add_noise(V, F, 0.01, seed=4)
    cmp = MeshComparison(V, F)
    assert len(cmp.sharp) > 0 and cmp.closed
    np.testing.assert_array_equal(cmp.face_normal_angles(W), face_normal_angles(W, V, F))
    assert cmp.area_change(W) == area_change(W, V, F)
    assert cmp.volume_change(W) == volume_change(W, V, F)
    assert cmp.sharp_edge_error(W) == sharp_edge_error(W, V, F)
    values = cmp.evaluate(W, hausdorff=False)
    assert (values["normal_mean"], values["normal_p95"]) == normal_angle_error(W, V, F)
    assert values["rms"] == pytest.approx(vertex_rms(W, V), rel=1e-14)
    assert (values["area_change"], values["volume_change"]) == (area_change(W, V, F), volume_change(W, V, F))
    assert values["sharp_edge_error"] > 0 and values["area_change"] > 0


# --- bad input ---------------------------------------------------------------


def test_different_vertex_counts_raise():
    V, F = icosphere(1)
    with pytest.raises(MeshError, match="same shape"):
        vertex_rms(V[:-1], V)
    with pytest.raises(MeshError, match="same shape"):
        MeshComparison(V, F).evaluate(V[:-1])


def test_nan_coordinates_raise_naming_the_vertex():
    V, F = icosphere(1)
    W = V.copy()
    W[7, 1] = np.nan
    with pytest.raises(MeshError, match="vertices 7"):
        denoising_metrics(W, V, F)


# --- smoothing measured: laws ------------------------------------------------

SCHEMES = [("explicit", "uniform"), ("explicit", "cotan"), ("implicit", "uniform"), ("implicit", "cotan")]


def smooth(V, F, method, weights, value, iterations):
    from geomlib import explicit_smoothing, implicit_smoothing
    from geomlib.teaching.experiments.sweep import scale_free_step

    step = scale_free_step(V, F, method, weights, value)
    run = explicit_smoothing if method == "explicit" else implicit_smoothing
    return run(V, F, step, iterations, weights)


@pytest.mark.parametrize("method, weights", SCHEMES)
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_smoothing_reduces_the_error_of_mild_noise_on_a_sphere(method, weights, seed):
    # noise a tenth of the edge length is high-frequency: one short smoothing
    # step removes more of it than the (low-frequency) shrinkage it causes
    V, F = icosphere(3)
    h = np.mean(np.linalg.norm(V[F[:, 0]] - V[F[:, 1]], axis=1))
    sigma = 0.1 * h / bounding_box_diagonal(V)
    W = add_noise(V, F, sigma, seed=seed)
    C = MeshComparison(V, F)
    before = C.evaluate(W, hausdorff=False)
    for value in (0.1, 0.25):
        after = C.evaluate(smooth(W, F, method, weights, value, 1), hausdorff=False)
        assert after["rms"] < before["rms"]
        assert after["normal_mean"] < before["normal_mean"]


@pytest.mark.parametrize("method, weights", SCHEMES)
def test_smoothing_a_clean_sphere_only_shrinks_it(method, weights):
    # without noise there is nothing to remove: the error grows with the
    # number of iterations and the volume falls (the sphere shrinks)
    V, F = icosphere(3)
    C = MeshComparison(V, F)
    previous = 0.0
    for iterations in (1, 4, 16):
        out = C.evaluate(smooth(V, F, method, weights, 0.25, iterations), hausdorff=False)
        assert out["rms"] > previous
        assert out["volume_change"] < 0
        previous = out["rms"]


def test_sweep_records_what_a_direct_run_gives():
    from geomlib.teaching.experiments.sweep import smoothing_sweep

    V, F = icosphere(2)
    settings = dict(seed=3, explicit_fractions=(0.25, 0.5), implicit_steps=(0.1, 1.0), iterations=(1, 3, 5))
    R = smoothing_sweep(V, F, [0.002, 0.01], progress=False, **settings)
    assert R.values["rms"].shape == (2, 4, 2, 3)
    assert not np.isnan(R.values["rms"]).any()
    # the second noise level ran in the worker process (on Linux): the same numbers as in this one
    serial = smoothing_sweep(V, F, [0.002, 0.01], progress=False, workers=1, **settings)
    for key in R.values:
        np.testing.assert_array_equal(R.values[key], serial.values[key], err_msg=key)
        np.testing.assert_array_equal(R.noisy[key], serial.noisy[key], err_msg=key)
    np.testing.assert_array_equal(R.steps, serial.steps)
    assert serial.worker_seconds == 0.0
    C = MeshComparison(V, F)
    # one entry redone by hand: implicit cotan, step value 1.0, 3 iterations, sigma 0.01
    W = add_noise(V, F, 0.01, seed=3)
    direct = C.evaluate(smooth(W, F, "implicit", "cotan", 1.0, 3), hausdorff=False)
    j = R.schemes.index(("implicit", "cotan"))
    assert R.values["rms"][1, j, 1, 1] == pytest.approx(direct["rms"], rel=1e-9)
    assert R.noisy["rms"][1] == pytest.approx(C.vertex_rms(W), rel=1e-12)
    best = R.best(1)
    j, k, l = best["index"]
    assert best["rms"] == np.nanmin(R.values["rms"][1])
    assert best["iterations"] == R.iterations[l]
    assert R.best(1, schemes=[("explicit", "cotan")])["method"] == "explicit"


@pytest.mark.parametrize("how", ["raises", "dies"])
def test_a_failed_sweep_worker_is_reported_not_waited_for(monkeypatch, how):
    """The forked worker of smoothing_sweep raising, or dying without a word (killed, out of
    memory): the sweep raises a MeshError that says so, instead of hanging on the pipe."""
    import os

    import geomlib.teaching.experiments.sweep as sweep_module
    from geomlib import MeshError, smoothing_sweep

    parent, real = os.getpid(), sweep_module._sweep_levels

    def failing_in_the_worker(*args):
        if os.getpid() != parent:
            if how == "dies":
                os._exit(3)
            raise RuntimeError("no memory left")
        return real(*args)

    monkeypatch.setattr(sweep_module, "_sweep_levels", failing_in_the_worker)
    V, F = icosphere(1)
    expected = "exit code 3" if how == "dies" else "RuntimeError: no memory left"
    with pytest.raises(MeshError, match=expected):
        smoothing_sweep(
            V,
            F,
            [0.002, 0.01],
            seed=3,
            explicit_fractions=(0.5,),
            implicit_steps=(1.0,),
            iterations=(1, 2),
            progress=False,
            workers=2,
        )
