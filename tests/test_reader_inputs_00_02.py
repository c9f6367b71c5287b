"""Notebooks 00-02 with a reader's inputs: other meshes, awkward files, the course's meshes, each parameter
at both ends of its documented range. No run may raise; the notes a run shows must name their cause.

The runs are chosen to take different code paths (flat mesh, unused vertices and holes, two components,
a model in millimetres, coarse and fine resolutions, a spheroid); several parameters move together per run.
Notebook 01 and 00 share the cleaning step (geomlib.mesh.repair.prepare), so the scan with holes runs in 00 only.
"""

import json

import numpy as np
import sympy as sp
from meshdata import COURSE, ROOT, needs_course
from notebook_runner import Raw, ran

from geomlib.teaching.shapes import surfaces

NB00, NB01, NB02 = "00_getting_started.ipynb", "01_uniform_laplace_curvature.ipynb", "02_fundamental_forms.ipynb"
NB01A = "01a_dig_deeper_tessellation.ipynb"
NB02A = "02a_dig_deeper_principal_curvatures.ipynb"


def test_saddle_height_stated_in_01_is_the_code():
    """The height function notebook 01 states (a sympy expression it displays) is surfaces.saddle_height."""
    nb = json.loads((ROOT / "notebooks" / NB01).read_text(encoding="utf-8"))
    source = next("".join(c["source"]) for c in nb["cells"] if "SADDLE_HEIGHT =" in "".join(c["source"]))
    statement = next(line for line in source.splitlines() if line.startswith("SADDLE_HEIGHT ="))
    x, y, A, B = sp.symbols("x y A B", real=True)
    expression = sp.sympify(statement.split("=", 1)[1], locals={"x_": x, "y_": y, "mu_": A, "nu_": B, "sp": sp})
    h = sp.lambdify((x, y, A, B), expression, "numpy")
    rng = np.random.default_rng(0)
    x, y = rng.uniform(-1, 1, (2, 500))
    for A, B in ((0.2, 0.1), (1.0, 0.0), (-0.3, 0.7)):
        assert np.allclose(h(x, y, A, B), surfaces.saddle_height(x, y, amplitude=A, monkey=B), rtol=1e-13, atol=1e-15)
    # and it is not the sine bump the text used to state (they differ by up to 0.045 on the default grid)
    sine = 0.2 * np.sin(np.pi * x) * np.sin(np.pi * y) + 0.1 * (x**3 - 3 * x * y**2)
    assert np.abs(sine - h(x, y, 0.2, 0.1)).max() > 0.01


def test_00_scan_with_holes_and_unused_vertices(awkward):
    run = ran(NB00, MESH=awkward["scan_with_holes"], UP="y")
    assert any("not used by any face" in n and "remove_unreferenced_vertices" in n for n in run.notes), run.notes


def test_00_flat_plane():
    run = ran(NB00, MESH=Raw('geomlib.data_path("plane.obj")'), UP="x")
    assert "$H$ from 0 to 0 1/length" in run.outputs_text()
    assert not run.notes, run.notes


def test_00_y_up_millimetres(awkward):
    run = ran(NB00, MESH=awkward["y_up_millimetres"], UP="y")
    assert not run.notes, run.notes


def test_01_low_ends_on_the_cad_part(awkward):
    run = ran(
        NB01,
        MESH=awkward["cad_part"],
        PLANE=Raw('geomlib.data_path("plane_irregular.obj")'),
        RESOLUTION=8,
        SLIDER_RESOLUTION=8,
        JITTER_MAX=0.0,
        SEED=0,
    )
    assert any("within 10 %" in n and "coarser grid" in n for n in run.notes), run.notes
    # no jitter: the slider's two ends are one mesh, and the claim that jitter hurts K more becomes a note
    assert any("hurts K more" in n for n in run.notes), run.notes


