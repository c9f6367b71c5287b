"""Progress bars (tqdm.auto) for the steps that can take more than a couple of seconds."""

import time

__all__ = ["SECONDS", "LARGE_MESH", "Iterations", "Stages", "loop"]

#: Runs estimated to take longer than this many seconds show a progress bar.
SECONDS = 2.0

#: Vertices: a notebook's loop over meshes at least this large takes seconds per item.
LARGE_MESH = 50_000


class Iterations:
    """A bar over ``total`` iterations: shown at once with ``progress=True``; with
    ``progress=None`` only when the first iteration predicts more than ``SECONDS``."""

    def __init__(self, total, progress, desc):
        self.total, self.progress, self.desc = total, progress, desc
        self.bar = None
        self.start = time.perf_counter()
        if progress is True and total > 0:
            self._open(0)

    def _open(self, done):
        from tqdm.auto import tqdm

        self.bar = tqdm(total=self.total, initial=done, desc=self.desc, leave=False)

    def step(self, k):
        """Call after iteration k (1-based) has finished."""
        if self.bar is not None:
            self.bar.update(1)
        elif self.progress is None and k == 1 and self.total > 1:
            if (time.perf_counter() - self.start) * self.total > SECONDS:
                self._open(1)

    def close(self):
        if self.bar is not None:
            self.bar.close()


class Stages:
    """A bar over named stages of one long computation, shown only when ``estimate`` (s) > ``SECONDS``.

    Use as ``with Stages(["factorising", "Lanczos"], estimate, "eigenbasis") as bar:``
    and call ``bar.next()`` when a stage finishes.
    """

    def __init__(self, names, estimate, desc):
        self.names, self.estimate, self.desc = list(names), estimate, desc
        self.bar = None

    def __enter__(self):
        if self.estimate > SECONDS:
            from tqdm.auto import tqdm

            self.bar = tqdm(total=len(self.names), desc=f"{self.desc} (about {self.estimate:.0f} s)", leave=False)
            self.bar.set_postfix_str(self.names[0])
        return self

    def next(self):
        if self.bar is not None:
            self.bar.update(1)
            if self.bar.n < len(self.names):
                self.bar.set_postfix_str(self.names[self.bar.n])

    def __exit__(self, *exc):
        if self.bar is not None:
            self.bar.close()


def loop(items, desc, vertices):
    """``items``, with a progress bar when the largest mesh of the loop has more than
    :data:`LARGE_MESH` vertices (``vertices``); for the notebooks' loops over meshes."""
    from tqdm.auto import tqdm

    return tqdm(items, desc=desc, leave=False, disable=vertices <= LARGE_MESH)
