"""CPUs a process may use and the user's thread-count variables, for the thread counts of
fe.linsolve (PARDISO) and sweep (workers).

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


def user_setting(large: bool) -> tuple[str, str] | None:
    """(name, value) of the first thread-count variable set (non-blank): for the large (3D)
    systems TACTILESKIN_THREADS, then MKL_NUM_THREADS; for the others MKL_NUM_THREADS."""
    for name in (("TACTILESKIN_THREADS",) if large else ()) + ("MKL_NUM_THREADS",):
        value = os.environ.get(name, "").strip()
        if value:
            return name, value
    return None