def test_01_high_ends_on_two_components(awkward):
    run = ran(
        NB01,
        MESH=awkward["two_components"],
        RESOLUTION=128,
        SLIDER_RESOLUTION=64,
        JITTER_MAX=0.35,
        SEED=123,
    )
    assert not run.notes, run.notes


def test_01a_low_ends_on_the_cad_part(awkward):
    run = ran(NB01A, MESH=awkward["cad_part"], RESOLUTION=8, SPHERE_SUBDIVISIONS=1, UV_RINGS=8, SEED=0)
    assert any("within 1 % of 1" in n and "coarse sphere" in n for n in run.notes), run.notes


def test_01a_high_ends_on_two_components(awkward):
    run = ran(NB01A, MESH=awkward["two_components"], RESOLUTION=128, SPHERE_SUBDIVISIONS=6, UV_RINGS=128, SEED=123)
    assert not run.notes, run.notes


def test_02_umbilic_and_a_long_ellipsoid_at_the_ends_of_the_ranges():
    # b = c: (a, 0, 0) is an umbilic, kappa_n is flat; the section drawn along p_u
    run = ran(NB02, A_NUM=3.0, B_NUM=0.2, C_NUM=0.2, PHI_DEGREES=0)
    assert not run.notes, run.notes
    assert "neither: b = c" in run.outputs_text()
    run = ran(NB02, A_NUM=0.2, B_NUM=3.0, C_NUM=0.2, PHI_DEGREES=180)
    assert not run.notes, run.notes
    assert "bends more along $p_v$" in run.outputs_text()


def test_02a_spheroid_and_a_flat_offset_mesh_at_the_ends_of_the_ranges(awkward):
    run = ran(
        NB02A,
        A_NUM=0.2,
        B_NUM=3.0,
        C_NUM=3.0,
        GENERIC_U=1.5,
        GENERIC_V=0.1,
        SUBDIVISIONS=1,
        MESH=awkward["y_up_millimetres"],
        OFFSET_MESH=Raw('geomlib.data_path("plane.obj")'),
        OFFSET_RANGE=0.5,
        SEED=0,
    )
    assert any("not all different" in n and "spheroid" in n for n in run.notes), run.notes
    assert "never fold" in run.outputs_text()


def test_02a_offsets_of_a_scan_with_holes(awkward):
    run = ran(NB02A, OFFSET_MESH=awkward["scan_with_holes"], OFFSET_RANGE=5.0, GENERIC_V=3.04, SUBDIVISIONS=6, SEED=7)
    assert any("not used by any face" in n and "remove_unreferenced_vertices" in n for n in run.notes), run.notes


def test_02a_offsets_of_a_model_in_millimetres(awkward):
    run = ran(NB02A, OFFSET_MESH=awkward["y_up_millimetres"])
    # the sphere folds near its radius, 1000 mm; the largest discrete |kappa| overstates the curvature
    assert len(run.notes) == 1 and "noisy at single vertices" in run.notes[0], run.notes


@needs_course
def test_course_meshes():
    run = ran(NB00, MESH=str(COURSE / "curvatures" / "plane.obj"))
    assert not run.notes, run.notes
    assert "$H$ from 0 to 0 1/length" in run.outputs_text()  # rounding noise reads as 0, not as -1e-15
    # the flat grid: rounding noise (|K| <= 8e-13) is no "K < 0", and no H prints as "-0"
    run = ran(NB01, MESH=str(COURSE / "curvatures" / "plane.obj"))
    text = run.outputs_text()
    assert "(mesh: uniform H), drawn 6.67 x larger; H uniform (length): 0 everywhere, up to rounding" in text
    assert "K: 0 .. 0 1/length^2" in text and "-0 .." not in text
    assert "0 interior vertices have $K > 0$ (curved like a bowl),\n0 have $K < 0$" in text
    assert "64 have $K = 0$ up to rounding" in text and not run.notes, run.notes
    run = ran(NB01, MESH=str(COURSE / "curvatures" / "lilium_s.obj"), PLANE=str(COURSE / "curvatures" / "plane.obj"))
    assert not run.notes, run.notes
