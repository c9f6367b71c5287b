"""A simulated class handing in notebook 01: who wrote what, and what the class report must say.

Twenty-two students, each answer written in their own way (so that no two honest students
share their code): honest students, the typical mistakes the checks name (the sign of C,
M the identity, no boundary rule for K, degrees), catch-alls, a forbidden call, copies of
the solution notebook's answer and of geomlib's routine, two near-identical pairs and
untouched stubs. :data:`CLASS` maps each student to their two functions' bodies (None: the
stub left as released) and whether they wrote the discussion; :data:`EXPECTED` is what the
report must count; :data:`FLAGGED` who must be flagged, and nobody else.
"""

import inspect
import textwrap

UNIFORM = "uniform_laplacian"
GAUSSIAN = "gaussian_curvature"
DISCUSSION = "uniform_curvature_discussion"

# ---------------------------------------------------------------------------
# uniform_laplacian, written nine ways
# ---------------------------------------------------------------------------

U_EDGE_SET = """
n = len(V)
edges = set()
for a, b, c in F:
    for i, j in ((a, b), (b, c), (c, a)):
        edges.add((min(i, j), max(i, j)))
rows = [i for i, j in edges] + [j for i, j in edges]
cols = [j for i, j in edges] + [i for i, j in edges]
A = sparse.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
deg = np.asarray(A.sum(axis=1)).ravel()
D = sparse.diags(deg)
return D, {C}
"""

U_LIL = """
n = V.shape[0]
A = sparse.lil_matrix((n, n))
for tri in F:
    for k in range(3):
        A[tri[k], tri[(k + 1) % 3]] = 1
        A[tri[(k + 1) % 3], tri[k]] = 1
A = A.tocsr()
valence = np.array(A.sum(1)).flatten()
M = {M}
C = {C}
return M, C
"""

U_UNIQUE = """
E = np.sort(np.vstack([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
E = np.unique(E, axis=0)
n = len(V)
both = (np.r_[E[:, 0], E[:, 1]], np.r_[E[:, 1], E[:, 0]])
adj = sparse.coo_matrix((np.ones(2 * len(E)), both), shape=(n, n)).tocsr()
d = np.bincount(E.ravel(), minlength=n).astype(float)
return sparse.diags(d), {C}
"""

U_DENSE = """
n = len(V)
A = np.zeros((n, n))
for face in F:
    i, j, k = face
    A[i, j] = A[j, i] = 1.0
    A[j, k] = A[k, j] = 1.0
    A[k, i] = A[i, k] = 1.0
C = {C}
M = np.diag(A.sum(axis=1))
return sparse.csr_matrix(M), sparse.csr_matrix(C)
"""

U_RINGS = """
neighbours = [set() for _ in range(len(V))]
for f in F:
    for a in f:
        for b in f:
            if a != b:
                neighbours[a].add(b)
rows, cols, vals = [], [], []
for i, ring in enumerate(neighbours):
    for j in ring:
        rows.append(i)
        cols.append(j)
        vals.append({s}1.0)
    rows.append(i)
    cols.append(i)
    vals.append({s_}float(len(ring)))
C = sparse.csr_matrix((vals, (rows, cols)), shape=(len(V), len(V)))
return sparse.diags([float(len(r)) for r in neighbours]), C
"""

U_PAIRS = """
n = len(V)
pairs = np.concatenate([F[:, [i, (i + 1) % 3]] for i in range(3)])
W = sparse.csr_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
W = (W + W.T).tocsr()
W.data[:] = 1.0
valence = W.getnnz(axis=1).astype(float)
return {M}, {C}
"""

U_DICT = """
count = {}
for f in F.tolist():
    for p, q in zip(f, f[1:] + f[:1]):
        count[(p, q)] = count[(q, p)] = 1.0
n = len(V)
keys = list(count)
A = sparse.coo_matrix(([count[k] for k in keys], ([k[0] for k in keys], [k[1] for k in keys])), shape=(n, n))
A = A.tocsr()
val = np.ravel(A.sum(axis=0))
return sparse.identity(n), A - sparse.diags(val)
"""

U_DOK = """
size = len(V)
L = sparse.dok_matrix((size, size))
for t in F:
    for u, w in [(t[0], t[1]), (t[1], t[2]), (t[0], t[2])]:
        L[u, w] = 1.0
        L[w, u] = 1.0
L = L.tocsr()
ones = np.ones(size)
degree = L @ ones
M = sparse.spdiags(degree, 0, size, size)
return sparse.eye(size), L - M
"""

