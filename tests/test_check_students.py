"""The exercise checks against a corpus of learners' routines, written the way students of this coursework
write them: Python loops over faces with dicts of neighbours, dense numpy, scipy.sparse lil, coo and csr,
np.linalg.eig, boundary handling half done, their own variable names.

Each routine is a complete answer to one auto-graded exercise, right or with the mistakes real students
make (often two at once). A right one must pass its check; a wrong one must fail it, and is named right
when the check's message holds the diagnosis written beside it. The corpus holds the checks to three
measures: no right routine fails, no wrong routine passes, and at least 80 % of the wrong ones are named.
"""

import functools
import re
import types
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from geomlib import boundary_vertices, check, enclosed_volume, implicit_smoothing, laplacian
from geomlib.lessons.curvature import signed_mean_curvature
from geomlib.lessons.laplace import edge_lengths

SEED = 20261128  # the checks' cases, drawn as one run of a class would draw them
NAMED_GOAL = 0.8

CORPUS = []  # (exercise, routine, diagnosis it must get, or None for a right routine)


def student(exercise, named=None):
    """Adds the routine to the corpus: an answer to ``exercise``, right (``named`` None) or with the mistake
    whose diagnosis (a phrase of the check's message) ``named`` gives."""

    def add(fn):
        CORPUS.append((exercise, fn, named))
        return fn

    return add


# ============================================================================ 01 · uniform_laplacian


@student("uniform_laplacian")
def uniform_dict_of_sets(V, F):
    n = len(V)
    nbrs = {i: set() for i in range(n)}
    for f in F:
        for a in range(3):
            i, j = f[a], f[(a + 1) % 3]
            nbrs[i].add(j)
            nbrs[j].add(i)
    C = np.zeros((n, n))
    M = np.zeros((n, n))
    for i in range(n):
        for j in nbrs[i]:
            C[i, j] = 1
        C[i, i] = -len(nbrs[i])
        M[i, i] = len(nbrs[i])
    return M, C


@student("uniform_laplacian")
def uniform_coo(V, F):
    I = np.concatenate([F[:, 0], F[:, 1], F[:, 2], F[:, 1], F[:, 2], F[:, 0]])
    J = np.concatenate([F[:, 1], F[:, 2], F[:, 0], F[:, 0], F[:, 1], F[:, 2]])
    n = V.shape[0]
    adj = sp.coo_matrix((np.ones(len(I)), (I, J)), shape=(n, n)).tocsr()
    adj.data[:] = 1.0  # an edge shared by two faces was summed twice
    deg = np.asarray(adj.sum(axis=1)).ravel()
    return sp.diags(deg), adj - sp.diags(deg)


@student("uniform_laplacian", named="an edge counts once per triangle")
def uniform_lil_counts_faces(V, F):
    n = len(V)
    L = sp.lil_matrix((n, n))
    for tri in F:
        for k in range(3):
            a, b = tri[k], tri[(k + 1) % 3]
            L[a, b] += 1
            L[b, a] += 1
    d = np.array(L.sum(axis=1)).flatten()
    L.setdiag(-d)
    return sp.diags(d), L.tocsr()


@student("uniform_laplacian", named="M holds 1/valence")
def uniform_inverse_mass(V, F):
    n = len(V)
    A = np.zeros((n, n))
    for i, j, k in F:
        A[i, j] = A[j, i] = A[j, k] = A[k, j] = A[k, i] = A[i, k] = 1
    valence = A.sum(1)
    return np.diag(1 / valence), A - np.diag(valence)


@student("uniform_laplacian", named="C holds diag(1/valence)")
def uniform_returns_minv_as_c(V, F):
    # the student's Laplacian is M^-1 C and they hand in its two factors, M^-1 in the second slot
    n = len(V)
    A = np.zeros((n, n))
    for i, j, k in F:
        A[i, j] = A[j, i] = A[j, k] = A[k, j] = A[k, i] = A[i, k] = 1
    deg = A.sum(axis=1)
    return A - np.diag(deg), np.diag(1.0 / deg)


@student("uniform_laplacian", named="(M, C) are swapped")
def uniform_swapped(V, F):
    n = len(V)
    A = sp.lil_matrix((n, n))
    for f in F:
        for a, b in ((0, 1), (1, 2), (2, 0)):
            A[f[a], f[b]] = 1
            A[f[b], f[a]] = 1
    A = A.tocsr()
    D = sp.diags(np.asarray(A.sum(axis=1)).ravel())
    return A - D, D


@student("uniform_laplacian", named="C is already divided by the valence")
def uniform_normalised(V, F):
    n = len(V)
    A = np.zeros((n, n))
    for f in F:
        for a in range(3):
            A[f[a], f[a - 1]] = 1
            A[f[a - 1], f[a]] = 1
    d = A.sum(axis=1)
    L = np.diag(1 / d) @ A - np.eye(n)
    return np.diag(d), L


# ============================================================================ 01 · gaussian_curvature


def _angle(p, q, r):
    """The angle at p of the triangle p, q, r."""
    e1, e2 = q - p, r - p
    return np.arccos(np.clip(e1 @ e2 / (np.linalg.norm(e1) * np.linalg.norm(e2)), -1, 1))


def _boundary_from_edges(F, n):
    count = {}
    for f in F:
        for a in range(3):
            e = tuple(sorted((f[a], f[(a + 1) % 3])))
            count[e] = count.get(e, 0) + 1
    on_boundary = np.zeros(n, dtype=bool)
    for (i, j), c in count.items():
        if c == 1:
            on_boundary[i] = on_boundary[j] = True
    return on_boundary


@student("gaussian_curvature")
def curvature_face_loop(V, F):
    n = len(V)
    angle_sum = np.zeros(n)
    area = np.zeros(n)
    for i, j, k in F:
        angle_sum[i] += _angle(V[i], V[j], V[k])
        angle_sum[j] += _angle(V[j], V[k], V[i])
        angle_sum[k] += _angle(V[k], V[i], V[j])
        A_f = 0.5 * np.linalg.norm(np.cross(V[j] - V[i], V[k] - V[i]))
        for v in (i, j, k):
            area[v] += A_f / 3
    K = (2 * np.pi - angle_sum) / area
    K[_boundary_from_edges(F, n)] = np.nan
    return K


@student("gaussian_curvature")
def curvature_vectorised(V, F):
    n = V.shape[0]
    angles = np.zeros(F.shape)
    for c in range(3):
        a = V[F[:, (c + 1) % 3]] - V[F[:, c]]
        b = V[F[:, (c + 2) % 3]] - V[F[:, c]]
        angles[:, c] = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b))
    dblA = np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    theta = np.bincount(F.ravel(), angles.ravel(), minlength=n)
    Avert = np.bincount(F.ravel(), np.repeat(dblA / 6, 3), minlength=n)
    edges = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    uniq, counts = np.unique(edges, axis=0, return_counts=True)
    bnd = np.unique(uniq[counts == 1])
    K = (2 * np.pi - theta) / Avert
    K[bnd] = np.nan
    return K


@student("gaussian_curvature", named="the angles are in degrees")
def curvature_degrees(V, F):
    n = len(V)
    angle_sum, area = np.zeros(n), np.zeros(n)
    for f in F:
        for c in range(3):
            i, j, k = f[c], f[(c + 1) % 3], f[(c + 2) % 3]
            angle_sum[i] += np.degrees(_angle(V[i], V[j], V[k]))
            area[i] += np.linalg.norm(np.cross(V[j] - V[i], V[k] - V[i])) / 6
    K = (360 - angle_sum) / area
    K[_boundary_from_edges(F, n)] = np.nan
    return K


@student("gaussian_curvature", named="the ring order")
def curvature_index_order_ring(V, F):
    # angles between consecutive neighbours, the neighbours taken in index order (not around the vertex)
    n = len(V)
    neighbours = {i: set() for i in range(n)}
    area = np.zeros(n)
    for i, j, k in F:
        neighbours[i].update((j, k))
        neighbours[j].update((k, i))
        neighbours[k].update((i, j))
        A = 0.5 * np.linalg.norm(np.cross(V[j] - V[i], V[k] - V[i]))
        area[[i, j, k]] += A / 3
    bnd = _boundary_from_edges(F, n)
    K = np.full(n, np.nan)
    for i in range(n):
        if bnd[i]:
            continue
        ring = sorted(neighbours[i])
        total = 0.0
        for a in range(len(ring)):
            total += _angle(V[i], V[ring[a]], V[ring[(a + 1) % len(ring)]])
        K[i] = (2 * np.pi - total) / area[i]
    return K


@student("gaussian_curvature", named="the interior formula is applied at boundary vertices")
def curvature_no_boundary(V, F):
    n = len(V)
    angle_sum, area = np.zeros(n), np.zeros(n)
    for f in F:
        p = V[f]
        A = np.linalg.norm(np.cross(p[1] - p[0], p[2] - p[0])) / 2
        for c in range(3):
            angle_sum[f[c]] += _angle(p[c], p[(c + 1) % 3], p[(c + 2) % 3])
            area[f[c]] += A / 3
    return (2 * np.pi - angle_sum) / area


@student("gaussian_curvature", named="boundary vertices have a value")
def curvature_boundary_zero(V, F):
    K = curvature_face_loop(V, F)
    K[np.isnan(K)] = 0.0
    return K


@student("gaussian_curvature", named="full area of its incident triangles")
def curvature_full_area(V, F):
    n = len(V)
    angle_sum, area = np.zeros(n), np.zeros(n)
    for i, j, k in F:
        A_f = 0.5 * np.linalg.norm(np.cross(V[j] - V[i], V[k] - V[i]))
        for a, b, c in ((i, j, k), (j, k, i), (k, i, j)):
            angle_sum[a] += _angle(V[a], V[b], V[c])
            area[a] += A_f
    K = (2 * np.pi - angle_sum) / area
    K[_boundary_from_edges(F, n)] = np.nan
    return K


# ============================================================================ 01 · mean_curvature


def _vertex_normals(V, F, unit_faces=False):
    N = np.zeros_like(V, dtype=float)
    for i, j, k in F:
        n_f = np.cross(V[j] - V[i], V[k] - V[i])
        if unit_faces:
            n_f = n_f / np.linalg.norm(n_f)
        N[[i, j, k]] += n_f
    return N


@student("mean_curvature")
def mean_curvature_loop(V, F, M, C):
    N = _vertex_normals(V, F)
    N /= np.linalg.norm(N, axis=1)[:, None]
    lap = (C @ V) / M.diagonal()[:, None]
    H = np.array([-0.5 * lap[i] @ N[i] for i in range(len(V))])
    H[_boundary_from_edges(F, len(V))] = np.nan
    return H


