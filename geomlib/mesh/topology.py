"""Combinatorics of triangle meshes: edges, boundaries, valence, one-rings, Euler characteristic.

Convention: ``F`` is an (m, 3) int64 array of 0-based vertex indices,
counter-clockwise seen from outside. Face ``f`` traverses the directed edges
``F[f,0] -> F[f,1] -> F[f,2] -> F[f,0]``; a boundary edge is an edge used by
exactly one face and is reported in the direction that face traverses it, so
walking along it the face lies on the left seen from outside.

Everything is vectorised around one sort of the 3m half-edges; loops are
followed by pointer jumping (log2 of the longest loop steps). The only Python
loops are the walk around a single vertex in :func:`one_ring` and the chaining
of boundary loops that touch at a vertex (non-manifold boundaries), both short.
Every function validates ``F`` at the door (:func:`geomlib.mesh.validate.as_faces`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components as _cc

from .errors import MeshError, format_indices
from .validate import as_faces, as_mesh

__all__ = [
    "unpaired_vertices",
    "edges_at_unpaired_vertices",
    "edges",
    "boundary_edges",
    "boundary_vertices",
    "boundary_loops",
    "valence",
    "one_ring",
    "euler_characteristic",
    "connected_components",
    "vertex_face_adjacency",
    "edge_face_counts",
    "boundary_edge_counts",
    "unreferenced_vertices",
    "non_manifold_edges",
    "Topology",
    "loops_from_edges",
]

_INT64_MAX = np.iinfo(np.int64).max


def _sort_with_order(key):
    """Sorted keys and the permutation that sorts them (stable).

    When the keys are small enough the index is packed into the low digits
    of the key and a plain ``np.sort`` is used: several times faster than
    ``np.argsort`` on millions of half-edges.
    """
    k = len(key)
    if k == 0:
        return key, np.zeros(0, np.int64)
    bits = max(int(k - 1).bit_length(), 1)
    if int(key.max()) < (1 << (62 - bits)):  # key and index share one non-negative int64
        packed = np.left_shift(key, bits)
        packed |= np.arange(k, dtype=np.int64)
        packed.sort()
        return packed >> bits, packed & ((1 << bits) - 1)
    order = np.argsort(key, kind="stable")
    return key[order], order


class Topology:
    """Half-edge table of a face array: the one edge table behind this module and check_mesh.

    ``Topology(F, n)`` sorts the 3m half-edges once; its attributes are the
    unique edges ``E`` (e, 2) (smaller index first, lexicographic),
    ``edge_face_count`` (e,), ``vertex_face_count`` (n,), and the methods give
    boundary edges, inconsistently oriented edges, non-manifold vertices,
    vertex components and duplicate faces. ``F`` must be valid
    (:func:`geomlib.mesh.validate.as_faces`).

    Half-edge ``h = 3 f + s`` runs from ``F[f, s]`` to ``F[f, (s + 1) % 3]``;
    corner ``3 f + s`` is the corner of face f at vertex ``F[f, s]`` (so a
    half-edge and the corner at its start share the index).
    """

    def __init__(self, F, n):
        self.F, self.n = F, n
        m = len(F)
        self.I = F.ravel()
        self.J = F[:, [1, 2, 0]].ravel()
        lo = np.minimum(self.I, self.J)
        hi = np.maximum(self.I, self.J)
        sk, order = _sort_with_order(lo * np.int64(n) + hi)
        first = np.empty(len(sk), bool)
        first[:1] = True
        np.not_equal(sk[1:], sk[:-1], out=first[1:])
        starts = np.flatnonzero(first)
        self.order = order
        self.group_start = starts
        self.edge_face_count = np.diff(np.append(starts, 3 * m))
        h = order[starts]
        self.E = np.stack([lo[h], hi[h]], axis=1)
        self.vertex_face_count = np.bincount(self.I, minlength=n)

    def boundary_halfedges(self):
        p = self.group_start[self.edge_face_count == 1]
        return np.sort(self.order[p])

    def euler_characteristic(self):
        """``chi = V - E + F``, V counting only the vertices some face uses."""
        return int(np.count_nonzero(self.vertex_face_count)) - len(self.E) + len(self.F)

    def boundary_edges(self):
        h = self.boundary_halfedges()
        return np.stack([self.I[h], self.J[h]], axis=1)

    def _pairs(self):
        p = self.group_start[self.edge_face_count == 2]
        return p, self.order[p], self.order[p + 1]

    def inconsistent_edges(self):
        p, h1, h2 = self._pairs()
        same = self.I[h1] == self.I[h2]
        return self.E[np.flatnonzero(self.edge_face_count == 2)[same]]

    def face_pairs(self):
        """Edges of exactly two faces that traverse them in opposite directions.

        Returns ``E`` (k, 2), each edge ``(i, j)`` as face ``f1`` traverses
        it, and ``f1``, ``f2`` (k,): the faces holding ``i -> j`` and ``j -> i``.
        """
        _, h1, h2 = self._pairs()
        opposite = self.I[h1] == self.J[h2]
        h1, h2 = h1[opposite], h2[opposite]
        return np.stack([self.I[h1], self.J[h1]], axis=1), h1 // 3, h2 // 3

    def non_manifold_vertices(self):
        """Vertices whose faces form more than one fan, sorted.

        Corners at the same vertex are linked when their faces share an edge
        at that vertex; a fan is a connected set of corners.
        """
        if (self.edge_face_count <= 2).all():
            p, h1, h2 = self._pairs()
            if (self.I[h1] != self.I[h2]).all():
                return self._multi_fan_oriented(h1, h2)
        return np.flatnonzero(self._fans_general() > 1)

    def _successor(self, h1, h2):
        """Successor of each corner around its vertex (oriented, manifold edges).

        The corner after corner c at vertex v is the corner at v of the face
        across the edge entering v in c's face; where that edge is a boundary
        edge the successor is c itself (c ends an open fan). Also returns the
        twin of each half-edge (-1 on the boundary).
        """
        m3 = len(self.I)
        twin = np.full(m3, -1, np.int64)
        twin[h1] = h2
        twin[h2] = h1
        c = np.arange(m3, dtype=np.int64)
        # the half-edge entering the corner's vertex: slot (s + 2) % 3 of the same face
        nxt = twin[c + np.tile(np.array([2, -1, -1], np.int64), m3 // 3)]
        term = nxt < 0
        nxt[term] = c[term]
        return nxt, twin

    def _multi_fan_oriented(self, h1, h2):
        """Walk once around every vertex from one corner; compare the fan with all corners there.

        A vertex has one fan when the walk from its representative corner
        (the start of its open fan, or any corner when it has no boundary
        edge) visits all of its corners. All vertices walk at once; the loop
        runs as many steps as the largest fan has corners.
        """
        n = self.n
        nxt, twin = self._successor(h1, h2)
        ncorner = self.vertex_face_count
        # open-fan starts: corners whose outgoing edge (half-edge c itself) is a boundary edge
        starts = np.flatnonzero(twin < 0)
        nstart = np.bincount(self.I[starts], minlength=n)
        bad = nstart > 1  # two open fans at one vertex
        rep = np.full(n, -1, np.int64)
        rep[self.I] = np.arange(len(self.I))  # some corner at each vertex (any will do)
        rep[self.I[starts]] = starts
        verts = np.flatnonzero((ncorner > 0) & ~bad)
        first = rep[verts]
        cur = first
        count = np.ones(len(verts), np.int64)
        steps = 0
        while len(verts):
            nx = nxt[cur]
            done = (nx == first) | (nx == cur)  # cycle closed, or open fan ended
            if done.any():
                fin = verts[done]
                bad[fin[count[done] != ncorner[fin]]] = True
                keep = ~done
                verts, first, cur, count = verts[keep], first[keep], nx[keep], count[keep]
            else:
                cur = nx
            count += 1
            steps += 1
            if steps > 3 * len(self.I):  # cannot happen for a valid successor map
                raise RuntimeError("corner walk did not terminate")
        return np.flatnonzero(bad)

    def _fans_general(self):
        """Fans by connected components of the corner graph (any mesh)."""
        m3 = len(self.I)
        # every half-edge of an edge with >= 2 faces is linked to the group's first
        multi = self.edge_face_count >= 2
        gs = self.group_start[multi]
        cnt = self.edge_face_count[multi]
        first_pos = np.repeat(gs, cnt - 1)
        other_pos = (
            first_pos + (np.arange(int((cnt - 1).sum())) - np.repeat(np.cumsum(cnt - 1) - (cnt - 1), cnt - 1)) + 1
        )
        h1 = self.order[first_pos]
        h2 = self.order[other_pos]
        end1 = h1 - h1 % 3 + (h1 % 3 + 1) % 3
        end2 = h2 - h2 % 3 + (h2 % 3 + 1) % 3
        same = self.I[h1] == self.I[h2]
        a = np.concatenate([h1, end1])
        b = np.concatenate([np.where(same, h2, end2), np.where(same, end2, h2)])
        G = sp.csr_matrix((np.ones(len(a), np.int8), (a, b)), shape=(m3, m3))
        k, labels = _cc(G, directed=False)
        comp_vertex = np.empty(k, np.int64)
        comp_vertex[labels] = self.I
        return np.bincount(comp_vertex, minlength=self.n)

    def vertex_components(self):
        """Component label per vertex through shared edges; -1 for unreferenced vertices."""
        n = self.n
        G = sp.csr_matrix((np.ones(len(self.E), np.int8), (self.E[:, 0], self.E[:, 1])), shape=(n, n))
        _, labels = _cc(G, directed=False)
        labels = labels.astype(np.int64)
        unref = self.vertex_face_count == 0
        if unref.any():
            used = ~unref
            _, labels[used] = np.unique(labels[used], return_inverse=True)
            labels[unref] = -1
        return labels

    def duplicate_faces(self):
        F, n = self.F, self.n
        S = np.sort(F, axis=1)
        if n**3 < _INT64_MAX:
            key = (S[:, 0] * n + S[:, 1]) * n + S[:, 2]
        else:  # rows as one void item each, compared bytewise
            key = np.ascontiguousarray(S).view(np.dtype((np.void, 24))).ravel()
        sk = np.sort(key)
        if not (sk[1:] == sk[:-1]).any():
            return np.zeros(0, np.int64)
        order = np.argsort(key, kind="stable")
        sk = key[order]
        dup = np.zeros(len(F), bool)
        dup[1:] = sk[1:] == sk[:-1]
        return np.sort(order[dup])


def _nverts(F, n):
    return int(F.max()) + 1 if n is None else int(n)


def edges(F):
    """Unique undirected edges, one row per edge, ``(e, 2)`` int64 sorted.

    Each row holds the smaller vertex index first; rows are in
    lexicographic order.

    Parameters
    ----------
    F : (m, 3) int64

    Returns
    -------
    E : (e, 2) int64
    """
    return edge_face_counts(F)[0]


def boundary_edges(F):
    """Boundary edges (used by exactly one face), directed as their face traverses them.

    With faces counter-clockwise seen from outside, the face lies to the left
    of each directed boundary edge. Rows are in the order of their faces
    (face index, then the edge's position in the face).

    Parameters
    ----------
    F : (m, 3) int64

    Returns
    -------
    B : (b, 2) int64
        ``B[k] = (i, j)`` with the face traversing ``i -> j``. Empty (0, 2) for
        a closed mesh.
    """
    F = as_faces(F)
    return Topology(F, _nverts(F, None)).boundary_edges()


def boundary_vertices(F, n=None):
    """Indices of the vertices on the boundary, sorted ascending (int64).

    A vertex is on the boundary when it is an end of a boundary edge (an
    edge with exactly one face). For a boolean mask use
    ``mask = np.zeros(n, bool); mask[boundary_vertices(F)] = True``.

    Parameters
    ----------
    F : (m, 3) int64
    n : int, optional
        Number of vertices, only used to check the indices in ``F``.

    Returns
    -------
    (k,) int64
    """
    return np.flatnonzero(boundary_edge_counts(F, n))


def loops_from_edges(B):
    """Chain directed boundary edges into loops (see :func:`boundary_loops`)."""
    if len(B) == 0:
        return []
    loops = _loops_vectorised(B)
    return loops if loops is not None else _loops_walk(B)


def _loops_vectorised(B):
    """Loops when every boundary vertex has one edge out and one in (the usual case).

    The successor map is then a permutation of the boundary vertices. Pointer
    jumping (log2 of the longest loop steps) labels each vertex with the
    smallest vertex of its loop and, with the loop cut just before that
    vertex, ranks it by its distance to the loop's end. Returns None when a
    vertex has two outgoing or incoming boundary edges.
    """
    a, b = B[:, 0], B[:, 1]
    n = int(B.max()) + 1
    if np.bincount(a, minlength=n).max() > 1 or np.bincount(b, minlength=n).max() > 1:
        return None
    verts = np.sort(a)
    if not np.array_equal(verts, np.sort(b)):
        return None
    k = len(verts)
    local = np.full(n, -1, np.int64)
    local[verts] = np.arange(k)
    nxt = np.empty(k, np.int64)
    nxt[local[a]] = local[b]
    # smallest vertex of each loop (local indices are sorted like the vertices)
    lab, jump = np.arange(k), nxt.copy()
    while True:
        new = np.minimum(lab, lab[jump])
        if np.array_equal(new, lab):
            break
        lab, jump = new, jump[jump]
    # cut each loop before its smallest vertex and rank by distance to the cut
    prev = np.empty(k, np.int64)
    prev[nxt] = np.arange(k)
    nxt = nxt.copy()
    tail = prev[lab[lab == np.arange(k)]]  # predecessor of each loop's first vertex
    nxt[tail] = tail
    dist = (nxt != np.arange(k)).astype(np.int64)
    while True:
        dist_new = dist + dist[nxt]
        nxt_new = nxt[nxt]
        if np.array_equal(nxt_new, nxt):
            break
        dist, nxt = dist_new, nxt_new
    order = np.lexsort((-dist, lab))
    sizes = np.bincount(lab)
    sizes = sizes[sizes > 0]
    return [verts[part] for part in np.split(order, np.cumsum(sizes)[:-1])]


def _loops_walk(B):
    """Chain directed boundary edges one by one (any input, also non-manifold)."""
    out = {}
    for a, b in B.tolist():
        out.setdefault(a, []).append(b)
    loops = []
    for s in sorted(out):
        while out[s]:
            loop = [s]
            v = out[s].pop(0)
            while v != s:
                loop.append(v)
                nxt = out.get(v)
                if not nxt:  # chain that does not close (inconsistent orientation)
                    break
                v = nxt.pop(0)
            loops.append(np.asarray(loop, dtype=np.int64))
    return loops


def boundary_loops(F):
    """Boundary loops as ordered vertex index arrays, one per loop.

    Each loop lists its vertices in the direction its faces traverse the
    boundary edges (face on the left seen from outside), starting at the
    loop's smallest vertex index; the first vertex is not repeated at the
    end, so a loop of k edges has k vertices. Loops are ordered by their
    first vertex. Where a vertex has two outgoing boundary edges (two loops
    touching at a non-manifold vertex) the edges are taken in face order,
    so the split into loops there is one of the possible ones.

    Parameters
    ----------
    F : (m, 3) int64

    Returns
    -------
    list of (k_i,) int64 arrays; empty for a closed mesh.
    """
    return loops_from_edges(boundary_edges(F))


def valence(F, n=None):
    """Number of distinct neighbours of each vertex (edges at the vertex).

    Parameters
    ----------
    F : (m, 3) int64
    n : int, optional
        Number of vertices; defaults to ``F.max() + 1``. Unreferenced vertices
        have valence 0.

    Returns
    -------
    (n,) int64
    """
    F = as_faces(F, n)
    n = _nverts(F, n)
    return np.bincount(edges(F).ravel(), minlength=n).astype(np.int64)


def one_ring(F, i):
    """Neighbours of vertex i in order, counter-clockwise around the outward normal.

    With faces counter-clockwise seen from outside, each face ``(i, a, b)``
    (rotated so i comes first) takes the ring from ``a`` to ``b``, and the
    next face around i is the one containing ``(i, b, .)``.

    * interior vertex of valence k: k neighbours; the ring starts at the
      second vertex of the lowest-numbered face at i;
    * boundary vertex with k faces: k + 1 neighbours from one boundary
      neighbour to the other (the first is the end of the boundary edge
      leaving i, the last the start of the one entering i);
    * unreferenced vertex: an empty array.

    O(m) per call (one scan of F).

    Parameters
    ----------
    F : (m, 3) int64
    i : int

    Returns
    -------
    (k,) int64

    Raises
    ------
    MeshError
        ``i`` out of range, or the faces at ``i`` do not form a single
        consistently oriented fan (non-manifold vertex, non-manifold edge or
        inconsistent orientation at i).
    """
    F = as_faces(F)
    i = int(i)
    if i < 0:
        raise MeshError(f"one_ring: vertex index {i} is negative")
    rows, cols = np.nonzero(F == i)
    if len(rows) == 0:
        return np.zeros(0, np.int64)
    a = F[rows, (cols + 1) % 3]
    b = F[rows, (cols + 2) % 3]
    if len(np.unique(a)) < len(a) or len(np.unique(b)) < len(b):
        raise MeshError(
            f"one_ring: vertex {i} is not a manifold vertex with consistent orientation: an edge at it is "
            f"traversed twice in one direction by faces {format_indices(rows)}"
        )
    succ = dict(zip(a.tolist(), b.tolist()))
    starts = sorted(set(a.tolist()) - set(b.tolist()))
    if len(starts) > 1:
        raise MeshError(
            f"one_ring: vertex {i} is non-manifold: its faces {format_indices(rows)} form {len(starts)} separate fans"
        )
    start = starts[0] if starts else int(a[0])
    ring = [start]
    v = succ.get(start)
    while v is not None and v != start:
        ring.append(v)
        v = succ.get(v)
    visited_faces = len(ring) - (0 if v == start else 1)
    if visited_faces != len(rows):
        raise MeshError(
            f"one_ring: vertex {i} is non-manifold: its faces {format_indices(rows)} form more than one fan "
            f"(the fan from neighbour {start} covers {visited_faces} of {len(rows)} faces)"
        )
    return np.asarray(ring, dtype=np.int64)


def euler_characteristic(V, F):
    """Euler characteristic ``chi = V - E + F`` of the surface the faces form.

    Only vertices used by at least one face are counted (an unreferenced
    vertex is not part of the surface), so a closed sphere gives 2, a torus
    0 and a disk 1, whatever stray vertices the file holds.

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64

    Returns
    -------
    int
    """
    V, F = as_mesh(V, F)
    return Topology(F, len(V)).euler_characteristic()


def connected_components(F, n=None):
    """Label of the connected component of each vertex (faces linked by shared vertices).

    Components are numbered 0, 1, ... in the order of their smallest vertex
    index; unreferenced vertices get label -1. The number of components is
    ``labels.max() + 1``.

    Parameters
    ----------
    F : (m, 3) int64
    n : int, optional
        Number of vertices; defaults to ``F.max() + 1``.

    Returns
    -------
    labels : (n,) int64
    """
    F = as_faces(F, n)
    return Topology(F, _nverts(F, n)).vertex_components()


def vertex_face_adjacency(F, n=None):
    """Sparse (n, m) incidence matrix, ``A[i, f] = 1`` when vertex i is a corner of face f.

    Returns a ``scipy.sparse.csr_matrix`` of int8; ``A @ x`` sums a per-face
    quantity ``x`` over the faces at each vertex, ``A.sum(axis=1)`` counts them.
    """
    F = as_faces(F, n)
    n = _nverts(F, n)
    m = len(F)
    return sp.csr_matrix((np.ones(3 * m, np.int8), (F.ravel(), np.repeat(np.arange(m), 3))), shape=(n, m))


def edge_face_counts(F, n=None):
    """Unique edges (e, 2) int64 (smaller index first, lexicographic) and the faces at each (e,) int64.

    A counting sort by sparse assembly: the fast path when only the counts are
    needed (curvature's boundary rule). O(n + m).
    """
    F = as_faces(F, n)
    n = _nverts(F, n)
    index = np.int32 if n < np.iinfo(np.int32).max else np.int64
    I, J = F.ravel(), F[:, [1, 2, 0]].ravel()
    lo, hi = np.minimum(I, J).astype(index), np.maximum(I, J).astype(index)
    counts = sp.csr_matrix((np.ones(len(lo), np.int32), (lo, hi)), shape=(n, n))  # duplicates summed
    counts.sort_indices()
    rows = np.repeat(np.arange(n, dtype=np.int64), np.diff(counts.indptr))
    return np.stack([rows, counts.indices.astype(np.int64)], axis=1), counts.data.astype(np.int64)


#: faces per block in :func:`unpaired_vertices` (a few MB of per-corner temporaries at a time)
PROBE_BLOCK = 1 << 17


def unpaired_vertices(F, n=None, block=PROBE_BLOCK):
    """Boolean (n,): vertices whose half-edges do not pair up, the only candidates for a boundary.

    Around a vertex i of a closed, consistently oriented fan, each neighbour j
    is the next corner of one triangle (half-edge ``i -> j``) and the previous
    corner of another (``j -> i``), so ``sum (next - prev)`` and ``sum (next^2
    - prev^2)`` over the corners at i are both 0. An edge of one triangle, of
    three, or of two with opposite orientations leaves a non-zero difference
    ``d_j`` at its ends, and two probes that vanish together need at least
    four such neighbours whose indices balance in both sums (three boundary
    fans at one vertex, at the least). The sums are exact integers in float64
    up to 2^22 vertices; above that every vertex is a candidate. Faces are
    summed block by block: memory of one block, not of every corner.
    """
    F = as_faces(F, n)
    return _unpaired(F, _nverts(F, n), block)


def _unpaired(F, n, block=PROBE_BLOCK):
    """:func:`unpaired_vertices` of checked faces."""
    if n > 1 << 22:
        return np.ones(n, dtype=bool)
    first, second = np.zeros(n), np.zeros(n)
    for start in range(0, len(F), block):
        Ft = F[start : start + block].T  # (3, b): corner rows
        corner = Ft.ravel()
        nxt = Ft[[1, 2, 0]].ravel().astype(np.float64)
        prv = Ft[[2, 0, 1]].ravel().astype(np.float64)
        d = nxt - prv
        np.add.at(first, corner, d)  # in place: no (n,) array per block
        np.add.at(second, corner, d * (nxt + prv))
    return (first != 0) | (second != 0)


def boundary_edge_counts(F, n=None):
    """Number of boundary edges (edges of exactly one face) at each vertex, (n,) int64.

    geomlib's one boundary rule: a vertex is on the boundary when this count is positive
    (:func:`boundary_vertices`; ``geomlib.lessons.curvature.boundary_mask``; the curvature
    functions' ``boundary=`` value and the smoothers' ``boundary_condition="fixed"`` apply there).

    0 at interior vertices, 2 at a simple boundary vertex, 2k where k open
    fans meet (a non-manifold "bow-tie"). Edges are counted only around the
    vertices whose half-edges do not pair up (:func:`unpaired_vertices`): on a
    closed mesh nothing is sorted.
    """
    E, count = edges_at_unpaired_vertices(F, n)
    return np.bincount(E[count == 1].ravel(), minlength=_nverts(np.asarray(F), n)).astype(np.int64)


def edges_at_unpaired_vertices(F, n=None):
    """:func:`edge_face_counts` restricted to the edges at :func:`unpaired_vertices`: every
    boundary edge, and every edge of three or more faces that unbalances the orientation."""
    F = as_faces(F, n)
    n = _nverts(F, n)
    unpaired = _unpaired(F, n)
    if not unpaired.any():  # closed and consistently oriented: no boundary, nothing to sort
        return np.zeros((0, 2), dtype=np.int64), np.zeros(0, dtype=np.int64)
    at_unpaired = unpaired[F].any(axis=1)
    E, count = edge_face_counts(F[at_unpaired], n)
    keep = unpaired[E].any(axis=1)  # every face of these edges was counted; an edge between two others was not
    return E[keep], count[keep]


def unreferenced_vertices(F, n):
    """Indices (k,) int64 of the vertices that no face uses (e.g. left over in a scan's file), sorted."""
    F = as_faces(F, n)
    return np.flatnonzero(np.bincount(F.ravel(), minlength=int(n)) == 0)


def non_manifold_edges(F, n=None):
    """Edges (k, 2) int64 that belong to three or more faces (smaller index first, lexicographic)."""
    E, count = edge_face_counts(F, n)
    return E[count > 2]
