"""Tests of the shipped meshes (geomlib/meshes/*.obj, geomlib/meshes/README.md) and their generator."""

import importlib.util
import re
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh

import geomlib
from geomlib.teaching.shapes import surfaces

ROOT = Path(__file__).resolve().parents[1]
MESHES = ROOT / "geomlib" / "meshes"
NAMES = [
    "plane.obj",
    "plane_irregular.obj",
    "plane_noisy.obj",
    "saddle.obj",
    "sphere.obj",
    "ellipsoid.obj",
    "ellipsoid_jittered.obj",
    "torus.obj",
    "creature.obj",
    "cad_part.obj",
    "cad_part_noisy.obj",
    "cube.obj",
]
CLOSED = {
    "sphere.obj",
    "ellipsoid.obj",
    "ellipsoid_jittered.obj",
    "torus.obj",
    "creature.obj",
    "cad_part.obj",
    "cad_part_noisy.obj",
    "cube.obj",
}


def _load_generator():
    spec = importlib.util.spec_from_file_location("make_meshes", ROOT / "tools" / "make_meshes.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


mm = _load_generator()


def load(name):
    m = trimesh.load(MESHES / name, process=False)
    return np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int64), m


def readme_table():
    """{file: {column: text}} from the table in geomlib/meshes/README.md."""
    lines = [ln for ln in (MESHES / "README.md").read_text().splitlines() if ln.startswith("|")]
    head = [c.strip() for c in lines[0].strip("|").split("|")]
    rows = {}
    for ln in lines[2:]:
        cells = [c.strip() for c in ln.strip("|").split("|")]
        rows[cells[0]] = dict(zip(head, cells))
    return rows


def dihedral_degrees(V, F):
    """Angle between the normals of the two faces of every interior edge."""
    FN = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    FN /= np.linalg.norm(FN, axis=1, keepdims=True)
    E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    face = np.tile(np.arange(len(F)), 3)
    order = np.lexsort((E[:, 1], E[:, 0]))
    E, face = E[order], face[order]
    same = np.all(E[1:] == E[:-1], axis=1)
    f1, f2 = face[:-1][same], face[1:][same]
    c = np.clip(np.einsum("ij,ij->i", FN[f1], FN[f2]), -1, 1)
    return np.degrees(np.arccos(c))


# ---------------------------------------------------------------------------
# the files, their counts and limits
# ---------------------------------------------------------------------------


def test_exactly_the_named_meshes_are_shipped():
    assert sorted(p.name for p in MESHES.glob("*.obj")) == sorted(NAMES)
    assert sorted(readme_table()) == sorted(NAMES)
    assert [s.name for s in mm.SPECS] == NAMES


def test_size_limits():
    total = 0
    for name in NAMES:
        V, F, _ = load(name)
        assert V.shape[0] <= 50_000
        total += (MESHES / name).stat().st_size
    assert total <= 20 * 2**20


@pytest.mark.parametrize("name", NAMES)
def test_loads_with_the_counts_of_the_readme(name):
    V, F, m = load(name)
    row = readme_table()[name]
    assert V.shape == (int(row["vertices"]), 3)
    assert F.shape == (int(row["faces"]), 3)
    assert int(row["bytes"]) == (MESHES / name).stat().st_size
    assert row["closed"] == ("yes" if name in CLOSED else "no")
    assert float(row["bbox diagonal"]) == pytest.approx(np.linalg.norm(V.max(0) - V.min(0)), rel=1e-3)
    E = m.edges_unique
    assert float(row["mean edge"]) == pytest.approx(np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1).mean(), rel=1e-3)
    assert int(row["Euler"]) == V.shape[0] - len(E) + F.shape[0]
    # geomlib's own reader gives the same arrays, in the file's order
    V2, F2 = geomlib.load_mesh(geomlib.data_path(name))
    np.testing.assert_array_equal(V2, V)
    np.testing.assert_array_equal(F2, F)


def test_readme_agrees_with_the_files():
    assert mm.readme_text(MESHES) == (MESHES / "README.md").read_text()


