"""How far a denoised mesh is from the clean one: distances, normals, volume, sharp edges.

Convention: every metric compares a mesh ``V`` (noisy or smoothed) with the
clean mesh ``V_clean`` *with the same connectivity* ``F`` (vertex ``i`` of one
is vertex ``i`` of the other), except the Hausdorff distance, which compares
the two surfaces as point sets and needs no correspondence. Lengths are given
*relative to the bounding-box diagonal of the clean mesh* (``relative=True``,
the default; a fraction, 0.01 = 1 % of the diagonal) or in the mesh's length
units (``relative=False``). Angles are in degrees. Relative changes of area and
volume are signed fractions, ``(X - X_clean) / |X_clean|``.

The functions take the arrays and recompute what they need. For many
comparisons against the same clean mesh (a parameter sweep) build one
:class:`MeshComparison`: it computes the clean mesh's normals, edges,
dihedral angles, area, volume and surface samples once.
:func:`smoothing_sweep` runs explicit and implicit smoothing (uniform and
cotangent weights) over noise levels, scale-free steps and iteration counts
and records every metric (notebook 07).

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

from .errors import MeshError
from .validate import as_faces, as_vertices

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
        raise MeshError(f"V and V_clean must have the same shape (same connectivity), "
                        f"got {V.shape} and {V_clean.shape}")


def bounding_box_diagonal(V):
    """Length of the diagonal of the axis-aligned bounding box of V (length units).

    Parameters
    ----------
    V : (n, 3) float64 vertex positions.

    Returns
    -------
    float
        ``|max(V) - min(V)|`` taken over the three axes.
    """
    V = as_vertices(V)
    return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))


# ----------------------------------------------------------------------------
# elementary geometry
# ----------------------------------------------------------------------------

def _cross_faces(V, F):
    """Per-face cross products ``(v1 - v0) x (v2 - v0)`` = 2 A n, (m, 3)."""
    P0 = V[F[:, 0]]
    a = V[F[:, 1]] - P0
    b = V[F[:, 2]] - P0
    N = np.empty_like(a)
    N[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    N[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    N[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return N


def _norms(X):
    return np.sqrt(X[:, 0] * X[:, 0] + X[:, 1] * X[:, 1] + X[:, 2] * X[:, 2])


def surface_area(V, F):
    """Total area of the triangles (length^2)."""
    V = as_vertices(V)
    F = as_faces(F, len(V))
    return 0.5 * float(np.linalg.norm(_cross_faces(V, F), axis=1).sum())


def enclosed_volume(V, F):
    """Signed enclosed volume (length^3) by the divergence theorem,
    ``1/6 sum_f v0 . (v1 x v2)``: positive for a closed mesh whose faces are
    counter-clockwise seen from outside. Only meaningful for a closed mesh
    (on an open one it depends on the origin); this function does not check."""
    V = as_vertices(V)
    F = as_faces(F, len(V))
    return float(np.einsum("ij,ij->", V[F[:, 0]], np.cross(V[F[:, 1]], V[F[:, 2]])) / 6.0)


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
    F = np.asarray(F, dtype=np.int64)
    m = len(F)
    I = F.ravel()
    J = F[:, [1, 2, 0]].ravel()
    face = np.repeat(np.arange(m), 3)
    lo, hi = np.minimum(I, J), np.maximum(I, J)
    n = int(F.max()) + 1 if m else 0
    key = lo * n + hi
    order = np.argsort(key, kind="stable")
    key_sorted = key[order]
    starts = np.flatnonzero(np.r_[True, key_sorted[1:] != key_sorted[:-1]])
    counts = np.diff(np.r_[starts, len(key_sorted)])
    first = order[starts]
    boundary = np.column_stack([I[first[counts == 1]], J[first[counts == 1]]])
    two = counts == 2
    a = order[starts[two]]
    b = order[starts[two] + 1]
    opposite = (I[a] == J[b]) & (J[a] == I[b])
    a, b = a[opposite], b[opposite]
    E = np.column_stack([I[a], J[a]])
    other_first = np.r_[first[counts > 2], order[starts[two]][~opposite]]
    other = np.column_stack([I[other_first], J[other_first]])
    return E, face[a], face[b], boundary.astype(np.int64), other.astype(np.int64)


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


def _bend_angles(V, F, E, f1, f2, N=None):
    N = _cross_faces(V, F) if N is None else N
    n1, n2 = N[f1], N[f2]
    angle = np.degrees(np.arctan2(np.linalg.norm(np.cross(n1, n2), axis=1),
                                  np.einsum("ij,ij->i", n1, n2)))
    # far vertex of f2: the corner that is neither end of the edge
    G = F[f2]
    far = np.where((G[:, 0] != E[:, 0]) & (G[:, 0] != E[:, 1]), G[:, 0],
                   np.where((G[:, 1] != E[:, 0]) & (G[:, 1] != E[:, 1]), G[:, 1], G[:, 2]))
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
    d2 = np.minimum(np.minimum(_segment_distance2(P, A, B), _segment_distance2(P, B, C)),
                    _segment_distance2(P, C, A))
    N = np.cross(B - A, C - A)
    N2 = np.einsum("ij,ij->i", N, N)
    inside = ((np.einsum("ij,ij->i", N, np.cross(B - A, P - A)) >= 0)
              & (np.einsum("ij,ij->i", N, np.cross(C - B, P - B)) >= 0)
              & (np.einsum("ij,ij->i", N, np.cross(A - C, P - C)) >= 0)
              & (N2 > 0))
    h = np.einsum("ij,ij->i", N[inside], P[inside] - A[inside])
    d2[inside] = np.minimum(d2[inside], h * h / N2[inside])
    return np.sqrt(d2)


class _SurfaceIndex:
    """A mesh prepared for exact point-to-surface distance queries."""

    def __init__(self, V, F, neighbours=8):
        self.V, self.F = V, F
        self.A, self.B, self.C = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
        centroid = (self.A + self.B + self.C) / 3.0
        self.radius = np.sqrt(np.max([np.einsum("ij,ij->i", X - centroid, X - centroid)
                                      for X in (self.A, self.B, self.C)], axis=0))
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

    def max_distance(self, P):
        """``max_i d(P[i], surface)``, exact, measuring few points exactly.

        The distance to the triangle with the nearest centroid is an upper
        bound ``u_i`` of each point's distance. Points are measured exactly
        (:meth:`distance`) in order of decreasing ``u_i`` until the next bound
        is no larger than the largest exact distance found: no point left can
        exceed it."""
        P = np.asarray(P, dtype=np.float64)
        _, nearest = self.tree.query(P, k=1)
        u = point_triangle_distance(P, self.A[nearest], self.B[nearest], self.C[nearest])
        order = np.argsort(-u, kind="stable")
        best = 0.0
        batch = max(64, len(P) // 64)
        for start in range(0, len(P), batch):
            chunk = order[start:start + batch]
            chunk = chunk[u[chunk] > best]
            if len(chunk) == 0:
                break
            best = max(best, float(self.distance(P[chunk]).max()))
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
    if count <= 0:
        return np.empty((0, 3))
    area = np.linalg.norm(_cross_faces(V, F), axis=1)
    total = area.sum()
    if total <= 0:
        return np.empty((0, 3))
    face = rng.choice(len(F), size=count, p=area / total)
    r1 = np.sqrt(rng.random(count))
    r2 = rng.random(count)
    a, b, c = (1 - r1), r1 * (1 - r2), r1 * r2
    return a[:, None] * V[F[face, 0]] + b[:, None] * V[F[face, 1]] + c[:, None] * V[F[face, 2]]


# ----------------------------------------------------------------------------
# the comparison against one clean mesh
# ----------------------------------------------------------------------------

class MeshComparison:
    """Metrics of meshes with the connectivity ``F`` against one clean mesh ``V_clean``.

    Everything that depends on the clean mesh only (its bounding-box
    diagonal, face normals, interior edges and their bend angles, the sharp
    edges, area, volume, the surface samples and the search tree for
    distances to it) is computed once here; :meth:`evaluate` then costs a few
    vectorised passes over the faces (plus the Hausdorff estimate when asked).

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
        Density of the Hausdorff estimate: ``round(samples_per_face * m)``
        area-weighted random points on each surface, plus all its vertices.
    seed : int
        Seed of the surface samples (the same seed gives the same estimate).

    Attributes
    ----------
    diagonal : float
        Bounding-box diagonal of the clean mesh (length units).
    closed : bool
        True when every edge is shared by exactly two opposite faces.
    sharp : (s,) int64
        Indices (into ``edges``) of the sharp edges.
    """

    def __init__(self, V_clean, F, sharp_angle=SHARP_ANGLE,
                 samples_per_face=HAUSDORFF_SAMPLES_PER_FACE, seed=0):
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
        E, f1, f2, boundary, other = interior_edges(self.F)
        self.edges, self._f1, self._f2 = E, f1, f2
        self.closed = len(boundary) == 0 and len(other) == 0
        self._N_clean = _cross_faces(self.V_clean, self.F)
        self.area_clean = 0.5 * float(np.linalg.norm(self._N_clean, axis=1).sum())
        self.volume_clean = _volume(self.V_clean, self.F, self._N_clean) if self.closed else float("nan")
        self.bend_clean = _bend_angles(self.V_clean, self.F, E, f1, f2)
        self.sharp = np.flatnonzero(np.abs(self.bend_clean) > self.sharp_angle)
        self._index_clean = None
        self._points_clean = None

    # -- single metrics ------------------------------------------------------

    def _check(self, V):
        V = as_vertices(V)
        _same_shape(V, self.V_clean)
        return V

    def vertex_rms(self, V, relative=True):
        """``sqrt(mean_i |v_i - v_i^clean|^2)``, relative to the clean diagonal by default."""
        V = self._check(V)
        rms = float(np.sqrt(np.mean(np.einsum("ij,ij->i", V - self.V_clean, V - self.V_clean))))
        return rms / self.diagonal if relative else rms

    def face_normal_angles(self, V):
        """Angle (degrees) between each face's normal and the clean one, (m,)."""
        V = self._check(V)
        return _normal_angles(_cross_faces(V, self.F), self._N_clean)

    def sharp_edge_error(self, V):
        """Mean absolute error (degrees) of the bend angle on the clean mesh's
        sharp edges; NaN when the clean mesh has no sharp edge."""
        V = self._check(V)
        if len(self.sharp) == 0:
            return float("nan")
        E, f1, f2 = self.edges[self.sharp], self._f1[self.sharp], self._f2[self.sharp]
        bend = _bend_angles(V, self.F, E, f1, f2)
        return float(np.mean(np.abs(bend - self.bend_clean[self.sharp])))

    def hausdorff(self, V, relative=True, seed=None):
        """Symmetric Hausdorff distance between the surfaces (V, F) and (V_clean, F).

        ``max(sup_{p on S} d(p, S_clean), sup_{q on S_clean} d(q, S))``,
        estimated as the maximum over all vertices plus
        ``round(samples_per_face * m)`` area-weighted random points of each
        surface, each measured exactly to the other surface (closest point in
        a triangle, on an edge or at a corner). Being a maximum over finitely
        many points it is an estimate *from below*: the true value is at least
        this, and since ``d(p, S)`` changes by at most ``|p - q|`` from p to q
        it exceeds the estimate by at most the covering radius of the samples
        (the largest distance from a point of a surface to its nearest
        sample), which shrinks as the density grows. Relative to the clean
        diagonal by default.
        """
        V = self._check(V)
        if self._index_clean is None:
            self._index_clean = _SurfaceIndex(self.V_clean, self.F)
            rng = np.random.default_rng(self.seed)
            count = int(round(self.samples_per_face * len(self.F)))
            self._points_clean = np.vstack([self.V_clean[np.unique(self.F)],
                                            _sample(self.V_clean, self.F, count, rng)])
        rng = np.random.default_rng(self.seed + 1 if seed is None else seed)
        count = int(round(self.samples_per_face * len(self.F)))
        points = np.vstack([V[np.unique(self.F)], _sample(V, self.F, count, rng)])
        there = self._index_clean.max_distance(points)
        back = _SurfaceIndex(V, self.F).max_distance(self._points_clean)
        h = float(max(there, back))
        return h / self.diagonal if relative else h

    def area_change(self, V):
        """``(A - A_clean) / A_clean``: signed relative change of the surface area."""
        V = self._check(V)
        return 0.5 * float(np.linalg.norm(_cross_faces(V, self.F), axis=1).sum()) / self.area_clean - 1.0

    def volume_change(self, V):
        """``(vol - vol_clean) / |vol_clean|``; raises MeshError on an open mesh."""
        V = self._check(V)
        if not self.closed:
            raise MeshError("the volume change is defined for closed meshes only; this mesh has "
                            "boundary or non-manifold edges")
        return (_volume(V, self.F, _cross_faces(V, self.F)) - self.volume_clean) / abs(self.volume_clean)

    # -- all at once -----------------------------------------------------------

    def evaluate(self, V, hausdorff=True):
        """All metrics of V against the clean mesh, as a dict.

        Keys (lengths relative to the clean bounding-box diagonal, angles in
        degrees): ``"rms"`` vertex RMS distance; ``"hausdorff"`` symmetric
        surface Hausdorff estimate (only when ``hausdorff=True``);
        ``"normal_mean"`` and ``"normal_p95"`` mean and 95th percentile of
        the face-normal angle error; ``"area_change"`` and
        ``"volume_change"`` signed relative changes (``volume_change`` is NaN
        for an open mesh, whose volume is undefined); ``"sharp_edge_error"``
        mean absolute bend-angle error on the sharp edges (NaN when the clean
        mesh has none).
        """
        V = self._check(V)
        N = _cross_faces(V, self.F)
        angles = _normal_angles(N, self._N_clean)
        D = V - self.V_clean
        out = {"rms": float(np.sqrt(np.mean(D * D) * 3)) / self.diagonal}
        if hausdorff:
            out["hausdorff"] = self.hausdorff(V)
        out["normal_mean"] = float(angles.mean())
        out["normal_p95"] = _percentile(angles, 95.0)
        out["area_change"] = 0.5 * float(_norms(N).sum()) / self.area_clean - 1.0
        if self.closed:
            out["volume_change"] = (_volume(V, self.F, N) - self.volume_clean) / abs(self.volume_clean)
        else:
            out["volume_change"] = float("nan")
        if len(self.sharp):
            s = self.sharp
            bend = _bend_angles(V, self.F, self.edges[s], self._f1[s], self._f2[s], N)
            out["sharp_edge_error"] = float(np.mean(np.abs(bend - self.bend_clean[s])))
        else:
            out["sharp_edge_error"] = float("nan")
        return out


