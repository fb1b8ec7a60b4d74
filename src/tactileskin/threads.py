"""CPUs a process may use and the user's thread-count variables, for the thread counts of
fe.linsolve (PARDISO), the compiled element and material loops (numba) and sweep (workers).

Plain os calls: the sweep's main process asks before it starts its workers and must not
import the solver for it.
"""

from __future__ import annotations

import contextlib
import os
import sys


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


# set in a fork()ed child (multiprocessing's default on Linux: a Pool.map of solves) whose parent
# had started numba's thread pool (any solve does, via numba_threads) or run PARDISO on several
# threads: GNU OpenMP's threads do not survive fork() (numba terminates such a child at its first
# parallel region, "fork() called from a process already using GNU OpenMP"; PARDISO on MKL's GNU
# threading layer waited for them), so there the compiled loops and PARDISO run on one thread
_parent_threads = False   # this process started them
_forked_from_threads = False


def threads_started() -> bool:
    """True if this process started numba's thread pool or PARDISO's threads: a child fork()ed
    now would run its compiled loops and PARDISO on one thread (forked_from_threads)."""
    parallel = sys.modules.get("numba.np.ufunc.parallel")
    return _parent_threads or (parallel is not None and getattr(parallel, "_is_initialized", True))


def _after_fork_in_child() -> None:
    global _forked_from_threads
    if threads_started():
        _forked_from_threads = True


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_after_fork_in_child)


def other_threads() -> list:
    """The Python threads of this process but the calling one, the idle pools of an earlier
    sweep's dask (Dask-Offload, ...) and the sweep command's progress bar (rich's refresh):
    threads that may hold a lock when fork() copies the process (sweep, report.background)."""
    import threading

    return [t for t in threading.enumerate()
            if t is not threading.current_thread() and not t.name.startswith("Dask-")
            and type(t).__module__ != "rich.live"]


def started_threads() -> None:
    """Note that this process started OpenMP threads (PARDISO on several threads)."""
    global _parent_threads
    _parent_threads = True


def forked_from_threads() -> bool:
    """True in a fork()ed child of a process that had started numba's or MKL's threads (and in
    its own fork()ed children): its compiled loops and PARDISO run on one thread."""
    return _forked_from_threads


def numba_parallel_threads() -> int:
    """Threads numba's parallel loops of this thread may use: numba.get_num_threads(), or 1 in
    a fork()ed child of a process that had started numba's or MKL's threads (the loops' serial
    twins then: the same bits)."""
    import numba

    return 1 if _forked_from_threads else numba.get_num_threads()


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
