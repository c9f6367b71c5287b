"""Checks of the exercises of notebook 01: the uniform Laplacian, its signed mean curvature and the angle-deficit
Gaussian curvature.

Each check runs the learner's function on a closed mesh whose valences are all equal (a tetrahedron), an
open one (a grid: boundary vertices and edges), and a closed one whose valences differ and which holds
obtuse triangles (a jittered icosphere), each placed anew every run (``meshes.placed``). The typical
mistakes are the catalogues below (``check.catalogue``): one is named only when the learner's answer
matches it on all the meshes and it differs from the right answer on one, so mistakes that coincide on a
single mesh (the mean and a ninth of the incident areas on a tetrahedron; -valence and -number of
triangles on a closed mesh) are told apart by the others.
"""

import numpy as np

from ...lessons.curvature import angle_deficit, boundary_mask, signed_mean_curvature
from ...lessons.curvature import gaussian_curvature as geomlib_gaussian_curvature
from ...lessons.laplace import barycentric_areas, laplacian
from ...mesh.geometry import face_cross, face_normals
from .area_mistakes import AREA_MISTAKES
from .catalogue import Case, Wrong, agree, first_mistake, judge, matrix_pair, mesh_cases, run, vector
from .meshes import bump_4x4, corner_tetrahedron, grid_3x3, jittered_icosphere
from .result import case_rng, exercise

__all__ = ["gaussian_curvature", "mean_curvature", "uniform_laplacian"]

# the rules in the learner's own terms, for the hints
_C_RULE = "C_ij = 1 for each edge ij (however many triangles share it), C_ii = -(number of neighbours of i)"
_M_RULE = "M = diag(valence), the number of neighbours of each vertex"


def _uniform_facts(V, F):
    """The right dense M and C, the adjacency A (1 per edge), D (how many triangles list i -> j), the
    triangles at each vertex, the cotangent pair."""
    n = len(V)
    M, C = (X.toarray() for X in laplacian(V, F, weights="uniform"))
    D = np.zeros((n, n))
    for a, b in ((0, 1), (1, 2), (2, 0)):
        np.add.at(D, (F[:, a], F[:, b]), 1.0)
    M_cot, C_cot = (X.toarray() for X in laplacian(V, F))
    triangles = np.bincount(F.ravel(), minlength=n).astype(float)
    return dict(
        M=M, C=C, A=C - np.diag(np.diag(C)), valence=np.diag(M), D=D, M_cot=M_cot, C_cot=C_cot, triangles=triangles
    )


_TETRAHEDRON, _ICOSPHERE = ("a tetrahedron", corner_tetrahedron()), ("a jittered icosphere", jittered_icosphere())


def uniform_cases(rng):
    """The cases of ``uniform_laplacian``, placed with ``rng``."""
    return mesh_cases((_TETRAHEDRON, ("a 3 x 3 grid", grid_3x3()), _ICOSPHERE), rng, _uniform_facts)