# a catch-all: the diagonal is minus twice the valence (no typical mistake the check names)
U_KRON = """
n = len(V)
inc = np.zeros((len(F), n))
inc[np.arange(len(F))[:, None], F] = 1
A = (inc.T @ inc > 0).astype(float) - np.eye(n)
v = A.sum(axis=0)
return sparse.diags(v), sparse.csr_matrix(A - 2 * np.diag(v))
"""

# the near-identical pair's common answer (each hands in a version with other names and comments)
U_PAIR_A = """
n = len(V)
# stack the three edges of every triangle, both directions
src = np.concatenate([F[:, 0], F[:, 1], F[:, 2], F[:, 1], F[:, 2], F[:, 0]])
dst = np.concatenate([F[:, 1], F[:, 2], F[:, 0], F[:, 0], F[:, 1], F[:, 2]])
A = sparse.coo_matrix((np.ones(len(src)), (src, dst)), shape=(n, n)).tocsr()
A.data = np.minimum(A.data, 1.0)
val = np.asarray(A.sum(axis=1)).ravel()
M = sparse.diags(val)
C = A - M
return M, C
"""
U_PAIR_B = """
nv = len(V)
a = np.concatenate([F[:, 0], F[:, 1], F[:, 2], F[:, 1], F[:, 2], F[:, 0]])
b = np.concatenate([F[:, 1], F[:, 2], F[:, 0], F[:, 0], F[:, 1], F[:, 2]])
adjacency = sparse.coo_matrix((np.ones(len(a)), (a, b)), shape=(nv, nv)).tocsr()
adjacency.data = np.minimum(adjacency.data, 1.0)   # an edge shared by two triangles counts once
valence = np.asarray(adjacency.sum(axis=1)).ravel()
Mass = sparse.diags(valence)
Lap = adjacency - Mass
return Mass, Lap
"""

U_FORBIDDEN = """
from geomlib.lessons.laplace import uniform_laplacian
return uniform_laplacian(V, F)
"""

# ---------------------------------------------------------------------------
# gaussian_curvature, written seven ways
# ---------------------------------------------------------------------------

G_LOOP = """
n = len(V)
angle_total = np.zeros(n)
area = np.zeros(n)
for f in F:
    P = V[f]
    face_area = 0.5 * np.linalg.norm(np.cross(P[1] - P[0], P[2] - P[0]))
    for c in range(3):
        u = P[(c + 1) % 3] - P[c]
        w = P[(c + 2) % 3] - P[c]
        angle_total[f[c]] += np.arctan2(np.linalg.norm(np.cross(u, w)), u @ w)
        area[f[c]] += face_area / 3
K = (2 * np.pi - angle_total) / area
K[boundary_mask(V, F)] = np.nan
return K
"""

G_COSINES = """
a = np.linalg.norm(V[F[:, 1]] - V[F[:, 2]], axis=1)
b = np.linalg.norm(V[F[:, 2]] - V[F[:, 0]], axis=1)
c = np.linalg.norm(V[F[:, 0]] - V[F[:, 1]], axis=1)
alpha = np.arccos(np.clip((b**2 + c**2 - a**2) / (2 * b * c), -1, 1))
beta = np.arccos(np.clip((a**2 + c**2 - b**2) / (2 * a * c), -1, 1))
gamma = np.pi - alpha - beta
s = (a + b + c) / 2
area = np.sqrt(np.maximum(s * (s - a) * (s - b) * (s - c), 0))
n = len(V)
sums = np.bincount(F.ravel(), weights=np.stack([alpha, beta, gamma], 1).ravel(), minlength=n)
A = np.bincount(F.ravel(), weights=np.repeat(area / 3, 3), minlength=n)
K = (2 * np.pi - sums) / A
K[boundary_mask(V, F)] = np.nan
return K
"""

G_EDGES = """
corners = [(0, 1, 2), (1, 2, 0), (2, 0, 1)]
theta = np.zeros(len(V))
third = np.zeros(len(V))
for i, j, k in corners:
    e1 = V[F[:, j]] - V[F[:, i]]
    e2 = V[F[:, k]] - V[F[:, i]]
    cross = np.cross(e1, e2)
    np.add.at(theta, F[:, i], np.arctan2(np.linalg.norm(cross, axis=1), (e1 * e2).sum(1)))
    np.add.at(third, F[:, i], np.linalg.norm(cross, axis=1) / 6.0)
E = np.sort(np.concatenate([F[:, :2], F[:, 1:], F[:, ::2]]), axis=1)
uniq, times = np.unique(E, axis=0, return_counts=True)
border = np.zeros(len(V), dtype=bool)
border[uniq[times == 1].ravel()] = True
out = (2 * np.pi - theta) / third
out[border] = np.nan
return out
"""