def _percentile(x, q):
    """``np.percentile(x, q)`` (linear interpolation) from two order statistics."""
    pos = q / 100.0 * (len(x) - 1)
    lo = int(np.floor(pos))
    hi = min(lo + 1, len(x) - 1)
    part = np.partition(x, [lo, hi])
    return float(part[lo] + (pos - lo) * (part[hi] - part[lo]))


def _volume(V, F, N):
    """Enclosed volume from the face cross products N:
    ``v0 . ((v1 - v0) x (v2 - v0)) = v0 . (v1 x v2)``, summed, over 6."""
    return float((V[F[:, 0]] * N).sum()) / 6.0


def _normal_angles(N, N_clean):
    """Angles (degrees) between the rows of two arrays of (unnormalised)
    normals; rows with a zero vector (degenerate faces) count as 90."""
    X = np.empty_like(N)
    X[:, 0] = N[:, 1] * N_clean[:, 2] - N[:, 2] * N_clean[:, 1]
    X[:, 1] = N[:, 2] * N_clean[:, 0] - N[:, 0] * N_clean[:, 2]
    X[:, 2] = N[:, 0] * N_clean[:, 1] - N[:, 1] * N_clean[:, 0]
    dot = N[:, 0] * N_clean[:, 0] + N[:, 1] * N_clean[:, 1] + N[:, 2] * N_clean[:, 2]
    angle = np.degrees(np.arctan2(_norms(X), dot))
    zero = (_norms(N) == 0) | (_norms(N_clean) == 0)
    angle[zero] = 90.0
    return angle


