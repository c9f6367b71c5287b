"""How far a denoised mesh is from the clean one: distances, normals, volume, sharp edges.

Convention: every metric compares a mesh ``V`` (noisy or smoothed) with the
clean mesh ``V_clean`` *with the same connectivity* ``F`` (vertex ``i`` of one
is vertex ``i`` of the other), except the Hausdorff distance, which compares
the two surfaces as point sets and needs no correspondence. Lengths are given
*relative to the bounding-box diagonal of the clean mesh* (``relative=True``,
the default; a fraction, 0.01 = 1 % of the diagonal) or in the mesh's length
units (``relative=False``). Angles are in degrees. Relative changes of area and
volume are signed fractions, ``(X - X_clean) / |X_clean|``.

Each metric is one function taking the arrays. :class:`MeshComparison`
holds one clean mesh and its properties (diagonal, closedness, sharp edges)
and calls the same functions. The smoothing sweep of notebook 07 that uses
them is :mod:`geomlib.teaching.experiments.sweep`; the elementary measurements (area, volume,
bounding-box diagonal, mean edge length) are :mod:`geomlib.mesh.geometry`'s.

Degenerate and special cases are stated where they are handled:

* A face of zero area has no normal; in :func:`face_normal_angles` it counts
  as 90 degrees off (an undefined normal is as wrong as an orthogonal one).
* Dihedral angles exist only on edges shared by exactly two faces with
  opposite orientations; boundary and non-manifold edges are left out.
* The volume of an open mesh is undefined: :func:`volume_change` raises
  MeshError, and :meth:`MeshComparison.evaluate` reports NaN under
  ``"volume_change"`` (and says so in its docstring).
"""

import numpy as np
from scipy.spatial import cKDTree

from ..mesh.errors import MeshError
from ..mesh.geometry import (
    bounding_box_diagonal,
    cross,
    enclosed_volume,
    face_cross,
    face_volumes,
    mean_edge_length,
    surface_area,
)
from ..mesh.topology import Topology
from ..mesh.validate import as_faces, as_vertices

__all__ = [
    "SHARP_ANGLE",
    "HAUSDORFF_SAMPLES_PER_FACE",
    "vertex_rms",
    "hausdorff_distance",
    "face_normal_angles",
    "normal_angle_error",
    "area_change",
    "volume_change",
    "dihedral_angles",
    "sharp_edges",
    "sharp_edge_error",
    "denoising_metrics",
    "MeshComparison",
    "interior_edges",
    "point_triangle_distance",
    "point_surface_distance",
    "sample_surface",
    "bounding_box_diagonal",
    "surface_area",
    "enclosed_volume",
    "mean_edge_length",
]

#: Default threshold (degrees) on the clean mesh's dihedral (bend) angle above
#: which an edge counts as a sharp feature edge.
SHARP_ANGLE = 30.0

#: Default number of area-weighted random surface samples per face used by the
#: Hausdorff estimate, on each of the two surfaces, in addition to all vertices.
HAUSDORFF_SAMPLES_PER_FACE = 2.0


# ----------------------------------------------------------------------------
# checks
# ----------------------------------------------------------------------------


def _same_shape(V, V_clean):
    if V.shape != V_clean.shape:
        raise MeshError(
            f"V and V_clean must have the same shape (same connectivity), got {V.shape} and {V_clean.shape}"
        )


def interior_edges(F):
    """Edges shared by exactly two consistently oriented faces, and the rest.

    Parameters
    ----------
    F : (m, 3) int64 triangles.

    Returns
    -------
    E : (k, 2) int64
        Vertex indices ``(i, j)`` of each interior edge, oriented as in ``f1``.
    f1, f2 : (k,) int64
        The face holding the half-edge ``i -> j`` and the face holding ``j -> i``.
    boundary : (b, 2) int64
        Edges used by a single face (the boundary of an open mesh).
    other : (c, 2) int64
        Non-manifold or inconsistently oriented edges (neither of the above).
    """
    F = as_faces(F)
    T = Topology(F, int(F.max()) + 1)
    E, f1, f2 = T.face_pairs()
    other = np.vstack([T.E[T.edge_face_count > 2], T.inconsistent_edges()])
    return E, f1, f2, T.boundary_edges(), other.astype(np.int64)


