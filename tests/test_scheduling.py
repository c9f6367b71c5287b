"""The checkout's conftest.py hands the test files to xdist's workers longest first.

xdist's own ``--dist loadfile`` orders the files by their number of tests, so the few tests that
grade a whole class came last and one worker finished the run alone. The scheduler is driven here
with two stand-in workers, as xdist's controller drives it.
"""

import importlib.util
from pathlib import Path
from types import SimpleNamespace

ROOT = Path(__file__).resolve().parents[1]
spec = importlib.util.spec_from_file_location("checkout_conftest", ROOT / "conftest.py")
checkout = importlib.util.module_from_spec(spec)
spec.loader.exec_module(checkout)


class Worker:
    """What the scheduler calls on one of xdist's workers: the test indexes it is sent."""

    shutting_down = False

    def __init__(self, name):
        self.gateway = SimpleNamespace(id=name)
        self.sent = []

    def send_runtest_some(self, indexes):
        self.sent.append(list(indexes))

    def shutdown(self):
        self.shutting_down = True


def scheduler(dist="loadfile"):
    config = SimpleNamespace(
        getvalue=lambda name: {"tx": ["2*popen"], "dist": dist}[name],
        option=SimpleNamespace(loadscopereorder=True),
    )
    return checkout.pytest_xdist_make_scheduler(config, log=None)


def test_every_file_the_table_names_is_in_the_checkout():
    missing = [name for name in checkout.FILE_SECONDS if not (ROOT / name).is_file()]
    assert not missing, f"conftest.py's FILE_SECONDS names files that are gone: {missing}"


def test_the_longest_files_go_first_and_the_rest_in_xdists_order():
    long, longer = list(checkout.FILE_SECONDS)[1], list(checkout.FILE_SECONDS)[0]
    assert checkout.FILE_SECONDS[longer] > checkout.FILE_SECONDS[long]
    files = {"tests/few.py": 2, long: 3, "tests/many.py": 40, longer: 1, "tests/some.py": 5}
    collection = [f"{file}::test_{k}" for file, n in files.items() for k in range(n)]
    sched, workers = scheduler(), [Worker("gw0"), Worker("gw1")]
    for w in workers:
        sched.add_node(w)
        sched.add_node_collection(w, collection)
    sched.schedule()
    order, ran = [], []
    while any(w.sent for w in workers):
        for w in workers:  # each worker runs the file it was sent, test by test
            if w.sent:
                indexes = w.sent.pop(0)
                order.append(collection[indexes[0]].split("::")[0])
                for i in indexes:
                    ran.append(i)
                    sched.mark_test_complete(w, i)
    assert order == [longer, long, "tests/many.py", "tests/some.py", "tests/few.py"]
    assert sorted(ran) == list(range(len(collection))) and sched.tests_finished


def test_other_distributions_keep_xdists_scheduler():
    assert scheduler("load") is None