@student("mean_curvature")
def mean_curvature_vectorised(V, F, M, C):
    cr = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    normals = np.zeros((len(V), 3))
    for c in range(3):
        np.add.at(normals, F[:, c], cr)
    normals = normals / np.linalg.norm(normals, axis=1, keepdims=True)
    Minv = sp.diags(1 / M.diagonal())
    H = -0.5 * np.sum((Minv @ C @ V) * normals, axis=1)
    edges = np.sort(np.vstack([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    e, cnt = np.unique(edges, axis=0, return_counts=True)
    H[np.unique(e[cnt == 1])] = np.nan
    return H


@student("mean_curvature", named="wrong sign")
def mean_curvature_no_minus(V, F, M, C):
    N = _vertex_normals(V, F)
    N = N / np.linalg.norm(N, axis=1)[:, None]
    H = 0.5 * np.einsum("ij,ij->i", (C @ V) / M.diagonal()[:, None], N)
    H[_boundary_from_edges(F, len(V))] = np.nan
    return H


@student("mean_curvature", named="the normals are not normalised")
def mean_curvature_raw_normals(V, F, M, C):
    N = _vertex_normals(V, F)
    H = -0.5 * np.einsum("ij,ij->i", (C @ V) / M.diagonal()[:, None], N)
    H[_boundary_from_edges(F, len(V))] = np.nan
    return H


@student("mean_curvature", named="no boundary rule")
def mean_curvature_everywhere(V, F, M, C):
    N = _vertex_normals(V, F)
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    return -0.5 * np.einsum("ij,ij->i", (C @ V) / M.diagonal()[:, None], N)


@student("mean_curvature", named="M^-1 is missing")
def mean_curvature_no_mass(V, F, M, C):
    N = _vertex_normals(V, F, unit_faces=False)
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    H = -0.5 * np.sum((C @ V) * N, axis=1)
    H[_boundary_from_edges(F, len(V))] = np.nan
    return H


# ============================================================================ 02 · fundamental_forms


def _forms(a, b, c, u, v, sign=1, unit=True):
    import sympy as sy

    p = sy.Matrix([a * sy.cos(u) * sy.sin(v), b * sy.sin(u) * sy.sin(v), c * sy.cos(v)])
    pu, pv = p.diff(u), p.diff(v)
    N = pu.cross(pv)
    if unit:
        N = N / sy.sqrt(N.dot(N))
    N = sign * N
    I = sy.Matrix([[pu.dot(pu), pu.dot(pv)], [pv.dot(pu), pv.dot(pv)]])
    II = sy.Matrix([[p.diff(u, 2).dot(N), p.diff(u, v).dot(N)], [p.diff(v, u).dot(N), p.diff(v, 2).dot(N)]])
    return I, II


@student("fundamental_forms")
def forms_sympy(a, b, c, u, v):
    return _forms(a, b, c, u, v)


@student("fundamental_forms")
def forms_six(a, b, c, u, v):
    import sympy as sy

    x = a * sy.cos(u) * sy.sin(v)
    y = b * sy.sin(u) * sy.sin(v)
    z = c * sy.cos(v)
    xu, yu, zu = sy.diff(x, u), sy.diff(y, u), sy.diff(z, u)
    xv, yv, zv = sy.diff(x, v), sy.diff(y, v), sy.diff(z, v)
    E = xu**2 + yu**2 + zu**2
    F_ = xu * xv + yu * yv + zu * zv
    G = xv**2 + yv**2 + zv**2
    n = sy.Matrix([yu * zv - zu * yv, zu * xv - xu * zv, xu * yv - yu * xv])
    n = n / sy.sqrt(n[0] ** 2 + n[1] ** 2 + n[2] ** 2)
    second = [sy.Matrix([sy.diff(w, *d) for w in (x, y, z)]).dot(n) for d in ((u, u), (u, v), (v, v))]
    return E, F_, G, second[0], second[1], second[2]


@student("fundamental_forms", named="the sign of the normal is flipped")
def forms_outward_normal(a, b, c, u, v):
    return _forms(a, b, c, u, v, sign=-1)


@student("fundamental_forms", named="the normal is not normalised")
def forms_unnormalised(a, b, c, u, v):
    return _forms(a, b, c, u, v, unit=False)


# ============================================================================ 02 · normal_curvature


def _numbers(forms, a, b, c, u, v):
    I, II = forms(a, b, c, u, v)
    return [float(x) for x in (I[0, 0], I[0, 1], I[1, 1], II[0, 0], II[0, 1], II[1, 1])]


@student("normal_curvature")
def kappa_tangent(forms, a, b, c, u, v, phi):
    E, F, G, e, f, g = _numbers(forms, a, b, c, u, v)
    W = np.sqrt(E * G - F**2)
    du = np.cos(phi) / np.sqrt(E) - np.sin(phi) * F / (np.sqrt(E) * W)
    dv = np.sin(phi) * np.sqrt(E) / W
    t = np.array([du, dv])
    I = np.array([[E, F], [F, G]])
    II = np.array([[e, f], [f, g]])
    return float(t @ II @ t / (t @ I @ t))


@student("normal_curvature", named="F is ignored in the tangent")
def kappa_orthogonal_tangent(forms, a, b, c, u, v, phi):
    E, F, G, e, f, g = _numbers(forms, a, b, c, u, v)
    du, dv = np.cos(phi) / np.sqrt(E), np.sin(phi) / np.sqrt(G)
    return (e * du**2 + 2 * f * du * dv + g * dv**2) / (E * du**2 + 2 * F * du * dv + G * dv**2)


@student("normal_curvature", named="guard")
def kappa_big_guard(forms, a, b, c, u, v, phi):
    # a guard against a zero denominator, written 1e10 where 1e-10 was meant
    E, F, G, e, f, g = _numbers(forms, a, b, c, u, v)
    W = np.sqrt(E * G - F**2)
    du = np.cos(phi) / np.sqrt(E) - np.sin(phi) * F / (np.sqrt(E) * W)
    dv = np.sin(phi) * np.sqrt(E) / W
    num = e * du**2 + 2 * f * du * dv + g * dv**2
    den = E * du**2 + 2 * F * du * dv + G * dv**2
    return num / max(den, 1e10)


@student("normal_curvature", named="phi is measured in the (u, v) parameter plane")
def kappa_parameter_angle(forms, a, b, c, u, v, phi):
    E, F, G, e, f, g = _numbers(forms, a, b, c, u, v)
    du, dv = np.cos(phi), np.sin(phi)
    return (e * du * du + 2 * f * du * dv + g * dv * dv) / (E * du * du + 2 * F * du * dv + G * dv * dv)


# ============================================================================ 02 · principal_curvatures


@student("principal_curvatures")
def principal_H_K(I, II):
    import sympy as sy

    L = I.inv() * II
    H = L.trace() / 2
    K = II.det() / I.det()
    return H + sy.sqrt(H**2 - K), H - sy.sqrt(H**2 - K)


@student("principal_curvatures")
def principal_characteristic_polynomial(I, II):
    import sympy as sy

    (E, F), (_, G) = I.tolist()
    (e, f), (_, g) = II.tolist()
    # det(II - kappa I) = 0, a quadratic a kappa^2 + b kappa + c
    a = E * G - F**2
    b = -(e * G - 2 * f * F + g * E)
    c = e * g - f**2
    disc = sy.sqrt(b**2 - 4 * a * c)
    return (-b + disc) / (2 * a), (-b - disc) / (2 * a)


@student("principal_curvatures", named="the pair is in the wrong order")
def principal_wrong_order(I, II):
    import sympy as sy

    H = (I.inv() * II).trace() / 2
    K = II.det() / I.det()
    return H - sy.sqrt(H**2 - K), H + sy.sqrt(H**2 - K)


@student("principal_curvatures", named="I is left out")
def principal_of_II(I, II):
    import sympy as sy

    H = II.trace() / 2
    K = II.det()
    return H + sy.sqrt(H * H - K), H - sy.sqrt(H * H - K)


@student("principal_curvatures", named="not half of it")
def principal_full_trace(I, II):
    import sympy as sy

    H = (I.inv() * II).trace()
    K = II.det() / I.det()
    return H + sy.sqrt(H**2 - K), H - sy.sqrt(H**2 - K)


# ============================================================================ 03 · cotangent_matrix


def _cot_weights(l, dtype=float):
    l = l.astype(dtype)
    s = l.sum(axis=1) / 2
    A = np.sqrt(s * (s - l[:, 0]) * (s - l[:, 1]) * (s - l[:, 2]))
    l2 = l**2
    cot = np.empty_like(l)
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        cot[:, i] = (l2[:, j] + l2[:, k] - l2[:, i]) / (4 * A)
    return cot


@student("cotangent_matrix")
def cotmatrix_lil(l, F):
    n = F.max() + 1
    cot = _cot_weights(l)
    C = sp.lil_matrix((n, n))
    for f in range(len(F)):
        for i in range(3):
            j, k = F[f, (i + 1) % 3], F[f, (i + 2) % 3]
            C[j, k] += cot[f, i] / 2
            C[k, j] += cot[f, i] / 2
    C = C.tocsr()
    return C - sp.diags(np.asarray(C.sum(axis=1)).ravel())


@student("cotangent_matrix")
def cotmatrix_loops_angles(l, F):
    n = int(np.max(F)) + 1
    C = np.zeros((n, n))
    for f, (a, b, c) in zip(F, l):
        # corner angles from the law of cosines, a opposite f[0]
        alpha = np.arccos((b * b + c * c - a * a) / (2 * b * c))
        beta = np.arccos((a * a + c * c - b * b) / (2 * a * c))
        gamma = np.pi - alpha - beta
        for ang, (j, k) in ((alpha, (f[1], f[2])), (beta, (f[2], f[0])), (gamma, (f[0], f[1]))):
            w = 0.5 / np.tan(ang)
            C[j, k] += w
            C[k, j] += w
    C -= np.diag(C.sum(axis=1))
    return C


@student("cotangent_matrix")  # right to float32 precision: within the check's tolerance, so accepted
def cotmatrix_float32(l, F):
    n = F.max() + 1
    cot = _cot_weights(l, dtype=np.float32)
    rows = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])
    cols = np.concatenate([F[:, 2], F[:, 0], F[:, 1]])
    w = 0.5 * np.concatenate([cot[:, 0], cot[:, 1], cot[:, 2]])
    C = sp.coo_matrix((w, (rows, cols)), shape=(n, n), dtype=np.float32)
    C = C + C.T
    return (C - sp.diags(np.asarray(C.sum(axis=1)).ravel())).astype(np.float32)


@student("cotangent_matrix", named="the angles are in degrees")
def cotmatrix_degrees_tan(l, F):
    n = F.max() + 1
    C = np.zeros((n, n))
    for f in range(len(F)):
        a, b, c = l[f]
        angles = np.degrees(
            [
                np.arccos((b**2 + c**2 - a**2) / (2 * b * c)),
                np.arccos((a**2 + c**2 - b**2) / (2 * a * c)),
                np.arccos((a**2 + b**2 - c**2) / (2 * a * b)),
            ]
        )
        for i in range(3):
            j, k = F[f, (i + 1) % 3], F[f, (i + 2) % 3]
            C[j, k] += 0.5 / np.tan(angles[i])
            C[k, j] += 0.5 / np.tan(angles[i])
    return C - np.diag(C.sum(1))


@student("cotangent_matrix", named="the factor 1/2 is missing")
def cotmatrix_no_half(l, F):
    n = F.max() + 1
    cot = _cot_weights(l)
    C = np.zeros((n, n))
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        np.add.at(C, (F[:, j], F[:, k]), cot[:, i])
        np.add.at(C, (F[:, k], F[:, j]), cot[:, i])
    np.fill_diagonal(C, -C.sum(axis=1))
    return C


@student("cotangent_matrix", named="the diagonal of C is missing")
def cotmatrix_no_diagonal(l, F):
    n = F.max() + 1
    cot = _cot_weights(l)
    C = sp.lil_matrix((n, n))
    for f, tri in enumerate(F):
        for i in range(3):
            C[tri[(i + 1) % 3], tri[(i + 2) % 3]] += 0.5 * cot[f, i]
            C[tri[(i + 2) % 3], tri[(i + 1) % 3]] += 0.5 * cot[f, i]
    return C.tocsr()


# ============================================================================ 03 · mixed_areas


def _corner_angles(V, F):
    ang = np.zeros(F.shape)
    for c in range(3):
        a = V[F[:, (c + 1) % 3]] - V[F[:, c]]
        b = V[F[:, (c + 2) % 3]] - V[F[:, c]]
        cosang = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
        ang[:, c] = np.arccos(np.clip(cosang, -1, 1))
    return ang


@student("mixed_areas")
def mixed_loop(V, F):
    n = len(V)
    A_mixed = np.zeros(n)
    l = edge_lengths(V, F)
    ang = _corner_angles(V, F)
    for f in range(len(F)):
        area = 0.5 * np.linalg.norm(np.cross(V[F[f, 1]] - V[F[f, 0]], V[F[f, 2]] - V[F[f, 0]]))
        for c in range(3):
            i = F[f, c]
            if ang[f].max() > np.pi / 2:  # obtuse triangle
                A_mixed[i] += area / 2 if ang[f, c] > np.pi / 2 else area / 4
            else:
                j, k = (c + 1) % 3, (c + 2) % 3
                # edge i-j is opposite corner k, edge i-k opposite corner j
                A_mixed[i] += (l[f, k] ** 2 / np.tan(ang[f, k]) + l[f, j] ** 2 / np.tan(ang[f, j])) / 8
    return A_mixed


@student("mixed_areas", named="the obtuse rule is missing")
def mixed_no_obtuse(V, F):
    n = len(V)
    A = np.zeros(n)
    l2 = edge_lengths(V, F) ** 2
    cot = 1 / np.tan(_corner_angles(V, F))
    for c in range(3):
        j, k = (c + 1) % 3, (c + 2) % 3
        np.add.at(A, F[:, c], (l2[:, k] * cot[:, k] + l2[:, j] * cot[:, j]) / 8)
    return A


@student("mixed_areas", named="barycentric areas")
def mixed_is_barycentric(V, F):
    areas = np.zeros(len(V))
    for tri in F:
        a, b, c = V[tri]
        areas[tri] += np.linalg.norm(np.cross(b - a, c - a)) / 6
    return areas


@student("mixed_areas", named="the halves are swapped")
def mixed_halves_swapped(V, F):
    A = mixed_no_obtuse(V, F) * 0  # start from zero, then the per-triangle rule
    ang = _corner_angles(V, F)
    l2 = edge_lengths(V, F) ** 2
    for f, tri in enumerate(F):
        Af = 0.5 * np.linalg.norm(np.cross(V[tri[1]] - V[tri[0]], V[tri[2]] - V[tri[0]]))
        obtuse = ang[f] > np.pi / 2
        for c in range(3):
            if obtuse.any():
                A[tri[c]] += Af / 4 if obtuse[c] else Af / 2
            else:
                j, k = (c + 1) % 3, (c + 2) % 3
                A[tri[c]] += (l2[f, k] / np.tan(ang[f, k]) + l2[f, j] / np.tan(ang[f, j])) / 8
    return A


# ============================================================================ 03 · discrete_principal_curvatures
# The answer builds on the learner's routines of sections 1 and 2, looked up where it is written: here, a
# notebook whose sections 1 and 2 hold these two right ones (``written_beside`` gives another notebook).
my_cotangent_matrix, my_mixed_areas = cotmatrix_lil, mixed_loop


def written_beside(**earlier):
    """The routine as written in a notebook whose earlier routines are ``earlier`` (my_cotangent_matrix=...)."""

    def rebind(fn):
        return types.FunctionType(fn.__code__, {**fn.__globals__, **earlier}, fn.__name__, fn.__defaults__)

    return rebind


@student("discrete_principal_curvatures")
def principal_own_pair(V, F, deficit):
    l = edge_lengths(V, F)
    C = my_cotangent_matrix(l, F)
    areas = my_mixed_areas(V, F)
    M = sp.diags(areas)
    H = signed_mean_curvature(V, F, M, C)
    K = deficit / areas
    disc = np.maximum(H**2 - K, 0)
    k1 = H + np.sqrt(disc)
    k2 = H - np.sqrt(disc)
    return k1, k2


@student("discrete_principal_curvatures")
def principal_vertex_loop(V, F, deficit):
    A = my_mixed_areas(V, F)
    C = my_cotangent_matrix(edge_lengths(V, F), F)
    H = signed_mean_curvature(V, F, np.diag(A), C)
    kappa1, kappa2 = np.full(len(V), np.nan), np.full(len(V), np.nan)
    for i in range(len(V)):
        if np.isnan(H[i]) or np.isnan(deficit[i]):
            continue  # boundary vertex
        r = np.sqrt(max(H[i] ** 2 - deficit[i] / A[i], 0.0))
        kappa1[i], kappa2[i] = H[i] + r, H[i] - r
    return kappa1, kappa2


@student("discrete_principal_curvatures", named="is not clamped")
def principal_no_clamp(V, F, deficit):
    C = my_cotangent_matrix(edge_lengths(V, F), F)
    A = my_mixed_areas(V, F)
    H = signed_mean_curvature(V, F, sp.diags(A), C)
    r = np.sqrt(H**2 - deficit / A)
    return H + r, H - r


@student("discrete_principal_curvatures", named="K is the deficit itself")
def principal_integrated_k(V, F, deficit):
    M = sp.diags(my_mixed_areas(V, F))
    C = my_cotangent_matrix(edge_lengths(V, F), F)
    H = signed_mean_curvature(V, F, M, C)
    K = deficit  # the angle deficit is the Gaussian curvature
    root = np.sqrt(np.maximum(H * H - K, 0))
    return H + root, H - root


@student("discrete_principal_curvatures", named="M is the identity in H")
def principal_identity_mass(V, F, deficit):
    C = my_cotangent_matrix(edge_lengths(V, F), F)
    A = my_mixed_areas(V, F)
    H = signed_mean_curvature(V, F, sp.identity(len(V)), C)  # M only for K
    K = deficit / A
    s = np.sqrt(np.maximum(H**2 - K, 0))
    return H + s, H - s


@student("discrete_principal_curvatures", named="M^-1 is handed to signed_mean_curvature")
def principal_inverse_mass(V, F, deficit):
    A = my_mixed_areas(V, F)
    Minv = sp.diags(1.0 / A)  # M^-1 C x
    H = signed_mean_curvature(V, F, Minv, my_cotangent_matrix(edge_lengths(V, F), F))
    d = np.clip(H**2 - deficit / A, 0, None)
    return H + np.sqrt(d), H - np.sqrt(d)


@student("discrete_principal_curvatures", named="have values at boundary vertices")
def principal_nan_to_num(V, F, deficit):
    A = my_mixed_areas(V, F)
    H = signed_mean_curvature(V, F, sp.diags(A), my_cotangent_matrix(edge_lengths(V, F), F))
    K = np.nan_to_num(deficit) / A  # the NaNs gave warnings
    d = np.sqrt(np.maximum(np.nan_to_num(H) ** 2 - K, 0.0))
    return np.nan_to_num(H) + d, np.nan_to_num(H) - d


@student("discrete_principal_curvatures", named="your my_cotangent_matrix (section 1) returns a wrong C")
@written_beside(my_cotangent_matrix=cotmatrix_no_half)
def principal_on_a_wrong_c(V, F, deficit):
    C = my_cotangent_matrix(edge_lengths(V, F), F)
    A = my_mixed_areas(V, F)
    H = signed_mean_curvature(V, F, sp.diags(A), C)
    root = np.sqrt(np.maximum(H**2 - deficit / A, 0.0))
    return H + root, H - root


@student("discrete_principal_curvatures", named="your my_mixed_areas (section 2) returns wrong areas")
@written_beside(my_mixed_areas=mixed_is_barycentric)
def principal_on_barycentric_areas_swapped(V, F, deficit):
    A = my_mixed_areas(V, F)
    H = signed_mean_curvature(V, F, sp.diags(A), my_cotangent_matrix(edge_lengths(V, F), F))
    root = np.sqrt(np.maximum(H**2 - deficit / A, 0.0))
    return H - root, H + root  # and the pair swapped: section 2 is named first


# ============================================================================ 04 · eigenpairs


@student("eigenpairs")
def eigen_reduction_numpy(M, C, k):
    m = M.diagonal()
    Mih = np.diag(1 / np.sqrt(m))
    Q = -Mih @ C.toarray() @ Mih
    lam, Z = np.linalg.eigh(Q)
    E = Mih @ Z
    return lam[:k], E[:, :k]


@student("eigenpairs")
def eigen_reduction_lanczos(M, C, k):
    d = sp.diags(1 / np.sqrt(M.diagonal()))
    Q = (-(d @ C @ d)).tocsc()
    lam, Z = spla.eigsh(Q, k=k, sigma=-1e-8, which="LM")
    order = np.argsort(lam)
    return lam[order], (d @ Z)[:, order]


@student("eigenpairs", named="not sorted")
def eigen_eig_unsorted(M, C, k):
    s = 1 / np.sqrt(M.diagonal())
    Q = -(s[:, None] * C.toarray() * s[None, :])
    vals, vecs = np.linalg.eig(Q)
    vals, vecs = vals.real, vecs.real
    return vals[:k], s[:, None] * vecs[:, :k]


@student("eigenpairs", named="M is left out")
def eigen_of_C_only(M, C, k):
    vals, vecs = np.linalg.eigh(-C.toarray())
    return vals[:k], vecs[:, :k]


@student("eigenpairs", named="the sign of C is flipped")
def eigen_sign(M, C, k):
    Dm = np.diag(M.diagonal() ** -0.5)
    Q = Dm @ C.toarray() @ Dm
    w, U = np.linalg.eigh(Q)
    return w[:k], Dm @ U[:, :k]


@student("eigenpairs", named="not transformed back")
def eigen_no_back_transform(M, C, k):
    m_inv_sqrt = 1 / np.sqrt(M.diagonal())
    Q = -sp.diags(m_inv_sqrt) @ C @ sp.diags(m_inv_sqrt)
    lam, Z = sla.eigh(Q.toarray(), subset_by_index=[0, k - 1])
    return lam, Z


# ============================================================================ 04 · spectral_reconstruction


@student("spectral_reconstruction")
def reconstruct_generalised(V, F, ks, solve):
    M, C = laplacian(V, F)
    lam, E = sla.eigh(-C.toarray(), M.toarray())  # my own solve, all of them
    A = M.diagonal()
    bbox = np.linalg.norm(np.max(V, axis=0) - np.min(V, axis=0))
    recons = []
    errors = []
    for k in ks:
        Ek = E[:, :k]
        Vk = Ek @ (Ek.T @ (M @ V))
        recons.append(Vk)
        diff = V - Vk
        errors.append(np.sqrt((A * (diff**2).sum(axis=1)).sum() / A.sum()) / bbox)
    return recons, errors


@student("spectral_reconstruction")
def reconstruct_stacked(V, F, ks, solve):
    M, C = laplacian(V, F)
    m = M.diagonal()
    K = max(ks)
    lam, E = solve(M, C, K)
    coeffs = E.T @ (m[:, None] * V)
    out = np.zeros((len(ks), V.shape[0], 3))
    for j, k in enumerate(ks):
        out[j] = E[:, :k] @ coeffs[:k]
    diffs = out - V[None, :, :]
    sq = np.einsum("i,jid->j", m, diffs**2)
    diag = np.sqrt(((V.max(0) - V.min(0)) ** 2).sum())
    return out, np.sqrt(sq / m.sum()) / diag


@student("spectral_reconstruction")
def reconstruct_centred_first(V, F, ks, solve):
    M, C = laplacian(V, F)
    centre = V.mean(axis=0)
    P = V - centre  # centre it first, add it back at the end
    results, errs = [], []
    for k in ks:
        lam, E = solve(M, C, k)  # one solve per k: slower but simple
        Pk = E @ (E.T @ M @ P) + centre
        results.append(Pk)
        d = V - Pk
        rms = np.sqrt(np.sum(M @ (d * d)) / M.diagonal().sum())
        errs.append(rms / np.linalg.norm(np.ptp(V, axis=0)))
    return results, np.array(errs)


@student("spectral_reconstruction", named="the mean is taken out twice")
def reconstruct_centred_and_dropped(V, F, ks, solve):
    M, C = laplacian(V, F)
    mu = np.mean(V, axis=0)
    Vc = V - mu
    lam, E = solve(M, C, max(ks))
    area = M.diagonal().sum()
    diag = np.linalg.norm(V.max(axis=0) - V.min(axis=0))
    Vs, err = [], []
    for k in ks:
        B = E[:, 1:k]  # e_0 is the constant, and V is centred already
        Vk = mu + B @ (B.T @ (M @ Vc))
        Vs.append(Vk)
        err.append(np.sqrt(np.sum(M.diagonal()[:, None] * (V - Vk) ** 2) / area) / diag)
    return Vs, err


@student("spectral_reconstruction", named="plain dot product")
def reconstruct_plain_dot(V, F, ks, solve):
    M, C = laplacian(V, F)
    lam, E = solve(M, C, max(ks))
    diag = np.linalg.norm(V.max(0) - V.min(0))
    recs, errs = [], []
    for k in ks:
        phi = E[:, :k]
        Vk = phi @ (phi.T @ V)
        recs.append(Vk)
        errs.append(np.sqrt(np.sum(M.diagonal() * np.sum((V - Vk) ** 2, axis=1)) / M.diagonal().sum()) / diag)
    return recs, errs


@student("spectral_reconstruction", named="the vertices are weighted equally")
def reconstruct_euclidean_error(V, F, ks, solve):
    M, C = laplacian(V, F)
    lam, E = solve(M, C, max(ks))
    c = E.T @ M @ V
    diag = np.linalg.norm(V.max(axis=0) - V.min(axis=0))
    Vks = [E[:, :k] @ c[:k] for k in ks]
    err = [np.sqrt(np.mean(np.sum((V - Vk) ** 2, axis=1))) / diag for Vk in Vks]  # RMS over the vertices
    return Vks, np.array(err)


@student("spectral_reconstruction", named="not divided by the bounding-box diagonal")
def reconstruct_error_not_relative(V, F, ks, solve):
    M, C = laplacian(V, F)
    A = M.diagonal()
    lam, E = solve(M, C, max(ks))
    recon = []
    error = []
    for k in ks:
        Vk = E[:, :k] @ (E[:, :k].T @ (A[:, None] * V))
        recon.append(Vk)
        error.append(np.sqrt(np.sum(A[:, None] * (V - Vk) ** 2) / np.sum(A)))
    return recon, error


@student("spectral_reconstruction", named="the square root is missing")
def reconstruct_error_squared(V, F, ks, solve):
    M, C = laplacian(V, F)
    lam, E = solve(M, C, max(ks))
    A = M.diagonal()
    box = V.max(axis=0) - V.min(axis=0)
    diag = np.sqrt(box @ box)
    res = [E[:, :k] @ (E[:, :k].T @ (M @ V)) for k in ks]
    errs = [np.sum(A[:, None] * (V - R) ** 2) / A.sum() / diag for R in res]  # mean squared distance
    return res, errs


@student("spectral_reconstruction", named="one eigenvector too many")
def reconstruct_k_plus_one(V, F, ks, solve):
    M, C = laplacian(V, F)
    lam, E = solve(M, C, max(ks) + 1)
    diag = np.linalg.norm(V.max(axis=0) - V.min(axis=0))
    out, errs = [], []
    for k in ks:
        Ek = E[:, : k + 1]  # e_0 .. e_k
        Vk = Ek @ Ek.T @ M @ V
        out.append(Vk)
        errs.append(np.sqrt(np.sum(M @ ((V - Vk) ** 2)) / M.diagonal().sum()) / diag)
    return out, errs


@student("spectral_reconstruction", named="the uniform operator")
def reconstruct_uniform(V, F, ks, solve):
    n = len(V)
    A = np.zeros((n, n))
    for i, j, l in F:
        A[i, j] = A[j, i] = A[j, l] = A[l, j] = A[i, l] = A[l, i] = 1
    deg = A.sum(axis=1)
    lam, E = sla.eigh(np.diag(deg) - A, np.diag(deg))
    diag = np.linalg.norm(V.max(0) - V.min(0))
    Vs = [E[:, :k] @ (E[:, :k].T @ (deg[:, None] * V)) for k in ks]
    return Vs, [np.sqrt(np.sum(deg[:, None] * (V - X) ** 2) / deg.sum()) / diag for X in Vs]


# ============================================================================ 05 · lam_max


@student("lam_max")
def lam_max_power(M, C):
    d = 1 / np.sqrt(M.diagonal())
    x = np.random.default_rng(0).standard_normal(C.shape[0])
    lam_old = 0.0
    for it in range(100000):
        y = -d * (C @ (d * x))
        lam = x @ y / (x @ x)
        x = y / np.linalg.norm(y)
        if abs(lam - lam_old) < 1e-13 * abs(lam):
            break
        lam_old = lam
    return lam


@student("lam_max")
def lam_max_eigsh(M, C):
    Dinv = sp.diags(M.diagonal() ** -0.5)
    Q = -(Dinv @ C @ Dinv)
    return float(spla.eigsh(Q, k=1, which="LA", return_eigenvectors=False)[0])


@student("lam_max", named="M is left out")
def lam_max_no_mass(M, C):
    v = np.ones(C.shape[0]) + np.arange(C.shape[0])
    v /= np.linalg.norm(v)
    lam = 0
    for _ in range(20000):
        w = -(C @ v)
        new = v @ w
        v = w / np.linalg.norm(w)
        if abs(new - lam) < 1e-14 * abs(new):
            break
        lam = new
    return new


@student("lam_max", named="stopped too early")
def lam_max_few_iterations(M, C):
    d = 1 / np.sqrt(M.diagonal())
    x = np.random.default_rng(3).random(C.shape[0])
    for _ in range(8):
        x = -d * (C @ (d * x))
        x = x / np.linalg.norm(x)
    return x @ (-d * (C @ (d * x)))


@student("lam_max", named="step limit")
def lam_max_returns_limit(M, C):
    Dinv = sp.diags(1 / np.sqrt(M.diagonal()))
    lam = spla.eigsh(-(Dinv @ C @ Dinv), k=1, which="LA")[0][0]
    return 2 / lam


# ============================================================================ 05 · smoothing_loop


def _interior(F, n):
    edges = np.sort(np.vstack([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    e, cnt = np.unique(edges, axis=0, return_counts=True)
    bnd = np.zeros(n, dtype=bool)
    bnd[e[cnt == 1].ravel()] = True
    return np.flatnonzero(~bnd)


def _interior_limit(m, C, I):
    d = 1 / np.sqrt(m[I])
    Q = -(d[:, None] * C[I][:, I].toarray() * d[None, :])
    return 2 / np.linalg.eigvalsh(Q)[-1]


@student("smoothing_loop")
def explicit_csr(V, F, tau, N):
    M, C = laplacian(V, F)
    m, C = M.diagonal(), C.tocsr()
    I = _interior(F, len(V))
    limit = _interior_limit(m, C, I)
    if tau >= limit:
        raise ValueError(f"tau = {tau} is past the limit 2 / lam_max = {limit}")
    P = V.copy()
    for _ in range(N):
        P[I] = P[I] + tau * (C[I] @ P) / m[I, None]
    return P


@student("smoothing_loop")
def explicit_masked(V, F, tau, N):
    M, C = laplacian(V, F)
    n = len(V)
    inner = np.zeros(n, dtype=bool)
    inner[_interior(F, n)] = True
    Minv = sp.diags(1 / M.diagonal())
    L = (Minv @ C).tocsr()
    II = np.flatnonzero(inner)
    m_I = M.diagonal()[II]
    C_II = C.tocsr()[II][:, II]
    dd = sp.diags(1 / np.sqrt(m_I))
    lmax = spla.eigsh(-(dd @ C_II @ dd), k=1, which="LA")[0][0]
    if tau >= 2 / lmax:
        raise ValueError("step too large for the explicit scheme")
    X = np.array(V, dtype=float)
    for it in range(N):
        step = tau * (L @ X)
        step[~inner] = 0
        X = X + step
    return X


@student("smoothing_loop", named="half a step")
def explicit_half_step(V, F, tau, N):
    M, C = laplacian(V, F)
    m = M.diagonal()
    I = _interior(F, len(V))
    if tau >= _interior_limit(m, C.tocsr(), I):
        raise ValueError("tau too large")
    P = V.copy()
    for _ in range(N):
        P[I] += 0.5 * tau * (C.tocsr()[I] @ P) / m[I][:, None]  # the midpoint of the step
    return P


@student("smoothing_loop", named="the boundary moves")
def explicit_moves_boundary(V, F, tau, N):
    M, C = laplacian(V, F)
    m = M.diagonal()
    I = _interior(F, len(V))
    if tau >= _interior_limit(m, C.tocsr(), I):
        raise ValueError("unstable")
    P = V.copy()
    for _ in range(N):
        P = P + tau * (C @ P) / m[:, None]
    return P


@student("smoothing_loop", named="ran instead of being refused")
def explicit_no_limit(V, F, tau, N):
    M, C = laplacian(V, F)
    m = M.diagonal()
    I = _interior(F, len(V))
    P = V.copy()
    for _ in range(N):
        P[I] += tau * (C.tocsr()[I] @ P) / m[I, None]
    return P


@student("smoothing_loop", named="rebuilt from the moving mesh")
def explicit_rebuilds(V, F, tau, N):
    M, C = laplacian(V, F)
    I = _interior(F, len(V))
    if tau >= _interior_limit(M.diagonal(), C.tocsr(), I):
        raise ValueError("tau >= 2/lam_max")
    P = V.copy()
    for _ in range(N):
        M, C = laplacian(P, F)
        P[I] += tau * (C.tocsr()[I] @ P) / M.diagonal()[I, None]
    return P


# ============================================================================ 06 · implicit_loop


@student("implicit_loop")
def implicit_splu(V, F, tau, N):
    M, C = laplacian(V, F)
    C = C.tocsr()
    I = _interior(F, len(V))
    B = np.setdiff1d(np.arange(len(V)), I)
    m = M.diagonal()
    A = (sp.diags(m[I]) - tau * C[I][:, I]).tocsc()
    lu = spla.splu(A)
    P = V.copy()
    for _ in range(N):
        P[I] = lu.solve(m[I, None] * P[I] + tau * (C[I][:, B] @ P[B]))
    return P


@student("implicit_loop")
def implicit_dense(V, F, tau, N):
    M, C = laplacian(V, F)
    Md, Cd = M.toarray(), C.toarray()
    inner = _interior(F, len(V))
    outer = np.array([i for i in range(len(V)) if i not in set(inner)], dtype=int)
    A = Md[np.ix_(inner, inner)] - tau * Cd[np.ix_(inner, inner)]
    P = np.copy(V)
    for step in range(N):
        rhs = Md[np.ix_(inner, inner)] @ P[inner] + tau * Cd[np.ix_(inner, outer)] @ P[outer]
        P[inner] = np.linalg.solve(A, rhs)
    return P


@student("implicit_loop", named="explicit steps")
def implicit_is_explicit(V, F, tau, N):
    M, C = laplacian(V, F)
    I = _interior(F, len(V))
    P = V.copy()
    for _ in range(N):
        P[I] = P[I] + tau * (C.tocsr()[I] @ P) / M.diagonal()[I, None]
    return P


@student("implicit_loop", named="the right-hand side holds P_I")
def implicit_rhs_without_mass(V, F, tau, N):
    M, C = laplacian(V, F)
    C = C.tocsr()
    I = _interior(F, len(V))
    B = np.setdiff1d(np.arange(len(V)), I)
    solve = spla.factorized((M.tocsr()[I][:, I] - tau * C[I][:, I]).tocsc())
    P = V.copy()
    for _ in range(N):
        rhs = P[I] + tau * C[I][:, B] @ P[B]
        P[I] = np.column_stack([solve(rhs[:, j]) for j in range(3)])
    return P


@student("implicit_loop", named="half a step")
def implicit_half_step(V, F, tau, N):
    M, C = laplacian(V, F)
    C = C.tocsr()
    m = M.diagonal()
    I = _interior(F, len(V))
    B = np.setdiff1d(np.arange(len(V)), I)
    h = tau / 2
    lu = spla.splu((sp.diags(m[I]) - h * C[I][:, I]).tocsc())
    P = V.copy()
    for _ in range(N):
        P[I] = lu.solve(m[I, None] * P[I] + h * (C[I][:, B] @ P[B]))
    return P


@student("implicit_loop", named="held boundary's term tau C_IB P_B is missing")
def implicit_no_coupling(V, F, tau, N):
    M, C = laplacian(V, F)
    I = _interior(F, len(V))
    m = M.diagonal()[I]
    A = (sp.diags(m) - tau * C.tocsr()[I][:, I]).tocsc()
    P = V.copy()
    for _ in range(N):
        P[I] = spla.spsolve(A, m[:, None] * P[I])
    return P


# ============================================================================ 06 · volume_kept


def _face_loop_solid(X, F, corner=4.0, signed=True):
    """Volume and centroid of the solid, one face at a time (a student's loop)."""
    vol, moment = 0.0, np.zeros(3)
    for a, b, c in F:
        v = np.dot(X[a], np.cross(X[b], X[c])) / 6.0
        v = v if signed else abs(v)
        vol += v
        moment += v * (X[a] + X[b] + X[c]) / corner
    return vol, moment / vol


@student("volume_kept")
def volume_face_loop(P, F, V):
    vol0, c0 = _face_loop_solid(V, F)
    vol, c = _face_loop_solid(P, F)
    return c0 + (P - c) * np.cbrt(vol0 / vol)


@student("volume_kept")
def volume_apex_at_a_vertex(P, F, V):
    def solid(X):
        o = X[0]  # any apex gives the same solid; the first vertex keeps the numbers small
        A, B, C = X[F[:, 0]] - o, X[F[:, 1]] - o, X[F[:, 2]] - o
        v = np.linalg.det(np.stack([A, B, C], axis=1))
        return v.sum(), o + (A + B + C).T @ v / (4 * v.sum())

    (vol0, c0), (vol, c) = solid(V), solid(P)
    return (P - c) * (vol0 / vol) ** (1 / 3) + c0


@student("volume_kept", named="the volume ratio itself")
def volume_no_cube_root(P, F, V):
    vol0, c0 = _face_loop_solid(V, F)
    vol, c = _face_loop_solid(P, F)
    return c0 + (P - c) * (vol0 / vol)


@student("volume_kept", named="means of the vertices")
def volume_vertex_means(P, F, V):
    vol0, _ = _face_loop_solid(V, F)
    vol, _ = _face_loop_solid(P, F)
    return V.mean(axis=0) + (P - P.mean(axis=0)) * np.cbrt(vol0 / vol)


@student("volume_kept", named="absolute values")
def volume_abs_tetrahedra(P, F, V):
    vol0, c0 = _face_loop_solid(V, F, signed=False)
    vol, c = _face_loop_solid(P, F, signed=False)
    return c0 + (P - c) * np.cbrt(vol0 / vol)


@student("volume_kept", named="not moved back")
def volume_stays_put(P, F, V):
    vol0, _ = _face_loop_solid(V, F)
    vol, c = _face_loop_solid(P, F)
    return c + (P - c) * np.cbrt(vol0 / vol)


# ============================================================================ 07 · add_noise


def _diag(V):
    return np.linalg.norm(V.max(axis=0) - V.min(axis=0))


@student("add_noise")
def noise_default_rng(V, F, sigma, seed):
    rng = np.random.default_rng(seed)
    return V + sigma * _diag(V) * rng.standard_normal(V.shape)


@student("add_noise")
def noise_normal(V, F, sigma, seed):
    gen = np.random.default_rng(seed)
    bbox = V.max(0) - V.min(0)
    return V + gen.normal(0.0, sigma * np.sqrt(bbox @ bbox), size=(len(V), 3))


@student("add_noise", named="not seeded")
def noise_unseeded(V, F, sigma, seed):
    return V + sigma * _diag(V) * np.random.randn(*V.shape)


@student("add_noise", named="float32")
def noise_float32(V, F, sigma, seed):
    rng = np.random.default_rng(seed)
    noise = rng.standard_normal(V.shape).astype(np.float32)
    return (V + sigma * _diag(V) * noise).astype(np.float32)


@student("add_noise", named="one normal number is shared")
def noise_shared(V, F, sigma, seed):
    rng = np.random.default_rng(seed)
    z = rng.standard_normal((len(V), 1))
    return V + sigma * _diag(V) * z


@student("add_noise", named="largest corner")
def noise_corner(V, F, sigma, seed):
    rng = np.random.default_rng(seed)
    return V + sigma * np.linalg.norm(V.max(axis=0)) * rng.standard_normal(V.shape)


# ============================================================================ 07 · denoising_metrics


def _unit_normals(X, F):
    N = np.cross(X[F[:, 1]] - X[F[:, 0]], X[F[:, 2]] - X[F[:, 0]])
    return N / np.linalg.norm(N, axis=1)[:, None]


@student("denoising_metrics")
def metrics_loops(V, V_clean, F):
    d = np.linalg.norm(np.ptp(V_clean, axis=0))
    rms = np.sqrt(sum(np.dot(p - x, p - x) for p, x in zip(V, V_clean)) / len(V)) / d
    angles, vol, vol0 = [], 0.0, 0.0
    for i, j, k in F:
        n = np.cross(V[j] - V[i], V[k] - V[i])
        n0 = np.cross(V_clean[j] - V_clean[i], V_clean[k] - V_clean[i])
        c = np.dot(n, n0) / (np.linalg.norm(n) * np.linalg.norm(n0))
        angles.append(np.degrees(np.arccos(min(1.0, max(-1.0, c)))))
        vol += np.dot(V[i], np.cross(V[j], V[k])) / 6
        vol0 += np.dot(V_clean[i], np.cross(V_clean[j], V_clean[k])) / 6
    return {"rms": rms, "normal_mean": np.mean(angles), "volume_change": (vol - vol0) / abs(vol0)}


@student("denoising_metrics")
def metrics_arctan2(V, V_clean, F):
    d = np.sqrt(((V_clean.max(0) - V_clean.min(0)) ** 2).sum())
    out = {"rms": np.sqrt(np.mean(np.linalg.norm(V - V_clean, axis=1) ** 2)) / d}
    N = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    N0 = np.cross(V_clean[F[:, 1]] - V_clean[F[:, 0]], V_clean[F[:, 2]] - V_clean[F[:, 0]])
    sine = np.linalg.norm(np.cross(N, N0), axis=1)
    out["normal_mean"] = np.rad2deg(np.arctan2(sine, np.einsum("ij,ij->i", N, N0))).mean()
    vol = np.einsum("ij,ij->", V[F[:, 0]], N) / 6  # x0 . (x1 - x0) x (x2 - x0) = x0 . (x1 x x2)
    vol0 = np.einsum("ij,ij->", V_clean[F[:, 0]], N0) / 6
    out["volume_change"] = vol / vol0 - 1
    return out


@student("denoising_metrics", named="radians")
def metrics_radians(V, V_clean, F):
    d = np.linalg.norm(V_clean.max(axis=0) - V_clean.min(axis=0))
    cos = np.sum(_unit_normals(V, F) * _unit_normals(V_clean, F), axis=1)
    vol = np.linalg.det(V[F]).sum() / 6
    vol0 = np.linalg.det(V_clean[F]).sum() / 6
    return {
        "rms": np.sqrt(np.mean(np.sum((V - V_clean) ** 2, axis=1))) / d,
        "normal_mean": np.mean(np.arccos(np.clip(cos, -1, 1))),
        "volume_change": (vol - vol0) / abs(vol0),
    }


@student("denoising_metrics", named="NaN")
def metrics_unclipped(V, V_clean, F):
    d = np.linalg.norm(V_clean.max(axis=0) - V_clean.min(axis=0))
    theta = np.degrees(np.arccos(np.einsum("ij,ij->i", _unit_normals(V, F), _unit_normals(V_clean, F))))
    vol = np.linalg.det(V[F]).sum() / 6
    vol0 = np.linalg.det(V_clean[F]).sum() / 6
    rms = np.sqrt(np.mean(np.sum((V - V_clean) ** 2, axis=1))) / d
    return {"rms": rms, "normal_mean": theta.mean(), "volume_change": (vol - vol0) / abs(vol0)}


@student("denoising_metrics", named="not of unit length")
def metrics_raw_normals(V, V_clean, F):
    e2 = ((V - V_clean) ** 2).sum(axis=1)
    d = np.linalg.norm(V_clean.max(axis=0) - V_clean.min(axis=0))
    a, b, c = (V[F[:, k]] for k in range(3))
    a0, b0, c0 = (V_clean[F[:, k]] for k in range(3))
    dots = (np.cross(b - a, c - a) * np.cross(b0 - a0, c0 - a0)).sum(axis=1)
    vol, vol0 = (a * np.cross(b, c)).sum() / 6, (a0 * np.cross(b0, c0)).sum() / 6
    return {
        "rms": np.sqrt(e2.mean()) / d,
        "normal_mean": np.degrees(np.arccos(np.clip(dots, -1, 1))).mean(),
        "volume_change": (vol - vol0) / abs(vol0),
    }


@student("denoising_metrics", named="volume change is absolute")
def metrics_absolute_volume(V, V_clean, F):
    d = np.linalg.norm(V_clean.max(axis=0) - V_clean.min(axis=0))
    cos = np.clip((_unit_normals(V, F) * _unit_normals(V_clean, F)).sum(1), -1, 1)
    vol = lambda X: np.sum(X[F[:, 0]] * np.cross(X[F[:, 1]], X[F[:, 2]])) / 6  # noqa: E731
    return {
        "rms": np.sqrt(((V - V_clean) ** 2).sum(1).mean()) / d,
        "normal_mean": np.degrees(np.arccos(cos)).mean(),
        "volume_change": vol(V) - vol(V_clean),
    }


@student("denoising_metrics", named="noisy mesh's diagonal")
def metrics_noisy_diagonal(V, V_clean, F):
    d = np.linalg.norm(V.max(axis=0) - V.min(axis=0))  # the mesh being measured
    cos = np.clip((_unit_normals(V, F) * _unit_normals(V_clean, F)).sum(1), -1, 1)
    vol = np.linalg.det(V[F]).sum() / 6
    vol0 = np.linalg.det(V_clean[F]).sum() / 6
    return {
        "rms": np.sqrt(((V - V_clean) ** 2).sum(1).mean()) / d,
        "normal_mean": np.degrees(np.arccos(cos)).mean(),
        "volume_change": (vol - vol0) / abs(vol0),
    }


@student("denoising_metrics", named="ratio vol / vol_clean")
def metrics_volume_ratio(V, V_clean, F):
    d = np.linalg.norm(V_clean.max(axis=0) - V_clean.min(axis=0))
    cos = np.clip((_unit_normals(V, F) * _unit_normals(V_clean, F)).sum(1), -1, 1)
    return {
        "rms": np.sqrt(((V - V_clean) ** 2).sum(1).mean()) / d,
        "normal_mean": np.degrees(np.arccos(cos)).mean(),
        "volume_change": enclosed_volume(V, F) / enclosed_volume(V_clean, F),  # how much of the volume is left
    }


@student("denoising_metrics", named="sign of the volume change is flipped")
def metrics_volume_lost(V, V_clean, F):
    diag = np.linalg.norm(np.ptp(V_clean, axis=0))
    theta = np.arccos(np.clip(np.einsum("ij,ij->i", _unit_normals(V, F), _unit_normals(V_clean, F)), -1, 1))
    vol0 = enclosed_volume(V_clean, F)
    lost = (vol0 - enclosed_volume(V, F)) / abs(vol0)  # the share of the volume lost by smoothing
    return {
        "rms": np.linalg.norm(V - V_clean) / np.sqrt(len(V)) / diag,
        "normal_mean": np.degrees(theta).mean(),
        "volume_change": lost,
    }


@student("denoising_metrics")
def metrics_handed_volume(V, V_clean, F):
    diag = np.linalg.norm(V_clean.max(axis=0) - V_clean.min(axis=0))
    theta = np.degrees(np.arccos(np.clip(np.sum(_unit_normals(V, F) * _unit_normals(V_clean, F), axis=1), -1, 1)))
    vol, vol0 = enclosed_volume(V, F), enclosed_volume(V_clean, F)
    return {"rms": np.sqrt(np.mean(np.sum((V - V_clean) ** 2, axis=1))) / diag, "normal_mean": theta.mean(),
            "volume_change": (vol - vol0) / abs(vol0)}  # fmt: skip


# ============================================================================ 07 · denoising_experiment


def _noisy(V, sigma, seed):
    return V + sigma * _diag(V) * np.random.default_rng(seed).standard_normal(V.shape)


def _E(P, V):
    return np.sqrt(np.mean(np.sum((P - V) ** 2, axis=1))) / _diag(V)


@student("denoising_experiment")
def experiment(V_clean, F, sigma, tau, iterations, seeds):
    errors = []
    for s in seeds:
        P = implicit_smoothing(_noisy(V_clean, sigma, s), F, tau, iterations)
        errors.append(_E(P, V_clean))
    return np.mean(errors), np.std(errors, ddof=1)


@student("denoising_experiment")
def experiment_statistics(V_clean, F, sigma, tau, iterations, seeds):
    import statistics

    Es = [float(_E(implicit_smoothing(_noisy(V_clean, sigma, seed), F, tau, iterations), V_clean)) for seed in seeds]
    return statistics.mean(Es), statistics.stdev(Es)  # stdev: the sample one, n - 1


@student("denoising_experiment", named="population one (ddof = 0)")
def experiment_population_std(V_clean, F, sigma, tau, iterations, seeds):
    E = np.array([_E(implicit_smoothing(_noisy(V_clean, sigma, s), F, tau, iterations), V_clean) for s in seeds])
    return E.mean(), E.std()


@student("denoising_experiment", named="same seed made every draw")
def experiment_one_seed(V_clean, F, sigma, tau, iterations, seeds):
    W = _noisy(V_clean, sigma, seeds[0])
    E = [_E(implicit_smoothing(W, F, tau, iterations), V_clean) for _ in seeds]  # the same noise each time
    return np.mean(E), np.std(E, ddof=1)


@student("denoising_experiment", named="standard deviation is that of the noisy meshes")
def experiment_spread_of_noise(V_clean, F, sigma, tau, iterations, seeds):
    E, E0 = [], []
    for seed in seeds:
        W = _noisy(V_clean, sigma, seed)
        E0.append(_E(W, V_clean))
        E.append(_E(implicit_smoothing(W, F, tau, iterations), V_clean))
    return np.mean(E), np.std(E0, ddof=1)


@student("denoising_experiment", named="seeds are ignored")
def experiment_counted_seeds(V_clean, F, sigma, tau, iterations, seeds):
    E = [_E(implicit_smoothing(_noisy(V_clean, sigma, k), F, tau, iterations), V_clean) for k in range(len(seeds))]
    return np.mean(E), np.std(E, ddof=1)


@student("denoising_experiment", named="one iteration short")
def experiment_short(V_clean, F, sigma, tau, iterations, seeds):
    E = []
    for seed in seeds:
        rng = np.random.default_rng(seed)
        noisy = V_clean + rng.standard_normal(V_clean.shape) * sigma * _diag(V_clean)
        smooth = implicit_smoothing(noisy, F, tau, max(iterations - 1, 0))  # "iterations must be at least 0"
        E.append(np.sqrt(((smooth - V_clean) ** 2).sum(axis=1).mean()) / _diag(V_clean))
    return sum(E) / len(E), np.std(E, ddof=1)


@student("denoising_experiment", named="measured against the noisy mesh")
def experiment_against_noisy(V_clean, F, sigma, tau, iterations, seeds):
    E = []
    for seed in seeds:
        W = _noisy(V_clean, sigma, seed)
        E.append(
            np.sqrt(np.mean(np.sum((implicit_smoothing(W, F, tau, iterations) - W) ** 2, axis=1))) / _diag(V_clean)
        )
    return np.mean(E), np.std(E, ddof=1)


# ============================================================================ 07 · denoising_sweep


def _rms(P, V_clean):
    return np.sqrt(np.mean(np.sum((P - V_clean) ** 2, axis=1))) / _diag(V_clean)


@student("denoising_sweep")
def sweep(W, F, V_clean, taus, iterations):
    M, C = laplacian(W, F)
    E = np.zeros((len(taus), iterations + 1))
    for i, tau in enumerate(taus):
        lu = spla.splu((M - tau * C).tocsc())
        P = W.copy()
        E[i, 0] = _rms(P, V_clean)
        for k in range(1, iterations + 1):
            P = lu.solve(M @ P)
            E[i, k] = _rms(P, V_clean)
    i, k = np.unravel_index(np.argmin(E), E.shape)
    return taus[i], k, E


@student("denoising_sweep", named="starts where the previous step's ended")
def sweep_carry(W, F, V_clean, taus, iterations):
    M, C = laplacian(W, F)
    E = np.zeros((len(taus), iterations + 1))
    P = W.copy()
    for i, tau in enumerate(taus):
        E[i, 0] = _rms(P, V_clean)
        for k in range(iterations):
            P = spla.spsolve((M - tau * C).tocsc(), M @ P)
            E[i, k + 1] = _rms(P, V_clean)
    best = np.argmin(E)
    return taus[best // (iterations + 1)], best % (iterations + 1), E


@student("denoising_sweep", named="explicit steps")
def sweep_explicit(W, F, V_clean, taus, iterations):
    M, C = laplacian(W, F)
    minv = 1 / M.diagonal()
    E = []
    for tau in taus:
        P, row = W.copy(), [_rms(W, V_clean)]
        for _ in range(iterations):
            P = P + tau * minv[:, None] * (C @ P)
            row.append(_rms(P, V_clean))
        E.append(row)
    E = np.array(E)
    i, k = np.unravel_index(E.argmin(), E.shape)
    return taus[i], k, E


# ============================================================================ 07 · taubin_smoothing


@student("taubin_smoothing")
def taubin_rows(V, F, tau_shrink, tau_inflate, pairs):
    M, C = laplacian(V, F, weights="uniform")
    inner = np.setdiff1d(np.arange(len(V)), boundary_vertices(F, len(V)))
    L = (sp.diags(1 / M.diagonal()) @ C).tocsr()[inner]  # the rows that move
    P = V.copy()
    for _ in range(pairs):
        for tau in (tau_shrink, tau_inflate):
            P[inner] = P[inner] + tau * (L @ P)
    return P


@student("taubin_smoothing")
def taubin_neighbour_average(V, F, tau_shrink, tau_inflate, pairs):
    n = len(V)
    edges = np.sort(np.vstack([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    e, count = np.unique(edges, axis=0, return_counts=True)
    A = sp.coo_matrix((np.ones(2 * len(e)), (np.r_[e[:, 0], e[:, 1]], np.r_[e[:, 1], e[:, 0]])), shape=(n, n)).tocsr()
    valence = np.asarray(A.sum(axis=1)).ravel()
    fixed = np.zeros(n, bool)
    fixed[e[count == 1].ravel()] = True  # an edge of one face lies on the boundary
    P = V.astype(float).copy()
    for _ in range(pairs):
        for t in (tau_shrink, tau_inflate):
            umbrella = (A @ P) / valence[:, None] - P  # the mean of the neighbours minus the vertex
            P = np.where(fixed[:, None], P, P + t * umbrella)
    return P


@student("taubin_smoothing", named="wrong sign")
def taubin_minus_mu(V, F, tau_shrink, tau_inflate, pairs):
    M, C = laplacian(V, F, "uniform")
    free = np.ones(len(V), bool)
    free[boundary_vertices(F, len(V))] = False
    m = M.diagonal()[free, None]
    P = V.copy()
    for _ in range(pairs):
        P[free] += tau_shrink * (C @ P)[free] / m
        P[free] -= tau_inflate * (C @ P)[free] / m  # inflate: the other direction
    return P


@student("taubin_smoothing", named="counted instead of pairs")
def taubin_alternating_steps(V, F, tau_shrink, tau_inflate, pairs):
    M, C = laplacian(V, F, "uniform")
    b = boundary_vertices(F, len(V))
    P = V.copy()
    for k in range(pairs):
        tau = tau_shrink if k % 2 == 0 else tau_inflate
        step = tau * (C @ P) / M.diagonal()[:, None]
        step[b] = 0
        P = P + step
    return P


@student("taubin_smoothing", named="boundary vertices moved")
def taubin_free_boundary(V, F, tau_shrink, tau_inflate, pairs):
    M, C = laplacian(V, F, weights="uniform")
    Minv = sp.diags(1.0 / M.diagonal())
    P = V.copy()
    for _ in range(pairs):
        P = P + tau_shrink * (Minv @ (C @ P))
        P = P + tau_inflate * (Minv @ (C @ P))
    return P


@student("taubin_smoothing", named="M^-1 is missing")
def taubin_no_mass(V, F, tau_shrink, tau_inflate, pairs):
    _, C = laplacian(V, F, "uniform")
    keep = boundary_vertices(F, len(V))
    P = V.copy()
    for _ in range(2 * pairs):
        tau = tau_inflate if _ % 2 else tau_shrink
        Q = P + tau * (C @ P)
        Q[keep] = V[keep]
        P = Q
    return P


@student("taubin_smoothing", named="same P")
def taubin_simultaneous(V, F, tau_shrink, tau_inflate, pairs):
    M, C = laplacian(V, F, "uniform")
    inner = np.setdiff1d(np.arange(len(V)), boundary_vertices(F, len(V)))
    P = V.copy()
    for _ in range(pairs):
        lap = (C @ P) / M.diagonal()[:, None]
        P[inner] += tau_shrink * lap[inner] + tau_inflate * lap[inner]  # both from this P
    return P


@student("taubin_smoothing", named="cotangent weights")
def taubin_cotan(V, F, tau_shrink, tau_inflate, pairs):
    M, C = laplacian(V, F)  # the default weights
    inner = np.setdiff1d(np.arange(len(V)), boundary_vertices(F, len(V)))
    P = V.copy()
    for _ in range(pairs):
        P[inner] += tau_shrink * (C @ P)[inner] / M.diagonal()[inner, None]
        P[inner] += tau_inflate * (C @ P)[inner] / M.diagonal()[inner, None]
    return P


# ============================================================================ a second batch, written before the
# catalogues were looked at again: the measure of how well the checks name what they were not tuned to


@student("uniform_laplacian", named="C is already divided by the valence")
def uniform_umbrella_rows(V, F):
    n = len(V)
    ring = [[] for _ in range(n)]
    for tri in F:
        for a in range(3):
            for b in range(3):
                if a != b and tri[b] not in ring[tri[a]]:
                    ring[tri[a]].append(tri[b])
    L = sp.lil_matrix((n, n))
    for i in range(n):
        L[i, ring[i]] = 1 / len(ring[i])
        L[i, i] = -1
    return sp.diags([float(len(r)) for r in ring]), L.tocsr()


@student("gaussian_curvature", named="mixed (Voronoi) areas")
def curvature_mixed_areas(V, F):
    n = len(V)
    theta = np.zeros(n)
    area = np.zeros(n)
    ang = _corner_angles(V, F)
    l2 = np.stack([np.sum((V[F[:, (c + 1) % 3]] - V[F[:, (c + 2) % 3]]) ** 2, axis=1) for c in range(3)], axis=1)
    for f, tri in enumerate(F):
        Af = 0.5 * np.linalg.norm(np.cross(V[tri[1]] - V[tri[0]], V[tri[2]] - V[tri[0]]))
        for c in range(3):
            theta[tri[c]] += ang[f, c]
            j, k = (c + 1) % 3, (c + 2) % 3
            if ang[f].max() > np.pi / 2:
                area[tri[c]] += Af / 2 if ang[f, c] > np.pi / 2 else Af / 4
            else:
                area[tri[c]] += (l2[f, k] / np.tan(ang[f, k]) + l2[f, j] / np.tan(ang[f, j])) / 8
    K = (2 * np.pi - theta) / area
    K[_boundary_from_edges(F, n)] = np.nan
    return K


@student("fundamental_forms", named="F is left out")
def forms_no_F(a, b, c, u, v):
    I, II = _forms(a, b, c, u, v)
    I[0, 1] = I[1, 0] = 0  # "the parametrisation is orthogonal"
    return I, II


@student("fundamental_forms", named="E and G are exchanged (and e and g)")
def forms_u_v_derivatives_swapped(a, b, c, u, v):
    I, II = _forms(a, b, c, u, v)
    return I[::-1, ::-1], II[::-1, ::-1]


@student("normal_curvature", named="the mixed terms lack their factor 2")
def kappa_no_factor_two(forms, a, b, c, u, v, phi):
    E, F, G, e, f, g = _numbers(forms, a, b, c, u, v)
    s = np.sqrt(E * G - F * F)
    du = np.cos(phi) / np.sqrt(E) - np.sin(phi) * F / (np.sqrt(E) * s)
    dv = np.sin(phi) * np.sqrt(E) / s
    return (e * du**2 + f * du * dv + g * dv**2) / (E * du**2 + F * du * dv + G * dv**2)


@student("normal_curvature", named="already in radians")
def kappa_degrees(forms, a, b, c, u, v, phi):
    return kappa_tangent(forms, a, b, c, u, v, phi * np.pi / 180)


@student("cotangent_matrix", named="without the 1/2")
def cotmatrix_edge_dict(l, F):
    n = F.max() + 1
    cot = _cot_weights(l)
    opposite = {}
    for f, tri in enumerate(F):
        for i in range(3):
            edge = tuple(sorted((tri[(i + 1) % 3], tri[(i + 2) % 3])))
            opposite.setdefault(edge, []).append(cot[f, i])
    C = np.zeros((n, n))
    for (j, k), cots in opposite.items():
        w = 0.5 * (cots[0] + cots[1]) if len(cots) == 2 else cots[0]  # one triangle: its cot
        C[j, k] = C[k, j] = w
    C[np.diag_indices(n)] = -C.sum(axis=1)
    return C


@student("cotangent_matrix", named="not of the corner opposite it")
def cotmatrix_edge_of_corner(l, F):
    # reads l[:, i] as the edge from corner i to corner i + 1
    n = F.max() + 1
    cot = _cot_weights(l)
    C = np.zeros((n, n))
    for i in range(3):
        a, b = F[:, i], F[:, (i + 1) % 3]
        np.add.at(C, (a, b), cot[:, i] / 2)
        np.add.at(C, (b, a), cot[:, i] / 2)
    return C - np.diag(C.sum(axis=1))


@student("mixed_areas", named="applied only at the obtuse corner")
def mixed_only_obtuse_corner(V, F):
    A = np.zeros(len(V))
    ang = _corner_angles(V, F)
    l2 = edge_lengths(V, F) ** 2
    for f, tri in enumerate(F):
        Af = np.linalg.norm(np.cross(V[tri[1]] - V[tri[0]], V[tri[2]] - V[tri[0]])) / 2
        for c in range(3):
            j, k = (c + 1) % 3, (c + 2) % 3
            if ang[f, c] > np.pi / 2:
                A[tri[c]] += Af / 2
            else:
                A[tri[c]] += (l2[f, k] / np.tan(ang[f, k]) + l2[f, j] / np.tan(ang[f, j])) / 8
    return A


@student("mixed_areas", named="mean of its triangles' pieces")
def mixed_mean(V, F):
    total = mixed_loop(V, F)
    count = np.bincount(F.ravel(), minlength=len(V))
    return total / count


@student("eigenpairs", named="the k largest")
def eigen_eigsh_default(M, C, k):
    d = sp.diags(1 / np.sqrt(M.diagonal()))
    vals, Z = spla.eigsh(-(d @ C @ d), k=k)  # which="LM" by default
    order = np.argsort(vals)
    return vals[order], d @ Z[:, order]


@student("eigenpairs", named="normalised in the plain dot product")
def eigen_unit_columns(M, C, k):
    lam, E = eigen_reduction_numpy(M, C, k)
    return lam, E / np.linalg.norm(E, axis=0)


@student("lam_max")
def lam_max_power_on_laplacian(M, C):
    # power iteration on -M^-1 C itself: not symmetric, but its eigenvalues are those of Q
    L = -(sp.diags(1 / M.diagonal()) @ C)
    x = np.linspace(1, 2, C.shape[0])
    prev = 0.0
    for _ in range(200000):
        y = L @ x
        mu = np.linalg.norm(y) / np.linalg.norm(x)
        x = y / np.linalg.norm(y)
        if abs(mu - prev) <= 1e-14 * mu:
            break
        prev = mu
    return mu


@student("lam_max", named="the sign of C is flipped")
def lam_max_sign(M, C):
    d = sp.diags(M.diagonal() ** -0.5)
    return spla.eigsh(d @ C @ d, k=1, which="LM")[0][0]


@student("lam_max", named="Gershgorin")
def lam_max_gershgorin(M, C):
    C = C.tocsr()
    bound = 0
    for i in range(C.shape[0]):
        bound = max(bound, np.abs(C[i].toarray()).sum() / M.diagonal()[i])
    return bound


@student("smoothing_loop", named="uniform operator")
def explicit_uniform(V, F, tau, N):
    M, C = laplacian(V, F)
    I = _interior(F, len(V))
    if tau >= _interior_limit(M.diagonal(), C.tocsr(), I):
        raise ValueError("tau past the limit")
    n = len(V)
    A = np.zeros((n, n))
    for f in F:
        for a in range(3):
            A[f[a], f[a - 1]] = A[f[a - 1], f[a]] = 1
    U = A - np.diag(A.sum(1))
    P = V.copy()
    for _ in range(N):
        P[I] += tau * (U[I] @ P) / A.sum(1)[I, None]
    return P


@student("smoothing_loop", named="multiplied by the vertex areas instead of divided")
def explicit_times_areas(V, F, tau, N):
    M, C = laplacian(V, F)
    I = _interior(F, len(V))
    if tau >= _interior_limit(M.diagonal(), C.tocsr(), I):
        raise ValueError("unstable step")
    P = V.copy()
    for _ in range(N):
        P[I] += tau * (M @ (C @ P))[I]
    return P


@student("smoothing_loop", named="changed its input V in place")
def explicit_overwrites_input(V, F, tau, N):
    M, C = laplacian(V, F)
    I = _interior(F, len(V))
    if tau >= _interior_limit(M.diagonal(), C.tocsr(), I):
        raise ValueError("tau >= 2/lambda_max")
    P = V  # no copy: the caller's V moves too
    for _ in range(N):
        P[I] += tau * (C.tocsr()[I] @ P) / M.diagonal()[I, None]
    return P


@student("implicit_loop", named="the sign of tau C is flipped")
def implicit_sign(V, F, tau, N):
    M, C = laplacian(V, F)
    C = C.tocsr()
    I = _interior(F, len(V))
    B = np.setdiff1d(np.arange(len(V)), I)
    m = M.diagonal()
    lu = spla.splu((sp.diags(m[I]) + tau * C[I][:, I]).tocsc())
    P = V.copy()
    for _ in range(N):
        P[I] = lu.solve(m[I, None] * P[I] - tau * (C[I][:, B] @ P[B]))
    return P


@student("implicit_loop", named="M is forgotten in the matrix and on the right")
def implicit_no_mass(V, F, tau, N):
    _, C = laplacian(V, F)
    C = C.tocsr()
    I = _interior(F, len(V))
    B = np.setdiff1d(np.arange(len(V)), I)
    A = (sp.identity(len(I)) - tau * C[I][:, I]).tocsc()
    P = V.copy()
    for _ in range(N):
        P[I] = spla.spsolve(A, P[I] + tau * C[I][:, B] @ P[B])
    return P


@student("add_noise", named="not Gaussian")
def noise_uniform(V, F, sigma, seed):
    rng = np.random.default_rng(seed)
    return V + sigma * _diag(V) * rng.uniform(-1, 1, V.shape) * np.sqrt(3)


@student("add_noise", named="its standard deviation is sigma itself")
def noise_unscaled(V, F, sigma, seed):
    return V + np.random.default_rng(seed).normal(scale=sigma, size=V.shape)


@student("denoising_metrics", named="not rooted")
def metrics_unrooted(V, V_clean, F):
    diag = np.linalg.norm(V_clean.max(axis=0) - V_clean.min(axis=0))
    n, n0 = _unit_normals(V, F), _unit_normals(V_clean, F)
    vols = [np.einsum("ij,ij->", X[F[:, 0]], np.cross(X[F[:, 1]], X[F[:, 2]])) / 6 for X in (V, V_clean)]
    return {
        "rms": np.mean(np.sum((V - V_clean) ** 2, axis=1)) / diag**2,
        "normal_mean": np.rad2deg(np.arccos(np.clip(np.sum(n * n0, axis=1), -1, 1))).mean(),
        "volume_change": (vols[0] - vols[1]) / abs(vols[1]),
    }


@student("denoising_metrics", named="divided by the new volume")
def metrics_over_new_volume(V, V_clean, F):
    diag = np.linalg.norm(V_clean.max(axis=0) - V_clean.min(axis=0))
    n, n0 = _unit_normals(V, F), _unit_normals(V_clean, F)
    vol, vol0 = (enclosed_volume(X, F) for X in (V, V_clean))
    return {
        "rms": np.sqrt(np.mean(np.sum((V - V_clean) ** 2, axis=1))) / diag,
        "normal_mean": np.rad2deg(np.arccos(np.clip(np.sum(n * n0, axis=1), -1, 1))).mean(),
        "volume_change": (vol - vol0) / vol,
    }


@student("denoising_experiment", named="the error is absolute")
def experiment_absolute(V_clean, F, sigma, tau, iterations, seeds):
    E = []
    for seed in seeds:
        P = implicit_smoothing(_noisy(V_clean, sigma, seed), F, tau, iterations)
        E.append(float(np.sqrt(np.mean(np.linalg.norm(P - V_clean, axis=1) ** 2))))
    return np.mean(E), np.std(E, ddof=1)


@student("denoising_sweep", named="N_best is one too many")
def sweep_count_from_one(W, F, V_clean, taus, iterations):
    tau_best, k, E = sweep(W, F, V_clean, taus, iterations)
    return tau_best, k + 1, E


@student("denoising_sweep", named="transposed")
def sweep_transposed(W, F, V_clean, taus, iterations):
    M, C = laplacian(W, F)
    E = np.zeros((iterations + 1, len(taus)))
    for j, tau in enumerate(taus):
        solve = spla.factorized((M - tau * C).tocsc())
        P = W.copy()
        E[0, j] = _rms(P, V_clean)
        for k in range(1, iterations + 1):
            P = np.column_stack([solve(M @ P[:, c]) for c in range(3)])
            E[k, j] = _rms(P, V_clean)
    k, j = np.unravel_index(E.argmin(), E.shape)
    return taus[j], k, E


# ============================================================================ the measures

EXERCISES = sorted({exercise for exercise, _, _ in CORPUS})
RIGHT = [(e, fn) for e, fn, named in CORPUS if named is None]
WRONG = [(e, fn, named) for e, fn, named in CORPUS if named is not None]


@functools.cache
def verdict(exercise, fn):
    """The check's result, once per routine (02's normal_curvature check takes seconds)."""
    return getattr(check, exercise).evaluate(fn, seed=SEED)


def test_the_corpus_covers_every_auto_graded_exercise():
    table = (Path(__file__).resolve().parents[1] / "docs" / "grading.md").read_text()
    rows = re.findall(r"^\| 0\d \| `(\w+)` \| (\d*) \|", table, flags=re.M)
    auto_graded = {name for name, points in rows if points}  # the rows with check points
    assert len(auto_graded) >= 15
    assert set(EXERCISES) == auto_graded
    assert len(CORPUS) >= 40
    for exercise in auto_graded:
        assert any(e == exercise for e, _ in RIGHT), exercise
        assert any(e == exercise for e, _, _ in WRONG), exercise


@pytest.mark.parametrize("exercise, fn", RIGHT, ids=[fn.__name__ for _, fn in RIGHT])
def test_a_right_routine_passes(exercise, fn):
    result = verdict(exercise, fn)
    assert result.passed, result.message


@pytest.mark.parametrize("exercise, fn, named", WRONG, ids=[fn.__name__ for _, fn, _ in WRONG])
def test_a_wrong_routine_fails(exercise, fn, named):
    assert not verdict(exercise, fn).passed


def test_most_wrong_routines_are_named_right():
    missed = []
    for exercise, fn, named in WRONG:
        result = verdict(exercise, fn)
        if named not in result.message or not result.partial:
            missed.append(f"{exercise}/{fn.__name__}: wanted {named!r}, got {result.message}")
    share = 1 - len(missed) / len(WRONG)
    assert share >= NAMED_GOAL, f"{share:.0%} named; missed:\n" + "\n".join(missed)
