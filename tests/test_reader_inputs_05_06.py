"""Notebooks 05 and 06 with a reader's inputs: the course's meshes with the assignment's own absolute
steps, the awkward meshes readers bring, and every parameter at an end of its documented range.

No run may raise; the notes a run shows must name the cause. Each run combines several parameters,
so that the module exercises the notebooks' different code paths (open and closed meshes, several
components, a large CUBE, steps past every limit, absolute and scale-free units) in a few runs.
"""

import pytest
from meshdata import COURSE, needs_course
from notebook_runner import ran

pytestmark = pytest.mark.slow


@needs_course
def test_05_course_meshes_with_the_assignments_absolute_step():
    run = ran(
        "05_explicit_smoothing.ipynb",
        PLANE=str(COURSE / "smoothing" / "plane_ns.obj"),
        PART=str(COURSE / "smoothing" / "fandisk_ns.obj"),
        STEP=1e-5,
        STEP_UNIT="length^2",
        BREAK_MARGIN=0.3,
        BREAK_ITERATIONS=20,
        ITERATIONS=0,
    )
    text, notes = run.outputs_text(), run.notes_text()
    # the conversion table: 1e-5 is 0.0278 of fandisk_ns's limit and 2.1 times plane_ns's
    assert "| part | assignment's 1e-05 | 1e-05 | 0.000833 | 0.02782 |" in text
    assert "| plane | assignment's 1e-06 | 1e-06 | 0.03545 | 0.2118 |" in text
    assert "past the cotangent limit on plane" in notes
    # the fixed boundary: the raw top coefficient settles instead of decaying, and the text says why
    assert "settles" in text and "fixed boundary vertices" in text
    assert len(run.notes) == 1, run.notes  # the step past plane_ns's limit


@needs_course
def test_05a_course_meshes():
    run = ran(
        "05a_dig_deeper_step_limit.ipynb",
        PLANE=str(COURSE / "smoothing" / "plane_ns.obj"),
        PART=str(COURSE / "smoothing" / "fandisk_ns.obj"),
        CUBE_STEPS=1,
    )
    text = run.outputs_text()
    # plane_ns is a regular grid: uniform weights have nothing to slide, and the text says so (no note)
    assert "flattened, this plane's triangulation is already even" in text
    assert "it evens out the triangles" not in text
    assert "PART's diagonal is 28.2 times PLANE's" in text
    assert not run.notes, run.notes


@needs_course
def test_05_one_step_per_mesh_runs_the_assignments_task_5_in_one_go():
    # task 5: explicit 1e-4 on fandisk_ns and 1e-6 on plane_ns; one STEP for both made the plane diverge
    run = ran(
        "05_explicit_smoothing.ipynb",
        PLANE=str(COURSE / "smoothing" / "plane_ns.obj"),
        PART=str(COURSE / "smoothing" / "fandisk_ns.obj"),
        STEP={"PLANE": 1e-6, "PART": 1e-4},
        STEP_UNIT="length^2",
        BREAK_MARGIN=0.3,
        BREAK_ITERATIONS=20,
        ITERATIONS=50,
    )
    text, notes = run.outputs_text(), run.notes_text()
    assert "| plane | STEP = 1e-06 length^2 | 1e-06 | 0.03545 | 0.2118 |" in text
    assert "| part | STEP = 0.0001 length^2 | 0.0001 | 0.00833 | 0.2782 |" in text
    assert "| cube | STEP = 1e-06 length^2 |" in text  # left out of the dict: the smallest step given
    assert "past the cotangent limit" not in notes
    # the live cell runs both at once, each below its own limit
    assert "plane: tau = 1e-06 = 0.212 x limit, stable" in text
    assert "part: tau = 0.0001 = 0.278 x limit, stable" in text
    assert "diverged, stopped at the last finite iterate" not in text


def test_05_awkward_meshes_and_the_other_ends_of_the_ranges(awkward):
    run = ran(
        "05_explicit_smoothing.ipynb",
        PLANE=awkward["y_up_millimetres"],
        PART=awkward["two_components"],
        CUBE=awkward["cad_part"],
        STEP=0.5,
        BREAK_MARGIN=0.005,
        BREAK_ITERATIONS=1000,
        ITERATIONS=1000,
    )
    notes = run.notes_text()
    assert "2 connected components" in notes and "largest_component" in notes
    assert "past the cotangent limit on cube, plane, part" in notes
    assert "STEP is 1.84 times PART's limit" in notes


def test_05a_awkward_meshes_and_the_other_end_of_the_range(awkward):
    run = ran(
        "05a_dig_deeper_step_limit.ipynb",
        PLANE=awkward["y_up_millimetres"],
        PART=awkward["two_components"],
        CUBE=awkward["cad_part"],
        CUBE_STEPS=50,
    )
    notes = run.notes_text()
    assert "2 connected components" in notes and "largest_component" in notes
    assert "CUBE may not be the 8-vertex cube" in notes
    assert "a PLANE that is not flat" in notes


@needs_course
def test_06_course_meshes_with_the_assignments_absolute_step():
    run = ran(
        "06_implicit_smoothing.ipynb",
        PLANE=str(COURSE / "smoothing" / "plane_ns.obj"),
        PART=str(COURSE / "smoothing" / "fandisk_ns.obj"),
        STEP=1e-5,
        STEP_UNIT="length^2",
        ITERATIONS=1,
    )
    text = run.outputs_text()
    assert "| part, assignment's τ | " in text and "| 1e-05 | 0.000833 | 0.02782 |" in text
    assert not run.notes, run.notes


@needs_course
def test_06_one_step_per_mesh():
    run = ran(
        "06_implicit_smoothing.ipynb",
        PLANE=str(COURSE / "smoothing" / "plane_ns.obj"),
        PART=str(COURSE / "smoothing" / "fandisk_ns.obj"),
        STEP={"PLANE": 1e-6, "PART": 1e-4},
        STEP_UNIT="length^2",
        ITERATIONS=1,
    )
    text = run.outputs_text()
    assert "| 1e-06 | 0.03545 | 0.2118 |" in text and "| 0.0001 | 0.00833 | 0.2782 |" in text
    assert "steps of STEP = {CUBE: 1e-06, PLANE: 1e-06, PART: 0.0001, SPHERE: 1e-06} (length^2)" in text
    assert "tau = 0.0001 (0.278 x the explicit limit)" in text  # the live view smooths PART with its own step


def test_06_awkward_meshes_and_the_other_ends_of_the_ranges(awkward):
    run = ran(
        "06_implicit_smoothing.ipynb",
        PLANE=awkward["scan_with_holes"],
        PART=awkward["scan_with_holes"],
        CUBE=awkward["two_components"],
        SPHERE=awkward["y_up_millimetres"],
        STEP=100.0,
        ITERATIONS=50,
    )
    notes = run.notes_text()
    assert "not used by any face" in notes and "remove_unreferenced_vertices" in notes
    assert "2 connected components" in notes and "largest_component" in notes
    assert "PART is open: it encloses no volume" in notes
    assert "where PLANE is not a noisy plane" in notes
