"""Errors and warnings raised by geomlib.

Every check on user input raises :class:`MeshError` with a message that names
the problem and where it is (file and line, or the offending vertex and face
indices). Conditions under which the computation can still go on (zero-area
faces, boundaries, several components, ...) are reported with
:class:`MeshWarning` instead, and nothing is altered silently.
"""


class MeshError(ValueError):
    """A mesh, file or argument that geomlib cannot work with.

    The message names the problem and where it is. Subclass of ValueError so
    that generic ``except ValueError`` code keeps working.
    """


class MeshWarning(UserWarning):
    """A mesh property that results depend on but that is not an error
    (zero-area faces, non-manifold edges, boundaries, several components)."""


def format_indices(idx, limit=10):
    """Short text listing of offending indices: '3, 17, 42 (and 5 more)'."""
    idx = [int(i) for i in idx]
    head = ", ".join(str(i) for i in idx[:limit])
    if len(idx) > limit:
        head += f" (and {len(idx) - limit} more)"
    return head


def count_text(items, singular, plural=None):
    """'1 edge', '3 edges': the number of ``items`` with its noun in the right number."""
    k = len(items)
    return f"{k} {singular if k == 1 else (plural or singular + 's')}"
