"""Set-up of a sweep's local workers when they are fork()ed (sweep._Runner); imports dask's
distributed, so only the runner imports this module."""

from __future__ import annotations

from distributed.diagnostics.plugin import WorkerPlugin


class ForkedWorker(WorkerPlugin):
    """Makes a fork()ed worker start as a spawned one did. One BLAS thread (dask's pre-spawn
    OPENBLAS_NUM_THREADS=1, read as numpy loads): a fork()ed worker inherits the BLAS its
    parent loaded, with the parent's thread count. Python's own SIGTERM handling: it inherits
    its parent's handlers (the CLI's turn SIGTERM into SystemExit). SIGINT ignored, as in a
    spawned one (ignore_interrupts). A plugin, so that a worker the nanny restarts gets it too."""

    name = "tactileskin-forked-worker"

    def setup(self, worker) -> None:
        import signal
        import threading

        from threadpoolctl import threadpool_limits

        threadpool_limits(limits=1, user_api="blas")  # for the process's life, not a context
        if threading.current_thread() is threading.main_thread():  # signal.signal's condition
            signal.signal(signal.SIGINT, signal.SIG_IGN)
            signal.signal(signal.SIGTERM, signal.SIG_DFL)


class IgnoreInterrupts(WorkerPlugin):
    """A local worker ignores SIGINT. A terminal's Ctrl-C reaches the whole foreground process
    group: each worker died of it with a KeyboardInterrupt traceback printed after the sweep's
    'interrupted'. The sweep's process handles it and closes its cluster, which ends the
    workers (the nanny's close, then SIGTERM)."""

    name = "tactileskin-ignore-interrupts"

    def setup(self, worker) -> None:
        import signal
        import threading

        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, signal.SIG_IGN)
