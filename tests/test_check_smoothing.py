"""The exercise checks of notebooks 05 and 06 (the loops and the volume kept): each accepts the reference solution and its
legitimate variants (power iteration or Lanczos; any way of holding the boundary; splu, a
dense solve or cg at its default tolerance, factorised once or every step), names every
entry of its catalogue of typical mistakes when a learner's code (written here with numpy
and scipy) makes it, refuses the shortcuts its ground rules exclude, and reports an
unwritten stub as "not written yet"."""

import numpy as np
import pytest
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from geomlib import boundary_vertices, check, laplacian
from geomlib.teaching.check.explicit import LAM_MAX_MISTAKES, LOOP_MISTAKES
from geomlib.teaching.check.implicit import IMPLICIT_MISTAKES, VOLUME_MISTAKES
from geomlib.teaching.check.meshes import jittered_icosphere


@pytest.fixture(autouse=True)
def lenient(monkeypatch):
    """Checks return their verdict instead of raising (the notebooks' reader mode)."""
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")


# --------------------------------------------------------------------------- lambda_max


def power(M, C, sign=1.0, exponent=-0.5, iterations=20_000, rtol=1e-12, limit=False, smallest=False):
    """A learner's power iteration on Q = -M^e C M^e, with the named changes."""
    d = M.diagonal() ** exponent
    Q = sp.diags(d) @ (-sign * C) @ sp.diags(d)
    if smallest:
        return float(sla.eigsh(Q, 1, which="SA")[0][0])
    z = np.random.default_rng(1).standard_normal(Q.shape[0])
    lam = 0.0
    for _ in range(iterations):
        Qz = Q @ z
        lam, previous = z @ Qz / (z @ z), lam
        z = Qz / np.linalg.norm(Qz)
        if abs(lam - previous) <= rtol * abs(lam):
            break
    return 2 / lam if limit else lam


def lanczos(M, C):
    d = 1 / np.sqrt(M.diagonal())
    Q = sla.LinearOperator(C.shape, matvec=lambda z: -d * (C @ (d * z)), dtype=float)
    return sla.eigsh(Q, 1, which="LA")[0][0]


def gershgorin(M, C):
    return np.max(np.asarray(abs(C).sum(axis=1)).ravel() / M.diagonal())


LAM_MAX_LEARNERS = {
    "the step limit 2 / lam_max": lambda M, C: power(M, C, limit=True),
    "the smallest eigenvalue was found": lambda M, C: power(M, C, smallest=True),
    "the sign of C is flipped": lambda M, C: power(M, C, sign=-1.0),
    "M is left out": lambda M, C: power(M, C, exponent=0.0),
    "M^-1 stands on both sides": lambda M, C: power(M, C, exponent=-1.0),
    "M multiplies instead of dividing": lambda M, C: power(M, C, exponent=0.5),
    "Gershgorin's bound": gershgorin,
    "stopped too early": lambda M, C: power(M, C, iterations=3),
    "differs from the largest eigenvalue": lambda M, C: 1.3 * power(M, C),
}


def test_power_iteration_and_lanczos_pass():
    assert check.lam_max.evaluate(power).passed
    assert check.lam_max.evaluate(lanczos).passed


@pytest.mark.parametrize("name", LAM_MAX_LEARNERS)
def test_each_lam_max_mistake_is_named(name):
    result = check.lam_max.evaluate(LAM_MAX_LEARNERS[name])
    assert not result.passed and name in result.message, result.message
    assert result.partial == (name != "differs from the largest eigenvalue")


def test_a_dense_or_generalised_solver_is_refused():
    dense = lambda M, C: np.linalg.eigvalsh(-C.toarray() / np.sqrt(np.outer(M.diagonal(), M.diagonal())))[-1]  # noqa: E731
    generalised = lambda M, C: scipy.linalg.eigh(-C.toarray(), M.toarray(), eigvals_only=True)[-1]  # noqa: E731
    for fn, name in ((dense, "numpy.linalg.eigvalsh"), (generalised, "scipy.linalg.eigh")):
        result = check.lam_max.evaluate(fn)
        assert not result.partial and f"calls {name}" in result.message, result.message


# --------------------------------------------------------------------------- the loops


def split(V, F):
    B = boundary_vertices(F, len(V))
    return np.setdiff1d(np.arange(len(V)), B), B


