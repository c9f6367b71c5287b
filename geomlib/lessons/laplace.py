"""Lesson (notebooks 01 and 03): the discrete Laplace-Beltrami operator Delta = M^-1 C.

The convention of the whole workbook:

* ``C`` is symmetric, negative semidefinite, its rows sum to zero. Off the
  diagonal ``C_ij = 1/2 (cot alpha_ij + cot beta_ij)`` for the cotangent
  operator (Pinkall and Polthier 1993; Meyer et al. 2003) and ``C_ij = 1`` for
  the uniform (graph) operator, for every edge ij; ``C_ii = -sum_j C_ij``.
* ``M`` is diagonal: the vertex area ``A_i`` for the cotangent operator (a
  third of the incident triangle areas, or the mixed Voronoi area of Meyer et
  al. 2003) and the valence for the uniform operator.
* ``Delta = M^-1 C``, so that ``Delta x = -2 H n`` with ``n`` the outward unit
  normal and ``H > 0`` on a sphere.

Policy for bad triangles (never a NaN or an infinity in ``M`` or ``C``):

* Zero-area triangles (``2 A <= ZERO_AREA_RTOL * longest edge^2``, the test of
  :func:`geomlib.mesh.validate.is_zero_area`) have no angles. They add nothing to
  the cotangent ``C`` or to ``M``, and a :class:`~geomlib.mesh.errors.MeshWarning`
  names them. The uniform operator is combinatorial: their edges still count.
* Needle triangles (small but non-zero area) keep their exact cotangents:
  large (at most ``1 / ZERO_AREA_RTOL``) but finite. Clamping them would break
  ``C x = 0`` for linear functions on flat regions.
* A vertex in no triangle of non-zero area has a zero row in ``C`` and a zero
  in ``M``: ``Delta`` is undefined there, and the functions that divide by
  ``M`` say so.
* A non-manifold edge (three or more triangles) gets the sum of all its
  opposite cotangents: ``C`` stays a sum of per-triangle NSD matrices.

Names: a function called ``*_laplacian`` returns the pair ``(M, C)``
(:func:`laplacian`, :func:`uniform_laplacian`, and the ``cotangent_laplacian``
a learner writes in notebook 03); one called ``*_matrix`` or ``*_areas``
returns one matrix or one vector (:func:`cotangent_matrix`, :func:`vertex_areas`).

Validation: each public function checks its mesh once, at its door
(:func:`geomlib.mesh.validate.as_mesh`), and measures its faces once
(:class:`FaceGeometry`); the functions it composes take that record as ``faces=``
and read (V, F) as checked. :func:`assemble_laplacian` is :func:`laplacian` for a
checked mesh, the one the operator and the curvature lessons compose.
"""

import warnings
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from ..mesh.errors import MeshWarning, format_indices
from ..mesh.geometry import FACE_BLOCK, corner_positions, cross, face_blocks
from ..mesh.topology import edges
from ..mesh.validate import as_faces, as_mesh, check_choice, is_zero_area

__all__ = [
    "laplacian",
    "assemble_laplacian",
    "graph_laplacian",
    "FaceGeometry",
    "uniform_laplacian",
    "cotangent_matrix",
    "intrinsic_cotangent_matrix",
    "edge_lengths",
    "vertex_areas",
    "barycentric_areas",
    "mixed_areas",
    "voronoi_pieces",
    "face_geometry",
    "uniform_adjacency",
    "WEIGHTS",
    "AREAS",
]

WEIGHTS = ("cotan", "uniform")
AREAS = ("barycentric", "mixed")

# the corners (j, k) that follow corner i = 0, 1, 2 counter-clockwise
NEXT, PREV = [1, 2, 0], [2, 0, 1]


def check_options(weights=None, area=None):
    """Raise MeshError for a ``weights`` or ``area`` that geomlib does not know (None: not checked)."""
    if weights is not None:
        check_choice("weights", weights, WEIGHTS)
    if area is not None:
        check_choice("area", area, AREAS)