G_NOBOUNDARY_A = """
n = len(V)
angsum = np.zeros(n)
A = np.zeros(n)
for tri in F:
    for m in range(3):
        p, q, r = tri[m], tri[(m + 1) % 3], tri[(m + 2) % 3]
        x, y = V[q] - V[p], V[r] - V[p]
        angsum[p] += np.arccos(np.dot(x, y) / np.sqrt(np.dot(x, x) * np.dot(y, y)))
        A[p] += np.linalg.norm(np.cross(x, y)) / 6
return (2 * np.pi - angsum) / A
"""

G_NOBOUNDARY_B = """
P0, P1, P2 = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
def corner(o, s, t):
    return np.arccos(np.clip(np.einsum("ij,ij->i", s - o, t - o)
                             / np.linalg.norm(s - o, axis=1) / np.linalg.norm(t - o, axis=1), -1, 1))
angles = np.column_stack([corner(P0, P1, P2), corner(P1, P2, P0), corner(P2, P0, P1)])
twice_area = np.linalg.norm(np.cross(P1 - P0, P2 - P0), axis=1)
total = np.zeros(V.shape[0])
np.add.at(total, F, angles)
shares = np.zeros(V.shape[0])
np.add.at(shares, F, np.tile(twice_area[:, None] / 6, (1, 3)))
return (2 * np.pi - total) / shares
"""

G_DEGREES = """
deg_sum = np.zeros(len(V))
vertex_area = np.zeros(len(V))
for face in F:
    pts = V[face]
    ar = np.linalg.norm(np.cross(pts[1] - pts[0], pts[2] - pts[0])) / 2
    for t in range(3):
        d1 = pts[(t + 1) % 3] - pts[t]
        d2 = pts[(t + 2) % 3] - pts[t]
        cosang = d1.dot(d2) / (np.linalg.norm(d1) * np.linalg.norm(d2))
        deg_sum[face[t]] += np.degrees(np.arccos(cosang))
        vertex_area[face[t]] += ar / 3
res = (360 - deg_sum) / vertex_area
res[boundary_mask(V, F)] = np.nan
return res
"""

# a catch-all: K shifted by a constant
G_HALF = """
import math
result = []
for i in range(len(V)):
    mine = F[(F == i).any(axis=1)]
    total, area = 0.0, 0.0
    for f in mine:
        k = list(f).index(i)
        u, w = V[f[(k + 1) % 3]] - V[i], V[f[(k + 2) % 3]] - V[i]
        total += math.acos(max(-1.0, min(1.0, u @ w / math.hypot(*u) / math.hypot(*w))))
        area += math.hypot(*np.cross(u, w)) / 6
    result.append((2 * math.pi - total) / area + 0.5)
K = np.array(result)
K[boundary_mask(V, F)] = np.nan
return K
"""

G_PAIR_A = """
tri = V[F]
e0 = tri[:, 1] - tri[:, 0]
e1 = tri[:, 2] - tri[:, 1]
e2 = tri[:, 0] - tri[:, 2]
def ang(x, y):
    return np.arctan2(np.linalg.norm(np.cross(x, y), axis=1), np.sum(x * y, axis=1))
th = np.stack([ang(e0, -e2), ang(e1, -e0), ang(e2, -e1)], axis=1)
area = 0.5 * np.linalg.norm(np.cross(e0, -e2), axis=1)
S = np.bincount(F.ravel(), th.ravel(), len(V))
Ai = np.bincount(F.ravel(), np.repeat(area, 3) / 3, len(V))
K = (2 * np.pi - S) / Ai
K[boundary_mask(V, F)] = np.nan
return K
"""
G_PAIR_B = """
T = V[F]
d0 = T[:, 1] - T[:, 0]     # the three sides
d1 = T[:, 2] - T[:, 1]
d2 = T[:, 0] - T[:, 2]
def angle_between(p, q):
    return np.arctan2(np.linalg.norm(np.cross(p, q), axis=1), np.sum(p * q, axis=1))
corners = np.stack([angle_between(d0, -d2), angle_between(d1, -d0), angle_between(d2, -d1)], axis=1)
tri_area = 0.5 * np.linalg.norm(np.cross(d0, -d2), axis=1)
angle_sum = np.bincount(F.ravel(), corners.ravel(), len(V))
vertex_area = np.bincount(F.ravel(), np.repeat(tri_area, 3) / 3, len(V))
curv = (2 * np.pi - angle_sum) / vertex_area
curv[boundary_mask(V, F)] = np.nan
return curv
"""


def renamed_solution(body):
    """The solution notebook's answer with every variable renamed and the comments dropped."""
    names = {"theta_sum": "s", "A": "ar", "cos_theta": "co", "K": "out", "l": "r", "a": "u", "b": "w"}
    out = []
    for line in body.splitlines():
        line = line.split("#")[0].rstrip()
        for old, new in names.items():
            line = __import__("re").sub(rf"\b{old}\b", new, line)
        out.append(line)
    return "\n".join(out)


