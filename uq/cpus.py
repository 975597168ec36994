"""The CPUs this process may run on: one count for every layer (the engine's threads,
the runner's numpy chunks, the campaign's threads, the benchmark's machine line and the
background compile's choice)."""
import os


def usable_cpus():
    """The CPUs this process may run on [1]: its affinity mask where the system has one
    (Linux: a container's or ``taskset``'s limit), else every CPU the machine has."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:                   # not on Linux
        return os.cpu_count() or 1