class FaceGeometry(NamedTuple):
    """Per face of a checked mesh: what the cotangent Laplacian and the vertex areas read, measured once.

    Corner ``i`` of face ``(v0, v1, v2)`` sits opposite the edge ``e_i = v_k - v_j``
    (``j, k`` the next two corners). A public call measures it once at its door
    (:meth:`of`, after :func:`geomlib.mesh.validate.as_mesh`) and hands it to the
    functions it composes as ``faces=``.

    Fields
    ------
    l2 : (m, 3) float64
        ``l2[f, i] = |e_i|^2`` (length^2).
    dblA : (m,) float64
        ``2 A_f = |(v1 - v0) x (v2 - v0)|`` (length^2).
    cot : (m, 3) float64
        ``cot theta_i = <e_j, -e_k> / 2A = (l_j^2 + l_k^2 - l_i^2) / (4 A)``
        (law of cosines over the cross product); 0 on zero-area faces.
    degenerate : (m,) bool
        Zero-area faces (:func:`geomlib.mesh.validate.is_zero_area`).
    """

    l2: np.ndarray
    dblA: np.ndarray
    cot: np.ndarray
    degenerate: np.ndarray

    @classmethod
    def of(cls, V, F):
        """The record of a checked (V, F) (as ``as_mesh`` returns them), measured block by block.

        Only one block's corner temporaries exist at a time (:func:`blocks`): at 655k vertices
        tens of MB instead of hundreds.
        """
        if len(F) <= FACE_BLOCK:
            return cls(*corner_geometry(*corner_positions(V, F)))
        parts = [faces for _, faces in cls.blocks(V, F)]
        return cls(*(np.concatenate(field) for field in zip(*parts)))

    @classmethod
    def blocks(cls, V, F):
        """``(block, record of block)`` for each of ``geomlib.mesh.geometry.face_blocks(F)`` (checked V, F)."""
        Vt = np.ascontiguousarray(V.T).T  # V, transposed once: corner_positions then copies nothing per block
        for block in face_blocks(F):
            yield block, cls(*corner_geometry(*corner_positions(Vt, block)))


def face_geometry(V, F):
    """The :class:`FaceGeometry` of (V, F): squared edge lengths, twice the areas, corner cotangents, zero-area flags.

    Unpacks as ``l2, dblA, cot, degenerate = face_geometry(V, F)``; see :class:`FaceGeometry`
    for the shapes and units.
    """
    V, F = as_mesh(V, F)
    return FaceGeometry.of(V, F)


def corner_geometry(v0, v1, v2):
    """:class:`FaceGeometry`'s fields from the (3, m) coordinate rows of the corners (unchecked input)."""
    e = (v2 - v1, v0 - v2, v1 - v0)  # e_i = v_k - v_j, the edge opposite corner i
    l2 = np.stack([np.einsum("cf,cf->f", ei, ei) for ei in e])  # |e_i|^2, (3, m)
    N2 = cross(e[1], e[2])  # (v0 - v2) x (v1 - v0) = (v1 - v0) x (v2 - v0) = 2 A n
    dblA = np.sqrt(np.einsum("cf,cf->f", N2, N2))
    degenerate = is_zero_area(dblA, l2.max(axis=0))
    cot = (0.5 * l2.sum(axis=0) - l2) / np.where(degenerate, 1.0, dblA)  # <e_j, -e_k> / 2A
    cot[:, degenerate] = 0.0
    # one row per face for the reader; the (3, m) arrays underneath keep each corner contiguous
    return l2.T, dblA, cot.T, degenerate


def warn_zero_area(degenerate, stacklevel=3):
    """One MeshWarning naming the zero-area faces (``degenerate``, (m,) bool), if there are any."""
    if degenerate.any():
        idx = np.flatnonzero(degenerate)
        warnings.warn(
            f"{len(idx)} zero-area triangle(s) contribute nothing to the cotangent Laplacian "
            f"and the vertex areas: faces {format_indices(idx)}",
            MeshWarning,
            stacklevel=stacklevel,
        )


def uniform_laplacian(V, F):
    """(M, C) of the uniform (graph) Laplacian: C_ij = 1 on every edge, C_ii = -valence, M = diag(valence).

    C is symmetric, NSD, rows sum to zero; ``M^-1 C x`` is the mean of the
    neighbours minus ``x_i`` (the weights of Taubin 1995; the name "umbrella" operator is Kobbelt et
    al. 1998's). No metric:
    zero-area faces count like any other.

    Returns
    -------
    M : (n, n) scipy.sparse DIA float64, the valences
    C : (n, n) scipy.sparse CSR float64
    """
    V, F = as_mesh(V, F)
    return graph_laplacian(len(V), F)


def graph_laplacian(n, F):
    """:func:`uniform_laplacian` of n vertices and checked faces F: ``(diag(valence), C)``."""
    E = edges(F)  # each edge ij once, i < j
    ones = np.ones(len(E))
    adjacency = sp.coo_matrix(
        (np.r_[ones, ones], (np.r_[E[:, 0], E[:, 1]], np.r_[E[:, 1], E[:, 0]])), shape=(n, n)
    ).tocsr()
    valence = np.diff(adjacency.indptr).astype(np.float64)
    C = (adjacency - sp.diags(valence)).tocsr()
    C.sort_indices()
    return sp.diags(valence), C


def edge_lengths(V, F):
    """(m, 3) float64: ``l[f, i]`` is the length of the edge of face f opposite its corner i (length).

    Everything the cotangent Laplacian needs of the geometry (:func:`intrinsic_cotangent_matrix`).
    """
    V, F = as_mesh(V, F)
    return np.sqrt(FaceGeometry.of(V, F).l2)


