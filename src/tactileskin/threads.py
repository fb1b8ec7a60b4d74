"""CPUs a process may use, for the thread counts of fe.linsolve (PARDISO) and sweep (workers).

Plain os calls: the sweep's main process asks before it starts its workers and must not
import the solver for it.
"""

from __future__ import annotations

import os


def available_cpus() -> int:
    """The CPUs this process may run on (its affinity mask; the CPU count off Linux)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1
