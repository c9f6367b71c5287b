"""A grade the lecturer can trust: the cheats a student might try earn nothing, an honest student everything.

``CHEATS`` is a catalogue of the ways a student might look for points without the work,
each as the solution cell they would hand in (notebooks 01 and 03) and what the verdict
must say. The fast tests run each function-level cheat through the check in this
process, where it can be refused (a student's interactive check). The slow ones build a
small nbgrader course (01 and 03, with the course's one configuration line for
``geomlib.course.grading.JudgeExercises``) and let a real ``nbgrader autograde`` grade
an honest student, a student with one typical mistake and four students who hand in
the whole catalogue (four cheats each, other exercises left as released): every cheating exercise
scores 0 and its feedback names what it did, while the honest student scores full
points. A replay of answers recorded from one run's cases passes that run and fails the
next (fresh cases each run). The lambda_max cheat (``numerics.eigen.largest_eigenpair``,
notebook 05) goes to the judge directly.
"""

import hashlib
import inspect
import json
import re
import sys
from pathlib import Path

import nbformat
import numpy as np
import pytest

from geomlib import check
from geomlib.course.grading import CONFIG_LINE
from geomlib.teaching.check import copies, judge, wire

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))
sys.path.insert(0, str(ROOT / "tests"))

import build_assignment  # noqa: E402
from test_nbgrader import flip_the_sign_of_C, nbgrader  # noqa: E402

NOTEBOOKS = {"01": "01_uniform_laplace_curvature", "03": "03_cotangent_laplace"}
ASSIGNMENT = "integrity"
REPLAY_SEED = 4182


def pasted_copy():
    """geomlib's intrinsic_cotangent_matrix pasted as the answer, its variables renamed, comments reworded."""
    source = inspect.getsource(__import__("geomlib.lessons.laplace", fromlist=["x"]).intrinsic_cotangent_matrix)
    for old, new in (("intrinsic_cotangent_matrix", "my_cotangent_matrix"), ("dblA", "twice_area"), ("l2", "squared")):
        source = source.replace(old, new)
    source = re.sub(r"  # .*", "  # mine", source)
    source = re.sub(r"\bdegenerate\b", "flat", source)
    return (
        "from geomlib.lessons.laplace import NEXT, PREV, warn_zero_area\n"
        "from geomlib.mesh.validate import is_zero_area\n\n" + source
    )


def replayed(recorded):
    """A uniform Laplacian that looks its inputs up among the answers recorded from an earlier run."""
    return (
        f"RECORDED = {recorded!r}\n\n"
        "def my_uniform_laplacian(V, F):\n"
        "    import hashlib\n"
        "    M, C = RECORDED[hashlib.sha1(np.ascontiguousarray(V, dtype=float).tobytes()).hexdigest()]\n"
        "    return sparse.diags(M), sparse.csr_matrix(np.array(C))\n"
    )


def record_uniform_laplacian(seed):
    """{sha1 of V: (diagonal of M, C as lists)} of the cases one run of check.uniform_laplacian draws with ``seed``."""
    honest = namespace("01")
    exec(solutions("01")["uniform_laplacian"], honest)
    recorded = {}

    def recorder(V, F):
        M, C = honest["my_uniform_laplacian"](V, F)
        key = hashlib.sha1(np.ascontiguousarray(V, dtype=float).tobytes()).hexdigest()
        recorded[key] = (M.diagonal().tolist(), C.toarray().tolist())
        return M, C

    assert check.uniform_laplacian.evaluate(recorder, seed=seed).passed
    return recorded


