"""Command-line interface. One module per command; only this layer prints and exits.

Commands are registered lazily by module name so that `tactileskin solve` never pays
for build123d or pyvista imports.
"""

from __future__ import annotations

import contextlib
import importlib
import importlib.util
import logging
import os
import signal
import sys
import threading

# One BLAS/OpenMP thread per process unless the user says otherwise (before numpy loads):
# the solver's vectors are small, and threaded BLAS spinning on a busy 2-core machine made
# each 11k-entry dot product take ~14 ms (measured under a running sweep). Dask workers get
# the same from distributed's defaults. MKL (PARDISO only) is left to fe.linsolve, which
# threads the large 3D systems of a lone solve.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import click

from tactileskin.errors import TactileSkinError

# command name -> module under tactileskin.cli that defines `command`
COMMANDS = {
    "build": "build",
    "mesh": "mesh",
    "solve": "solve",
    "sweep": "sweep",
    "film": "film",
    "array": "array",
    "material": "material",
    "export": "export",
}


class _LazyGroup(click.Group):
    def list_commands(self, ctx):
        return sorted(n for n, m in COMMANDS.items()
                      if importlib.util.find_spec(f"tactileskin.cli.{m}") is not None)

    def get_command(self, ctx, name):
        mod = COMMANDS.get(name)
        if mod is None or importlib.util.find_spec(f"tactileskin.cli.{mod}") is None:
            return None
        return importlib.import_module(f"tactileskin.cli.{mod}").command


QUIET_LIBRARIES = ("skfem", "distributed", "numba", "matplotlib", "PIL")


@click.group(cls=_LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.option("-v", "--verbose", count=True, help="More log output (-v info, -vv debug).")
@click.version_option(package_name="tactileskin")
def cli(verbose: int) -> None:
    """tactileskin: soft artificial skins over tactile sensors.

    Units everywhere: mm, s, N, MPa.
    """
    level = logging.WARNING - 10 * min(verbose, 2)
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")
    # -v shows tactileskin's steps (cut-backs, meshes, solves); the libraries' own info
    # lines (scikit-fem's "Initializing finished", Dask's) only with -vv
    for name in QUIET_LIBRARIES:
        logging.getLogger(name).setLevel(logging.WARNING if verbose < 2 else logging.DEBUG)


# the signals received during this run: an exception raised by a signal handler is lost when
# it lands in a __del__ or in compiled code ("Exception ignored in ..."), and the run went on
# to exit 0 (about 1 SIGTERM in 8 during a solve); `raise_if_signalled` raises it again at the
# next progress step, and `main` returns the signal's exit status in any case
_signalled: list[int] = []


def _on_signal(signum, frame):
    # an exception, so that `finally` blocks remove temporaries and staging folders
    _signalled.append(signum)
    _raise_for(signum)


def _raise_for(signum):
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise SystemExit(128 + signum)


def raise_if_signalled() -> None:
    """Raise again for a signal whose exception was swallowed (called from progress steps)."""
    if _signalled:
        _raise_for(_signalled[-1])


@contextlib.contextmanager
def _signals_raise():
    """SIGTERM (a scheduler's kill, `timeout`) unwinds like Ctrl-C instead of dying in place;
    both are remembered (`_signalled`)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _signalled.clear()
    previous = {s: signal.signal(s, _on_signal) for s in (signal.SIGTERM, signal.SIGINT)}
    try:
        yield
    finally:
        for s, h in previous.items():
            signal.signal(s, h)


def main(argv: list[str] | None = None) -> int:
    """Run the CLI in-process; returns the exit code (tests call this directly)."""
    from rich.markup import escape

    from tactileskin.cli._console import new_console

    err = new_console(stderr=True)
    try:
        with _signals_raise():
            rv = cli.main(args=argv, prog_name="tactileskin", standalone_mode=False)
            raise_if_signalled()  # a signal whose exception was swallowed: not a normal end
    except TactileSkinError as e:
        # the message quotes user text (names, Braille text, paths): print it as text, not markup
        err.print(f"[bold red]error:[/] {escape(str(e))}", highlight=False, soft_wrap=True)
        return 2
    except click.exceptions.Exit as e:
        return e.exit_code
    except click.ClickException as e:
        e.show()
        return e.exit_code
    except (click.exceptions.Abort, KeyboardInterrupt):
        # 128 + SIGINT, the shell's code for Ctrl-C (SIGTERM exits 143, _on_signal): not 1,
        # which `sweep` uses for "some case failed, the others reported"
        err.print("interrupted: no output was left half-written (a sweep keeps its finished cases in its cache)")
        return 130
    except Exception as e:
        if _signalled:
            # the signal's exception came out of compiled code as another one ("SystemError:
            # CPUDispatcher(...) returned a result with an exception set"): the interruption
            err.print("interrupted: no output was left half-written (a sweep keeps its finished cases in its cache)")
            return 130 if _signalled[-1] == signal.SIGINT else 128 + _signalled[-1]
        if not isinstance(e, OSError):
            raise
        # last resort: a file error that no writer turned into an OutputError
        where = f"{e.filename}: " if e.filename else ""
        err.print(f"[bold red]error:[/] {escape(where + str(e.strerror or e))}", highlight=False, soft_wrap=True)
        return 2
    finally:
        if argv is None and _signalled:
            # the process ends here (the console script): dask's cluster, still closing, logs
            # the failure of its interrupted start-up (a nanny whose worker was ended) after
            # "interrupted"; nothing is left to report
            logging.disable(logging.CRITICAL)
        if threading.current_thread() is threading.main_thread():
            _signalled.clear()  # read above; a later run (a notebook's, another thread's) starts clean
    return rv if isinstance(rv, int) else 0


def run() -> None:
    """The console script (and `python -m tactileskin`): main(), then the process ends without
    Python's teardown of every module's objects (a cached preview rerun 1.12 -> 0.96 s, idle;
    benchmarks/results/cli_exit.md). The exit handlers (dask closing its clusters, logging's flush)
    and the streams' flush run first, as at a normal exit; a thread still running (none of
    the package's) gets the normal exit, which waits for it."""
    import atexit

    code = main()
    if any(t.is_alive() and not t.daemon for t in threading.enumerate() if t is not threading.main_thread()):
        sys.exit(code)
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        # as Python's own exit: a stream that is None (started with that fd closed, `>&-`) or
        # closed is not flushed, and not a failure
        if stream is None or getattr(stream, "closed", False):
            continue
        try:
            stream.flush()
        except (OSError, ValueError):  # a pipe whose reader left, a full disk
            code = code or 120  # Python's own status when the final flush fails
    os._exit(code)


if __name__ == "__main__":  # pragma: no cover
    run()