@pytest.mark.parametrize("name", NAMES)
def test_clean_consistently_oriented_one_component(name):
    V, F, m = load(name)
    assert np.unique(F).size == V.shape[0]  # no unused vertices
    assert len(np.unique(np.round(V, 9), axis=0)) == V.shape[0]  # no duplicate positions
    A = m.area_faces
    assert A.min() > 1e-4 * A.mean()  # no zero-area faces
    assert m.is_winding_consistent
    assert m.body_count == 1
    if name in CLOSED:
        assert m.is_watertight
        assert m.volume > 0  # outward
        assert len(m.edges_unique) * 2 == 3 * len(F)  # every edge in exactly two faces
    else:
        assert not m.is_watertight
        assert V.shape[0] - len(m.edges_unique) + F.shape[0] == 1  # a disc


# ---------------------------------------------------------------------------
# individual meshes
# ---------------------------------------------------------------------------


def test_cube():
    V, F, m = load("cube.obj")
    assert V.shape == (8, 3) and F.shape == (12, 3)
    assert m.volume == pytest.approx(1.0, rel=1e-12)
    np.testing.assert_array_equal(np.sort(np.unique(V)), [-0.5, 0.5])


def test_creature_is_a_sphere_topologically():
    V, F, m = load("creature.obj")
    assert 15_000 <= V.shape[0] <= 25_000
    assert m.body_count == 1 and m.is_watertight and m.volume > 0
    assert m.euler_number == 2
    angles = np.degrees(m.face_angles)
    assert angles.min() > 1.0
    # no face folded over by the clean-up: every face normal agrees with the
    # gradient of the implicit function, and vertices stay near its zero set
    C = V[F].mean(axis=1)
    e = 1e-5
    g = np.stack([(mm.creature_field(C + e * d) - mm.creature_field(C - e * d)) / (2 * e) for d in np.eye(3)], 1)
    assert np.all(np.einsum("ij,ij->i", m.face_normals, g / np.linalg.norm(g, axis=1, keepdims=True)) > 0.1)
    assert np.abs(mm.creature_field(V)).max() < mm.CREATURE_CLAMP * mm.CREATURE_SPACING


def test_analytic_meshes_lie_on_their_surfaces():
    V, F, _ = load("sphere.obj")
    assert np.abs(np.linalg.norm(V, axis=1) - 1).max() < 1e-8
    for name in ("ellipsoid.obj", "ellipsoid_jittered.obj"):
        V, F, _ = load(name)
        assert np.abs((V[:, 0] / 1.0) ** 2 + (V[:, 1] / 0.7) ** 2 + (V[:, 2] / 0.5) ** 2 - 1).max() < 1e-8
    V, F, _ = load("torus.obj")
    assert np.abs(np.hypot(np.hypot(V[:, 0], V[:, 1]) - 1.0, V[:, 2]) - 0.4).max() < 1e-8
    V, F, _ = load("saddle.obj")
    assert np.abs(V[:, 2] - surfaces.saddle_height(V[:, 0], V[:, 1], 0.2, 0.1)).max() < 1e-8
    for name in ("plane.obj", "plane_irregular.obj"):
        V, F, _ = load(name)
        assert np.all(V[:, 2] == 0) and np.abs(V[:, :2]).max() == 1.0


def test_files_match_geomlib_surfaces():
    """The analytic files are geomlib.teaching.shapes.surfaces' meshes written with 9 digits."""
    cases = {
        "sphere.obj": surfaces.sphere(1.0, subdivisions=4),
        "ellipsoid.obj": surfaces.ellipsoid(1.0, 0.7, 0.5, subdivisions=4),
        "ellipsoid_jittered.obj": surfaces.ellipsoid(1.0, 0.7, 0.5, subdivisions=4, jitter=0.3, seed=4),
        "torus.obj": surfaces.torus(1.0, 0.4, n=80, m=32),
        "saddle.obj": surfaces.saddle(n=48, jitter=0.3, seed=3),
        "plane.obj": surfaces.plane(n=40),
        "plane_irregular.obj": surfaces.plane(n=40, jitter=0.3, seed=1),
    }
    for name, m in cases.items():
        V, F, _ = load(name)
        np.testing.assert_array_equal(F, m.F)
        np.testing.assert_allclose(V, m.V, rtol=0, atol=1e-8)