# ----------------------------------------------------------------------------
# function forms
# ----------------------------------------------------------------------------

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


def hausdorff_distance(V, V_clean, F, F_clean=None, relative=True,
                       samples_per_face=HAUSDORFF_SAMPLES_PER_FACE, seed=0):
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
    rng = np.random.default_rng(seed)

    def points(X, G):
        count = int(round(samples_per_face * len(G)))
        return np.vstack([X[np.unique(G)], _sample(X, G, count, rng)])

    there = _SurfaceIndex(V_clean, F_clean).max_distance(points(V, F))
    back = _SurfaceIndex(V, F).max_distance(points(V_clean, F_clean))
    h = float(max(there, back))
    return h / bounding_box_diagonal(V_clean) if relative else h


def face_normal_angles(V, V_clean, F):
    """Angle (degrees) between each face's unit normal in V and in V_clean, (m,).

    ``atan2(|n x n_clean|, n . n_clean)`` in [0, 180] (accurate for small
    angles too); a face of zero area in either mesh counts as 90.
    """
    V = as_vertices(V)
    V_clean = as_vertices(V_clean, where="V_clean")
    _same_shape(V, V_clean)
    F = as_faces(F, len(V))
    return _normal_angles(_cross_faces(V, F), _cross_faces(V_clean, F))


