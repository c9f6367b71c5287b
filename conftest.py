"""pytest set-up for every run from this checkout (tests, notebooks or both).

With xdist's workers (``pytest -n 2``), each file stays whole on one worker: nbval runs a notebook's cells
in order in one kernel, so its cells must not be spread over workers. Set here rather than as
``--dist loadfile`` in pyproject's addopts, so that a pytest without xdist (an environment with nbval
only) still reads the configuration.

The files are handed to the workers longest first (:data:`FILE_SECONDS`), each when a worker is free,
so that the run does not end with one worker grading a class while the other has nothing left to do.
"""

import pytest

#: seconds the long test files took in a full run on a quiet 2-core machine with two workers (its
#: ``--durations`` of 10 s or more, summed per file); the files not listed follow in xdist's order
#: (most tests first). Refresh it from ``python3 workbook.py test --durations=0`` when a file's share
#: changes much: an entry off by a factor of two still orders the long files roughly right
FILE_SECONDS = {
    "tests/test_course.py": 400,
    "tests/browser/test_site.py": 324,
    "tests/browser/test_notebooks_browser.py": 269,
    "tests/test_nbgrader.py": 166,
    "tests/browser/test_accessibility.py": 132,
    "tests/browser/test_frontends_browser.py": 90,
    "tests/test_integrity.py": 101,
    "tests/test_check_students.py": 87,
    "tests/test_install.py": 47,
    "tests/test_assignment.py": 37,
    "tests/test_pictures.py": 29,
    "tests/test_reader_inputs_00_02.py": 23,
    "tests/test_check_forms.py": 13,
    "tests/test_reader_inputs_07.py": 10,
}


@pytest.hookimpl(hookwrapper=True)
def pytest_cmdline_main(config):
    # before xdist's own hook turns "-n N" without "--dist" into its default, "load"
    if getattr(config.option, "numprocesses", None) and getattr(config.option, "dist", "no") == "no":
        config.option.dist = "loadfile"
    yield


@pytest.hookimpl(tryfirst=True, optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """``--dist loadfile`` with the longest files first (xdist's own order is by test count, which
    puts a file of three tests that grade a class last of all)."""
    if config.getvalue("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadFileScheduling

    class LongestFileFirst(LoadFileScheduling):
        def _reschedule(self, node):
            # A worker starts a test once it knows the next one, so xdist hands it the next file while
            # two tests of its file are left, committing that file to a worker still busy for minutes
            # (a file's last tests grade a class or run the guide's trial). With one test left the
            # worker is waiting for exactly this: the next file goes to the worker that is free.
            if node.shutting_down or not self.workqueue or self._pending_of(self.assigned_work[node]) <= 1:
                super()._reschedule(node)

        def _assign_work_unit(self, node):
            # the costliest file still waiting goes next; among equals, xdist's order (max keeps the first)
            scope = max(self.workqueue, key=lambda file: FILE_SECONDS.get(file, 0))
            self.workqueue.move_to_end(scope, last=False)
            super()._assign_work_unit(node)

    return LongestFileFirst(config, log)
