"""Set-up of a sweep's local workers (sweep._Runner); imports dask's distributed, so only the
runner imports this module."""

from __future__ import annotations

from distributed.diagnostics.plugin import WorkerPlugin


def worker_signals(default_sigterm: bool) -> None:
    """SIGINT ignored: a terminal's Ctrl-C reaches the whole foreground process group, and each
    worker died of it with a KeyboardInterrupt traceback printed after the sweep's
    'interrupted'; the sweep's process handles it and closes its cluster, which ends the
    workers (the nanny's close, then SIGTERM). default_sigterm: Python's own SIGTERM handling,
    not the handler a fork()ed worker inherits (the CLI's turns SIGTERM into SystemExit)."""
    import signal
    import threading

    if threading.current_thread() is threading.main_thread():  # signal.signal's condition
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        if default_sigterm:
            signal.signal(signal.SIGTERM, signal.SIG_DFL)


class IgnoreInterrupts(WorkerPlugin):
    """A local (spawned) worker ignores SIGINT once it has registered (worker_signals)."""

    name = "tactileskin-ignore-interrupts"

    def setup(self, worker) -> None:
        worker_signals(default_sigterm=False)


class ForkedWorker(WorkerPlugin):
    """Makes a fork()ed worker start as a spawned one did. One BLAS thread (dask's pre-spawn
    OPENBLAS_NUM_THREADS=1, read as numpy loads): a fork()ed worker inherits the BLAS its
    parent loaded, with the parent's thread count. Its signals as worker_signals(True) sets
    them. A plugin, so that a worker the nanny restarts gets it too."""

    name = "tactileskin-forked-worker"

    def setup(self, worker) -> None:
        from threadpoolctl import threadpool_limits

        threadpool_limits(limits=1, user_api="blas")  # for the process's life, not a context
        worker_signals(default_sigterm=True)
