"""Ground rules: an allow-list. An answer may use numpy and scipy (sympy in 02) and the geomlib
routines its exercise hands it (``check.NAME.allow``); any other geomlib routine or a geometry
library fails the check with no points, named.

``SHORTCUTS`` holds, for every exercise of ``geomlib.check``, the shortest answer through
geomlib's own routine: a new exercise without one fails ``test_every_exercise_has_a_shortcut_here``.
``BREACHES`` holds answers through a routine the exercise's rules do not name (geomlib's helpers,
libigl, trimesh): refused all the same. The exercise text (tests/test_reading_path.py), the
sentence ``check.NAME.rules`` and the grading guide say the same thing.
"""

from pathlib import Path

import igl
import numpy as np
import pytest
import scipy.sparse as sp
import trimesh

import geomlib
import geomlib.lessons.filters as filters
import geomlib.lessons.smoothing as smoothing
import geomlib.lessons.spectral as spectral
import geomlib.lessons.symbolic as symbolic
import geomlib.numerics.eigen as eigen
from geomlib import check
from geomlib.lessons.laplace import FaceGeometry, face_geometry, intrinsic_cotangent_matrix, voronoi_pieces
from geomlib.mesh.topology import edges
from geomlib.numerics.eigen import largest_eigenpair
from geomlib.teaching.check.fence import Fence
from geomlib.teaching.check.result import reveal

SHORTCUTS = {
    "uniform_laplacian": lambda V, F: geomlib.laplacian(V, F, weights="uniform"),
    "gaussian_curvature": lambda V, F: geomlib.gaussian_curvature(V, F),
    "mean_curvature": lambda V, F, M, C: geomlib.mean_curvature(V, F, "uniform", signed=True, boundary="nan"),
    "cotangent_matrix": lambda l, F: intrinsic_cotangent_matrix(l, F),
    "mixed_areas": lambda V, F: geomlib.vertex_areas(V, F, area="mixed"),
    "discrete_principal_curvatures": lambda V, F, deficit: geomlib.lessons.curvature.mixed_principal_curvatures(
        V, F, deficit
    ),
    "spectral_reconstruction": lambda V, F, ks, solve: spectral.spectral_reconstructions(V, F, ks, solve),
    "eigenpairs": lambda M, C, k: spectral.eigenpairs(M, C, k),
    "lam_max": lambda M, C: eigen.largest_eigenvalue(
        -(sp.diags(M.diagonal() ** -0.5) @ C @ sp.diags(M.diagonal() ** -0.5))
    ),
    "implicit_loop": lambda V, F, tau, iterations: smoothing.implicit_smoothing(V, F, tau, iterations),
    "volume_kept": lambda P, F, V: smoothing.volume_rescaled(P, F, V),
    "smoothing_loop": lambda V, F, tau, iterations: geomlib.explicit_smoothing(V, F, tau, iterations),
    "add_noise": geomlib.add_noise,
    "denoising_metrics": geomlib.denoising_metrics,
    "denoising_experiment": geomlib.denoising_spread,
    "denoising_sweep": lambda W, F, V_clean, taus, iterations: geomlib.denoising_sweep(W, F, V_clean, taus, iterations),
    "taubin_smoothing": lambda V, F, tau_shrink, tau_inflate, pairs: geomlib.taubin_smoothing(
        V, F, tau_shrink, tau_inflate, pairs
    ),
    "normal_curvature": lambda forms, a, b, c, u, v, phi: symbolic.forms_normal_curvature(forms, a, b, c, u, v, phi),
    "fundamental_forms": lambda a, b, c, u, v: symbolic.ellipsoid_forms(a, b, c, u, v),
    "principal_curvatures": lambda I, II: symbolic.forms_principal_curvatures(I, II),
}


def exercises():
    return sorted(name for name in dir(check) if hasattr(getattr(check, name), "evaluate"))


def test_every_exercise_has_a_shortcut_here():
    assert sorted(SHORTCUTS) == exercises()


@pytest.mark.parametrize("name", exercises())
def test_the_geomlib_shortcut_earns_nothing_and_is_named(name):
    checker = getattr(check, name)
    assert checker.forbid, f"{name} names no routine its answer may not call"
    result = checker.evaluate(SHORTCUTS[name])
    assert not result.passed and not result.partial, result.message
    assert "calls geomlib's `" in result.message and "earns no points" in result.message, result.message
    named = result.message.split("`")[1]
    assert named not in {dotted.rpartition(".")[2] for dotted in checker.allow}
    assert checker.rules.startswith("Ground rules: ") and "no other geomlib routine" in checker.rules


def _edges_and_valence(V, F):
    from geomlib.mesh.topology import edges, valence

    E, n = edges(F), len(V)
    A = sp.coo_matrix((np.ones(2 * len(E)), (np.r_[E[:, 0], E[:, 1]], np.r_[E[:, 1], E[:, 0]])), (n, n))
    d = valence(F, n).astype(float)
    return sp.diags(d), (A - sp.diags(d)).tocsr()