def intrinsic_cotangent_matrix(l, F, n=None, dblA=None):
    """C (n, n) CSR from the edge lengths alone: ``C_ij = 1/2 (cot alpha_ij + cot beta_ij)``, ``C_ii = -sum_j C_ij``.

    ``l`` (m, 3): ``l[f, i]`` the length of the edge opposite corner i of face f (:func:`edge_lengths`);
    ``n``: the vertex count (default ``F.max() + 1``). Heron's formula gives the area A of each face,
    the law of cosines its corner cotangents ``cot theta_i = (l_j^2 + l_k^2 - l_i^2) / (4 A)``; corner
    i adds ``1/2 cot theta_i`` to the edge (j, k) opposite it, so a boundary edge, with one triangle,
    gets ``1/2 cot alpha_ij``. C is symmetric, negative semidefinite, rows sum to zero. Zero-area
    triangles add nothing (MeshWarning). Jacobson's intrinsic ``cotmatrix``; Pinkall and Polthier 1993.

    ``dblA`` (m,): twice the face areas, when the caller has them from the positions. A needle's
    area is exact from a cross product, while its rounded lengths can make Heron's vanish
    (sides 1, 1 and 2 for a height of 1e-9): :func:`cotangent_matrix` passes it.
    """
    l, F = np.asarray(l, dtype=np.float64), np.asarray(F)
    n = int(F.max()) + 1 if n is None else n
    if dblA is None:
        a, b, c = np.sort(l, axis=1)[:, ::-1].T  # a >= b >= c: Heron in Kahan's order, stable for thin faces
        A = 0.25 * np.sqrt(np.maximum((a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c)), 0.0))
    else:
        A = 0.5 * np.asarray(dblA, dtype=np.float64)
    l2 = l**2
    degenerate = is_zero_area(2 * A, l2.max(axis=1))
    warn_zero_area(degenerate)
    cot = (l2[:, NEXT] + l2[:, PREV] - l2) / (4 * np.where(degenerate, 1.0, A)[:, None])  # law of cosines / sine
    cot[degenerate] = 0.0
    index = np.int32 if n < 2**31 - 1 else np.int64
    j, k = F[:, NEXT].T.ravel().astype(index), F[:, PREV].T.ravel().astype(index)  # edge (j, k) opposite i
    w = 0.5 * cot.T.ravel()  # gets 1/2 cot theta_i
    diagonal = -(np.bincount(j, w, minlength=n) + np.bincount(k, w, minlength=n))  # rows sum to zero
    d = np.arange(n, dtype=index)
    rows, cols = np.concatenate([j, k, d]), np.concatenate([k, j, d])
    return sp.coo_matrix((np.concatenate([w, w, diagonal]), (rows, cols)), shape=(n, n)).tocsr()


def cotangent_matrix(V, F):
    """C (n, n) CSR: ``C_ij = 1/2 (cot alpha_ij + cot beta_ij)``, ``C_ii = -sum_j C_ij``; NSD.

    :func:`intrinsic_cotangent_matrix` of the mesh's edge lengths, with the face areas from
    cross products: the cotangents depend on the lengths alone. A boundary edge has one triangle, so one angle:
    ``C_ij = 1/2 cot alpha_ij``. Zero-area triangles add nothing (MeshWarning).
    Pinkall and Polthier 1993; Meyer et al. 2003, eq. (8).
    """
    V, F = as_mesh(V, F)
    faces = FaceGeometry.of(V, F)
    return intrinsic_cotangent_matrix(np.sqrt(faces.l2), F, len(V), faces.dblA)


def barycentric_areas(V, F, faces=None):
    """(n,) vertex areas A_i in length^2: a third of the area of every incident triangle.

    Zero-area triangles add 0 (MeshWarning), so a vertex in no other triangle
    has area 0. Sums to the surface area. ``faces``: the :class:`FaceGeometry` of (V, F)
    when the caller has checked (V, F) and measured it (then no warning: the caller gives it).
    """
    if faces is None:  # a call of its own: its door
        V, F = as_mesh(V, F)
        faces = FaceGeometry.of(V, F)
        warn_zero_area(faces.degenerate)
    third = np.where(faces.degenerate, 0.0, faces.dblA / 6.0)
    return np.bincount(F.ravel(), np.repeat(third, 3), minlength=len(V))  # to each of the 3 corners