def dihedral_angles(V, F, edges=None):
    """Signed bend angle (degrees) at every interior edge: 0 where flat,
    positive where convex, negative where concave.

    The bend angle is the angle between the two unit face normals,
    ``atan2(|n1 x n2|, n1 . n2)`` (so a cube's edges have 90 degrees; the
    interior dihedral angle is 180 minus it). It is positive when the far
    vertex of the second face lies below the plane of the first (a convex,
    outward fold for counter-clockwise outward-facing triangles).

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64
    edges : tuple (E, f1, f2) from :func:`interior_edges`, optional
        Pass it to avoid recomputing the edge list.

    Returns
    -------
    E : (k, 2) int64 edge vertex indices (interior edges only).
    angle : (k,) float64 signed bend angle in degrees, in (-180, 180].
    """
    V = as_vertices(V)
    F = as_faces(F, len(V))
    if edges is None:
        E, f1, f2, _, _ = interior_edges(F)
    else:
        E, f1, f2 = edges[:3]
    return E, _bend_angles(V, F, E, f1, f2)


def _bend_angles(V, F, E, f1, f2):
    n1, n2 = face_cross(V, F[f1]), face_cross(V, F[f2])  # only the faces at these edges
    angle = _angles(n1, n2)
    # far vertex of f2: the corner that is neither end of the edge
    G = F[f2]
    far = np.where(
        (G[:, 0] != E[:, 0]) & (G[:, 0] != E[:, 1]),
        G[:, 0],
        np.where((G[:, 1] != E[:, 0]) & (G[:, 1] != E[:, 1]), G[:, 1], G[:, 2]),
    )
    height = np.einsum("ij,ij->i", n1, V[far] - V[E[:, 0]])
    return np.where(height > 0, -angle, angle)


# ----------------------------------------------------------------------------
# exact point-to-surface distance
# ----------------------------------------------------------------------------


def _segment_distance2(P, A, B):
    AB = B - A
    L2 = np.einsum("ij,ij->i", AB, AB)
    t = np.einsum("ij,ij->i", P - A, AB) / np.where(L2 > 0, L2, 1.0)
    t = np.clip(t, 0.0, 1.0)
    D = P - (A + t[:, None] * AB)
    return np.einsum("ij,ij->i", D, D)


def point_triangle_distance(P, A, B, C):
    """Exact Euclidean distance from points to triangles, row by row.

    Parameters
    ----------
    P, A, B, C : (k, 3) float64
        Point ``P[i]`` and triangle ``(A[i], B[i], C[i])``.

    Returns
    -------
    (k,) float64
        The distance to the closest point of the (closed, filled) triangle:
        the distance to its plane when the projection of the point falls
        inside the triangle, otherwise the distance to the nearest of its
        three edges. Degenerate triangles reduce to segments or points.
    """
    d2 = np.minimum(np.minimum(_segment_distance2(P, A, B), _segment_distance2(P, B, C)), _segment_distance2(P, C, A))
    N = np.cross(B - A, C - A)
    N2 = np.einsum("ij,ij->i", N, N)
    inside = (
        (np.einsum("ij,ij->i", N, np.cross(B - A, P - A)) >= 0)
        & (np.einsum("ij,ij->i", N, np.cross(C - B, P - B)) >= 0)
        & (np.einsum("ij,ij->i", N, np.cross(A - C, P - C)) >= 0)
        & (N2 > 0)
    )
    h = np.einsum("ij,ij->i", N[inside], P[inside] - A[inside])
    d2[inside] = np.minimum(d2[inside], h * h / N2[inside])
    return np.sqrt(d2)


