"""Notebooks 03 and 04 with a reader's inputs: other meshes, awkward files, each parameter at both ends.

Every run goes through the notebook's ``parameters`` cell (tests/notebook_runner.py) with strict claims
off: no run may raise, and where the text's claims do not hold for these inputs the notes must name
the cause. Runs are chosen to take different code paths at small sizes (the budget for this module is
about two minutes on a quiet machine); the convergence study of 03 runs on two or three coarse levels.
"""

import re

from awkward_meshes import cad_part, scan_with_holes, two_components, y_up_millimetres
from meshdata import COURSE, needs_course
from notebook_runner import ran

NB03, NB03A, NB04 = "03_cotangent_laplace.ipynb", "03a_dig_deeper_cotangent.ipynb", "04_spectral_reconstruction.ipynb"
NB04A = "04a_dig_deeper_spectral.ipynb"


def test_03_scan_with_small_jitter_and_low_ends(tmp_path):
    # issue 11: LEVELS = [2, 3, 4] with JITTER = 0.1 stopped at an AssertionError ('K', 'barycentric')
    run = ran(
        NB03,
        MESH=str(scan_with_holes(tmp_path)),
        LEVELS=[2, 3, 4],
        JITTER=0.1,
        VIEW_LEVEL=1,
        SADDLE_N=8,
        SADDLE_JITTER=0.0,
        AXES=(1.0, 0.7, 0.5),
    )
    run.assert_said(
        "12 vertices are not used by any face",
        "geomlib.mesh.repair.remove_unreferenced_vertices",
        "does not converge on jittered meshes",
        "JITTER = 0.1",
    )
    # the principal curvatures and the saddle are in the appendix
    run = ran(NB03A, MESH=str(scan_with_holes(tmp_path)), VIEW_LEVEL=1, SADDLE_N=8, SADDLE_JITTER=0.0)
    run.assert_said("12 vertices are not used by any face", "VIEW_LEVEL = 1", "SADDLE_JITTER = 0.0")


def test_03_two_components_sphere_axes_and_high_ends(tmp_path):
    run = ran(
        NB03,
        MESH=str(two_components(tmp_path)),
        LEVELS=[1],
        JITTER=0.4,
        AXES=(1.0, 1.0, 1.0),
        VIEW_LEVEL=5,
        SADDLE_N=200,
        SADDLE_JITTER=0.35,
        SEED=7,
    )
    run.assert_said("A slope needs at least two levels")
    assert not re.search(r"\bnan\b", run.outputs_text()), "a number printed as nan"
    run = ran(NB03A, MESH=str(two_components(tmp_path)), AXES=(1.0, 1.0, 1.0), VIEW_LEVEL=5, SADDLE_N=200, SEED=7)
    assert not re.search(r"\bnan\b", run.outputs_text()), "a number printed as nan"


def test_03_cad_part_long_ellipsoid(tmp_path):
    run = ran(
        NB03, MESH=str(cad_part(tmp_path)), LEVELS=[1, 2], AXES=(3.0, 1.0, 0.2), JITTER=0.3, VIEW_LEVEL=2, SADDLE_N=16
    )
    run.assert_said("over levels [1, 2]")


def test_04_scan_with_unused_vertices(tmp_path):
    # issue 11: unused vertices gave divide-by-zero warnings, NaN in S, then an assert
    for run in (
        ran(NB04, MESH=str(scan_with_holes(tmp_path)), K_VALUES=(1, 2, 30), SPHERE_LEVEL=3),
        ran(NB04A, MESH=str(scan_with_holes(tmp_path)), K_MAX=30, SMALL_LEVEL=0),  # k = n on 12 vertices
    ):
        run.assert_said("12 vertices are not used by any face", "geomlib.mesh.repair.remove_unreferenced_vertices")
        text = run.outputs_text()
        assert "divide by zero" not in text and "invalid value" not in text


def test_04_two_components_k_beyond_n_and_high_ends(tmp_path):
    run = ran(NB04, MESH=str(two_components(tmp_path)), K_VALUES=(5, 15, 5000), SPHERE_LEVEL=6)
    run.assert_said("at most 1284 eigenvectors exist; k is capped at 1284")
    run = ran(NB04A, MESH=str(two_components(tmp_path)), K_MAX=300, SMALL_LEVEL=3)  # k = n = 642 on the small mesh
    assert "1284 vertices; 300 eigenpairs" in run.outputs_text()


def test_04_y_up_millimetres(tmp_path):
    run = ran(NB04, MESH=str(y_up_millimetres(tmp_path)), UP="y", K_VALUES=(4, 40))
    assert "sphere_y_up_mm.obj" in run.outputs_text()


@needs_course
def test_03_course_lilium():
    ran(NB03, MESH=str(COURSE / "curvatures" / "lilium_s.obj"), LEVELS=[1, 2, 3])
    ran(NB03A, MESH=str(COURSE / "curvatures" / "lilium_s.obj"))


@needs_course
def test_04_course_armadillo_every_eigenvector():
    run = ran(NB04, MESH=str(COURSE / "decompose" / "armadillo.obj"), K_VALUES=(5, 15, 361))
    assert "armadillo.obj" in run.outputs_text()
