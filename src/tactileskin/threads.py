"""CPUs a process may use and the user's thread-count variables, for the thread counts of
fe.linsolve (PARDISO), the compiled element and material loops (numba) and sweep (workers).

Plain os calls: the sweep's main process asks before it starts its workers and must not
import the solver for it.
"""

from __future__ import annotations

import contextlib
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


@contextlib.contextmanager
def numba_threads(n: int):
    """Inside: numba's parallel loops of this thread run on n threads (at most numba's pool;
    numba.set_num_threads is thread-local), restored on exit."""
    import numba

    old = numba.get_num_threads()
    numba.set_num_threads(max(1, min(int(n), numba.config.NUMBA_NUM_THREADS)))
    try:
        yield
    finally:
        numba.set_num_threads(old)