C_MISTAKES = [
    Wrong("the sign of C is flipped", _C_RULE + ", so that C is negative semidefinite", build=lambda c: -c.C),
    Wrong(
        "the diagonal of C is missing (its rows do not sum to zero)",
        "set C_ii = -(number of neighbours of i)",
        build=lambda c: c.A,
    ),
    Wrong(
        "the diagonal of C has the wrong sign (+valence)", "C_ii = -valence", build=lambda c: c.A + np.diag(c.valence)
    ),
    Wrong(
        "C is already divided by the valence: that is the Laplacian M^-1 C, not C",
        "keep C_ij = 1 and put the valences in M",
        build=lambda c: c.C / c.valence[:, None],
    ),
    Wrong(
        "an edge counts once per triangle: 2 on edges inside the mesh, 1 on boundary edges",
        "each interior edge lies in two triangles; set its entry to 1, do not add",
        build=lambda c: c.D + c.D.T - np.diag((c.D + c.D.T).sum(axis=1)),
    ),
    Wrong(
        "the diagonal counts the triangles at a vertex, not its neighbours (the two differ at the boundary)",
        "C_ii = -(number of neighbours of i): a boundary vertex has one neighbour more than triangles",
        build=lambda c: c.A - np.diag(c.triangles),
    ),
    Wrong(
        "each edge is entered only in the direction the triangles list it, so a boundary edge gets one entry "
        "and C is not symmetric",
        "set both C_ij and C_ji for every edge",
        build=lambda c: c.D - np.diag(c.D.sum(axis=1)),
    ),
    Wrong(
        "C holds the cotangent weights (notebook 03's operator), not 1 per edge",
        "the uniform Laplacian ignores the geometry: " + _C_RULE,
        build=lambda c: c.C_cot,
    ),
    Wrong(
        "C holds diag(1/valence), the inverse of M, not the weights: the factors of M^-1 C handed in the wrong slots",
        "return M, C with M = diag(valence) and " + _C_RULE,
        build=lambda c: np.diag(1 / c.valence),
    ),
    Wrong("(M, C) are swapped: C holds diag(valence)", "end with `return M, C`: M first", build=lambda c: c.M),
    Wrong(
        "C is not symmetric on {label}", "set both C_ij and C_ji for every edge", when=lambda C, _, c: not agree(C, C.T)
    ),
    Wrong("C differs from the uniform Laplacian on {label}", _C_RULE, typical=False),
]
M_MISTAKES = [
    Wrong("M is the identity", _M_RULE, build=lambda c: np.eye(len(c.V))),
    Wrong("M has the wrong sign", "M holds positive valences", build=lambda c: -c.M),
    Wrong("M holds 1/valence: that is M^-1, not M", _M_RULE, build=lambda c: np.diag(1 / c.valence)),
    Wrong(
        "M counts the triangles at a vertex, not its neighbours (the two differ at the boundary)",
        _M_RULE,
        build=lambda c: np.diag(c.triangles),
    ),
    Wrong("M holds vertex areas (the cotangent Laplacian's M), not the valences", _M_RULE, build=lambda c: c.M_cot),
    Wrong("M differs from diag(valence) on {label}", _M_RULE, typical=False),
]


@exercise(
    "uniform_laplacian",
    reread="section 2 · The uniform Laplacian, derived",
    forbid=("lessons.laplace.uniform_laplacian", "lessons.laplace.laplacian", "lessons.laplace.uniform_adjacency"),
)
def uniform_laplacian(fn):
    """Check ``fn(V, F) -> (M, C)``: C_ij = 1 on edges, C_ii = -valence, M = diag(valence)."""
    cases = uniform_cases(case_rng())
    answers = run(fn, cases, matrix_pair)
    judge(C_MISTAKES, cases, [C for _, C in answers], right=lambda c: c.C)
    judge(M_MISTAKES, cases, [M for M, _ in answers], right=lambda c: c.M)
    return [c.label for c in cases]


def _normal_sums(V, F, per_face):
    """(n, 3): at each vertex, the sum of ``per_face`` (m, 3) over the faces at it."""
    return np.stack([np.bincount(F.ravel(), np.repeat(per_face[:, k], 3), minlength=len(V)) for k in range(3)], 1)


def mean_facts(V, F, M, C):
    """The right H and what the mistakes are made of: Delta x, the normal sums, the boundary."""
    A = M.diagonal()
    N2, N1 = _normal_sums(V, F, face_cross(V, F)), _normal_sums(V, F, face_normals(V, F))
    facts = dict(H=signed_mean_curvature(V, F, M, C), DX=(C @ V) / A[:, None], CX=C @ V, N2=N2)
    facts.update(N=N2 / np.linalg.norm(N2, axis=1)[:, None], N1=N1 / np.linalg.norm(N1, axis=1)[:, None])
    return dict(facts, boundary=boundary_mask(V, F))


def mean_cases(rng):
    """The cases of ``mean_curvature``, placed with ``rng``: three meshes with their uniform (M, C), and the
    icosphere with its cotangent (M, C), so that M is read from the input, not rebuilt from the valences."""
    meshes = (_TETRAHEDRON, ("a bump on a 4 x 4 grid", bump_4x4()), _ICOSPHERE, _ICOSPHERE)
    cases = []
    for k, c in enumerate(mesh_cases(meshes, rng)):
        cotan = k == 3
        M, C = laplacian(c.V, c.F) if cotan else laplacian(c.V, c.F, weights="uniform")
        label = c.label + (" with the cotangent (M, C)" if cotan else "")
        cases.append(Case(label, V=c.V, F=c.F, M=M, C=C).but(**mean_facts(c.V, c.F, M, C)))
    return cases


def _normal_part(X, N):
    return -0.5 * np.einsum("ij,ij->i", X, N)


