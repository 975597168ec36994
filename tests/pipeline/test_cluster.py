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


def test_a_local_cluster_leaves_this_process_s_environment_as_it_was(monkeypatch):
    """dask's nanny writes its workers' variables (MALLOC_TRIM_THRESHOLD_=65536, ...)
    into the spawning process's environment; every later child would inherit them."""
    import os
    from uq.pipeline.cluster import local_cluster
    monkeypatch.delenv("MALLOC_TRIM_THRESHOLD_", raising=False)
    monkeypatch.setenv("OMP_NUM_THREADS", "3")
    before = dict(os.environ)
    with local_cluster(1) as client:
        assert client.submit(os.getenv, "MALLOC_TRIM_THRESHOLD_").result() == "65536"
        assert dict(os.environ) == before            # restored once the workers started
    assert dict(os.environ) == before


def test_restore_environment_removes_adds_and_resets(monkeypatch):
    import os
    from uq.pipeline.cluster import restore_environment
    monkeypatch.setenv("UQ_TEST_KEPT", "1")
    monkeypatch.delenv("UQ_TEST_ADDED", raising=False)
    before = dict(os.environ)
    monkeypatch.setenv("UQ_TEST_ADDED", "x")
    monkeypatch.setenv("UQ_TEST_KEPT", "2")
    restore_environment(before)
    assert dict(os.environ) == before