def geomlib_copy():
    """geomlib's uniform Laplacian pasted into the answer: the body of the routine that does the
    work, its docstring dropped and geomlib's edge table (which the ground rules refuse) rebuilt."""
    from geomlib.lessons import laplace

    source = inspect.getsource(laplace.graph_laplacian)
    body = textwrap.dedent(source.split('"""')[2].split("\n", 1)[1])
    body = body.replace(
        "edges(F)", "np.unique(np.sort(np.r_[F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]], axis=1), axis=0)"
    )
    return "n = len(V)\n" + body.replace("sp.", "sparse.")


SOLUTION = "solution"  # stands for the solution notebook's answer, verbatim
RENAMED = "renamed solution"  # the same with renamed variables

#: student -> (uniform_laplacian body, gaussian_curvature body, wrote the discussion);
#: None leaves the released stub
CLASS = {
    "honest_1": (U_EDGE_SET.replace("{C}", "A - D"), G_LOOP, True),
    "honest_2": (U_LIL.replace("{M}", "sparse.diags(valence)").replace("{C}", "A - M"), G_COSINES, True),
    "honest_3": (U_UNIQUE.replace("{C}", "adj - sparse.diags(d)"), G_EDGES, True),
    "sign_1": (U_DENSE.replace("{C}", "np.diag(A.sum(axis=1)) - A"), None, True),
    "sign_2": (U_RINGS.replace("{s}", "-").replace("{s_}", ""), None, False),
    "sign_3": (U_PAIRS.replace("{M}", "sparse.diags(valence)").replace("{C}", "sparse.diags(valence) - W"), None, True),
    "identity_1": (U_DICT, None, False),
    "identity_2": (U_DOK, None, True),
    "catch_all_1": (U_KRON, None, False),
    "boundary_1": (None, G_NOBOUNDARY_A, True),
    "boundary_2": (None, G_NOBOUNDARY_B, False),
    "degrees_1": (None, G_DEGREES, True),
    "catch_all_2": (None, G_HALF, False),
    "forbidden_1": (U_FORBIDDEN, None, False),
    "copy_solution": (SOLUTION, RENAMED, True),
    "copy_geomlib": ("geomlib", None, False),
    "pair_a1": (U_PAIR_A, None, True),
    "pair_a2": (U_PAIR_B, None, True),
    "pair_b1": (None, G_PAIR_A, False),
    "pair_b2": (None, G_PAIR_B, True),
    "stub_1": (None, None, False),
    "stub_2": (None, None, False),
}

SIGN = "the sign of C is flipped"
IDENTITY = "M is the identity"
NO_BOUNDARY = "the interior formula is applied at boundary vertices (no boundary rule)"
DEGREES = "the angles are in degrees (360 - sum of angles)"

#: (exercise, kind, diagnosis or None for any) -> students, as the class report must count them
EXPECTED = {
    (UNIFORM, "passed", None): {"honest_1", "honest_2", "honest_3", "copy_solution", "copy_geomlib", "pair_a1", "pair_a2"},
    (UNIFORM, "named mistake", SIGN): {"sign_1", "sign_2", "sign_3"},
    (UNIFORM, "named mistake", IDENTITY): {"identity_1", "identity_2"},
    (UNIFORM, "catch-all", None): {"catch_all_1"},
    (UNIFORM, "refused", None): {"forbidden_1"},
    (UNIFORM, "not written", None): {
        "boundary_1", "boundary_2", "degrees_1", "catch_all_2", "pair_b1", "pair_b2", "stub_1", "stub_2",
    },
    (GAUSSIAN, "passed", None): {"honest_1", "honest_2", "honest_3", "copy_solution", "pair_b1", "pair_b2"},
    (GAUSSIAN, "named mistake", NO_BOUNDARY): {"boundary_1", "boundary_2"},
    (GAUSSIAN, "named mistake", DEGREES): {"degrees_1"},
    (GAUSSIAN, "catch-all", None): {"catch_all_2"},
}  # fmt: skip

#: (student, exercise, flag): who must be flagged, and for what
FLAGGED = {
    ("copy_solution", UNIFORM, "copy of the solution notebook's answer"),
    ("copy_solution", GAUSSIAN, "copy of the solution notebook's answer"),
    ("copy_geomlib", UNIFORM, "copy of geomlib's own routine"),
    ("pair_a1", UNIFORM, "near-identical pair"),
    ("pair_a2", UNIFORM, "near-identical pair"),
    ("pair_b1", GAUSSIAN, "near-identical pair"),
    ("pair_b2", GAUSSIAN, "near-identical pair"),
}