def explicit(
    V,
    F,
    tau,
    N,
    held=True,
    rebuild=False,
    weights="cotan",
    coupled=True,
    refuse=True,
    block=True,
    in_place=False,
    extra=0,
    scale=1.0,
    same_V=False,
):
    """A learner's explicit loop with the named changes."""
    I, B = split(V, F) if held else (np.arange(len(V)), [])
    M, C = laplacian(V, F, weights=weights)
    m_I, C_I = M.diagonal()[I], C.tocsr()[I]
    J = I if block else np.arange(len(V))  # the limit's rows and columns: the interior block, or the whole pair
    d = 1 / np.sqrt(M.diagonal()[J])
    if refuse and tau >= 2 / np.linalg.eigvalsh(-(d[:, None] * C.toarray()[np.ix_(J, J)] * d))[-1]:
        raise ValueError("past the limit")
    P = V if in_place else V.copy()
    for _ in range(N + extra):
        if rebuild:
            M, C = laplacian(P, F, weights=weights)
            m_I, C_I = M.diagonal()[I], C.tocsr()[I]
        step = (C_I @ P) if coupled else C_I[:, I] @ P[I]
        P[I] += scale * tau * step / m_I[:, None]
    return V.copy() if same_V else P


def explicit_areas(a):
    """The loop with C P multiplied by M^a (a = 0: M forgotten, a = 1: multiplied)."""

    def learner(V, F, tau, N):
        I, _ = split(V, F)
        M, C = laplacian(V, F)
        P = V.copy()
        for _ in range(N):
            P[I] += tau * (M.diagonal()[I] ** a)[:, None] * (C.tocsr()[I] @ P)
        return P

    return learner


LOOP_LEARNERS = {
    "no step was taken": lambda V, F, tau, N: explicit(V, F, tau, N, same_V=True),
    "one step too few": lambda V, F, tau, N: explicit(V, F, tau, N, extra=-1),
    "one step too many": lambda V, F, tau, N: explicit(V, F, tau, N, extra=1),
    "the boundary moves": lambda V, F, tau, N: explicit(V, F, tau, N, held=False),
    "rebuilt from the moving mesh": lambda V, F, tau, N: explicit(V, F, tau, N, rebuild=True),
    "sign of the step is flipped": lambda V, F, tau, N: explicit(V, F, tau, N, scale=-1.0),
    "half a step": lambda V, F, tau, N: explicit(V, F, tau, N, scale=0.5),
    "M is forgotten": explicit_areas(0.0),
    "multiplied by the vertex areas": explicit_areas(1.0),
    "uniform operator": lambda V, F, tau, N: explicit(V, F, tau, N, weights="uniform", refuse=False),
    "pull C_IB P_B is left out": lambda V, F, tau, N: explicit(V, F, tau, N, coupled=False),
    "changed its input V in place": lambda V, F, tau, N: explicit(V, F, tau, N, in_place=True),
    "ran instead of being refused": lambda V, F, tau, N: explicit(V, F, tau, N, refuse=False),
    "the whole pair (M, C), not from its interior block": lambda V, F, tau, N: explicit(V, F, tau, N, block=False),
}


def test_the_loop_and_its_variants_pass():
    assert check.smoothing_loop.evaluate(explicit).passed

    def put_back(V, F, tau, N):  # every vertex steps, the boundary put back after each step: fine
        I, B = split(V, F)
        M, C = laplacian(V, F)
        d = 1 / np.sqrt(M.diagonal()[I])
        if tau >= 2 / np.linalg.eigvalsh(-(d[:, None] * C.toarray()[np.ix_(I, I)] * d))[-1]:
            raise ValueError("past the limit")
        P = V.copy()
        for _ in range(N):
            P = P + tau * (C @ P) / M.diagonal()[:, None]
            P[B] = V[B]
        return P

    assert check.smoothing_loop.evaluate(put_back).passed


@pytest.mark.parametrize("name", LOOP_LEARNERS)
def test_each_loop_mistake_is_named(name):
    result = check.smoothing_loop.evaluate(LOOP_LEARNERS[name])
    assert not result.passed and result.partial and name in result.message, result.message


