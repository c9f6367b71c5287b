#!/usr/bin/env python3
"""Make the meshes the workbook ships (geomlib/meshes/*.obj and geomlib/meshes/README.md).

    python tools/make_meshes.py                 # every mesh, then geomlib/meshes/README.md
    python tools/make_meshes.py --only sphere   # some of them (README from the files present)
    python tools/make_meshes.py --out DIR       # somewhere else

Deterministic: fixed seeds and parameters, vertices written with ``%.9g``, so
running it again gives byte-identical files (the tests check this). Every mesh
is checked before it is written: no zero-area faces, no unused vertices,
consistently oriented, and for the closed ones every edge shared by exactly two
faces and a positive enclosed volume (outward normals).

The measurements and checks are geomlib's own public functions (the edge
table, boundary loops, components, areas, angles, volume, ``add_noise``); only
the welding of coincident vertices and the renumbering in first-use order belong
to the generator.

Convention of the files: triangles counter-clockwise seen from outside (from +z
for the open height fields), 1-based ``f`` lines, one ``v`` line per vertex.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:  # run from a checkout without installing
    sys.path.insert(0, str(ROOT))

from geomlib.lessons.curvature import corner_angles  # noqa: E402
from geomlib.lessons.noise import add_noise  # noqa: E402
from geomlib.mesh.errors import MeshError  # noqa: E402
from geomlib.mesh.geometry import (  # noqa: E402
    bounding_box_diagonal,
    enclosed_volume,
    face_areas,
    face_cross,
    mean_edge_length,
)
from geomlib.mesh.topology import Topology, boundary_loops, euler_characteristic  # noqa: E402
from geomlib.teaching.shapes import surfaces  # noqa: E402
from geomlib.teaching.shapes.surfaces import grid_faces  # noqa: E402

FLOAT = "%.9g"

# ---------------------------------------------------------------------------
# writing and checking
# ---------------------------------------------------------------------------


def obj_text(V, F, header):
    """OBJ text: comment lines, ``v x y z`` with %.9g, ``f i j k`` 1-based."""
    V = np.asarray(V, dtype=np.float64) + 0.0  # turns -0.0 into 0.0
    lines = [f"# {h}" for h in header]
    fmt = f"v {FLOAT} {FLOAT} {FLOAT}"
    lines += [fmt % (x, y, z) for x, y, z in V.tolist()]
    lines += ["f %d %d %d" % (a, b, c) for a, b, c in (np.asarray(F, dtype=np.int64) + 1).tolist()]
    return "\n".join(lines) + "\n"


def read_obj(path):
    """(V, F) of a file written by :func:`obj_text` (v and f lines only)."""
    V, F = [], []
    for line in Path(path).read_text().splitlines():
        if line.startswith("v "):
            V.append([float(t) for t in line.split()[1:4]])
        elif line.startswith("f "):
            F.append([int(t.split("/")[0]) - 1 for t in line.split()[1:4]])
    return np.array(V, dtype=np.float64).reshape(-1, 3), np.array(F, dtype=np.int64).reshape(-1, 3)


def stats(V, F):
    """The numbers the README table shows, computed from (V, F) by geomlib."""
    T = Topology(F, len(V))
    closed = bool(np.all(T.edge_face_count == 2))
    angles = np.degrees(corner_angles(V, F))
    return dict(
        vertices=int(V.shape[0]),
        faces=int(F.shape[0]),
        edges=int(len(T.E)),
        euler=int(euler_characteristic(V, F)),
        closed=closed,
        boundary_loops=len(boundary_loops(F)),
        components=int(T.vertex_components().max() + 1),
        bbox_diagonal=bounding_box_diagonal(V),
        mean_edge=mean_edge_length(V, F),
        min_angle=float(angles.min()),
        obtuse_percent=float(100.0 * np.mean(angles.max(axis=1) > 90.0 + 1e-9)),
        volume=enclosed_volume(V, F) if closed else None,
    )


def check_mesh(name, V, F, closed):
    """Raise MeshError unless the mesh is clean (see the module docstring)."""
    if V.dtype != np.float64 or F.dtype != np.int64 or V.ndim != 2 or F.ndim != 2:
        raise MeshError(f"{name}: V must be float64 (n, 3), F int64 (m, 3)")
    if not np.isfinite(V).all():
        raise MeshError(f"{name}: non-finite coordinates")
    if np.unique(F).size != V.shape[0] or F.min() != 0:
        raise MeshError(f"{name}: unused vertices")
    A = face_areas(V, F)
    T = Topology(F, len(V))
    h = mean_edge_length(V, F)
    if A.min() <= 1e-6 * h * h:
        raise MeshError(f"{name}: {np.sum(A <= 1e-6 * h * h)} (near) zero-area faces")
    if np.any(T.edge_face_count > 2):
        raise MeshError(f"{name}: non-manifold edges")
    if len(T.inconsistent_edges()):
        raise MeshError(f"{name}: inconsistently oriented faces")
    if np.unique(np.round(V, 12), axis=0).shape[0] != V.shape[0]:
        raise MeshError(f"{name}: duplicate vertex positions")
    if closed:
        if not np.all(T.edge_face_count == 2):
            raise MeshError(f"{name}: not closed ({np.sum(T.edge_face_count == 1)} boundary edges)")
        if enclosed_volume(V, F) <= 0:
            raise MeshError(f"{name}: faces point inwards")


# ---------------------------------------------------------------------------
# small mesh tools
# ---------------------------------------------------------------------------


def weld(V, F, tol):
    """Merge vertices closer than ``tol`` (kept: the lowest index of each
    cluster, in first-use order), drop faces that became degenerate."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    pairs = cKDTree(V).query_pairs(tol, output_type="ndarray")
    n = V.shape[0]
    A = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, label = connected_components(A, directed=False)
    # representative of each cluster: its smallest index
    rep = np.full(label.max() + 1, n, dtype=np.int64)
    np.minimum.at(rep, label, np.arange(n))
    F = rep[label][F]
    F = F[(F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 2] != F[:, 0])]
    return compact(V, F)


