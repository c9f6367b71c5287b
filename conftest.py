"""pytest set-up for every run from this checkout (tests, notebooks or both).

With xdist's workers (``pytest -n 2``), each file stays whole on one worker: nbval runs a notebook's cells
in order in one kernel, so its cells must not be spread over workers. Set here rather than as
``--dist loadfile`` in pyproject's addopts, so that a pytest without xdist (an environment with nbval
only) still reads the configuration.
"""

import pytest


@pytest.hookimpl(hookwrapper=True)
def pytest_cmdline_main(config):
    # before xdist's own hook turns "-n N" without "--dist" into its default, "load"
    if getattr(config.option, "numprocesses", None) and getattr(config.option, "dist", "no") == "no":
        config.option.dist = "loadfile"
    yield