def normal_angle_error(V, V_clean, F):
    """Face-normal angle error against the clean mesh: ``(mean, p95)`` in degrees.

    The mean and the 95th percentile (linear interpolation) over faces of
    :func:`face_normal_angles` (unweighted: every face counts once).
    """
    angles = face_normal_angles(V, V_clean, F)
    return float(angles.mean()), float(np.percentile(angles, 95))


def area_change(V, V_clean, F):
    """Signed relative change of the surface area, ``(A - A_clean) / A_clean``."""
    A = surface_area(V, F)
    A_clean = surface_area(V_clean, F)
    if not A_clean > 0:
        raise MeshError("the clean mesh has zero area")
    return A / A_clean - 1.0


def volume_change(V, V_clean, F):
    """Signed relative change of the enclosed volume, ``(vol - vol_clean) / |vol_clean|``.

    Closed meshes only (every edge shared by two opposite faces); an open
    mesh raises MeshError naming its boundary edges.
    """
    V = as_vertices(V)
    V_clean = as_vertices(V_clean, where="V_clean")
    _same_shape(V, V_clean)
    F = as_faces(F, len(V))
    _, _, _, boundary, other = interior_edges(F)
    if len(boundary) or len(other):
        bad = np.vstack([boundary, other])
        raise MeshError("the volume change is defined for closed meshes only; "
                        f"{len(bad)} edge(s) are boundary or non-manifold, e.g. "
                        + ", ".join(f"({i}, {j})" for i, j in bad[:5]))
    vol_clean = enclosed_volume(V_clean, F)
    if vol_clean == 0:
        raise MeshError("the clean mesh encloses zero volume")
    return (enclosed_volume(V, F) - vol_clean) / abs(vol_clean)