def implicit(
    V,
    F,
    tau,
    N,
    held=True,
    rebuild=False,
    sign=1.0,
    mass=True,
    rhs_mass=True,
    coupling=1.0,
    weights="cotan",
    solver="splu",
    extra=0,
    scale=1.0,
    every_step=False,
    same_V=False,
    in_place=False,
):
    """A learner's implicit loop with the named changes."""
    I, B = split(V, F) if held else (np.arange(len(V)), np.arange(0))
    tau = scale * tau
    P = V if in_place else V.copy()
    for k in range(N + extra):
        if k == 0 or rebuild or every_step:
            M, C = laplacian(P if rebuild else V, F, weights=weights)
            m, C_I = M.diagonal()[I], C.tocsr()[I]
            A = (sp.diags(m if mass else np.ones(len(I))) - sign * tau * C_I[:, I]).tocsc()
            if solver == "splu":
                solve = sla.splu(A).solve
            elif solver == "dense":
                solve = lambda R, A=A.toarray(): np.linalg.solve(A, R)  # noqa: E731
            else:
                solve = lambda R, A=A: np.column_stack([sla.cg(A, R[:, j])[0] for j in range(3)])  # noqa: E731
        P[I] = solve((m[:, None] if rhs_mass else 1.0) * P[I] + coupling * sign * tau * (C_I[:, B] @ P[B]))
    return V.copy() if same_V else P


IMPLICIT_LEARNERS = {
    "no step was taken": lambda V, F, tau, N: implicit(V, F, tau, N, same_V=True),
    "one step too few": lambda V, F, tau, N: implicit(V, F, tau, N, extra=-1),
    "one step too many": lambda V, F, tau, N: implicit(V, F, tau, N, extra=1),
    "the boundary moves": lambda V, F, tau, N: implicit(V, F, tau, N, held=False),
    "rebuilt from the moving mesh": lambda V, F, tau, N: implicit(V, F, tau, N, rebuild=True),
    "sign of tau C is flipped": lambda V, F, tau, N: implicit(V, F, tau, N, sign=-1.0),
    "half a step": lambda V, F, tau, N: implicit(V, F, tau, N, scale=0.5),
    "M is forgotten in the matrix: (I - tau C_II)": lambda V, F, tau, N: implicit(V, F, tau, N, mass=False),
    "forgotten in the matrix and on the right": lambda V, F, tau, N: implicit(V, F, tau, N, mass=False, rhs_mass=False),
    "holds P_I where M_II P_I belongs": lambda V, F, tau, N: implicit(V, F, tau, N, rhs_mass=False),
    "term tau C_IB P_B is missing": lambda V, F, tau, N: implicit(V, F, tau, N, coupling=0.0),
    "term has the wrong sign": lambda V, F, tau, N: implicit(V, F, tau, N, coupling=-1.0),
    "these are explicit steps": lambda V, F, tau, N: explicit(V, F, tau, N, refuse=False),
    "uniform operator": lambda V, F, tau, N: implicit(V, F, tau, N, weights="uniform"),
    "changed its input V in place": lambda V, F, tau, N: implicit(V, F, tau, N, in_place=True),
}


@pytest.mark.parametrize("solver", ["splu", "dense", "cg"])
@pytest.mark.parametrize("every_step", [False, True])
def test_the_implicit_loop_passes_with_any_fair_solver(solver, every_step):
    learner = lambda V, F, tau, N: implicit(V, F, tau, N, solver=solver, every_step=every_step)  # noqa: E731
    result = check.implicit_loop.evaluate(learner)
    assert result.passed, result.message


@pytest.mark.parametrize("name", IMPLICIT_LEARNERS)
def test_each_implicit_mistake_is_named(name):
    result = check.implicit_loop.evaluate(IMPLICIT_LEARNERS[name])
    assert not result.passed and result.partial and name in result.message, result.message


@pytest.mark.parametrize(
    "catalogue, learners",
    [(LAM_MAX_MISTAKES, LAM_MAX_LEARNERS), (LOOP_MISTAKES, LOOP_LEARNERS), (IMPLICIT_MISTAKES, IMPLICIT_LEARNERS)],
)
def test_every_named_mistake_of_a_catalogue_has_a_learner_here(catalogue, learners):
    for entry in catalogue:
        if entry.when is None and entry.build is None:
            continue
        if "boundary vertices moved" in entry.diagnosis:  # the general form of the named ways a boundary moves
            continue
        assert any(name in entry.diagnosis for name in learners), entry.diagnosis


