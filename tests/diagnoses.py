"""The test suite's one assertion of a failed exercise check (geomlib.teaching.check)."""


def assert_diagnosed(result, *phrases):
    """The check did not pass and its message holds every phrase (a failure shows the message)."""
    assert not result.passed, result.message
    for phrase in phrases:
        assert phrase in result.message, result.message
