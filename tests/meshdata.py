"""Where the tests find meshes: the ones the workbook ships, and the course's.

The course's meshes are not part of the repository; CI has them in
``../shared/meshes`` beside the checkout. Tests that need them use
``needs_course`` and are skipped, saying so, where the folder is absent.
"""

import warnings
from pathlib import Path

import pytest

from geomlib import MeshWarning, load_mesh

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ROOT / "geomlib" / "meshes"
COURSE = ROOT.parent / "shared" / "meshes"

SHIPPED_MESHES = sorted(p.name for p in SHIPPED.glob("*.obj"))
COURSE_MESHES = sorted(str(p.relative_to(COURSE)) for p in COURSE.rglob("*.obj")) if COURSE.is_dir() else []

needs_course = pytest.mark.skipif(not COURSE.is_dir(), reason="the course meshes (../shared/meshes) are not present")


def load_quietly(path):
    """load_mesh without its report warning (the tests check the arrays)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshWarning)
        return load_mesh(path)