# name: (notebook, exercise, the solution cell handed in, what the judge says, what the kernel's check says
# or None where the kernel cannot see it: the check object or the module replaced, a copy, a replay)
CHEATS = {
    # the first cheating student
    "the routine in a ThreadPoolExecutor worker": (
        "01",
        "uniform_laplacian",
        "def my_uniform_laplacian(V, F):\n"
        "    from concurrent.futures import ThreadPoolExecutor\n"
        "    with ThreadPoolExecutor(1) as pool:\n"
        '        return pool.submit(geomlib.laplacian, V, F, "uniform").result()\n',
        "starts a thread",
        "calls geomlib's `laplacian`",
    ),
    "sys.setprofile(None), then the routine": (
        "01",
        "gaussian_curvature",
        "def my_gaussian_curvature(V, F):\n"
        "    import sys\n"
        "    sys.setprofile(None)\n"
        "    return geomlib.gaussian_curvature(V, F)\n",
        "calls sys.setprofile",
        "calls sys.setprofile",
    ),
    "libigl's intrinsic cotmatrix": (
        "03",
        "cotangent_matrix",
        "def my_cotangent_matrix(l, F):\n    import igl\n    return igl.cotmatrix_intrinsic(l, F)\n",
        "imports igl",
        ("imports igl", "calls libigl's `"),
    ),
    "geomlib's voronoi_pieces for the mixed areas": (
        "03",
        "mixed_areas",
        "def my_mixed_areas(V, F):\n"
        "    from geomlib.lessons.laplace import voronoi_pieces\n"
        "    A_f = np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1) / 2\n"
        "    pieces = voronoi_pieces(V, F)\n"
        "    per = np.where((pieces < 0).any(axis=1, keepdims=True), A_f[:, None] / 4, pieces)\n"
        "    return np.bincount(F.ravel(), weights=per.ravel(), minlength=len(V))\n",
        "calls geomlib's `voronoi_pieces`",
        "calls geomlib's `voronoi_pieces`",
    ),
    # the second
    "a replay of recorded answers": (
        "01",
        "uniform_laplacian",
        None,
        "uniform_laplacian: the function raised KeyError",
        None,
    ),
    "geomlib's face_angles for the angle sums": (
        "01",
        "gaussian_curvature",
        "def my_gaussian_curvature(V, F):\n"
        "    from geomlib.lessons.curvature import face_angles\n"
        "    e = [V[F[:, (c + 2) % 3]] - V[F[:, (c + 1) % 3]] for c in range(3)]\n"
        "    l2 = np.stack([np.sum(x**2, axis=1) for x in e], axis=1)\n"
        "    dblA = np.linalg.norm(np.cross(e[0], e[1]), axis=1)\n"
        "    cot = (0.5 * l2.sum(axis=1, keepdims=True) - l2) / dblA[:, None]\n"
        "    theta = face_angles((l2, dblA, cot, np.zeros(len(F), bool)))\n"
        "    K = 2 * np.pi - np.bincount(F.ravel(), theta.ravel(), minlength=len(V))\n"
        "    K = K / np.bincount(F.ravel(), np.repeat(dblA / 6, 3), minlength=len(V))\n"
        "    K[boundary_mask(V, F)] = np.nan\n"
        "    return K\n",
        "calls geomlib's `face_angles`",
        "calls geomlib's `face_angles`",
    ),
    "a pasted copy of geomlib's routine, variables renamed": (
        "03",
        "cotangent_matrix",
        None,
        "a copy of geomlib's code earns no points",
        "calls geomlib's `",
    ),
    "geomlib's face_geometry for the cotangent weights": (
        "03",
        "mixed_areas",
        "def my_mixed_areas(V, F):\n"
        "    from geomlib.lessons.laplace import face_geometry\n"
        "    l2, dblA, cot, flat = face_geometry(V, F)\n"
        "    lc = l2 * cot\n"
        "    voronoi = (lc[:, [1, 2, 0]] + lc[:, [2, 0, 1]]) / 8\n"
        "    share = np.where(cot < 0, dblA[:, None] / 4, dblA[:, None] / 8)\n"
        "    pieces = np.where((cot < 0).any(axis=1, keepdims=True), share, voronoi)\n"
        "    return np.bincount(F.ravel(), weights=pieces.ravel(), minlength=len(V))\n",
        "calls geomlib's `face_geometry`",
        "calls geomlib's `face_geometry`",
    ),
    # the third
    "geomlib's topology.edges and valence": (
        "01",
        "uniform_laplacian",
        "def my_uniform_laplacian(V, F):\n"
        "    from geomlib.mesh.topology import edges, valence\n"
        "    E, n = edges(F), len(V)\n"
        "    A = sparse.coo_matrix((np.ones(2 * len(E)), (np.r_[E[:, 0], E[:, 1]], np.r_[E[:, 1], E[:, 0]])), (n, n))\n"
        "    d = valence(F, n).astype(float)\n"
        "    return sparse.diags(d), (A - sparse.diags(d)).tocsr()\n",
        "calls geomlib's `edges`",
        "calls geomlib's `edges`",
    ),
    "trimesh's Gaussian curvature measure": (
        "01",
        "gaussian_curvature",
        "def my_gaussian_curvature(V, F):\n"
        "    import trimesh\n"
        "    from trimesh.curvature import discrete_gaussian_curvature_measure\n"
        "    mesh = trimesh.Trimesh(V, F, process=False)\n"
        "    K = discrete_gaussian_curvature_measure(mesh, V, 0.0)\n"
        "    A = np.bincount(F.ravel(), np.repeat(mesh.area_faces / 3, 3), minlength=len(V))\n"
        "    return np.where(boundary_mask(V, F), np.nan, K / A)\n",
        "imports trimesh",
        ("imports trimesh", "calls trimesh's `"),
    ),
    "geomlib's source through inspect.getsource and exec": (
        "03",
        "cotangent_matrix",
        "def my_cotangent_matrix(l, F):\n"
        "    import inspect\n"
        "    from geomlib.lessons import laplace\n"
        "    ns = dict(vars(laplace))\n"
        "    exec(inspect.getsource(laplace.intrinsic_cotangent_matrix), ns)\n"
        '    return ns["intrinsic_cotangent_matrix"](l, F)\n',
        "runs compile on code of its own",
        "calls geomlib's `",
    ),
    "numpy and geomlib's comparison monkeypatched": (
        "03",
        "mixed_areas",
        "import geomlib.teaching.check.result\n"
        "np.allclose = lambda *args, **kwargs: True\n"
        "geomlib.teaching.check.result.close = lambda *args, **kwargs: True\n\n"
        "def my_mixed_areas(V, F):\n"
        "    return np.full(len(V), 7.0)\n",
        "mixed_areas: ",
        None,
    ),
    # the fourth
    "the check module replaced in sys.modules": (
        "01",
        "uniform_laplacian",
        "import sys, types\n\n"
        "class Passes:\n"
        "    def __call__(self, fn):\n"
        "        return None\n\n"
        "    def partial_credit(self, fn):\n"
        "        return None\n\n"
        'sys.modules["geomlib.teaching.check"] = types.SimpleNamespace(uniform_laplacian=Passes(), gaussian_curvature=Passes())\n'
        "import geomlib.teaching.check as check\n\n"
        "def my_uniform_laplacian(V, F):\n"
        "    return sparse.eye(len(V)), sparse.eye(len(V))\n",
        "uniform_laplacian: ",
        None,
    ),
    "libigl's gaussian_curvature": (
        "01",
        "gaussian_curvature",
        "def my_gaussian_curvature(V, F):\n"
        "    import igl\n"
        "    A = np.bincount(F.ravel(), np.repeat(igl.doublearea(V, F) / 6, 3), minlength=len(V))\n"
        "    return np.where(boundary_mask(V, F), np.nan, igl.gaussian_curvature(V, F) / A)\n",
        "imports igl",
        ("imports igl", "calls libigl's `"),
    ),
    "check.NAME replaced from a solution cell": (
        "03",
        "cotangent_matrix",
        "check.cotangent_matrix = lambda fn: None\n"
        "check.cotangent_matrix.partial_credit = lambda fn: None\n\n"
        "def my_cotangent_matrix(l, F):\n"
        "    from geomlib.lessons.laplace import intrinsic_cotangent_matrix\n"
        "    return intrinsic_cotangent_matrix(l, F)\n",
        "calls geomlib's `intrinsic_cotangent_matrix`, which this exercise asks you to write",
        None,
    ),
    "libigl's massmatrix (Voronoi)": (
        "03",
        "mixed_areas",
        "def my_mixed_areas(V, F):\n"
        "    import igl\n"
        "    return igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI).diagonal()\n",
        "imports igl",
        ("imports igl", "calls libigl's `"),
    ),
}
# four cheating students: each hands in one cheat per exercise of 01 and 03, in the order above
CHEATERS = {f"cheat_{k}": list(CHEATS)[4 * k : 4 * k + 4] for k in range(4)}