def sharp_edges(V_clean, F, threshold=SHARP_ANGLE):
    """Interior edges of the clean mesh whose absolute bend angle exceeds ``threshold`` degrees.

    Returns ``(E, angle)``: (s, 2) int64 vertex pairs and their signed bend
    angles in degrees (see :func:`dihedral_angles`).
    """
    E, angle = dihedral_angles(V_clean, F)
    keep = np.abs(angle) > threshold
    return E[keep], angle[keep]


def sharp_edge_error(V, V_clean, F, threshold=SHARP_ANGLE):
    """Mean absolute error (degrees) of the bend (dihedral) angle on the sharp edges.

    The sharp edges are the interior edges where the clean mesh bends by more
    than ``threshold`` degrees (default 30); on those the error is
    ``|theta(V) - theta(V_clean)|`` with the signed bend angle of
    :func:`dihedral_angles`. Returns NaN when the clean mesh has no sharp
    edge (there is nothing to measure).
    """
    V = as_vertices(V)
    V_clean = as_vertices(V_clean, where="V_clean")
    _same_shape(V, V_clean)
    F = as_faces(F, len(V))
    return MeshComparison(V_clean, F, sharp_angle=threshold).sharp_edge_error(V)


def denoising_metrics(V, V_clean, F, sharp_angle=SHARP_ANGLE,
                      samples_per_face=HAUSDORFF_SAMPLES_PER_FACE, seed=0):
    """Every metric of V against the clean mesh, as a dict (see :meth:`MeshComparison.evaluate`)."""
    return MeshComparison(V_clean, F, sharp_angle, samples_per_face, seed).evaluate(V)