_H_RULE = "H_i = -1/2 <(M^-1 C x)_i, n_i>, n_i the normalised sum of the cross products of the faces at i"
H_MISTAKES = [
    Wrong(
        "H has the wrong sign: the normals point inward, or the minus sign of -1/2 <M^-1 C x, n> is missing",
        "each face's (x_j - x_i) x (x_k - x_i), in the order F lists it, points outward; H > 0 on a sphere",
        build=lambda c: -c.H,
    ),
    Wrong("the factor 1/2 is missing", _H_RULE, build=lambda c: 2 * c.H),
    Wrong(
        "M^-1 is missing: C x sums the neighbours' differences, M^-1 C x is the Laplacian",
        "divide row i of C x by M_ii",
        build=lambda c: _normal_part(c.CX, c.N),
    ),
    Wrong(
        "the normals are not normalised (the sum of the cross products has length twice the fan's area)",
        "divide each vertex's sum of cross products by its length",
        build=lambda c: _normal_part(c.DX, c.N2),
    ),
    Wrong(
        "H is unsigned: 1/2 |M^-1 C x| drops the side the surface bends to",
        "project onto the normal: " + _H_RULE,
        build=lambda c: 0.5 * np.linalg.norm(c.DX, axis=1),
    ),
    Wrong(
        "the normals average the unit face normals (equal weights), not the area-weighted sum asked for",
        "sum the cross products themselves, whose length is twice each face's area, and normalise the sum",
        build=lambda c: _normal_part(c.DX, c.N1),
    ),
    Wrong("H differs from -1/2 <M^-1 C x, n> at interior vertices of {label}", _H_RULE, typical=False),
]
H_BOUNDARY_MISTAKES = [
    Wrong(
        "the formula is applied at boundary vertices (no boundary rule)",
        "the one-ring of a boundary vertex is open, M^-1 C x points along the surface there: return NaN",
        build=lambda c: _normal_part(c.DX, c.N),
    ),
    Wrong("boundary vertices have a value (the wrong boundary rule)", "return NaN (np.nan) at boundary vertices"),
]


@exercise(
    "mean_curvature",
    reread="section 4 · The signed mean curvature",
    forbid=(
        "lessons.curvature.signed_mean_curvature",
        "lessons.curvature.mean_curvature",
        "mesh.geometry.vertex_normals",
        "mesh.geometry.face_normals",
    ),
    allow=("lessons.curvature.boundary_mask",),
)
def mean_curvature(fn):
    """Check ``fn(V, F, M, C) -> (n,)``: H_i = -1/2 <(M^-1 C x)_i, n_i>, n_i area-weighted, NaN on the boundary."""
    cases = mean_cases(case_rng())
    Hs = run(fn, cases, vector)
    judge(H_MISTAKES, [c.but(where=~c.boundary) for c in cases], Hs, lambda c: c.H)
    judge(H_BOUNDARY_MISTAKES, [c.but(where=c.boundary) for c in cases], Hs, lambda c: c.H)
    return [c.label for c in cases]


def curvature_cases(rng):
    """The cases of ``gaussian_curvature``, placed with ``rng``: the bump is open, so that interior K is
    clearly non-zero and the boundary rule matters (valences 2 to 4 along its boundary, 6 inside)."""
    meshes = (_TETRAHEDRON, ("a bump on a 4 x 4 grid", bump_4x4()), _ICOSPHERE)
    facts = dict(K=geomlib_gaussian_curvature, A=barycentric_areas, deficit=angle_deficit, boundary=boundary_mask)
    return mesh_cases(meshes, rng, lambda V, F: {name: f(V, F) for name, f in facts.items()})


# Legitimate rounding: pi to 7 digits moves a deficit by 7e-7, single-precision angles by about 1e-6. K is
# compared in the deficit's own unit (K_i A_i, radians), so a vertex whose deficit is small is not held to a
# relative tolerance its rounding cannot meet; the mistakes below change a deficit by a tenth or more.
_DEFICIT_TOL = 1e-5


def same_K(K, K_ref, case):
    """K and K_ref agree on ``case.where`` to _DEFICIT_TOL radians of angle deficit (NaN agrees with NaN)."""
    K, K_ref, A = K[case.where], K_ref[case.where], case.A[case.where]
    both_nan = np.isnan(K) & np.isnan(K_ref)
    near = np.abs(K - K_ref) * A <= _DEFICIT_TOL + 1e-6 * np.abs(K_ref * A)
    return bool(np.all(both_nan | near))


