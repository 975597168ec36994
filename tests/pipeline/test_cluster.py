"""The local cluster's clean-up after a stop (uq/pipeline/cluster.py)."""
import types

from uq.pipeline.cluster import _close_after_stop


def test_a_failed_close_after_a_stop_marks_the_client_closed():
    """A close that times out leaves no client for ``__del__`` to close again (and print
    that failure with a traceback at garbage collection)."""
    def close():
        raise TimeoutError("timed out while closing")
    client = types.SimpleNamespace(status="running", close=close)
    _close_after_stop(client)
    assert client.status == "closed"


def test_a_close_that_returns_unfinished_is_marked_closed():
    # its __del__ would close it again and print that failure with a traceback
    client = types.SimpleNamespace(status="running")
    client.close = lambda: setattr(client, "status", "closing")
    _close_after_stop(client)
    assert client.status == "closed"


def test_a_close_that_works_is_left_alone():
    calls = []
    client = types.SimpleNamespace(status="running", close=lambda: calls.append(1))
    _close_after_stop(client)
    assert calls == [1] and client.status == "running"