class _SurfaceIndex:
    """A mesh prepared for exact point-to-surface distance queries."""

    def __init__(self, V, F, neighbours=8):
        self.V, self.F = V, F
        self.A, self.B, self.C = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
        centroid = (self.A + self.B + self.C) / 3.0
        self.radius = np.sqrt(
            np.max([np.einsum("ij,ij->i", X - centroid, X - centroid) for X in (self.A, self.B, self.C)], axis=0)
        )
        self.R = float(self.radius.max())
        self.centroid = centroid
        self.tree = cKDTree(centroid)
        self._vertex_tree = None
        self.k = int(min(neighbours, len(F)))

    def distance(self, P):
        """Exact distance (k,) from each point of P to the surface.

        The ``k`` triangles with the nearest centroids are measured first. A
        triangle further away has its centroid at least ``d_k`` (the k-th
        centroid distance) from the point, so it is at least ``d_k - R`` away
        (``R`` the largest centroid-to-corner radius); where the best distance
        found is not below that bound the point is measured against every
        triangle whose bounding ball can hold a closer point."""
        P = np.asarray(P, dtype=np.float64)
        k = self.k
        dc, idx = self.tree.query(P, k=k)
        if k == 1:
            dc, idx = dc[:, None], idx[:, None]
        Pk = np.repeat(P, k, axis=0)
        flat = idx.ravel()
        d = point_triangle_distance(Pk, self.A[flat], self.B[flat], self.C[flat]).reshape(-1, k).min(axis=1)
        if k == len(self.F):
            return d
        unsure = np.flatnonzero(d > dc[:, -1] - self.R)
        if len(unsure):
            d[unsure] = self._distance_ball(P[unsure], d[unsure])
        return d

    def max_distance(self, P, upper=None, floor=0.0):
        """``max(floor, max_i d(P[i], surface))``, exact, measuring few points exactly.

        Every point needs an upper bound ``u_i`` of its distance: ``upper``
        when given (for example the distance to its corresponding point on
        this surface), else the distance to the triangle with the nearest
        centroid. Points are measured exactly (:meth:`distance`) in order of
        decreasing ``u_i`` until the next bound is no larger than the largest
        exact distance found (or ``floor``, a value known to be reached anyway):
        no point left can exceed it."""
        P = np.asarray(P, dtype=np.float64)
        if upper is None:
            _, nearest = self.tree.query(P, k=1, workers=-1)  # every point: both cores
            upper = point_triangle_distance(P, self.A[nearest], self.B[nearest], self.C[nearest])
        u = np.asarray(upper, dtype=np.float64)
        best = float(floor)
        batch = max(64, len(P) // 64)
        left = np.flatnonzero(u > best)  # the points that could still exceed best
        while len(left):
            # the batch with the largest bounds (a partition: most runs end after one or two batches)
            top = np.argpartition(-u[left], batch)[:batch] if len(left) > batch else np.arange(len(left))
            best = max(best, float(self.distance(P[left[top]]).max()))
            left = np.delete(left, top)
            left = left[u[left] > best]
        return best

    def _distance_ball(self, P, upper):
        if self._vertex_tree is None:
            self._vertex_tree = cKDTree(self.V[np.unique(self.F)])
        dv, _ = self._vertex_tree.query(P)
        upper = np.minimum(upper, dv)
        lists = self.tree.query_ball_point(P, upper + self.R, return_sorted=False)
        lengths = np.fromiter((len(x) for x in lists), dtype=np.int64, count=len(lists))
        faces = np.fromiter((f for x in lists for f in x), dtype=np.int64, count=int(lengths.sum()))
        owner = np.repeat(np.arange(len(P)), lengths)
        dist = point_triangle_distance(P[owner], self.A[faces], self.B[faces], self.C[faces])
        out = upper.copy()
        np.minimum.at(out, owner, dist)
        return out


def point_surface_distance(P, V, F):
    """Exact Euclidean distance (k,) from each point of P (k, 3) to the surface (V, F).

    The closest point may lie inside a triangle, on an edge or at a corner;
    all three are handled exactly (:func:`point_triangle_distance`), with a
    k-d tree over triangle centroids to find the candidate triangles. Length
    units of the mesh.
    """
    V = as_vertices(V)
    F = as_faces(F, len(V))
    P = as_vertices(P, where="P")
    return _SurfaceIndex(V, F).distance(P)


def sample_surface(V, F, count, seed):
    """``count`` points drawn uniformly by area on the surface (V, F), seeded.

    A face is chosen with probability proportional to its area, then a point
    uniformly inside it (the square-root rule for barycentric coordinates).
    Returns ``(count, 3)`` float64.
    """
    V = as_vertices(V)
    F = as_faces(F, len(V))
    return _sample(V, F, int(count), np.random.default_rng(seed))


def _sample(V, F, count, rng):
    face, weights = _sample_barycentric(V, F, count, rng)
    return np.einsum("kc,kcd->kd", weights, V[F[face]])


def _sample_barycentric(V, F, count, rng):
    """Faces (k,) and barycentric weights (k, 3) of ``count`` points uniform by area on (V, F)."""
    area = np.linalg.norm(face_cross(V, F), axis=1) if count > 0 else np.zeros(0)
    total = area.sum()
    if count <= 0 or total <= 0:
        return np.zeros(0, dtype=np.int64), np.zeros((0, 3))
    face = rng.choice(len(F), size=count, p=area / total)
    r1 = np.sqrt(rng.random(count))
    r2 = rng.random(count)
    return face, np.stack([1 - r1, r1 * (1 - r2), r1 * r2], axis=1)


class _SurfacePoints:
    """The points of the Hausdorff estimate on one surface (V, F): its vertices and random samples
    uniform by area, kept as vertex indices and (face, barycentric weights), so that the same points
    can be placed on any mesh of the same connectivity (:meth:`on`)."""

    def __init__(self, V, F, samples_per_face, rng):
        self.F, self.vertices = F, np.unique(F)
        self.faces, self.weights = _sample_barycentric(V, F, int(round(samples_per_face * len(F))), rng)
        self.points = self.on(V)

    def on(self, X):
        """The same points on the mesh (X, F): vertex i at X[i], a sample at its weights of its face's corners."""
        return np.vstack([X[self.vertices], np.einsum("kc,kcd->kd", self.weights, X[self.F[self.faces]])])


def _sample_streams(seed):
    """Two independent random streams, for the samples of the two surfaces of a Hausdorff estimate
    (independent, so that the clean side can be drawn once and kept, :class:`MeshComparison`)."""
    return [np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(2)]


def _one_sided(points, index, X=None, floor=0.0):
    """``max(floor, max d(p, surface of index))`` over ``points`` (:class:`_SurfacePoints`), exact.

    ``X``: the positions of the index's mesh when it shares the points' connectivity;
    then each point's distance to its corresponding point there bounds its distance from above
    (that point lies on the surface), so no nearest-triangle search is needed for the bounds."""
    upper = None if X is None else np.linalg.norm(points.points - points.on(X), axis=1)
    return index.max_distance(points.points, upper, floor)


# ----------------------------------------------------------------------------
# the comparison against one clean mesh
# ----------------------------------------------------------------------------


class MeshComparison:
    """One clean mesh ``(V_clean, F)`` to compare meshes of the same connectivity against.

    Holds the clean mesh, its properties and the metric settings; every
    method shares its formula with the function of the same name, and the
    clean mesh's side of it (face normals, area, volume, bend angles) is
    computed once, here.

    Parameters
    ----------
    V_clean : (n, 3) float64
        The clean (reference) vertex positions.
    F : (m, 3) int64
        The triangles, shared by the clean mesh and every mesh compared.
    sharp_angle : float
        Degrees; an interior edge is *sharp* when the absolute bend angle of
        the clean mesh there exceeds this (default :data:`SHARP_ANGLE`).
    samples_per_face : float
        Density of the Hausdorff estimate (:func:`hausdorff_distance`).
    seed : int
        Seed of the Hausdorff surface samples (the same seed, the same estimate).

    Attributes
    ----------
    diagonal : float
        Bounding-box diagonal of the clean mesh (length units).
    closed : bool
        True when every edge is shared by exactly two opposite faces.
    edges : (k, 2) int64
        The interior edges (:func:`interior_edges`).
    bend_clean : (k,) float64
        The clean mesh's signed bend angles there (degrees).
    sharp : (s,) int64
        Indices (into ``edges``) of the sharp edges.
    """

    def __init__(self, V_clean, F, sharp_angle=SHARP_ANGLE, samples_per_face=HAUSDORFF_SAMPLES_PER_FACE, seed=0):
        self.V_clean = as_vertices(V_clean, where="V_clean").copy()
        self.F = as_faces(F, len(self.V_clean))
        self.diagonal = bounding_box_diagonal(self.V_clean)
        if not self.diagonal > 0:
            raise MeshError("the clean mesh has a zero bounding-box diagonal (all vertices coincide)")
        self.sharp_angle = float(sharp_angle)
        self.samples_per_face = float(samples_per_face)
        if not self.samples_per_face >= 0:
            raise MeshError(f"samples_per_face must be >= 0, got {samples_per_face}")
        self.seed = seed
        self._interior = interior_edges(self.F)
        _, _, _, boundary, other = self._interior
        self.closed = len(boundary) == 0 and len(other) == 0
        self.edges, self.bend_clean = dihedral_angles(self.V_clean, self.F, self._interior)
        self.sharp = np.flatnonzero(np.abs(self.bend_clean) > self.sharp_angle)
        self._sharp_edges = tuple(x[self.sharp] for x in self._interior[:3])
        # the clean side of every metric, computed once (evaluate runs thousands of times in a sweep)
        self._N_clean = face_cross(self.V_clean, self.F)
        self._area_clean = surface_area(self.V_clean, self.F)
        self._volume_clean = enclosed_volume(self.V_clean, self.F) if self.closed else None
        self._clean_sides = {}  # seed -> the clean surface's Hausdorff points and triangle index

    def _check(self, V):
        V = as_vertices(V)
        _same_shape(V, self.V_clean)
        return V

    def vertex_rms(self, V, relative=True):
        """:func:`vertex_rms` against the clean mesh (relative: over the diagonal computed once)."""
        rms = vertex_rms(self._check(V), self.V_clean, relative=False)
        return rms / self.diagonal if relative else rms

    def face_normal_angles(self, V):
        """:func:`face_normal_angles` against the clean mesh, (m,) degrees."""
        return _normal_angles(face_cross(self._check(V), self.F), self._N_clean)

    def sharp_edge_error(self, V):
        """:func:`sharp_edge_error` with this comparison's ``sharp_angle``; NaN without sharp edges."""
        if not len(self.sharp):
            return float("nan")
        return _bend_error(self._check(V), self.F, *self._sharp_edges, self.bend_clean[self.sharp])

    def hausdorff(self, V, relative=True, seed=None):
        """:func:`hausdorff_distance` to the clean surface, with this comparison's density and seed.

        The clean surface's points and triangle index are prepared once per seed and kept."""
        seed = self.seed if seed is None else seed
        moved, clean = _sample_streams(seed)
        if seed not in self._clean_sides:
            points = _SurfacePoints(self.V_clean, self.F, self.samples_per_face, clean)
            self._clean_sides[seed] = points, _SurfaceIndex(self.V_clean, self.F)
        h = _hausdorff(
            self._check(V), self.F, self.samples_per_face, moved, self.V_clean, self._clean_sides[seed], True
        )
        return h / self.diagonal if relative else h

    def area_change(self, V):
        """:func:`area_change`: ``(A - A_clean) / A_clean``."""
        return _area_change(surface_area(self._check(V), self.F), self._area_clean)

    def volume_change(self, V):
        """:func:`volume_change`: ``(vol - vol_clean) / |vol_clean|``; MeshError on an open mesh."""
        if not self.closed:
            return volume_change(self._check(V), self.V_clean, self.F, self._interior)  # raises, naming the edges
        return _volume_change(enclosed_volume(self._check(V), self.F), self._volume_clean)

    def evaluate(self, V, hausdorff=True):
        """All metrics of V against the clean mesh, as a dict.

        Keys (lengths relative to the clean bounding-box diagonal, angles in
        degrees): ``"rms"`` (:func:`vertex_rms`); ``"hausdorff"`` (only when
        ``hausdorff=True``); ``"normal_mean"`` and ``"normal_p95"``
        (:func:`normal_angle_error`); ``"area_change"``; ``"volume_change"``
        (NaN for an open mesh, whose volume is undefined);
        ``"sharp_edge_error"`` (NaN when the clean mesh has no sharp edge).
        """
        V = self._check(V)
        out = {"rms": vertex_rms(V, self.V_clean, relative=False) / self.diagonal}
        if hausdorff:
            out["hausdorff"] = self.hausdorff(V)
        # N = 2 A_f n_f of every face, once for the normals, the area (face_areas: |N| / 2) and the
        # volume, since a sweep evaluates thousands of meshes
        N = face_cross(V, self.F)
        out["normal_mean"], out["normal_p95"] = _mean_and_p95(_normal_angles(N, self._N_clean))
        out["area_change"] = _area_change(float((0.5 * np.linalg.norm(N, axis=1)).sum()), self._area_clean)
        volume = float(face_volumes(V, self.F, N).sum()) if self.closed else None  # enclosed_volume, V and F checked
        out["volume_change"] = _volume_change(volume, self._volume_clean) if self.closed else float("nan")
        out["sharp_edge_error"] = self.sharp_edge_error(V)
        return out


def _angles(a, b):
    """Angles (degrees, 0..180) between the rows of a and b: arctan2(|a x b|, a . b), exact near 0 and 180."""
    sine = np.sqrt((cross(a.T, b.T) ** 2).sum(axis=0))  # |a x b| on coordinate rows: several times np.cross's speed
    return np.degrees(np.arctan2(sine, np.einsum("ij,ij->i", a, b)))


def _normal_angles(N, N_clean):
    """Angles (degrees) between the rows of two arrays of (unnormalised)
    normals; rows with a zero vector (degenerate faces) count as 90."""
    angle = _angles(N, N_clean)
    zero = ~N.any(axis=1) | ~N_clean.any(axis=1)
    angle[zero] = 90.0
    return angle


def vertex_rms(V, V_clean, relative=True):
    """Vertex RMS distance ``sqrt(mean_i |v_i - v_i^clean|^2)`` (same vertex order).

    Parameters
    ----------
    V, V_clean : (n, 3) float64
    relative : bool
        Divide by the bounding-box diagonal of ``V_clean`` (default) or give
        length units.

    Returns
    -------
    float
    """
    V = as_vertices(V)
    V_clean = as_vertices(V_clean, where="V_clean")
    _same_shape(V, V_clean)
    rms = float(np.sqrt(np.mean(np.einsum("ij,ij->i", V - V_clean, V - V_clean))))
    return rms / bounding_box_diagonal(V_clean) if relative else rms


def hausdorff_distance(V, V_clean, F, F_clean=None, relative=True, samples_per_face=HAUSDORFF_SAMPLES_PER_FACE, seed=0):
    """Symmetric Hausdorff distance between two triangle surfaces, estimated from below.

    ``max(sup_{p on S} d(p, S_clean), sup_{q on S_clean} d(q, S))`` where
    ``S = (V, F)`` and ``S_clean = (V_clean, F_clean)`` (``F_clean``
    defaults to ``F``; the two meshes need not correspond). Each surface
    is represented by all its vertices plus ``round(samples_per_face * m)``
    random points drawn uniformly by area (seeded), and every point is
    measured *exactly* to the other surface (closest point in a triangle, on
    an edge or at a corner), so the result is the exact maximum over those
    points: an estimate from below of the true Hausdorff distance, short of it
    by at most the covering radius of the samples (the largest distance from
    a point of a surface to its nearest sample; ``d(p, S)`` is 1-Lipschitz in
    p). With ``samples_per_face=0`` it is the largest distance from a vertex
    of either mesh to the other surface, exactly.

    Only the points that can hold the maximum are measured: a point's
    distance is bounded from above by its distance to the nearest-centroid
    triangle, or, when the meshes share F (``F_clean`` omitted), to its
    corresponding point on the other mesh; the second side measures only
    points whose bound exceeds the first side's maximum. On the 6,209-vertex
    CAD part of notebook 07 this took a call from 110-220 ms to 35-45 ms, the
    same value.

    Parameters
    ----------
    V, V_clean : (n, 3), (n', 3) float64
    F : (m, 3) int64
    F_clean : (m', 3) int64, optional
    relative : bool
        Divide by the bounding-box diagonal of ``V_clean`` (default).
    samples_per_face : float
    seed : int

    Returns
    -------
    float
    """
    V = as_vertices(V)
    V_clean = as_vertices(V_clean, where="V_clean")
    F = as_faces(F, len(V))
    F_clean = F if F_clean is None else as_faces(F_clean, len(V_clean), where="F_clean")
    moved, clean = _sample_streams(seed)
    clean_side = _SurfacePoints(V_clean, F_clean, samples_per_face, clean), _SurfaceIndex(V_clean, F_clean)
    h = _hausdorff(V, F, samples_per_face, moved, V_clean, clean_side, shared=F_clean is F)
    return h / bounding_box_diagonal(V_clean) if relative else h


def _hausdorff(V, F, samples_per_face, rng, V_clean, clean_side, shared):
    """The larger of the two one-sided distances; ``clean_side``: the clean surface's points and index.
    ``shared``: the two meshes have the same connectivity (vertex i and face f of one are those of the other)."""
    P, (Q, clean_index) = _SurfacePoints(V, F, samples_per_face, rng), clean_side
    there = _one_sided(P, clean_index, V_clean if shared else None)
    # only a point further than `there` can change the maximum: the other side measures only those
    return float(_one_sided(Q, _SurfaceIndex(V, F), V if shared else None, floor=there))


def face_normal_angles(V, V_clean, F):
    """Angle (degrees) between each face's unit normal in V and in V_clean, (m,).

    ``atan2(|n x n_clean|, n . n_clean)`` in [0, 180] (accurate for small
    angles too); a face of zero area in either mesh counts as 90.
    """
    V = as_vertices(V)
    V_clean = as_vertices(V_clean, where="V_clean")
    _same_shape(V, V_clean)
    F = as_faces(F, len(V))
    return _normal_angles(face_cross(V, F), face_cross(V_clean, F))


def normal_angle_error(V, V_clean, F):
    """Face-normal angle error against the clean mesh: ``(mean, p95)`` in degrees.

    The mean and the 95th percentile (linear interpolation) over faces of
    :func:`face_normal_angles` (unweighted: every face counts once).
    """
    return _mean_and_p95(face_normal_angles(V, V_clean, F))


def _mean_and_p95(angles):
    return float(angles.mean()), float(np.percentile(angles, 95))


def area_change(V, V_clean, F):
    """Signed relative change of the surface area, ``(A - A_clean) / A_clean``."""
    return _area_change(surface_area(V, F), surface_area(V_clean, F))


def _area_change(A, A_clean):
    if not A_clean > 0:
        raise MeshError("the clean mesh has zero area")
    return A / A_clean - 1.0


def volume_change(V, V_clean, F, edges=None):
    """Signed relative change of the enclosed volume, ``(vol - vol_clean) / |vol_clean|``.

    Closed meshes only (every edge shared by two opposite faces); an open
    mesh raises MeshError naming its boundary edges. ``edges``: the result of
    :func:`interior_edges` for F, to avoid recomputing it.
    """
    V = as_vertices(V)
    V_clean = as_vertices(V_clean, where="V_clean")
    _same_shape(V, V_clean)
    F = as_faces(F, len(V))
    _, _, _, boundary, other = interior_edges(F) if edges is None else edges
    if len(boundary) or len(other):
        bad = np.vstack([boundary, other])
        raise MeshError(
            "the volume change is defined for closed meshes only; "
            f"{len(bad)} edge(s) are boundary or non-manifold, e.g. " + ", ".join(f"({i}, {j})" for i, j in bad[:5])
        )
    return _volume_change(enclosed_volume(V, F), enclosed_volume(V_clean, F))


def _volume_change(vol, vol_clean):
    if vol_clean == 0:
        raise MeshError("the clean mesh encloses zero volume")
    return (vol - vol_clean) / abs(vol_clean)


def sharp_edges(V_clean, F, threshold=SHARP_ANGLE):
    """Interior edges of the clean mesh whose absolute bend angle exceeds ``threshold`` degrees.

    Returns ``(E, angle)``: (s, 2) int64 vertex pairs and their signed bend
    angles in degrees (see :func:`dihedral_angles`).
    """
    E, angle = dihedral_angles(V_clean, F)
    keep = np.abs(angle) > threshold
    return E[keep], angle[keep]


def sharp_edge_error(V, V_clean, F, threshold=SHARP_ANGLE, edges=None):
    """Mean absolute error (degrees) of the bend (dihedral) angle on the sharp edges.

    The sharp edges are the interior edges where the clean mesh bends by more
    than ``threshold`` degrees (default 30); on those the error is
    ``|theta(V) - theta(V_clean)|`` with the *signed* bend angle of
    :func:`dihedral_angles` (+90 at a cube's convex edge, -90 at a concave one), so an
    edge that turned over counts the whole turn and the error can exceed 90 degrees
    (a concave 60-degree fold made convex: 120). Returns NaN when the clean mesh has no sharp
    edge (there is nothing to measure). ``edges``: ``(E, f1, f2)`` of
    :func:`interior_edges` for F (or any subset that holds the sharp edges),
    to avoid recomputing them.
    """
    V = as_vertices(V)
    V_clean = as_vertices(V_clean, where="V_clean")
    _same_shape(V, V_clean)
    F = as_faces(F, len(V))
    E, f1, f2 = (interior_edges(F) if edges is None else edges)[:3]
    bend_clean = _bend_angles(V_clean, F, E, f1, f2)
    sharp = np.abs(bend_clean) > threshold
    if not sharp.any():
        return float("nan")
    return _bend_error(V, F, E[sharp], f1[sharp], f2[sharp], bend_clean[sharp])


def _bend_error(V, F, E, f1, f2, bend_clean):
    """Mean |theta(V) - theta_clean| (degrees) over the edges E with faces f1, f2."""
    return float(np.mean(np.abs(_bend_angles(V, F, E, f1, f2) - bend_clean)))


def denoising_metrics(V, V_clean, F, sharp_angle=SHARP_ANGLE, samples_per_face=HAUSDORFF_SAMPLES_PER_FACE, seed=0):
    """Every metric of V against the clean mesh, as a dict (see :meth:`MeshComparison.evaluate`)."""
    return MeshComparison(V_clean, F, sharp_angle, samples_per_face, seed).evaluate(V)
