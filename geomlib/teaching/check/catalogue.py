"""Checks as data: a typical mistake is a named wrong answer, an exercise's catalogue a list of them.

A check runs the learner's function on a few cases (small meshes from ``check.meshes``,
placed anew each run), turns what comes back into arrays with a coercion helper, and
asks ONE matcher which entry of its catalogue the answers are::

    from ...lessons.laplace import barycentric_areas
    from .catalogue import Wrong, judge, mesh_cases, run, vector
    from .meshes import grid_3x3, irregular_tetrahedron
    from .result import case_rng, exercise

    AREA_MISTAKES = [
        Wrong("each vertex gets the full area of its triangles (not divided by 3)",
              "a triangle gives a third of its area to each corner",
              build=lambda c: 3 * c.A),                       # the wrong answer, made from a case
        Wrong("the areas are negative", "A_f = |cross| / 2 >= 0",
              when=lambda A, right, c: (A < 0).any()),        # a property seen on one case
        Wrong("the areas differ from the barycentric areas on {label}",
              "A_i = 1/3 of the areas of the triangles around i", typical=False),   # the catch-all
    ]

    @exercise("vertex_areas", reread="section 2 · Which area?", forbid=("lessons.laplace.barycentric_areas",))
    def vertex_areas(fn):
        meshes = (("an irregular tetrahedron", irregular_tetrahedron()), ("a 3 x 3 grid", grid_3x3()))
        cases = mesh_cases(meshes, case_rng(), lambda V, F: {"A": barycentric_areas(V, F)})
        # case_rng(): a fresh seed per run, named in the message; each mesh moved, scaled, jittered,
        # renumbered; a case holds its inputs (c.V, c.F) and the facts the builders read (c.A)
        answers = run(fn, cases, vector)                      # fn(V, F) on copies, coerced to (n,)
        judge(AREA_MISTAKES, cases, answers, right=lambda c: c.A)
        return [c.label for c in cases]                       # what was checked

A test hands every entry's wrong answer in and expects its diagnosis (``tests/diagnoses.replaying``
replays ``entry.build(case)`` for the cases a seed gives), and keeps a few wrong answers written by
hand as an oracle independent of the catalogue.

The matcher (:func:`first_mistake`; :func:`judge` raises what it finds):

* answers right on every case (``same``, default :func:`agree`): no mistake;
* a ``Wrong`` with ``build`` is named when the answers match its wrong answer on EVERY
  case and that wrong answer differs from the right one on at least one case (two
  mistakes that coincide on one mesh are told apart by the others);
* a ``Wrong`` with ``when`` is named at the first case where ``when(answer, right, case)``;
* the first ``Wrong`` with neither is the catch-all. Before it, an answer within float32
  precision of the right one on every case (:data:`FLOAT32_RTOL` of its scale) is named
  ``"right to float32 precision: compute in float64"`` (a typical mistake, partial credit).
  It is named rather than accepted: the check's own tolerance (1e-6 of the scale) is what
  tells the typical mistakes apart, and the cells after an exercise feed its routine to
  solvers and loops that amplify single-precision error.

``{label}`` in a diagnosis becomes the label of the case it is seen on. Entries are tried
in catalogue order, so put the specific before the general. ``typical=False`` marks a
diagnosis that only says *that* something is wrong: no partial credit.

Patterns: an answer with a free part (an eigenvector's sign, the basis of a repeated
eigenspace) is compared by what defines it, with ``same=`` (a function of answer, expected,
case); a mistake seen in a property rather than a value is a ``when`` (eigenvalues right but
unsorted: ``when=lambda lam, right, c: not (np.diff(lam) >= 0).all() and agree(np.sort(lam), right)``;
one normal draw shared by x, y and z: ``when=lambda X, right, c: np.allclose(*(X - c.V).T[:2])``);
inputs beyond the mesh (tau, k, sigma, a seed) are inputs of the ``Case``, in the order the
learner's function takes them; a check that calls the function twice (another seed, another
count) runs two lists of cases. Several catalogues may be judged in turn (C before M).

Coercion helpers (:func:`matrix_pair`, :func:`vector`, :func:`positions`,
:func:`eigenpairs`, :func:`number`) turn what the learner returned into float arrays or
raise a ``Mistake``; a wrong shape or type is never partial credit (``typical=False``),
as the grading guide says. :func:`run` calls the learner's function on copies of each
case's inputs through ``result.call``, which names an input changed in place (:func:`answer`: one
case, some inputs replaced).
"""

import numpy as np
import scipy.sparse as sp

from .meshes import placed
from .result import Mistake, call

__all__ = [
    "Case",
    "Wrong",
    "agree",
    "first_mistake",
    "judge",
    "run",
    "answer",
    "mesh_cases",
    "named",
    "matrix_pair",
    "vector",
    "positions",
    "eigenpairs",
    "number",
    "FLOAT32_RTOL",
]

#: Relative error (of the right answer's largest entry) within which an answer is "right to float32
#: precision": float32 keeps 7 digits, and the sums and cotangents of a check case lose one or two.
FLOAT32_RTOL = 1e-4
#: The check's own tolerance: a match with a wrong answer, or with the right one.
RTOL = 1e-6


