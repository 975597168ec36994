"""The local dask cluster of a distributed sweep (``uq run --workers N``). No physics.

:func:`local_cluster` starts N worker processes of one thread each; the scheduler runs
in a thread of the process that drives the run. dask's periodic housekeeping is slowed
down (:data:`CLUSTER_SETTINGS`): by default each event loop checks its own health every
20 ms, every process samples its system load every 0.5 s and every worker samples its
stacks every 10 ms for the dashboard's profile. On a busy
machine that costs the driving process about 0.03 s of CPU time per second of run and
each worker as much again (measured with 2 workers, 2 cores, idle cluster: 0.034 -> 0.010
s/s in the driver, 0.058 -> 0.011 s/s in the workers): CPU time taken from the sweep
itself, and the driver's part of it is serial (``uq.bench.sweep.serial_fraction``).
None of it changes a number: the chunks are a fixed function of the scenario.
"""
import contextlib
import os

#: dask settings of the local cluster (:func:`local_cluster`), dask's own config keys.
CLUSTER_SETTINGS = {
    "distributed.admin.tick.interval": "1s",             # event-loop health check (20 ms)
    "distributed.admin.system-monitor.interval": "5s",   # CPU/memory sampling (500 ms)
    "distributed.worker.profile.enabled": False,         # stack sampling every 10 ms
}


@contextlib.contextmanager
def local_cluster(workers, starting=contextlib.nullcontext, **options):
    """A ``dask.distributed.Client`` of a new LocalCluster of `workers` processes, one
    thread each, with :data:`CLUSTER_SETTINGS`, its HTTP server (and dashboard, where
    bokeh is installed) on a free port; closed at the end of the
    block. `starting`: a context manager held while the worker processes start (the
    command line's, which keeps Ctrl-C from them); `options` go to LocalCluster (e.g.
    ``host``). The client is not made dask's default scheduler."""
    import dask
    from dask.distributed import Client, LocalCluster
    environment = dict(os.environ)
    with dask.config.set(CLUSTER_SETTINGS):
        try:
            with starting():
                cluster = LocalCluster(n_workers=workers, threads_per_worker=1,
                                       processes=True, dashboard_address=":0", **options)
        finally:                                 # (a start that failed wrote them too)
            restore_environment(environment)
        client = None
        try:
            with cluster:
                client = Client(cluster, set_as_default=False)
                try:
                    yield client
                except BaseException:
                    _close_after_stop(client)
                    raise
                client.close()
        finally:
            # the cluster and its event loop are gone: a client not marked closed (a stop
            # that came during its close) would close again at garbage collection and
            # print "Exception ignored in: Client.__del__ ... IOLoop is closed"
            if client is not None and client.status != "closed":
                client.status = "closed"
            restore_environment(environment)


def restore_environment(environment):
    """Make ``os.environ`` `environment` again. dask's nanny sets its workers' variables
    (``distributed.nanny.pre-spawn-environ``: ``MALLOC_TRIM_THRESHOLD_=65536``,
    ``OMP_NUM_THREADS=1`` and others) in this process's own environment before it
    spawns them; left there, every later child of this process inherits them (a
    record-mode ``uq run`` started after a cluster took 3x its time, most of it in the
    kernel returning memory)."""
    for key in set(os.environ) - set(environment):
        del os.environ[key]
    for key, value in environment.items():
        if os.environ.get(key) != value:
            os.environ[key] = value


def _close_after_stop(client):
    """Close `client` after the block stopped (Ctrl-C, SIGTERM, a failure): the stop's
    own exception is what the user is told. A close that fails (on a loaded machine it
    can time out while the scheduler is busy cancelling) leaves the client "closing", and
    its ``__del__`` would close it again at garbage collection and print that failure
    with a traceback ("Exception ignored in: Client.__del__"); it is marked closed
    instead (the cluster's own close follows, and the process is ending), also where the
    close returned without finishing (seen once in a loaded test run)."""
    try:
        client.close()
    except Exception:
        client.status = "closed"
    if client.status == "closing":               # returned before the close finished
        client.status = "closed"
