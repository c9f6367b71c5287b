"""The small meshes the exercise checks run on, named for what they are, and how a check places them.

Each function returns ``(V, F)``: float64 positions and int faces, counter-clockwise seen
from outside. A check runs on meshes whose valences differ, with a boundary and with obtuse
triangles, so that typical mistakes which coincide on one mesh are told apart by another.
:func:`placed` moves a mesh by a random similarity, away from the origin, with a small
jitter and its vertices renumbered: a check's cases differ from run to run, a right answer
does not care.
"""

import numpy as np

from ..shapes.surfaces import sphere

__all__ = [
    "corner_tetrahedron",
    "irregular_tetrahedron",
    "irregular_bipyramid",
    "obtuse_triangle",
    "grid_3x3",
    "jittered_grid_4x4",
    "bump_4x4",
    "jittered_icosphere",
    "placed",
]

_TET_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def _grid_faces(side):
    """Two triangles per square of a side x side vertex grid numbered row by row."""
    return np.array(
        [
            f
            for y in range(side - 1)
            for x in range(side - 1)
            for f in (
                [side * y + x, side * y + x + 1, side * (y + 1) + x + 1],
                [side * y + x, side * (y + 1) + x + 1, side * (y + 1) + x],
            )
        ]
    )


def corner_tetrahedron():
    """The corner of the unit cube: closed, valence 3 everywhere, three right angles at vertex 0."""
    return np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]), _TET_F.copy()


def irregular_tetrahedron():
    """Closed, valence 3 everywhere, every angle different and none right."""
    return np.array([[0.0, 0.0, 0.0], [1.3, 0.1, 0.0], [0.4, 1.1, 0.2], [0.3, 0.4, 0.9]]), _TET_F.copy()


def irregular_bipyramid():
    """A triangular bipyramid: closed, valences 3 and 4, three obtuse triangles."""
    V = np.array([[0.0, 0, 0], [2.2, 0.1, 0], [0.5, 1.2, 0.1], [0.9, 0.45, 0.3], [0.7, 0.5, -0.8]])
    return V, np.array([[0, 1, 3], [1, 2, 3], [2, 0, 3], [1, 0, 4], [2, 1, 4], [0, 2, 4]])


def obtuse_triangle():
    """One triangle, obtuse at vertex 2, area 2 (mixed areas A/4, A/4, A/2)."""
    return np.array([[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [1.0, 1.0, 0.0]]), np.array([[0, 1, 2]])


def grid_3x3():
    """A flat 3 x 3 vertex grid: open, valences 2 to 6, one interior vertex."""
    return np.array([[x, y, 0.0] for y in range(3) for x in range(3)]), _grid_faces(3)


def jittered_grid_4x4():
    """A 4 x 4 grid on z = 0.1 x y, jittered in the plane: open, valences 2 to 6, obtuse triangles."""
    rng = np.random.default_rng(3)
    V = np.array([[x, y, 0.1 * x * y] for y in range(4) for x in range(4)], dtype=float)
    V[:, :2] += rng.uniform(-0.3, 0.3, size=(16, 2))
    return V, _grid_faces(4)


def bump_4x4():
    """A 4 x 4 grid lifted into a Gaussian bump: open, interior K clearly non-zero, boundary valences 2 to 4."""
    V = np.array([[x, y, np.exp(-((x - 1.5) ** 2 + (y - 1.5) ** 2))] for y in range(4) for x in range(4)])
    return V, _grid_faces(4)


def jittered_icosphere():
    """42 vertices on the unit sphere, jittered: closed, valences 5 and 6, six obtuse triangles,
    every angle deficit at least 0.16."""
    s = sphere(1.0, subdivisions=1, jitter=0.3, seed=3)
    return s.V, s.F


def placed(V, F, rng, jitter=0.01):
    """``(V, F)`` moved by a random similarity (rotation, scale 1/2 to 2, a shift of 2 to 5 away from the
    origin along each axis), each vertex jittered by up to ``jitter`` of the mean edge length, and the
    vertices renumbered (F follows; the corners of each face keep their cyclic order)."""
    V, F = np.asarray(V, dtype=float), np.asarray(F)
    edges = V[F] - V[np.roll(F, 1, axis=1)]
    step = jitter * float(np.linalg.norm(edges, axis=2).mean())
    V = V + rng.uniform(-step, step, size=V.shape)
    Q, R = np.linalg.qr(rng.normal(size=(3, 3)))
    Q = Q * np.sign(np.diag(R))  # a uniformly random orthogonal matrix
    if np.linalg.det(Q) < 0:
        Q[:, 0] = -Q[:, 0]  # a rotation: the faces stay counter-clockwise seen from outside
    shift = rng.uniform(2.0, 5.0, size=3) * rng.choice([-1.0, 1.0], size=3)
    V = 2.0 ** rng.uniform(-1, 1) * V @ Q.T + shift
    order = rng.permutation(len(V))  # new vertex i is old vertex order[i]
    new = np.empty_like(order)
    new[order] = np.arange(len(V))
    F = np.roll(new[F], int(rng.integers(3)), axis=1)
    return V[order], F
