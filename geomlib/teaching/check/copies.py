"""Copies: a student's function whose code is geomlib's routine or the solution notebook's.

Two functions are the same code when their *normalised* syntax trees agree: docstrings,
comments, annotations and layout dropped, every name (arguments, variables, the
function's own, the modules' aliases) replaced by its order of first use, keyword
arguments sorted. Renaming the variables of a pasted routine, re-wrapping its lines or
rewording its comments leaves the tree unchanged; writing it from the derivation rarely
gives the same tree, and a function under ``MIN_NODES`` nodes (a one-line answer) is
never called a copy, because two honest students can write the same line.

``find_copies(source, index(references))`` lists, for each function defined in ``source``,
the reference functions with the same tree; ``exercise_copies`` is what the grading judge
asks for one exercise: the exercise's solution cell against geomlib's own modules (a
copy earns no points: ``refusal``; their index, ``geomlib_index``, is made once per
process) and against the solution notebook's cell (flagged for the grader). The solutions
are public (the repository's notebooks/ is the solution version), so a flag is a question
for the grader, not a verdict.
"""

import ast
import functools
from pathlib import Path

MIN_NODES = 40  # smaller functions are not called copies: one or two lines can agree by chance


class _Normalise(ast.NodeTransformer):
    def __init__(self):
        self.names = {}

    def rename(self, name):
        return self.names.setdefault(name, f"v{len(self.names)}")

    def visit_Name(self, node):
        return ast.copy_location(ast.Name(id=self.rename(node.id), ctx=node.ctx), node)

    def visit_arg(self, node):
        return ast.arg(arg=self.rename(node.arg), annotation=None)

    def _function(self, node):
        node.name = self.rename(node.name)
        node.returns = None
        body = node.body
        if body and isinstance(body[0], ast.Expr) and isinstance(getattr(body[0], "value", None), ast.Constant):
            if isinstance(body[0].value.value, str):
                node.body = body[1:] or [ast.Pass()]
        node.decorator_list = []
        self.generic_visit(node)
        return node

    visit_FunctionDef = visit_AsyncFunctionDef = _function

    def visit_AnnAssign(self, node):
        if node.value is None:
            return None
        return self.visit(ast.Assign(targets=[node.target], value=node.value, lineno=0))

    def visit_Call(self, node):
        self.generic_visit(node)
        node.keywords.sort(key=lambda k: k.arg or "")
        return node

    def visit_Global(self, node):
        node.names = [self.rename(n) for n in node.names]
        return node

    visit_Nonlocal = visit_Global


def fingerprint(node):
    """(normalised tree as text, its number of nodes) of a function definition."""
    tree = _Normalise().visit(ast.parse(ast.unparse(node)).body[0])
    return ast.dump(tree, annotate_fields=False), sum(1 for _ in ast.walk(tree))


def functions(source):
    """{name: (fingerprint, nodes)} of every function defined in ``source`` (nested ones too)."""
    try:
        tree = ast.parse(source)
    except SyntaxError:
        return {}
    return {
        node.name: fingerprint(node)
        for node in ast.walk(tree)
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))
    }


def index(references):
    """{normalised tree: (label, function)} of the functions of ``references`` ({label: source}) that have
    ``MIN_NODES`` nodes or more (of equal trees, the first)."""
    found = {}
    for label, text in references.items():
        for name, (tree, nodes) in functions(text).items():
            if nodes >= MIN_NODES:
                found.setdefault(tree, (label, name))
    return found


def find_copies(source, references):
    """[(function in source, reference label, reference function)] of the functions of ``source``
    whose normalised tree is in ``references`` (an ``index``)."""
    return [(name, *references[tree]) for name, (tree, _) in functions(source).items() if tree in references]


@functools.cache
def geomlib_index():
    """The ``index`` of geomlib's routines (lessons, mesh, numerics), read from the package folder: made once
    per process, since a grading run asks it for every exercise of every student."""
    root = Path(__file__).resolve().parents[2]
    return index(
        {
            path.relative_to(root.parent).with_suffix("").as_posix().replace("/", "."): path.read_text()
            for folder in ("lessons", "mesh", "numerics")
            for path in sorted((root / folder).glob("*.py"))
        }
    )


def exercise_copies(source, solution=""):
    """The copy flags of one exercise's solution cell ``source``: [{"function", "of", "matches"}],
    ``of`` "geomlib" (a copy of geomlib's code: no points) or "solution" (flagged for the grader)."""
    flags = [
        {"function": name, "of": "geomlib", "matches": f"{label}.{ref}"}
        for name, label, ref in find_copies(source, geomlib_index())
    ]
    if solution:
        flags += [
            {"function": name, "of": "solution", "matches": ref}
            for name, _, ref in find_copies(source, index({"solution": solution}))
        ]
    return flags


def refusal(flag):
    """The diagnosis of a copy of geomlib's code."""
    return (
        f"`{flag['function']}` is geomlib's `{flag['matches'].rpartition('.')[2]}` ({flag['matches']}) with "
        "the names changed: a copy of geomlib's code earns no points. Write it from the derivation."
    )


def flag_sentence(flag):
    """What the feedback tells the grader about a function with the solution notebook's code."""
    return (
        f"Flagged for the grader: `{flag['function']}` has the syntax tree of the solution notebook's "
        f"`{flag['matches']}` (names aside)."
    )
