"""The test suite's one assertion of a failed exercise check (geomlib.teaching.check)."""


def assert_diagnosed(result, *phrases):
    """The check did not pass and its message holds every phrase (a failure shows the message)."""
    assert not result.passed, result.message
    for phrase in phrases:
        assert phrase in result.message, result.message


def replaying(cases, answer):
    """A learner's function that hands back ``answer(case)`` on each of a check's cases (found by its first
    input): a catalogue's wrong answers handed in as the check, run with the same seed, will see them."""
    import numpy as np

    table = {np.asarray(next(iter(c.inputs.values()))).tobytes(): answer(c) for c in cases}

    def handed_in(*inputs):
        return table[np.asarray(inputs[0]).tobytes()]

    return handed_in