def _index_order_sums(c):
    """2 pi - the angles at each vertex between its neighbours in index order, the last to the first."""
    ring = [set() for _ in range(len(c.V))]
    for i, j, k in c.F:
        ring[i] |= {j, k}
        ring[j] |= {k, i}
        ring[k] |= {i, j}
    total = np.zeros(len(c.V))
    for i, around in enumerate(ring):
        e = c.V[sorted(around)] - c.V[i]
        e /= np.linalg.norm(e, axis=1, keepdims=True)
        total[i] = np.arccos(np.clip(np.einsum("ij,ij->i", e, np.roll(e, -1, axis=0)), -1, 1)).sum()
    return 2 * np.pi - total


K_MISTAKES = [
    Wrong(
        "the sign of the deficit is flipped (sum of angles - 2 pi)",
        "K_i = (2 pi - sum of angles) / A_i: positive where the angles around i sum to less than 2 pi "
        "(the fan, laid flat, leaves a gap), as on a sphere",
        build=lambda c: -c.K,
    ),
    Wrong(
        "the angles are in degrees (360 - sum of angles)",
        "use radians: 2 pi - sum of angles, with np.arccos giving radians",
        build=lambda c: 180 / np.pi * c.K,
    ),
    Wrong(
        "the deficit is not divided by the vertex area (integrated, not pointwise, K)",
        "divide 2 pi - sum of angles by A_i",
        build=lambda c: c.deficit,
    ),
    Wrong(
        "the angles are taken between neighbours in index order, not in the ring order around the vertex: two "
        "neighbours next to each other in a sorted list need not share a triangle with it",
        "sum the angles of the triangles at i, one per face (each face gives its corner angle at i)",
        build=lambda c: _index_order_sums(c) / c.A,
    ),
    *(
        Wrong(area.diagnosis, area.hint, build=lambda c, area=area: c.deficit / area.build(c))
        for area in AREA_MISTAKES["barycentric"]
    ),
    Wrong(
        "K differs from the angle-deficit curvature at interior vertices of {label}",
        "K_i = (2 pi - sum of the angles at i) / (a third of the incident triangle areas)",
        typical=False,
    ),
]
K_BOUNDARY_MISTAKES = [
    Wrong(
        "the interior formula is applied at boundary vertices (no boundary rule)",
        "the fan of a boundary vertex is open: there 2 pi - sum of angles is pi plus the boundary's turning "
        "angle, not curvature; return NaN there",
        build=lambda c: c.deficit / c.A,
    ),
    Wrong(
        "boundary vertices have a value (the wrong boundary rule)",
        "K is not defined at a boundary vertex: return NaN there (np.nan)",
    ),
]


@exercise(
    "gaussian_curvature",
    reread="section 3 · Gaussian curvature from the angle deficit",
    forbid=(
        "lessons.curvature.gaussian_curvature",
        "lessons.curvature.angle_deficit",
        "lessons.curvature.angle_sums",
        "lessons.curvature.angle_and_area_sums",
        "lessons.curvature.corner_angles",
        "lessons.laplace.barycentric_areas",
        "lessons.laplace.vertex_areas",
    ),
    own=("lessons.curvature.gaussian_curvature", "lessons.curvature.angle_deficit"),
    allow=("lessons.curvature.boundary_mask",),
)
def gaussian_curvature(fn):
    """Check ``fn(V, F) -> (n,)``: K_i = (2 pi - sum of angles) / (a third of the incident areas), NaN on the boundary."""
    cases = curvature_cases(case_rng())
    Ks = run(fn, cases, vector)
    mistake = first_mistake(K_MISTAKES, [c.but(where=~c.boundary) for c in cases], Ks, lambda c: c.K, same_K)
    if mistake is not None:
        valued = [c.label for c, K in zip(cases, Ks) if np.isfinite(K[c.boundary]).any()]
        if not mistake.typical and valued:
            mistake.diagnosis += f"; and boundary vertices of {valued[0]} have values, where K is not defined (NaN)"
        raise mistake
    judge(K_BOUNDARY_MISTAKES, [c.but(where=c.boundary) for c in cases], Ks, lambda c: c.K, same_K)
    return [c.label for c in cases]