class Case:
    """One case of a check: its ``label``, the inputs the learner's function gets (keywords, in order),
    and facts the builders read (``case.but(**facts)``). Inputs and facts read as attributes."""

    def __init__(self, label, **inputs):
        self.label, self.inputs, self.facts = label, dict(inputs), {}

    def __getattr__(self, name):
        for table in (self.__dict__.get("inputs", {}), self.__dict__.get("facts", {})):
            if name in table:
                return table[name]
        raise AttributeError(name)

    @property
    def n(self):
        """The number of vertices (a fact ``n``, else the rows of the first input, a sparse matrix too)."""
        if "n" in self.facts:
            return self.facts["n"]
        first = next(iter(self.inputs.values()))
        return first.shape[0] if hasattr(first, "shape") else len(first)

    def but(self, **facts):
        """This case with more facts (``where=`` restricts :func:`agree` to those entries)."""
        other = Case(self.label, **self.inputs)
        other.facts = {**self.facts, **facts}
        return other


class Wrong:
    """A typical mistake as data: a diagnosis, a hint, and how to recognise the wrong answer.

    ``build(case)`` makes the wrong answer from a case; ``when(answer, right, case)`` says the
    mistake is seen on that case; neither: the catch-all (the answer differs from the right one).
    """

    def __init__(self, diagnosis, hint="", build=None, when=None, typical=True):
        if build is not None and when is not None:
            raise ValueError(f"{diagnosis!r}: give build or when, not both")
        self.diagnosis, self.hint, self.build, self.when, self.typical = diagnosis, hint, build, when, typical

    def at(self, case):
        """The ``Mistake`` of this entry, seen on ``case``."""
        return Mistake(self.diagnosis.replace("{label}", case.label), self.hint, typical=self.typical)

    def __repr__(self):
        return f"Wrong({self.diagnosis!r})"


FLOAT32 = Wrong(
    "right to float32 precision: compute in float64",
    "numpy computes in float64 unless told otherwise: drop the dtype=np.float32 (or astype) and keep the inputs' dtype",
)
_CATCH_ALL = Wrong("the answer differs from the right one on {label}", typical=False)


def _dense(A):
    return A.toarray() if sp.issparse(A) else np.asarray(A)


def agree(answer, expected, case=None, rtol=RTOL):
    """Whether two arrays have the same shape and agree to ``rtol`` of ``expected``'s largest entry.

    NaN agrees with NaN. With ``case.where`` (a boolean mask) only those entries are compared.
    """
    a, b = _dense(answer), _dense(expected)
    if a.shape != b.shape:
        return False
    where = None if case is None else case.facts.get("where")
    if where is not None:
        a, b = a[where], b[where]
    a, b = a.astype(float), b.astype(float)
    finite = np.abs(b[np.isfinite(b)])
    scale = max(float(finite.max(initial=0.0)), 1e-300)
    return bool(np.allclose(a, b, rtol=rtol, atol=rtol * scale, equal_nan=True))


def first_mistake(catalogue, cases, answers, right, same=agree):
    """The ``Mistake`` of the first entry of ``catalogue`` the answers are, or None when they are right.

    ``answers[i]`` is the (coerced) answer on ``cases[i]``; ``right(case)`` the right answer;
    ``same(answer, expected, case)`` the comparison. See the module docstring for the rules.
    """
    rights = [right(case) for case in cases]
    wrong_on = [case for case, a, r in zip(cases, answers, rights) if not same(a, r, case)]
    if not wrong_on:
        return None
    for entry in (*catalogue, _CATCH_ALL):
        if entry.build is not None:
            built = [entry.build(case) for case in cases]
            if all(same(a, w, case) for case, a, w in zip(cases, answers, built)):
                differ = [case for case, w, r in zip(cases, built, rights) if not same(w, r, case)]
                if differ:
                    return entry.at(differ[0])
        elif entry.when is not None:
            for case, a, r in zip(cases, answers, rights):
                if entry.when(a, r, case):
                    return entry.at(case)
        else:
            if all(agree(a, r, case, rtol=FLOAT32_RTOL) for case, a, r in zip(cases, answers, rights)):
                return FLOAT32.at(wrong_on[0])
            return entry.at(wrong_on[0])
    return None  # unreachable: the catch-all always answers


def judge(catalogue, cases, answers, right, same=agree):
    """Raise the ``Mistake`` :func:`first_mistake` finds; return None when the answers are right."""
    mistake = first_mistake(catalogue, cases, answers, right, same)
    if mistake is not None:
        raise mistake


def run(fn, cases, coerce):
    """``[coerce(fn(*inputs), case.n) for each case]``: the learner's answers, called on copies of the inputs."""
    return [coerce(answer(fn, case), case.n) for case in cases]


def answer(fn, case, **inputs):
    """What ``fn`` returns on copies of the case's inputs, some replaced by ``inputs`` (another seed, say)."""
    return call(fn, *(_copy(x) for x in {**case.inputs, **inputs}.values()))