def _trimesh_measure(V, F):
    from trimesh.curvature import discrete_gaussian_curvature_measure

    mesh = trimesh.Trimesh(V, F, process=False)
    return discrete_gaussian_curvature_measure(mesh, V, 0.0) / (mesh.area / len(V))


# answers through a routine no ground rule names: geomlib's helpers, libigl (compiled), trimesh
BREACHES = {
    "uniform_laplacian": (_edges_and_valence, "geomlib's `edges`"),
    "gaussian_curvature": (_trimesh_measure, "trimesh's `"),
    "cotangent_matrix": (lambda l, F: igl.cotmatrix_intrinsic(l, F), "libigl's `cotmatrix_intrinsic`"),
    "mixed_areas": (lambda V, F: voronoi_pieces(V, F).sum(axis=1)[F].ravel()[: len(V)], "geomlib's `voronoi_pieces`"),
    "lam_max": (lambda M, C: largest_eigenpair(-C.tocsr())[0], "geomlib's `largest_eigenpair`"),
}


@pytest.mark.parametrize("name", sorted(BREACHES))
def test_a_routine_outside_the_allow_list_earns_nothing_and_is_named(name):
    fn, named = BREACHES[name]
    result = getattr(check, name).evaluate(fn)
    assert not result.passed and not result.partial, result.message
    assert f"calls {named}" in result.message and "earns no points" in result.message, result.message


def test_the_guide_states_the_allow_list_in_the_checks_words():
    guide = " ".join((Path(__file__).resolve().parents[1] / "docs" / "grading.md").read_text().split())
    assert "The ground rules are an allow-list." in guide
    assert " ".join(check.mixed_areas.rules.split()) in guide


def test_a_call_hidden_in_a_helper_is_still_seen():
    def helper(V, F):
        return geomlib.mean_curvature(V, F)  # calls laplacian inside

    def answer(V, F):
        helper(V, F)
        return geomlib.laplacian(V, F, weights="uniform")

    result = check.uniform_laplacian.evaluate(answer)  # the first routine entered is named
    assert not result.passed and "`mean_curvature`" in result.message


# the ways into fenced code an answer might take: (answer of (V, F), the entry the fence must name)
WAYS_IN = {
    "a direct call": (lambda V, F: edges(F), "geomlib's `edges`"),
    "a lambda": (lambda V, F: (lambda G: edges(G))(F), "geomlib's `edges`"),
    "geomlib's generator, resumed": (lambda V, F: next(FaceGeometry.blocks(V, F)), "geomlib's `FaceGeometry.blocks`"),
    "geomlib's routine as numpy's callback": (
        lambda V, F: np.apply_along_axis(filters.mode_factor, 0, np.ones(3), 0.1, "explicit"),
        "geomlib's `mode_factor`",
    ),
    "a geometry library": (lambda V, F: trimesh.triangles.area(V[F]), "trimesh's `area`"),
}


def fence_hits(answer, allow=()):
    """The entries the fence names while ``answer`` runs on a tetrahedron (the fence as the checks arm it)."""
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    hits = []
    import sys

    sys.setprofile(Fence(allow).profile(hits.append))
    try:
        answer(V, F)
    finally:
        sys.setprofile(None)
    return hits


@pytest.mark.parametrize("way", sorted(WAYS_IN))
def test_the_fence_names_every_way_into_fenced_code(way):
    answer, named = WAYS_IN[way]
    assert fence_hits(answer)[:1] == [named]


def test_the_fence_lets_an_allowed_routine_use_its_helpers_and_numpy_pass():
    assert fence_hits(lambda V, F: face_geometry(V, F), allow=("lessons.laplace.face_geometry",)) == []
    assert fence_hits(lambda V, F: np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]))) == []


def power_iteration(M, C):
    d = M.diagonal() ** -0.5
    z, lam = np.random.default_rng(0).standard_normal(len(d)), 0.0
    for _ in range(20_000):
        Qz = -d * (C @ (d * z))
        lam, previous = z @ Qz / (z @ z), lam
        z = Qz / np.linalg.norm(Qz)
        if abs(lam - previous) <= 1e-12 * abs(lam):
            return lam
    return lam


def test_a_numpy_answer_is_not_refused_and_rules_leave_no_profile_behind():
    import sys

    assert check.lam_max.evaluate(power_iteration).passed
    assert sys.getprofile() is None


def test_reveal_waits_for_a_passing_answer(capsys, monkeypatch):
    def stub(M, C):
        raise NotImplementedError

    shown = []
    monkeypatch.setattr("IPython.display.display", lambda *objs, **kw: shown.extend(objs))
    assert reveal(stub, check.lam_max) is None and shown == []
    assert "once your stub passes" in capsys.readouterr().out
    assert reveal(power_iteration, check.lam_max) is None
    assert any("Lanczos" in obj._repr_html_() for obj in shown)