def solutions(nb_id):
    nb = nbformat.read(ROOT / "notebooks" / f"{NOTEBOOKS[nb_id]}.ipynb", as_version=4)
    return {c.metadata["nbgrader"]["grade_id"]: c.source for _, c in build_assignment.solution_cells(nb)}


def namespace(nb_id):
    """The notebook's namespace after its import statements (as a student's kernel has it)."""
    nb = nbformat.read(ROOT / "notebooks" / f"{NOTEBOOKS[nb_id]}.ipynb", as_version=4)
    source = next(c.source for c in nb.cells if c.cell_type == "code")
    ns = {"__name__": "__main__"}
    exec(
        "\n".join(
            line for line in source.splitlines() if line.startswith(("import ", "from ")) or line.startswith(" ")
        ),
        ns,
    )
    return ns


def cheat_source(name, recorded=None):
    source = CHEATS[name][2]
    if source is None:
        return pasted_copy() if "pasted" in name else replayed(recorded)
    return source


@pytest.mark.parametrize("name", [n for n, c in CHEATS.items() if c[4] is not None])
def test_the_kernels_check_refuses_the_cheats_it_can_see(name, monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")
    nb_id, exercise, _, _, said = CHEATS[name]
    ns = namespace(nb_id)
    exec(cheat_source(name), ns)
    result = getattr(check, exercise).evaluate(ns[f"my_{exercise}"])
    assert not result.passed and not result.partial, result.message
    said = (said,) if isinstance(said, str) else said  # a library loaded earlier is seen at its call
    assert any(s in result.message for s in said) and "earns no points" in result.message, result.message


def test_a_copy_is_found_through_renamed_variables_and_a_one_liner_is_never_called_one():
    flags = copies.exercise_copies(pasted_copy())
    assert {
        "function": "my_cotangent_matrix",
        "of": "geomlib",
        "matches": "geomlib.lessons.laplace.intrinsic_cotangent_matrix",
    } in flags
    assert "a copy of geomlib's code earns no points" in copies.refusal(flags[0])
    short = "def my_explicit_step(P, M, C, tau):\n    return P + tau * (C @ P) / M.diagonal()[:, None]\n"
    assert copies.exercise_copies(short, short) == []
    for nb_id in NOTEBOOKS:  # the solution notebook's answers are written from the derivations, not geomlib's code
        for source in solutions(nb_id).values():
            assert [f for f in copies.exercise_copies(source) if f["of"] == "geomlib"] == []


def test_the_wire_carries_plain_data_and_refuses_to_evaluate_anything_else():
    import scipy.sparse as sparse
    import sympy

    a, x = sympy.symbols("a x", positive=True)
    values = [np.arange(6.0).reshape(2, 3), np.float32(1.5), (sparse.diags([1.0, 2.0]), 3), sympy.sqrt(a) * x / 3]
    back = wire.decode(json.loads(json.dumps(wire.encode(values))))
    assert np.array_equal(back[0], values[0]) and back[1].dtype == np.float32
    assert (back[2][0] != values[2][0]).nnz == 0 and back[2][1] == 3 and back[3] == values[3]
    assert repr(wire.decode(wire.encode(object()))) == "object"
    with pytest.raises(ValueError, match="not a sympy class"):
        wire.parse_srepr("__import__('os')")
    with pytest.raises(ValueError):
        wire.parse_srepr("Symbol('x').__class__")


@pytest.mark.slow
def test_a_replay_passes_the_run_it_was_recorded_from_and_fails_the_next(monkeypatch):
    monkeypatch.setenv("GEOMLIB_STRICT_CLAIMS", "0")
    recorded = record_uniform_laplacian(REPLAY_SEED)
    ns = namespace("01")
    exec(replayed(recorded), ns)
    assert check.uniform_laplacian.evaluate(ns["my_uniform_laplacian"], seed=REPLAY_SEED).passed  # a real replay
    again = check.uniform_laplacian.evaluate(ns["my_uniform_laplacian"])
    assert not again.passed and not again.partial and "KeyError" in again.message, again.message
    assert re.search(r"Cases seed \d+\.", again.message)


@pytest.mark.slow
def test_the_judge_refuses_lam_max_from_geomlibs_largest_eigenpair():
    nb = nbformat.read(ROOT / "notebooks" / "05_explicit_smoothing.ipynb", as_version=4)
    kept = []
    for cell in nb.cells:
        grade_id = cell.metadata.get("nbgrader", {}).get("grade_id", "")
        if grade_id.startswith("smoothing_loop"):
            continue  # the judge grades one exercise here: lambda_max
        if grade_id == "lam_max":
            cell.source = (
                "def my_lam_max(M, C):\n"
                "    from geomlib.numerics.eigen import largest_eigenpair\n"
                "    d = sp.diags(1 / np.sqrt(M.diagonal()))\n"
                "    return largest_eigenpair((-(d @ C @ d)).tocsr())[0]\n"
            )
        kept.append(cell)
    nb.cells = kept
    found = judge.verdicts(nb)
    assert list(found) == ["lam_max"]
    passed, message = found["lam_max"]["check"]
    assert not passed and "calls geomlib's `largest_eigenpair`" in message, message
    assert found["lam_max"]["partial_credit"][0] is False


@pytest.mark.slow
def test_the_judge_finds_the_earlier_routine_an_answer_builds_on_in_the_sandbox():
    """03's principal curvatures call the student's section-1 C: the judge's check asks it there and names it."""
    nb = nbformat.read(ROOT / "notebooks" / "03_cotangent_laplace.ipynb", as_version=4)
    for cell in nb.cells:
        if cell.metadata.get("nbgrader", {}).get("grade_id") == "cotangent_matrix":
            cell.source = cell.source.replace("def my_cotangent_matrix", "def right_C") + (
                "\n\ndef my_cotangent_matrix(l, F):\n    return 2 * right_C(l, F)\n"
            )
    found = judge.verdicts(nb)
    assert not found["cotangent_matrix"]["check"][0]
    passed, message = found["discrete_principal_curvatures"]["check"]
    assert not passed and "your my_cotangent_matrix (section 1) returns a wrong C" in message, message
    assert found["mixed_areas"]["check"][0]


@pytest.mark.slow
def test_a_solution_cell_that_raises_costs_only_what_it_did_not_define():
    """As in a kernel, a cell stops at its error and the next cells still run. Grading runs the
    solution cells without the lesson's variables: a trial call on the lesson's mesh after the
    function costs nothing; an error before a function's definition fails that exercise only,
    saying which cell raised and why."""
    nb = nbformat.read(ROOT / "notebooks" / "02_fundamental_forms.ipynb", as_version=4)
    for cell in nb.cells:
        grade_id = cell.metadata.get("nbgrader", {}).get("grade_id")
        if grade_id == "fundamental_forms":
            cell.source += "\n\nforms_here = my_fundamental_forms(A_NUM, B_NUM, C_NUM, u, v)   # the lesson's names\n"
        if grade_id == "normal_curvature":
            cell.source = "undefined_name\n" + cell.source
    found = judge.verdicts(nb)
    assert found["fundamental_forms"]["check"][0] and found["principal_curvatures"]["check"][0]
    passed, message = found["normal_curvature"]["check"]
    assert not passed and "solution cell 2 raised NameError: name 'undefined_name' is not defined" in message, message
    assert "without the lesson's variables" in message


@pytest.mark.slow
def test_each_exercise_is_judged_in_a_fresh_process_of_its_own():
    # the sandboxes of a notebook are forked from one process holding its imports: what one
    # exercise's calls leave behind (here a count on the numpy module) must not reach the next
    nb = nbformat.read(ROOT / "notebooks" / "05_explicit_smoothing.ipynb", as_version=4)
    for cell in nb.cells:
        grade_id = cell.metadata.get("nbgrader", {}).get("grade_id", "")
        if grade_id == "lam_max":
            cell.source = cell.source.replace("    return lam", "    np.lam_max_calls = 1\n    return lam")
        if grade_id == "smoothing_loop":  # wrong, should it see a call of my_lam_max made before its own first
            cell.source = cell.source.replace(
                "    ### BEGIN SOLUTION\n",
                "    ### BEGIN SOLUTION\n"
                "    if getattr(np, 'lam_max_calls', 0) and not getattr(np, 'smooth_called', False):\n"
                "        return V + 1.0\n"
                "    np.smooth_called = True\n",
            )
    found = judge.verdicts(nb)
    assert [found[e]["check"][0] for e in ("lam_max", "smoothing_loop")] == [True, True], found


@pytest.mark.slow
def test_one_zygote_serves_the_run_and_no_student_can_change_what_it_holds(monkeypatch):
    # every student's sandboxes, notebook after notebook, fork from the grading run's one zygote, which
    # holds the solution notebooks' imports: student A's import statements and what A's cells rebind
    # in a module (here a module only A imports, and a mark on numpy) must not reach student B
    solution = nbformat.read(ROOT / "notebooks" / "05_explicit_smoothing.ipynb", as_version=4)
    a, b = (nbformat.reads(nbformat.writes(solution), as_version=4) for _ in "ab")
    a.cells.insert(1, nbformat.v4.new_code_cell("import wave"))
    for cell in a.cells:
        if cell.metadata.get("nbgrader", {}).get("grade_id") == "lam_max":
            cell.source = "np.student_a = wave.WAVE_FORMAT_PCM\n\n" + cell.source
    for cell in b.cells:
        if cell.metadata.get("nbgrader", {}).get("grade_id") == "smoothing_loop":  # wrong, should it see A's traces
            cell.source = cell.source.replace(
                "    ### BEGIN SOLUTION\n",
                "    ### BEGIN SOLUTION\n"
                "    import sys\n"
                "    if hasattr(np, 'student_a') or 'wave' in sys.modules:\n"
                "        return V + 1.0\n",
            )
    implicit = nbformat.read(ROOT / "notebooks" / "06_implicit_smoothing.ipynb", as_version=4)  # B's next notebook
    started = []
    zygote = judge.Zygote.__init__
    monkeypatch.setattr(judge.Zygote, "__init__", lambda self: started.append(1) or zygote(self))
    try:
        found = [judge.judge_notebook(nb, model) for nb, model in ((a, solution), (b, solution), (implicit, implicit))]
    finally:
        judge.close_zygote()
    assert len(started) == 1
    assert [[v["check"][0] for v in verdicts.values()] for verdicts in found] == [[True, True]] * 3, found


def hand_in(course, student, notebooks, edit):
    """The released notebooks ``notebooks`` as ``student`` hands them in, each solution cell through ``edit``."""
    out = course / "submitted" / student / ASSIGNMENT
    out.mkdir(parents=True)
    for nb_id in notebooks:
        name = NOTEBOOKS[nb_id]
        nb = nbformat.read(course / "release" / ASSIGNMENT / f"{name}.ipynb", as_version=4)
        written = solutions(nb_id)
        for _, cell in build_assignment.solution_cells(nb):
            exercise = cell.metadata["nbgrader"]["grade_id"]
            cell.source = edit(exercise, written[exercise], cell.source)  # the solution, the released stub
        for _, cell in build_assignment.answer_cells(nb):
            cell.source = "My answer, in a few sentences, from the numbers above."
        nbformat.write(nb, out / f"{name}.ipynb")


@pytest.fixture(scope="module")
def course(tmp_path_factory):
    course = tmp_path_factory.mktemp("integrity")
    (course / "nbgrader_config.py").write_text(
        "c = get_config()\n"
        f"c.CourseDirectory.root = {str(course)!r}\n"
        "c.CourseDirectory.course_id = 'geomlib'\n"
        f"c.Exchange.root = {str(course / 'exchange')!r}\n"
        "c.Execute.timeout = 600\n" + CONFIG_LINE + "\n"
    )
    (course / "exchange").mkdir()
    source = course / "source" / ASSIGNMENT
    source.mkdir(parents=True)
    for name in NOTEBOOKS.values():
        (source / f"{name}.ipynb").write_bytes((ROOT / "notebooks" / f"{name}.ipynb").read_bytes())
    nbgrader(course, "generate_assignment", ASSIGNMENT)
    hand_in(course, "honest", NOTEBOOKS, lambda exercise, source, stub: source)
    hand_in(course, "mistaken", ["01"], lambda exercise, source, stub: flip_the_sign_of_C(exercise, source))
    recorded = record_uniform_laplacian(REPLAY_SEED)
    for student, names in CHEATERS.items():
        by_exercise = {CHEATS[n][1]: cheat_source(n, recorded) for n in names}
        hand_in(course, student, NOTEBOOKS, lambda exercise, source, stub, by=by_exercise: by.get(exercise, stub))
    nbgrader(course, "autograde", ASSIGNMENT)
    return course


def scores(course):
    """{student: {notebook id: (auto-graded score, max auto-graded)}} from nbgrader's gradebook."""
    from nbgrader.api import Gradebook

    out = {}
    with Gradebook(f"sqlite:///{course / 'gradebook.db'}") as gb:
        for student in ("honest", "mistaken", *CHEATERS):
            out[student] = {}
            for nb_id, name in NOTEBOOKS.items():
                submission = gb.find_submission_notebook(name, ASSIGNMENT, student)
                auto = [g for g in submission.grades if g.cell.name.endswith(("_check", "_partial_credit"))]
                out[student][nb_id] = (sum(g.score for g in auto), sum(g.max_score for g in auto))
    return out


def grade_cell_outputs(course, student, nb_id, exercise):
    """The texts under the exercise's two grade cells, each on one line (a verdict is wrapped as the kernel wraps it)."""
    nb = nbformat.read(course / "autograded" / student / ASSIGNMENT / f"{NOTEBOOKS[nb_id]}.ipynb", as_version=4)
    cells = {c.metadata.get("nbgrader", {}).get("grade_id"): c for c in nb.cells}
    return [
        " ".join(("\n".join(o.get("traceback", [])) if o.output_type == "error" else o.data["text/plain"]).split())
        for part in ("_check", "_partial_credit")
        for o in cells[exercise + part].outputs
    ]


@pytest.mark.slow
def test_autograde_gives_the_honest_student_full_points_and_the_mistaken_one_fewer(course):
    got = scores(course)
    assert all(score == top and top > 0 for score, top in got["honest"].values()), got["honest"]
    wrong = build_assignment_points("01", "uniform_laplacian_check")
    assert got["mistaken"]["01"] == (got["honest"]["01"][0] - wrong, got["honest"]["01"][1])
    assert got["mistaken"]["03"][0] == 0  # not handed in
    said = grade_cell_outputs(course, "mistaken", "01", "uniform_laplacian")
    assert "the sign of C is flipped" in said[0] and "earned. what is wrong is a typical mistake" in said[1]
    assert all(
        "decided by the grading judge" in text for text in grade_cell_outputs(course, "honest", "03", "mixed_areas")
    )


def build_assignment_points(nb_id, grade_id):
    nb = nbformat.read(ROOT / "notebooks" / f"{NOTEBOOKS[nb_id]}.ipynb", as_version=4)
    return next(
        c.metadata["nbgrader"]["points"] for c in nb.cells if c.metadata.get("nbgrader", {}).get("grade_id") == grade_id
    )


@pytest.mark.slow
@pytest.mark.parametrize("name", list(CHEATS))
def test_autograde_gives_each_cheat_no_points_and_says_why(course, name):
    nb_id, exercise, _, said, _ = CHEATS[name]
    student = next(s for s, names in CHEATERS.items() if name in names)
    check_out, partial_out = grade_cell_outputs(course, student, nb_id, exercise)
    assert check_out.startswith("CheckFailed: ") and said in check_out, check_out
    assert partial_out.startswith("CheckFailed: "), partial_out


@pytest.mark.slow
def test_autograde_gives_every_cheating_student_zero(course):
    got = scores(course)
    for student in CHEATERS:
        assert [score for score, _ in got[student].values()] == [0, 0], (student, got[student])


def test_the_grading_guide_gives_the_configuration_line():
    assert CONFIG_LINE in (ROOT / "docs" / "grading.md").read_text()