# ----------------------------------------------------------------------------
# a sweep of Laplacian smoothing over noise levels, schemes, steps, iterations
# ----------------------------------------------------------------------------

#: (method, weights) pairs compared by :func:`smoothing_sweep`.
SCHEMES = (("explicit", "uniform"), ("explicit", "cotan"),
           ("implicit", "uniform"), ("implicit", "cotan"))

#: Explicit steps of the sweep, as fractions of the stability limit
#: ``2 / lambda_max`` of the mesh being smoothed (below 1 is stable).
EXPLICIT_FRACTIONS = (0.1, 0.25, 0.5, 0.9)

#: Implicit steps of the sweep, scale-free (see :func:`scale_free_step`).
IMPLICIT_STEPS = (0.1, 0.3, 1.0)

#: Iteration counts at which the sweep measures every run.
SWEEP_ITERATIONS = (1, 2, 3, 5, 8, 13, 20, 30, 50)

#: Metric keys recorded by the sweep (all of :meth:`MeshComparison.evaluate`
#: except the Hausdorff estimate, which is measured for chosen results only).
SWEEP_KEYS = ("rms", "normal_mean", "normal_p95", "area_change", "volume_change",
              "sharp_edge_error")


def unique_edges(F):
    """Every edge of the triangles once, as sorted vertex pairs (k, 2) int64."""
    F = np.asarray(F, dtype=np.int64)
    E = np.sort(F[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    return np.unique(E, axis=0)


def mean_edge_length(V, F, edges=None):
    """Mean length of the mesh's edges, each counted once (length units).

    ``edges``: the result of :func:`unique_edges` for F, to avoid recomputing it."""
    V = as_vertices(V)
    F = as_faces(F, len(V))
    E = unique_edges(F) if edges is None else edges
    return float(_norms(V[E[:, 0]] - V[E[:, 1]]).mean())


def scale_free_step(V, F, method, weights, value, edges=None):
    """The smoothing step (units of :mod:`geomlib.smoothing`) for a scale-free ``value``.

    * explicit: ``value`` is a fraction of the stability limit of this mesh,
      ``step = value * explicit_step_limit(V, F, weights)``.
    * implicit, uniform weights: ``Delta`` is dimensionless, ``step = value``.
    * implicit, cotangent weights: ``step = value * h^2 / 4`` with ``h`` the
      mean edge length of this mesh. On an equilateral mesh the cotangent
      Laplacian is the uniform one divided by ``h^2 / 4``, so the same
      ``value`` diffuses by the same amount with either weights, at any scale.

    For the cotangent operator of a *noisy* mesh the explicit limit collapses
    (noise makes obtuse triangles with large cotangents), which is why the
    implicit step is not tied to it.
    """
    if method == "explicit":
        from .smoothing import explicit_step_limit

        return float(value) * explicit_step_limit(V, F, weights)
    if method != "implicit":
        raise MeshError(f"method must be 'explicit' or 'implicit', not {method!r}")
    if weights == "uniform":
        return float(value)
    if weights == "cotan":
        return float(value) * mean_edge_length(V, F, edges) ** 2 / 4.0
    raise MeshError(f"weights must be 'cotan' or 'uniform', not {weights!r}")


class SmoothingSweep:
    """Results of :func:`smoothing_sweep`: every metric for every setting.

    Attributes
    ----------
    sigmas : (a,) float64
        Noise levels (fractions of the bounding-box diagonal).
    schemes : list of (method, weights)
    step_values : dict method -> tuple
        The scale-free step values (:func:`scale_free_step`).
    steps : (a, s, b) float64
        The actual step used for noise level i, scheme j, step value k.
    iterations : (c,) int64
    values : dict key -> (a, s, b, c) float64
        ``values["rms"][i, j, k, l]``: the metric after ``iterations[l]``
        iterations. NaN where a run stopped early (divergence).
    noisy : dict key -> (a,) float64
        The metrics of the noisy input itself.
    seconds : float
        Wall-clock time of the sweep.
    """

    def __init__(self, sigmas, schemes, step_values, iterations):
        self.sigmas = np.asarray(sigmas, dtype=np.float64)
        self.schemes = list(schemes)
        self.step_values = dict(step_values)
        self.iterations = np.asarray(iterations, dtype=np.int64)
        b = max(len(v) for v in self.step_values.values())
        shape = (len(self.sigmas), len(self.schemes), b, len(self.iterations))
        self.steps = np.full(shape[:3], np.nan)
        self.values = {key: np.full(shape, np.nan) for key in SWEEP_KEYS}
        self.noisy = {key: np.full(len(self.sigmas), np.nan) for key in SWEEP_KEYS}
        self.seconds = float("nan")

    def best(self, i, key="rms", schemes=None):
        """The setting with the smallest ``key`` at noise level ``i``.

        Parameters
        ----------
        i : int
            Index into ``sigmas``.
        key : str
            A metric of ``values`` (smaller is better; for signed changes the
            absolute value counts).
        schemes : list of (method, weights), optional
            Restrict the search to these schemes.

        Returns
        -------
        dict with ``method``, ``weights``, ``step_value``, ``step``,
        ``iterations``, the metrics of that setting (every key of ``values``)
        and ``index`` (j, k, l) into ``values``.
        """
        allowed = [j for j, s in enumerate(self.schemes) if schemes is None or s in schemes]
        block = np.abs(self.values[key][i])
        mask = np.full(block.shape, np.inf)
        mask[allowed] = 0.0
        block = np.where(np.isnan(block), np.inf, block) + mask
        j, k, l = np.unravel_index(int(np.argmin(block)), block.shape)
        method, weights = self.schemes[j]
        out = {"method": method, "weights": weights,
               "step_value": self.step_values[method][k], "step": float(self.steps[i, j, k]),
               "iterations": int(self.iterations[l]), "index": (int(j), int(k), int(l))}
        out.update({name: float(v[i, j, k, l]) for name, v in self.values.items()})
        return out


def smoothing_sweep(V_clean, F, sigmas, seed, schemes=SCHEMES, explicit_fractions=EXPLICIT_FRACTIONS,
                    implicit_steps=IMPLICIT_STEPS, iterations=SWEEP_ITERATIONS, direction="isotropic",
                    comparison=None, progress=True):
    """Add noise at each level, smooth it with every scheme, step and iteration count, measure.

    For every noise level ``sigma`` (a fraction of the bounding-box
    diagonal) the noisy mesh is ``add_noise(V_clean, F, sigma, seed,
    direction)`` (the same seed at every level: the same noise pattern,
    growing). Every scheme ``(method, weights)`` then smooths it with every
    step value (:func:`scale_free_step`) for ``max(iterations)`` iterations,
    and the mesh is measured against the clean one after each count in
    ``iterations`` (:meth:`MeshComparison.evaluate` without the Hausdorff
    estimate). One run per (noise level, scheme, step) covers all iteration
    counts; implicit runs factorise ``M - step C`` once per (noisy mesh,
    weights, step) and reuse it (:class:`geomlib.smoothing.ImplicitSmoother`).
    The operators are those of the noisy mesh, built once per run and kept
    fixed (as in :func:`geomlib.explicit_smoothing` and
    :func:`geomlib.implicit_smoothing`).

    Parameters
    ----------
    V_clean : (n, 3) float64
    F : (m, 3) int64
    sigmas : sequence of float
    seed : int
    schemes : sequence of (method, weights)
    explicit_fractions, implicit_steps : sequence of float
        Scale-free step values of the explicit and implicit runs.
    iterations : sequence of int
        Increasing iteration counts at which to measure.
    direction : "isotropic" or "normal"
        Of the noise (:func:`geomlib.add_noise`).
    comparison : MeshComparison, optional
        Reuse one built for (V_clean, F).
    progress : bool
        A tqdm.auto progress bar over the runs.

    Returns
    -------
    SmoothingSweep
    """
    import time
    import warnings

    from .errors import MeshWarning
    from .noise import add_noise
    from .smoothing import ImplicitSmoother, explicit_smoothing

    C = comparison if comparison is not None else MeshComparison(V_clean, F)
    iterations = np.asarray(sorted(set(int(k) for k in iterations)), dtype=np.int64)
    if len(iterations) == 0 or iterations[0] < 1:
        raise MeshError("iterations must be positive whole numbers")
    step_values = {"explicit": tuple(explicit_fractions), "implicit": tuple(implicit_steps)}
    for method, weights in schemes:
        if method not in step_values or weights not in ("uniform", "cotan"):
            raise MeshError(f"unknown scheme ({method!r}, {weights!r}); methods are 'explicit' and "
                            "'implicit', weights 'uniform' and 'cotan'")
    out = SmoothingSweep(sigmas, schemes, step_values, iterations)
    where = {int(k): l for l, k in enumerate(iterations)}
    edges = unique_edges(C.F)
    last = int(iterations[-1])
    runs = sum(len(step_values[m]) for m, _ in schemes) * len(out.sigmas)
    bar = None
    if progress:
        from tqdm.auto import tqdm

        bar = tqdm(total=runs, desc="smoothing sweep")
    start = time.perf_counter()
    try:
        for i, sigma in enumerate(out.sigmas):
            Vn = add_noise(C.V_clean, C.F, sigma, seed, direction=direction)
            for key, value in C.evaluate(Vn, hausdorff=False).items():
                out.noisy[key][i] = value
            for j, (method, weights) in enumerate(schemes):
                smoother = ImplicitSmoother(Vn, C.F, weights) if method == "implicit" else None
                for k, value in enumerate(step_values[method]):
                    step = scale_free_step(Vn, C.F, method, weights, value, edges)
                    out.steps[i, j, k] = step

                    def record(it, P, i=i, j=j, k=k):
                        if it in where:
                            for name, v in C.evaluate(P, hausdorff=False).items():
                                out.values[name][i, j, k, where[it]] = v

                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore", MeshWarning)
                        if method == "explicit":
                            explicit_smoothing(Vn, C.F, step, last, weights, callback=record,
                                               on_failure="stop", progress=False)
                        else:
                            smoother.smooth(step, last, callback=record, progress=False)
                    if bar is not None:
                        bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    out.seconds = time.perf_counter() - start
    return out