def voronoi_pieces(V, F, faces=None):
    """(m, 3) Voronoi piece of each corner, ``1/8 (|e_j|^2 cot theta_j + |e_k|^2 cot theta_k)``, without the obtuse rule.

    The circumcentric region of corner i inside its triangle, a signed area in length^2: it
    leaves the triangle when the triangle is obtuse, and is negative at corner i exactly when
    the other two angles differ by more than 90 degrees (notebook 03, section 2).
    ``faces`` as in :func:`barycentric_areas`.
    """
    if faces is None:
        V, F = as_mesh(V, F)
        faces = FaceGeometry.of(V, F)
    lc = faces.l2 * faces.cot
    return (lc[:, NEXT] + lc[:, PREV]) / 8.0


def mixed_areas(V, F, faces=None):
    """(n,) mixed Voronoi vertex areas A_i in length^2 (Meyer et al. 2003, Fig. 4).

    Per triangle and corner i (j, k the other two corners, A the triangle area):

    * no obtuse angle: the Voronoi part ``1/8 (|e_j|^2 cot theta_j + |e_k|^2 cot theta_k)``,
      the two edges at i weighted by the cotangents of the angles opposite them;
    * obtuse at i: ``A / 2`` (the Voronoi region would leave the triangle);
    * obtuse at another corner: ``A / 4``.

    Sums to the surface area. Zero-area triangles add 0 (MeshWarning).
    ``faces`` as in :func:`barycentric_areas`.
    """
    if faces is None:  # a call of its own: its door
        V, F = as_mesh(V, F)
        faces = FaceGeometry.of(V, F)
        warn_zero_area(faces.degenerate)
    A = 0.5 * faces.dblA[:, None]
    voronoi = voronoi_pieces(V, F, faces)
    obtuse = faces.cot < 0  # cot theta < 0 <=> theta > pi/2
    obtuse_triangle = obtuse.any(axis=1, keepdims=True)
    per_corner = np.where(obtuse_triangle, np.where(obtuse, A / 2.0, A / 4.0), voronoi)
    per_corner[faces.degenerate] = 0.0
    return np.bincount(F.T.ravel(), per_corner.T.ravel(), minlength=len(V))


def vertex_areas(V, F, area="barycentric", faces=None):
    """(n,) vertex areas A_i in length^2, the diagonal of the cotangent M.

    ``area="barycentric"``: :func:`barycentric_areas`; ``"mixed"``:
    :func:`mixed_areas` (Meyer et al. 2003). Both sum to the surface area.
    ``faces`` as in :func:`barycentric_areas`.
    """
    check_options(area=area)
    return (barycentric_areas if area == "barycentric" else mixed_areas)(V, F, faces)


def laplacian(V, F, weights="cotan", area="barycentric"):
    """The Laplace-Beltrami operator ``Delta = M^-1 C`` as the pair (M, C); C is NSD.

    Parameters
    ----------
    V : (n, 3) float64
        Vertex positions.
    F : (m, 3) int64
        Triangles, counter-clockwise seen from outside.
    weights : {"cotan", "uniform"}
        :func:`cotangent_matrix` with vertex areas, or :func:`uniform_laplacian`
        (then ``area`` is ignored and M holds the valences).
    area : {"barycentric", "mixed"}
        The vertex areas of M (:func:`vertex_areas`).

    Returns
    -------
    M : (n, n) scipy.sparse DIA float64
    C : (n, n) scipy.sparse CSR float64
        Symmetric, negative semidefinite, rows summing to zero. With this sign
        ``Delta x = -2 H n`` for the outward unit normal n, H > 0 on a sphere.

    Raises
    ------
    MeshError
        Unknown ``weights`` or ``area``; malformed V or F (:func:`geomlib.mesh.validate.as_mesh`).

    Notes
    -----
    Boundary edges have one triangle and get ``1/2 cot alpha``: the operator
    with natural (Neumann) boundary conditions. See the module docstring for
    zero-area and needle triangles and isolated vertices.
    Pinkall and Polthier 1993; Desbrun et al. 1999; Meyer et al. 2003.
    """
    check_options(weights, area)
    V, F = as_mesh(V, F)
    return assemble_laplacian(V, F, weights, area)


def assemble_laplacian(V, F, weights="cotan", area="barycentric"):
    """:func:`laplacian` of a checked mesh ((V, F) as ``as_mesh`` returns them, options checked)."""
    if weights == "uniform":
        return graph_laplacian(len(V), F)
    faces = FaceGeometry.of(V, F)  # once for both matrices
    C = intrinsic_cotangent_matrix(np.sqrt(faces.l2), F, len(V), faces.dblA)  # names the zero-area faces, if any
    return sp.diags(vertex_areas(V, F, area, faces)), C


def uniform_adjacency(n, F):
    """Adjacency matrix (n, n) CSR float64 with 1 for every edge ij (each edge once, both directions)."""
    M, C = graph_laplacian(n, as_faces(F, n))
    A = (C + M).tocsr()
    A.eliminate_zeros()
    return A
