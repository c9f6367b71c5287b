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
    """What the scheduler calls on one of xdist's workers: the tests it is sent, in a queue; and how
    many were still waiting in its queue each time it was sent a file."""

    shutting_down = False

    def __init__(self, name):
        self.gateway = SimpleNamespace(id=name)
        self.queue, self.waiting_when_sent = [], []

    def send_runtest_some(self, indexes):
        self.waiting_when_sent.append(len(self.queue))
        self.queue += indexes

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
    # as xdist's worker does, a worker runs a test once it knows the next one (or that none will come)
    while any(len(w.queue) >= 2 or (w.queue and w.shutting_down) for w in workers):
        for w in workers:
            if len(w.queue) >= 2 or (w.queue and w.shutting_down):
                i = w.queue.pop(0)
                file = collection[i].split("::")[0]
                if file not in order:
                    order.append(file)
                ran.append(i)
                sched.mark_test_complete(w, i)
    assert order == [longer, long, "tests/many.py", "tests/some.py", "tests/few.py"]
    assert sorted(ran) == list(range(len(collection))) and sched.tests_finished
    # a file is handed out when its worker has at most the one test waiting that it cannot start alone
    assert all(waiting <= 1 for w in workers for waiting in w.waiting_when_sent), [w.waiting_when_sent for w in workers]


def test_other_distributions_keep_xdists_scheduler():
    assert scheduler("load") is None
