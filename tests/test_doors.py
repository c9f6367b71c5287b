"""Validate once, compose unchecked: a public call checks its mesh once, at its door.

Every module's binding of ``as_mesh`` is replaced by a counting one; each public call of
DESIGN's contract must then run it exactly once, however many lessons it composes (before
this rule: 4 in ``laplacian``, 5 in ``mean_curvature``, 7 in ``explicit_smoothing``, 8 in
``spectral_reconstruction``). The smoothers and the spectral solve take a built operator
(M, C) too, and give the same answer with it as without.
"""

import importlib
import pkgutil
import warnings

import numpy as np
import pytest

import geomlib
from geomlib.mesh import validate
from geomlib.teaching.shapes import surfaces

LAYERS = ("geomlib.mesh", "geomlib.numerics", "geomlib.lessons")


@pytest.fixture
def as_mesh_calls(monkeypatch):
    """A list that grows by one at every call of as_mesh, from whichever module calls it."""
    for info in pkgutil.walk_packages(geomlib.__path__, "geomlib."):
        if info.name.startswith(LAYERS):
            importlib.import_module(info.name)
    original, calls = validate.as_mesh, []

    def counting(*args, **kwargs):
        calls.append(1)
        return original(*args, **kwargs)

    for name, module in list(importlib.sys.modules.items()):
        if name.startswith("geomlib") and getattr(module, "as_mesh", None) is original:
            monkeypatch.setattr(module, "as_mesh", counting)
    return calls


@pytest.fixture(scope="module")
def sphere():
    S = surfaces.sphere(1.0, subdivisions=2)
    return S.V, S.F


@pytest.fixture(scope="module")
def plane():
    S = surfaces.plane(n=8)
    return S.V, S.F


CALLS = {
    "laplacian": lambda V, F: geomlib.laplacian(V, F),
    "laplacian, mixed areas": lambda V, F: geomlib.laplacian(V, F, area="mixed"),
    "laplacian, uniform": lambda V, F: geomlib.laplacian(V, F, weights="uniform"),
    "mean_curvature": lambda V, F: geomlib.mean_curvature(V, F),
    "mean_curvature, signed, boundary nan": lambda V, F: geomlib.mean_curvature(V, F, signed=True, boundary="nan"),
    "gaussian_curvature": lambda V, F: geomlib.gaussian_curvature(V, F),
    "eigenbasis": lambda V, F: geomlib.eigenbasis(V, F, 5),
    "spectral_reconstruction": lambda V, F: geomlib.spectral_reconstruction(V, F, 5, cache=False),
    "explicit_smoothing": lambda V, F: geomlib.explicit_smoothing(V, F, 1e-4, 2),
    "explicit_smoothing, step fraction": lambda V, F: geomlib.explicit_smoothing(V, F, step_fraction=0.5),
    "implicit_smoothing": lambda V, F: geomlib.implicit_smoothing(V, F, 1e-3, 2),
    "add_noise": lambda V, F: geomlib.add_noise(V, F, 0.01, 1),
}


@pytest.mark.parametrize("mesh", ["sphere", "plane"])
@pytest.mark.parametrize("call", sorted(CALLS))
def test_a_public_call_checks_its_mesh_once(call, mesh, request, as_mesh_calls):
    V, F = request.getfixturevalue(mesh)
    as_mesh_calls.clear()  # the first use of a mesh fixture makes the mesh, which checks it
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        CALLS[call](V, F)
    assert len(as_mesh_calls) == 1, f"{call} on the {mesh} ran as_mesh {len(as_mesh_calls)} times"


def test_the_counter_counts(sphere, as_mesh_calls):
    # a lesson that checks twice must show as 2: the test above can fail
    V, F = sphere
    geomlib.laplacian(V, F)
    geomlib.laplacian(V, F)
    assert len(as_mesh_calls) == 2


def test_the_smoothers_take_a_built_operator(plane):
    V, F = plane
    V = V + np.random.default_rng(5).normal(0.0, 0.01, V.shape)
    M, C = geomlib.laplacian(V, F, weights="uniform")
    for smooth, tau in ((geomlib.explicit_smoothing, 0.3), (geomlib.implicit_smoothing, 2.0)):
        np.testing.assert_array_equal(smooth(V, F, tau, 3, operator=(M, C)), smooth(V, F, tau, 3, weights="uniform"))
    # a pair of another mesh's size is named, not stepped
    with pytest.raises(geomlib.MeshError, match="M and C must be square and of one size"):
        geomlib.explicit_smoothing(V[:-1], F[F.max(axis=1) < len(V) - 1], 0.1, 1, operator=(M, C))


def test_the_spectral_solve_takes_a_built_operator(sphere):
    V, F = sphere
    M, C = geomlib.laplacian(V, F, area="mixed")
    lam, E = geomlib.eigenbasis(V, F, 6, operator=(M, C))
    lam_mixed, E_mixed = geomlib.eigenbasis(V, F, 6, area="mixed")
    np.testing.assert_array_equal(lam, lam_mixed)
    np.testing.assert_array_equal(E, E_mixed)