def test_exact_truth_attaches_to_the_files():
    V, F, _ = load("ellipsoid_jittered.obj")
    t = surfaces.attach_truth("ellipsoid", V, F, a=1.0, b=0.7, c=0.5)
    assert np.all(t.H > 0) and np.all(t.K > 0)
    x, y, z = V.T
    q = x**2 / 1.0**4 + y**2 / 0.7**4 + z**2 / 0.5**4
    np.testing.assert_allclose(t.K, 1 / (1.0 * 0.7 * 0.5) ** 2 / q**2, rtol=1e-6)
    V, F, _ = load("saddle.obj")
    t = surfaces.attach_truth("saddle", V, F)
    assert (t.K < 0).mean() > 0.2 and (t.K > 0).mean() > 0.2  # saddles and bumps


def test_saddle_has_many_obtuse_triangles():
    V, F, m = load("saddle.obj")
    obtuse = np.degrees(m.face_angles).max(axis=1) > 90
    assert 0.3 < obtuse.mean() < 0.7
    assert 2000 <= V.shape[0] <= 4000
    assert np.degrees(m.face_angles).min() > 5


def test_noisy_plane_is_the_irregular_plane_plus_normal_noise():
    V0, F0, m0 = load("plane_irregular.obj")
    V1, F1, _ = load("plane_noisy.obj")
    np.testing.assert_array_equal(F0, F1)
    np.testing.assert_array_equal(V0[:, :2], V1[:, :2])
    sigma = 0.005 * np.linalg.norm(V0.max(0) - V0.min(0))
    assert np.std(V1[:, 2]) == pytest.approx(sigma, rel=0.1)


def test_noisy_cad_part_moves_along_normals():
    V0, F0, m0 = load("cad_part.obj")
    V1, F1, _ = load("cad_part_noisy.obj")
    np.testing.assert_array_equal(F0, F1)
    D = V1 - V0
    N = geomlib.vertex_normals(V0, F0)
    tangential = D - np.einsum("ij,ij->i", D, N)[:, None] * N
    assert np.abs(tangential).max() < 1e-7
    sigma = 0.005 * np.linalg.norm(V0.max(0) - V0.min(0))
    assert np.std(np.einsum("ij,ij->i", D, N)) == pytest.approx(sigma, rel=0.1)


def test_cad_part_has_sharp_creases_and_flat_faces():
    V, F, m = load("cad_part.obj")
    assert 5_000 <= V.shape[0] <= 10_000
    assert m.volume == pytest.approx(mm.cad_volume(), rel=1e-3)  # the boss wall is an inscribed polygon
    d = dihedral_degrees(V, F)
    flat = d < 1e-4
    boss_wall = (d > 7.0) & (d < 8.0)  # 360 / 47 between neighbouring wall facets
    sharp = d > 20.0  # the roof meets the top at atan(1/2) = 26.6 degrees, the chamfer at 45, the box at 90
    assert np.all(flat | boss_wall | sharp)  # nothing rounded: creases are one edge wide
    np.testing.assert_allclose(np.unique(np.round(d[sharp], 3)), [26.565, 45.0, 63.435, 90.0], atol=2e-3)
    assert sharp.sum() > 300 and flat.mean() > 0.9
    assert d.max() == pytest.approx(90.0, abs=1e-4)
    # the bottom face is exactly the plane z = 0
    assert np.sum(V[:, 2] == 0) > 400 and V[:, 2].min() == 0


# ---------------------------------------------------------------------------
# the generator
# ---------------------------------------------------------------------------


def test_generator_is_deterministic(tmp_path):
    written = mm.generate(tmp_path, skip_expensive=True)
    names = sorted(p.name for p in written)
    assert names == sorted(n for n in NAMES if n != "creature.obj")
    for path in written:
        assert path.read_bytes() == (MESHES / path.name).read_bytes(), path.name


@pytest.mark.slow
def test_generator_is_deterministic_for_the_creature(tmp_path):
    (path,) = mm.generate(tmp_path, names=["creature"])
    assert path.read_bytes() == (MESHES / "creature.obj").read_bytes()


def test_generator_writes_plain_obj():
    text = (MESHES / "cube.obj").read_text()
    lines = [ln for ln in text.splitlines() if not ln.startswith("#")]
    assert all(re.fullmatch(r"v( -?[0-9.e+-]+){3}|f( [0-9]+){3}", ln) for ln in lines)
    assert "-0 " not in text and not text.endswith("\n\n")
