"""Test-suite set-up shared by every test.

Notebooks run by nbval with their default parameters must hold every claim of
their text: ``GEOMLIB_STRICT_CLAIMS=1`` makes ``geomlib.teaching.notebook.claim`` (and a
failed exercise check of a written function) raise instead of showing a note.
The kernels nbval starts inherit this environment. Runs with a reader's
inputs (tests/notebook_runner.py) set it to 0 for their own kernels.
"""

import os

import pytest
from awkward_meshes import make_all

os.environ["GEOMLIB_STRICT_CLAIMS"] = "1"


@pytest.fixture(scope="module")
def awkward(tmp_path_factory):
    """The awkward meshes of tests/awkward_meshes.py, written once per test module: name -> path (str)."""
    return {name: str(path) for name, path in make_all(tmp_path_factory.mktemp("awkward")).items()}