def mesh_cases(meshes, rng, facts=None):
    """``[Case(label, V=V, F=F).but(**facts(V, F))]`` for each ``(label, (V, F))`` of ``meshes``, placed
    anew with ``rng`` (``meshes.placed``: moved, scaled, jittered, renumbered)."""
    cases = [Case(label, **dict(zip("VF", placed(V, F, rng)))) for label, (V, F) in meshes]
    return cases if facts is None else [c.but(**facts(c.V, c.F)) for c in cases]


def named(module, names):
    """``("module.a", "module.b", ...)`` for ``names = "a b ..."``: an exercise's forbidden or own routines."""
    return tuple(f"{module}.{name}" for name in names.split())


def _copy(x):
    return x.copy() if hasattr(x, "copy") else x


# ---------------------------------------------------------------- coercion: what came back, as float arrays


def _shape(diagnosis, hint):
    return Mistake(diagnosis, hint, typical=False)


def matrix_pair(out, n):
    """The pair (M, C) of n x n matrices the function returned, dense float arrays."""
    if not isinstance(out, tuple) or len(out) != 2:
        raise _shape(
            f"the function returned {type(out).__name__}, not the pair (M, C)",
            "end with `return M, C`, M the diagonal mass matrix and C the weight matrix",
        )
    M, C = (_dense(A) for A in out)
    for name, A in (("M", M), ("C", C)):
        if A.shape == (n,) and name == "M":
            raise _shape("M is a vector, not a matrix", "return the diagonal matrix scipy.sparse.diags(areas)")
        if A.shape != (n, n):
            raise _shape(
                f"{name} has shape {A.shape}, expected ({n}, {n}) for a mesh with {n} vertices",
                "one row and one column per vertex",
            )
    return M.astype(float), C.astype(float)


def vector(out, n, what="the function"):
    """The length-n vector of numbers the function returned, a float array ((n, 1) and (1, n) read as (n,))."""
    x = _dense(out)
    if x.dtype == object or x.shape not in ((n,), (n, 1), (1, n)):
        raise _shape(
            f"{what} returned shape {x.shape}, expected ({n},): one value per vertex",
            "return a flat numpy array with one entry per vertex",
        )
    return x.astype(float).reshape(n)


def positions(out, n, what="the function", nan_hint="look for a division by zero"):
    """The (n, 3) finite positions the function returned, a float array; ``nan_hint`` says what NaN means."""
    P = _dense(out)
    if P.shape != (n, 3):
        raise _shape(
            f"{what} returned shape {P.shape}, expected ({n}, 3): one new position per vertex",
            "return the (n, 3) array of new positions, like P",
        )
    if not np.isfinite(P.astype(float)).all():
        raise _shape(f"{what} returned NaN or infinite positions", nan_hint)
    return P.astype(float)


def _real(x, what):
    x = _dense(x)
    if np.iscomplexobj(x):
        if np.abs(x.imag).max(initial=0.0) > 1e-8 * max(np.abs(x.real).max(initial=0.0), 1e-300):
            raise Mistake(
                f"{what} has complex entries: a solver for non-symmetric matrices was used",
                "solve the symmetric generalised problem, e.g. scipy.linalg.eigh(-C, M), whose eigenpairs are real",
            )
        x = x.real
    return x.astype(float)


def eigenpairs(out, n, k):
    """The pair (lam (k,), E (n, k)) the function returned, real float arrays."""
    if not isinstance(out, (tuple, list)) or len(out) != 2:
        raise _shape(f"the function returned {type(out).__name__}, not the pair (lam, E)", "end with `return lam, E`")
    lam, E = _real(out[0], "lam"), _real(out[1], "E")
    if lam.ndim == 2 and E.ndim == 1:
        raise _shape("the pair is returned as (E, lam)", "return the eigenvalues first: `return lam, E`")
    lam = lam.reshape(-1) if lam.ndim == 2 and 1 in lam.shape else lam
    if E.shape == (k, n) and k != n:
        raise _shape(f"E is transposed: shape {E.shape}, expected ({n}, {k})", "the eigenvectors are the columns of E")
    if lam.ndim == 1 and E.ndim == 2 and E.shape[0] == n and len(lam) == E.shape[1] and len(lam) != k:
        raise _shape(
            f"{len(lam)} eigenpairs were returned where k = {k} were asked for",
            "keep exactly the k smallest: lam[:k], E[:, :k] (eigsh's k, or eigh's subset_by_index=[0, k - 1])",
        )
    if lam.shape != (k,) or E.shape != (n, k):
        raise _shape(
            f"lam has shape {lam.shape} and E {E.shape}, expected ({k},) and ({n}, {k})",
            "lam holds the k eigenvalues, E the k eigenvectors as columns",
        )
    return lam, E


def number(out, what="the function", hint="return one number, a float"):
    """The one real number the function returned, a float."""
    if isinstance(out, np.ndarray) and out.size != 1:
        raise _shape(f"{what} returned an array of shape {out.shape}, not one number", hint)
    try:
        return float(np.asarray(out).reshape(-1)[0] if isinstance(out, np.ndarray) else out)
    except (TypeError, ValueError):
        raise _shape(f"{what} returned {type(out).__name__}, not a number", hint) from None