def compact(V, F):
    """Drop unused vertices, renumber in order of first use in F."""
    order, first = np.unique(F.ravel(), return_index=True)
    order = order[np.argsort(first)]
    new = np.full(V.shape[0], -1, dtype=np.int64)
    new[order] = np.arange(order.size)
    return V[order], new[F]


# ---------------------------------------------------------------------------
# the creature: marching cubes of a smooth union of ellipsoids and capsules
# ---------------------------------------------------------------------------


def _ellipsoid_field(P, centre, radii):
    """Zero on the ellipsoid, negative inside; about the distance near it."""
    q = (P - np.asarray(centre)) / np.asarray(radii)
    return (np.linalg.norm(q, axis=-1) - 1.0) * min(radii)


def _capsule_field(P, a, b, radius):
    """Distance to the segment ab minus the radius."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    ab = b - a
    t = np.clip(((P - a) @ ab) / (ab @ ab), 0.0, 1.0)
    return np.linalg.norm(P - (a + t[..., None] * ab), axis=-1) - radius


def _smooth_union(d1, d2, k):
    """Polynomial smooth minimum of two fields with blend width k."""
    h = np.clip(0.5 + 0.5 * (d2 - d1) / k, 0.0, 1.0)
    return d2 * (1.0 - h) + d1 * h - k * h * (1.0 - h)


CREATURE_PARTS = [
    ("ellipsoid", dict(centre=(0.0, 0.0, 0.0), radii=(0.72, 0.36, 0.30))),  # body
    ("ellipsoid", dict(centre=(0.98, 0.0, 0.30), radii=(0.26, 0.20, 0.20))),  # head
    ("ellipsoid", dict(centre=(1.20, 0.0, 0.24), radii=(0.14, 0.11, 0.09))),  # snout
    ("capsule", dict(a=(0.55, 0.0, 0.08), b=(0.88, 0.0, 0.26), radius=0.15)),  # neck
    ("ellipsoid", dict(centre=(0.94, 0.12, 0.50), radii=(0.05, 0.04, 0.11))),  # ears
    ("ellipsoid", dict(centre=(0.94, -0.12, 0.50), radii=(0.05, 0.04, 0.11))),
    ("capsule", dict(a=(0.45, 0.20, -0.10), b=(0.52, 0.24, -0.72), radius=0.085)),  # legs
    ("capsule", dict(a=(0.45, -0.20, -0.10), b=(0.52, -0.24, -0.72), radius=0.085)),
    ("capsule", dict(a=(-0.45, 0.20, -0.10), b=(-0.52, 0.24, -0.72), radius=0.09)),
    ("capsule", dict(a=(-0.45, -0.20, -0.10), b=(-0.52, -0.24, -0.72), radius=0.09)),
    ("capsule", dict(a=(-0.62, 0.0, 0.05), b=(-0.95, 0.0, 0.22), radius=0.07)),  # tail
    ("capsule", dict(a=(-0.95, 0.0, 0.22), b=(-1.22, 0.0, 0.45), radius=0.05)),
]
CREATURE_BLEND = 0.08  # smooth-min width (length units)
CREATURE_SPACING = 0.0185  # marching-cubes grid step (length units)
CREATURE_CLAMP = 0.15  # vertex kept at least this fraction of a grid step from a grid node


def creature_field(P):
    """Smooth union of the parts (negative inside)."""
    d = None
    for kind, p in CREATURE_PARTS:
        f = _ellipsoid_field(P, **p) if kind == "ellipsoid" else _capsule_field(P, **p)
        d = f if d is None else _smooth_union(d, f, CREATURE_BLEND)
    return d


def creature():
    """Closed genus-0 animal: marching cubes of :func:`creature_field`, cleaned.

    Clean-up rules (each checked afterwards):

    1. Every marching-cubes vertex lies on a grid edge at fraction t of the
       step; t is clamped to [CREATURE_CLAMP, 1 - CREATURE_CLAMP], so no
       vertex comes closer than 0.15 h to a grid node. This is what removes
       the zero-area and needle triangles marching cubes makes where the
       surface passes (nearly) through a grid node; the vertex moves along
       its edge by at most 0.15 h, the connectivity is unchanged.
    2. Vertices closer than 1e-9 h are merged (none are expected: the
       Lewiner variant shares the vertex of each grid edge), faces that
       became degenerate are dropped, unused vertices removed.
    3. Faces are turned outwards (positive enclosed volume).
    Then: one component, closed, manifold, consistently oriented, Euler
    characteristic 2, no face with an angle under 1 degree.
    """
    from skimage.measure import marching_cubes

    h = CREATURE_SPACING
    lo = np.array([-1.35, -0.45, -0.88])
    hi = np.array([1.42, 0.45, 0.70])
    n = np.ceil((hi - lo) / h).astype(int) + 1
    axes = [lo[i] + h * np.arange(n[i]) for i in range(3)]
    X, Y, Z = np.meshgrid(*axes, indexing="ij")
    field = creature_field(np.stack([X, Y, Z], axis=-1))
    if (
        field[0].min() <= 0
        or field[-1].min() <= 0
        or field[:, 0].min() <= 0
        or field[:, -1].min() <= 0
        or field[:, :, 0].min() <= 0
        or field[:, :, -1].min() <= 0
    ):
        raise MeshError("creature: the shape touches the sampling box")
    verts, faces, _, _ = marching_cubes(field, level=0.0, allow_degenerate=True, method="lewiner")
    # rule 1: clamp the fractional coordinate (grid units) away from the nodes
    frac = verts - np.floor(verts)
    on_edge = frac > 1e-12  # the coordinate along the vertex's own edge
    t = np.clip(frac, CREATURE_CLAMP, 1.0 - CREATURE_CLAMP)
    verts = np.where(on_edge, np.floor(verts) + t, np.round(verts))
    V = lo + h * verts.astype(np.float64)
    F = faces.astype(np.int64)
    V, F = weld(V, F, 1e-9 * h)  # rule 2
    if enclosed_volume(V, F) < 0:  # rule 3
        F = F[:, [0, 2, 1]]
    s = stats(V, F)
    if s["components"] != 1 or not s["closed"] or s["euler"] != 2 or s["min_angle"] < 1.0:
        raise MeshError(f"creature: clean-up failed: {s}")
    return V, F


# ---------------------------------------------------------------------------
# the CAD part: an extruded profile with a chamfer and a slanted face, and a
# cylindrical boss; every face meshed on its own, stitched along shared edges
# ---------------------------------------------------------------------------

CAD_PROFILE = [(0.0, 0.0), (2.0, 0.0), (2.0, 0.5), (1.7, 0.8), (0.8, 0.8), (0.0, 0.4)]  # (x, z), CCW
CAD_DEPTH = 1.2  # extrusion along y
CAD_BOSS = dict(centre=(1.25, 0.6), radius=0.3, height=0.35)  # on the top face z = 0.8
CAD_EDGE = 0.04  # target edge length


def _segment_points(p, q, n):
    t = np.arange(n + 1) / n
    return np.asarray(p)[None, :] * (1 - t)[:, None] + np.asarray(q)[None, :] * t[:, None]


def _lattice(lo, hi, h):
    """Triangular (hexagonal) lattice points of spacing h covering a 2D box."""
    rows = int(np.ceil((hi[1] - lo[1]) / (h * np.sqrt(3) / 2))) + 2
    cols = int(np.ceil((hi[0] - lo[0]) / h)) + 2
    j, i = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
    x = lo[0] + h * (i + 0.5 * (j % 2)) - h
    y = lo[1] + h * np.sqrt(3) / 2 * j - h
    return np.stack([x.ravel(), y.ravel()], axis=1)


def _distance_to_polyline(P, Q, closed=True):
    """Distance of 2D points P to the polyline through Q."""
    A = Q
    B = np.roll(Q, -1, axis=0) if closed else Q[1:]
    A = A[: len(B)]
    d = np.full(len(P), np.inf)
    for a, b in zip(A, B):
        ab = b - a
        t = np.clip(((P - a) @ ab) / (ab @ ab), 0.0, 1.0)
        d = np.minimum(d, np.linalg.norm(P - (a + t[:, None] * ab), axis=1))
    return d


def _inside_polygon(P, Q):
    """Even-odd rule for 2D points P in the polygon Q."""
    inside = np.zeros(len(P), dtype=bool)
    x, y = P[:, 0], P[:, 1]
    for a, b in zip(Q, np.roll(Q, -1, axis=0)):
        crosses = (a[1] > y) != (b[1] > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            xc = a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
        inside ^= crosses & (x < xc)
    return inside


def _planar_patch(outer, holes, h, to3d, normal):
    """Triangulate a planar region given by 2D boundary points.

    ``outer``: (k, 2) closed boundary polyline (points in order, spacing about
    h); ``holes``: list of such polylines. Interior points are a triangular
    lattice of spacing h kept at least 0.6 h from every boundary; the Delaunay
    triangulation of all points is cut to the region (centroid test). Every
    boundary segment must come out as an edge (they are Gabriel edges when no
    lattice point lies within 0.6 h), which is checked. ``to3d`` maps 2D
    points to 3D; triangles are oriented so that their normal is ``normal``.
    """
    from scipy.spatial import Delaunay

    loops = [outer] + list(holes)
    B = np.concatenate(loops)
    L = _lattice(B.min(axis=0) - 2 * h, B.max(axis=0) + 2 * h, h)
    keep = np.ones(len(L), dtype=bool)
    for hole in holes:
        keep &= ~_inside_polygon(L, hole)
    for loop in loops:
        keep &= _distance_to_polyline(L, loop) >= 0.6 * h
    # lattice points outside the outer boundary (up to 2 h away) stay in the
    # point set: the boundary points are then not on the convex hull, where
    # qhull leaves zero-area triangles between collinear points; the
    # triangles outside are cut away below with the others
    keep &= _inside_polygon(L, outer) | (_distance_to_polyline(L, outer) <= 2 * h)
    P = np.concatenate([B, L[keep]])
    T = Delaunay(P).simplices.astype(np.int64)
    C = P[T].mean(axis=1)
    inside = _inside_polygon(C, outer)
    for hole in holes:
        inside &= ~_inside_polygon(C, hole)
    T = T[inside]
    used = np.unique(T)  # the outside lattice points drop out here
    keep_pts = np.zeros(len(P), dtype=bool)
    keep_pts[used] = True
    new = np.cumsum(keep_pts) - 1
    P, T = P[keep_pts], new[T]
    if not np.all(keep_pts[: len(B)]):
        raise MeshError("cad_part: a boundary point is not used by a planar patch")
    # every boundary segment is an edge of exactly one kept triangle
    E = np.sort(np.concatenate([T[:, [0, 1]], T[:, [1, 2]], T[:, [2, 0]]]), axis=1)
    have = set(map(tuple, E.tolist()))
    start = 0
    for loop in loops:
        k = len(loop)
        for i in range(k):
            e = tuple(sorted((start + i, start + (i + 1) % k)))
            if e not in have:
                raise MeshError(f"cad_part: boundary segment {e} missing from a planar patch")
        start += k
    V = to3d(P)
    flip = face_cross(V, T) @ np.asarray(normal) < 0
    T[flip] = T[flip][:, [0, 2, 1]]
    return V, T


def _strip(p0, p1, y0, y1, nu, nv, outward):
    """Structured grid on the rectangle {p0 + s (p1 - p0)} x [y0, y1] (p in the
    x-z plane), quads split into two triangles, oriented along ``outward``."""
    s = np.arange(nu + 1) / nu
    t = np.arange(nv + 1) / nv
    S, T_ = np.meshgrid(s, t, indexing="ij")
    x = p0[0] + S * (p1[0] - p0[0])
    z = p0[1] + S * (p1[1] - p0[1])
    y = y0 + T_ * (y1 - y0)
    V = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    F = grid_faces(nu + 1, nv + 1)
    flip = face_cross(V, F) @ np.asarray(outward) < 0
    F[flip] = F[flip][:, [0, 2, 1]]
    return V, F


def cad_part():
    """Closed CAD-like part with sharp edges (see CAD_* for the dimensions).

    An extruded 6-sided profile (a box with a 45-degree chamfer along one top
    edge and a slanted roof face) with a cylindrical boss on the top face.
    Flat side strips and the boss's wall are structured grids; the two end
    caps, the top face (with the boss's circular hole) and the boss's top disk
    are Delaunay triangulations of boundary points plus a lattice. All faces
    share their boundary points, and coincident points are welded (1e-9), so
    the edges between faces are exact sharp creases. Exact volume:
    profile area x depth + pi r^2 x boss height.
    """
    h = CAD_EDGE
    Q = np.array(CAD_PROFILE)
    D = CAD_DEPTH
    ny = max(1, int(round(D / h)))
    seg_n = [max(1, int(round(np.linalg.norm(Q[(i + 1) % len(Q)] - Q[i]) / h))) for i in range(len(Q))]
    # boundary of the profile, sampled per segment (shared by the caps and strips)
    ring = np.concatenate([_segment_points(Q[i], Q[(i + 1) % len(Q)], seg_n[i])[:-1] for i in range(len(Q))])
    parts = []
    # end caps y = 0 (outward -y) and y = D (outward +y)
    for y, ny_sign in ((0.0, -1.0), (D, 1.0)):
        parts.append(
            _planar_patch(
                ring, [], h, lambda P, y=y: np.stack([P[:, 0], np.full(len(P), y), P[:, 1]], 1), (0, ny_sign, 0)
            )
        )
    cx, cy = CAD_BOSS["centre"]
    rad, bh = CAD_BOSS["radius"], CAD_BOSS["height"]
    ztop = 0.8
    nc = max(8, int(round(2 * np.pi * rad / h)))
    ang = 2 * np.pi * np.arange(nc) / nc
    circle = np.stack([cx + rad * np.cos(ang), cy + rad * np.sin(ang)], axis=1)  # (x, y)
    centroid = Q.mean(axis=0)
    for i in range(len(Q)):
        p0, p1 = Q[i], Q[(i + 1) % len(Q)]
        d = p1 - p0
        out2 = np.array([d[1], -d[0]])  # right normal of a CCW polygon edge in (x, z) = outward
        if out2 @ ((p0 + p1) / 2 - centroid) < 0:
            out2 = -out2
        outward = (out2[0], 0.0, out2[1])
        if np.isclose(p0[1], ztop) and np.isclose(p1[1], ztop):
            # the top face: a rectangle in (x, y) with the boss's hole
            xs = _segment_points(p0, p1, seg_n[i])[:, 0]
            ys = D * np.arange(ny + 1) / ny
            rect = np.concatenate(
                [
                    np.stack([xs[:-1], np.zeros(seg_n[i])], 1),
                    np.stack([np.full(ny, xs[-1]), ys[:-1]], 1),
                    np.stack([xs[::-1][:-1], np.full(seg_n[i], D)], 1),
                    np.stack([np.full(ny, xs[0]), ys[::-1][:-1]], 1),
                ]
            )
            parts.append(
                _planar_patch(
                    rect, [circle], h, lambda P: np.stack([P[:, 0], P[:, 1], np.full(len(P), ztop)], 1), (0, 0, 1)
                )
            )
        else:
            parts.append(_strip(p0, p1, 0.0, D, seg_n[i], ny, outward))
    # the boss: wall (structured) and top disk
    nz = max(1, int(round(bh / h)))
    k, j = np.meshgrid(np.arange(nc), np.arange(nz + 1), indexing="ij")
    wall = np.stack([circle[k.ravel(), 0], circle[k.ravel(), 1], ztop + bh * j.ravel() / nz], axis=1)
    Fw = grid_faces(nc, nz + 1, periodic_u=True)
    radial = wall[:, :2] - np.array([cx, cy])
    flip = np.einsum("ij,ij->i", face_cross(wall, Fw)[:, :2], radial[Fw].mean(axis=1)) < 0
    Fw[flip] = Fw[flip][:, [0, 2, 1]]
    parts.append((wall, Fw))
    parts.append(
        _planar_patch(circle, [], h, lambda P: np.stack([P[:, 0], P[:, 1], np.full(len(P), ztop + bh)], 1), (0, 0, 1))
    )
    # stitch
    V = np.concatenate([p[0] for p in parts])
    offs = np.cumsum([0] + [len(p[0]) for p in parts[:-1]])
    F = np.concatenate([p[1] + o for p, o in zip(parts, offs)])
    V, F = weld(V, F, 1e-9)
    return V, F


def cad_volume():
    Q = np.array(CAD_PROFILE)
    area = 0.5 * abs(np.sum(Q[:, 0] * np.roll(Q[:, 1], -1) - np.roll(Q[:, 0], -1) * Q[:, 1]))
    return area * CAD_DEPTH + np.pi * CAD_BOSS["radius"] ** 2 * CAD_BOSS["height"]


# ---------------------------------------------------------------------------
# cube
# ---------------------------------------------------------------------------


def cube():
    """The unit cube [-0.5, 0.5]^3: 8 vertices, 12 outward triangles."""
    V = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    F = []
    for a, b, c, d in quads:
        F += [(a, b, c), (a, c, d)]
    F = np.array(F, dtype=np.int64)
    if enclosed_volume(V, F) < 0:
        F = F[:, [0, 2, 1]]
    return V, F


# ---------------------------------------------------------------------------
# the list of shipped meshes
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Spec:
    name: str
    make: Callable[[], tuple]
    how: str  # how it is made (for the README)
    use: str  # what it is for (notebooks)
    closed: bool
    expensive: bool = False


def _from_surface(m):
    return m.V, m.F


PLANE_N = 40
NOISE_SIGMA = 0.005  # relative to the bounding-box diagonal

SPECS = [
    Spec(
        "plane.obj",
        lambda: _from_surface(surfaces.plane(n=PLANE_N, size=2.0)),
        f"`geomlib.teaching.shapes.surfaces.plane(n={PLANE_N}, size=2.0)`: regular grid on [-1, 1]^2, z = 0, each square split by the same diagonal. Exact H = K = 0.",
        "01, 03: flat mesh, every curvature estimate should give 0",
        False,
    ),
    Spec(
        "plane_irregular.obj",
        lambda: _from_surface(surfaces.plane(n=PLANE_N, size=2.0, jitter=0.3, seed=1)),
        f"`geomlib.teaching.shapes.surfaces.plane(n={PLANE_N}, size=2.0, jitter=0.3, seed=1)`: the same grid with every vertex moved in the plane by up to 0.3 grid steps (boundary vertices along their side). Exact H = K = 0.",
        "01, 03: uniform weights see curvature on a flat but irregular mesh, cotan weights do not; the clean reference of plane_noisy.obj",
        False,
    ),
    Spec(
        "plane_noisy.obj",
        lambda: _noisy_plane(),
        f'plane_irregular.obj (same vertex order and faces) with z = sigma d z_i, z_i ~ N(0, 1) from `numpy.random.default_rng(2)`, sigma = {NOISE_SIGMA} of the bounding-box diagonal d of the clean plane (noise along the normal, as `geomlib.add_noise(V, F, {NOISE_SIGMA}, seed, direction="normal")` defines it).',
        "05, 06, 07: smoothing and denoising an open mesh (the course's plane_ns role); compare with plane_irregular.obj",
        False,
    ),
    Spec(
        "saddle.obj",
        lambda: _from_surface(surfaces.saddle(n=48, size=2.0, amplitude=0.2, monkey=0.1, jitter=0.3, seed=3)),
        '`geomlib.teaching.shapes.surfaces.saddle(n=48, size=2.0, amplitude=0.2, monkey=0.1, jitter=0.3, seed=3)`: z = 0.2 (27/4) x (1 - x^2) y (1 - y^2) + 0.1 (x^3 - 3 x y^2) over [-1, 1]^2, (x, y) jittered by up to 0.3 grid steps, z evaluated again. Exact truth: `geomlib.teaching.shapes.surfaces.attach_truth("saddle", V, F)`.',
        "01, 03: open curved surface with K < 0 and K > 0 regions, a boundary, and many obtuse triangles (mixed vs barycentric areas)",
        False,
    ),
    Spec(
        "sphere.obj",
        lambda: _from_surface(surfaces.sphere(1.0, subdivisions=4)),
        "`geomlib.teaching.shapes.surfaces.sphere(1.0, subdivisions=4)`: icosphere of radius 1. Exact H = 1, K = 1.",
        "00, 01, 03: H = 1/r, Gauss-Bonnet (integral of K = 4 pi)",
        True,
    ),
    Spec(
        "ellipsoid.obj",
        lambda: _from_surface(surfaces.ellipsoid(1.0, 0.7, 0.5, subdivisions=4)),
        '`geomlib.teaching.shapes.surfaces.ellipsoid(1.0, 0.7, 0.5, subdivisions=4)`: the icosphere mapped by (x, y, z) -> (a x, b y, c z), a, b, c = 1.0, 0.7, 0.5. Exact truth: `geomlib.teaching.shapes.surfaces.attach_truth("ellipsoid", V, F, a=1.0, b=0.7, c=0.5)` (from geomlib.lessons.symbolic).',
        "02, 03: discrete curvature against the exact curvature of the fundamental forms",
        True,
    ),
    Spec(
        "ellipsoid_jittered.obj",
        lambda: _from_surface(surfaces.ellipsoid(1.0, 0.7, 0.5, subdivisions=4, jitter=0.3, seed=4)),
        "`geomlib.teaching.shapes.surfaces.ellipsoid(1.0, 0.7, 0.5, subdivisions=4, jitter=0.3, seed=4)`: the same surface, every vertex moved along the surface by up to 0.3 of its mean edge length (on the unit sphere, before the map). Same exact truth.",
        "03: the same comparison on an irregular tessellation (uniform weights break down, cotan weights hold)",
        True,
    ),
    Spec(
        "torus.obj",
        lambda: _from_surface(surfaces.torus(1.0, 0.4, n=80, m=32)),
        '`geomlib.teaching.shapes.surfaces.torus(1.0, 0.4, n=80, m=32)`: R = 1, r = 0.4, an 80 x 32 grid in (u, v), no seam duplicates. Exact truth: `geomlib.teaching.shapes.surfaces.attach_truth("torus", V, F, R=1.0, r=0.4)`.',
        "01, 03: K of both signs, Gauss-Bonnet with Euler characteristic 0",
        True,
    ),
    Spec(
        "creature.obj",
        lambda: creature(),
        f"Marching cubes (`skimage.measure.marching_cubes`, Lewiner, grid step {CREATURE_SPACING}) of a smooth union (polynomial smooth minimum, width {CREATURE_BLEND}) of ellipsoids (body, head, snout, ears) and capsules (neck, four legs, a two-piece tail); clean-up: vertices clamped to at least {CREATURE_CLAMP} grid steps from grid nodes along their grid edge (removes zero-area and needle triangles), coincident vertices merged, faces turned outwards; checked to be one closed, manifold, consistently oriented component with Euler characteristic 2. See `creature()` in tools/make_meshes.py.",
        "04: spectral reconstruction from k Laplacian eigenvectors (limbs appear as k grows)",
        True,
        expensive=True,
    ),
    Spec(
        "cad_part.obj",
        lambda: cad_part(),
        "A 2.0 x 1.2 x 0.8 block: the profile (x, z) = (0, 0), (2, 0), (2, 0.5), (1.7, 0.8), (0.8, 0.8), (0, 0.4) (a 45-degree chamfer and a slanted roof face) extruded along y by 1.2, with a cylindrical boss (radius 0.3, height 0.35) on the top face. Flat strips and the boss wall are structured grids, end caps, top face and boss top are Delaunay triangulations of boundary points plus a triangular lattice (target edge 0.04); faces share their boundary points, so the edges are exact sharp creases. See `cad_part()` in tools/make_meshes.py.",
        "05, 06, 07: sharp features under smoothing and denoising (the course's fandisk role); the clean reference of cad_part_noisy.obj",
        True,
    ),
    Spec(
        "cad_part_noisy.obj",
        lambda: _noisy_cad(),
        f"cad_part.obj (same vertex order and faces) with noise sigma d z_i n_i along the area-weighted vertex normals n_i, z_i ~ N(0, 1) from `numpy.random.default_rng(5)`, sigma = {NOISE_SIGMA} of the bounding-box diagonal d.",
        "05, 06, 07: denoising with sharp edges; compare with cad_part.obj",
        True,
    ),
    Spec(
        "cube.obj",
        lambda: cube(),
        "The cube [-0.5, 0.5]^3, 8 vertices, 12 triangles (two per face), outward.",
        "05, 06: the handout's simple cube (smoothing shrinks it towards a sphere, then a point)",
        True,
    ),
]


def _noisy_plane():
    V, F = _from_surface(surfaces.plane(n=PLANE_N, size=2.0, jitter=0.3, seed=1))
    return add_noise(V, F, NOISE_SIGMA, seed=2, direction="normal"), F  # the normal is +z: only z moves


def _noisy_cad():
    V, F = cad_part()
    return add_noise(V, F, NOISE_SIGMA, seed=5, direction="normal"), F


def generate(out, names=None, skip_expensive=False, verbose=False):
    """Write the meshes (all, or ``names``) into the folder ``out``; returns their paths."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    known = {s.name: s for s in SPECS}
    if names is not None:
        unknown = [n for n in names if n not in known and n + ".obj" not in known]
        if unknown:
            raise SystemExit(f"unknown mesh {unknown}; known: {', '.join(known)}")
        names = {n if n in known else n + ".obj" for n in names}
    written = []
    for spec in SPECS:
        if names is not None and spec.name not in names:
            continue
        if skip_expensive and spec.expensive:
            continue
        V, F = spec.make()
        V = np.ascontiguousarray(V, dtype=np.float64)
        F = np.ascontiguousarray(F, dtype=np.int64)
        check_mesh(spec.name, V, F, spec.closed)
        header = [
            f"{spec.name}: made by tools/make_meshes.py (deterministic; see meshes/README.md)",
            f"{V.shape[0]} vertices, {F.shape[0]} triangles, counter-clockwise seen from outside",
        ]
        path = out / spec.name
        path.write_text(obj_text(V, F, header))
        written.append(path)
        if verbose:
            print(f"{spec.name}: {V.shape[0]} vertices, {F.shape[0]} faces, {path.stat().st_size} bytes")
    return written


README_HEAD = """# Meshes shipped with the workbook

Every file here is made by `tools/make_meshes.py` from an exact definition; run

    python tools/make_meshes.py

to make them all again (byte-identical: fixed seeds, `%.9g` coordinates). In a
notebook, open one with `geomlib.load_mesh(geomlib.data_path("sphere.obj"))`.
All are triangle meshes, counter-clockwise seen from outside (from +z for the
open height fields), with no zero-area faces, no duplicate or unused vertices
and one connected component. The exact curvature of the analytic ones is
`geomlib.teaching.shapes.surfaces.attach_truth(name, V, F, **params)` (from `geomlib.lessons.symbolic`),
with the parameters below.

The table is written by the generator from the files themselves.
"Euler" is V - E + F; "obtuse" the share of triangles with an angle over 90
degrees; lengths in the meshes' own units.

"""


def readme_text(folder):
    folder = Path(folder)
    rows = [
        "| file | vertices | faces | closed | boundary loops | Euler | bbox diagonal | mean edge | min angle (deg) | obtuse % | bytes | for notebooks |",
        "| --- | ---: | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |",
    ]
    sections = []
    total = 0
    for spec in SPECS:
        path = folder / spec.name
        if not path.exists():
            continue
        V, F = read_obj(path)
        s = stats(V, F)
        size = path.stat().st_size
        total += size
        rows.append(
            f"| {spec.name} | {s['vertices']} | {s['faces']} | {'yes' if s['closed'] else 'no'} | "
            f"{s['boundary_loops']} | {s['euler']} | {s['bbox_diagonal']:.4g} | {s['mean_edge']:.4g} | "
            f"{s['min_angle']:.3g} | {s['obtuse_percent']:.1f} | {size} | {spec.use.split(':')[0]} |"
        )
        extra = f" Enclosed volume of the mesh: {s['volume']:.6g}." if s["volume"] is not None else ""
        if spec.name == "cad_part.obj":
            extra += f" Exact volume of the part: {cad_volume():.6g}."
        sections.append(f"### {spec.name}\n\n{spec.how}{extra}\n\nFor: {spec.use}.\n")
    return (
        README_HEAD
        + "\n".join(rows)
        + f"\n\nTotal: {total} bytes.\n\n## How each mesh is made\n\n"
        + "\n".join(sections)
    )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default=str(ROOT / "geomlib" / "meshes"), help="output folder (default: geomlib/meshes/)")
    ap.add_argument("--only", nargs="+", help="make only these meshes (names with or without .obj)")
    ap.add_argument("--skip-expensive", action="store_true", help="leave out the creature (marching cubes)")
    args = ap.parse_args(argv)
    generate(args.out, args.only, args.skip_expensive, verbose=True)
    Path(args.out, "README.md").write_text(readme_text(args.out))
    print(f"wrote {Path(args.out, 'README.md')}")


if __name__ == "__main__":
    main()