@pytest.mark.parametrize("name", ["lam_max", "smoothing_loop", "implicit_loop", "volume_kept"])
def test_a_stub_is_not_written_yet(name):
    def stub(*args):
        raise NotImplementedError

    result = getattr(check, name).evaluate(stub)
    assert not result.passed and not result.written and "not written yet" in result.message


def test_the_checks_pass_whatever_the_seed():
    for seed in (0, 1, 2):
        assert check.lam_max.evaluate(power, seed=seed).passed
        assert check.smoothing_loop.evaluate(explicit, seed=seed).passed
        assert check.implicit_loop.evaluate(implicit, seed=seed).passed
        assert check.volume_kept.evaluate(rescaled, seed=seed).passed


# --------------------------------------------------------------------------- the volume kept


def rescaled(P, F, V, origin=None, cube=True, about_solid=True, back=True, sixth=True, corner=4.0):
    """A learner's volume rescaling: signed tetrahedra with ``origin`` (default the coordinate origin), with
    the named changes."""
    o = np.zeros(3) if origin is None else origin

    def solid(X):
        x0, x1, x2 = X[F[:, 0]] - o, X[F[:, 1]] - o, X[F[:, 2]] - o
        vol_f = np.linalg.det(np.stack([x0, x1, x2], axis=1)) / (6.0 if sixth else 1.0)
        return vol_f.sum(), o + (x0 + x1 + x2).T @ vol_f / (corner * vol_f.sum())

    (vol0, c0), (vol, c) = solid(V), solid(P)
    if not about_solid:
        c0, c = V.mean(axis=0), P.mean(axis=0)
    s = (vol0 / vol) ** (1 / 3 if cube else 1.0)
    return (c0 if back else c) + s * (P - c)


@pytest.mark.parametrize(
    "fn",
    [
        rescaled,
        lambda P, F, V: rescaled(P, F, V, origin=V[0]),  # the tetrahedra's apex at a vertex: the same solid
        lambda P, F, V: rescaled(P, F, V, sixth=False),  # the 1/6 cancels in the ratio and the centroid
        lambda P, F, V: rescaled(P, F, V).tolist(),  # a list of rows
    ],
)
def test_the_volume_kept_passes_correct_variants(fn):
    result = check.volume_kept.evaluate(fn, seed=4)
    assert result.passed and "icosphere" in result.message, result.message


VOLUME_LEARNERS = {
    "the volume ratio itself": lambda P, F, V: rescaled(P, F, V, cube=False),
    "not moved back": lambda P, F, V: rescaled(P, F, V, back=False),
    "means of the vertices": lambda P, F, V: rescaled(P, F, V, about_solid=False),
    "the fourth corner, the origin, is left out": lambda P, F, V: rescaled(P, F, V, corner=3.0),
    "returned as it came": lambda P, F, V: P,
}


@pytest.mark.parametrize("name", VOLUME_LEARNERS)
def test_each_volume_mistake_written_by_hand_is_named(name):
    result = check.volume_kept.evaluate(VOLUME_LEARNERS[name], seed=5)
    assert not result.passed and result.partial and name in result.message, result.message


@pytest.mark.parametrize("seed", [0, 1])
@pytest.mark.parametrize("entry", [e for e in VOLUME_MISTAKES if e.build is not None], ids=repr)
def test_every_wrong_rescaling_of_the_catalogue_gets_its_own_diagnosis(entry, seed):
    from diagnoses import replaying

    from geomlib.teaching.check.implicit import volume_kept_cases

    result = check.volume_kept.evaluate(
        replaying(volume_kept_cases(np.random.default_rng(seed)), entry.build), seed=seed
    )
    assert not result.passed and result.partial and entry.diagnosis in result.message, result.message


def test_the_volume_kept_holds_the_volume_and_the_centroid_it_claims():
    from geomlib.mesh.geometry import volume_and_centroid
    from geomlib.teaching.check.meshes import placed

    V, F = placed(*jittered_icosphere(), np.random.default_rng(2))
    P = 0.8 * V + np.array([1.0, -2.0, 0.5])
    vol0, c0 = volume_and_centroid(V, F)
    vol, c = volume_and_centroid(rescaled(P, F, V), F)
    assert abs(vol / vol0 - 1) < 1e-12 and np.allclose(c, c0, atol=1e-12)
