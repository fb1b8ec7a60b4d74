"""Sweep plumbing that does not need a solve: grids, parsing, the atomic cache, discrimination."""

import json
import sys

import numpy as np
import pytest

from tactileskin.discrimination import THRESHOLD, discriminate, profile_distance
from tactileskin.errors import ParameterError
from tactileskin.fileio import OutputError
from tactileskin.scene import Scene
from tactileskin.sweep import ResultCache, expand_grid, parse_values


def test_paper_grid_has_18_distinct_cases():
    scenes = expand_grid(braille_dims=[2])  # the default quality adds the six Braille cases in 3D
    assert len(scenes) == 18 and len({s.key() for s in scenes}) == 18
    assert len(expand_grid()) == 24 and len(expand_grid(quality="preview")) == 18
    assert sorted({round(s.indentation, 12) for s in scenes}) == pytest.approx([0.2, 0.6, 1.0])


def test_braille_texts_only_multiply_braille_cases():
    scenes = expand_grid(thicknesses=[1.0], materials=["silicone"], braille_texts=["", "ab"], braille_dims=[2])
    assert len(scenes) == 4  # flat, curved, braille, braille 'ab'


def test_a_refused_non_braille_case_is_its_own_error_not_a_braille_fallback(caplog):
    # `sweep -i flat,sphere` without a radius: the sphere's refusal (3D, as every sphere case)
    # was taken for the Braille dots' ("the Braille cases stay 2D ... the 3D dots of the dot at
    # t = 1 mm are refused") before the same error came again: a warning about cases not there
    with pytest.raises(ParameterError, match="indenter_radius"):
        expand_grid(thicknesses=[1.0], materials=["silicone"], indenters=["flat", "sphere"])
    assert not [r for r in caplog.records if "Braille" in r.getMessage()]


def test_a_braille_standard_is_the_braille_cases_alone():
    # [scene] braille_standard = "ada_2010" went onto the flat and curved cases too: their
    # results were bit-identical, yet re-solved under other keys and left out of the paper checks
    from tactileskin.cache import cache_key
    from tactileskin.report.markdown import at_paper_conditions

    grid = dict(thicknesses=[1.0], materials=["silicone"], braille_dims=[2], quality="preview")
    plain = expand_grid(**grid)
    ada = expand_grid(base=Scene(braille_standard="ada_2010"), **grid)
    assert [s.indenter.value for s in ada] == ["flat", "curved", "braille"]
    for a, p in zip(ada[:2], plain[:2]):
        assert a == p and cache_key(a) == cache_key(p) and at_paper_conditions(a)
    assert ada[2].braille_standard == "ada_2010" and cache_key(ada[2]) != cache_key(plain[2])


@pytest.mark.parametrize("text, expect", [("1,3,5", [1, 3, 5]), ("1:2:0.5", [1, 1.5, 2]), (" 2 ", [2])])
def test_parse_values(text, expect):
    assert parse_values(text, "thickness") == pytest.approx(expect)


@pytest.mark.parametrize("text", ["", "a,b", "1:0:1", "1:2:0", "0:1e6:1"])
def test_parse_values_rejects(text):
    with pytest.raises(ParameterError, match="thickness"):
        parse_values(text, "thickness")


def test_unknown_indenter_in_grid():
    with pytest.raises(ParameterError, match="indenter"):
        expand_grid(indenters=["pyramid"])


class _Written:
    """Minimal object with the Result.write contract, to exercise the cache alone."""

    def __init__(self, fail=False):
        self.fail = fail

    def write_owned(self, d):
        d.mkdir(parents=True, exist_ok=True)  # Result.write creates the folder or writes into it
        (d / "profile.csv").write_text("s_mm,pressure_mpa\n0,1.5\n1,0.5\n")
        if self.fail:
            raise OSError(28, "No space left on device")
        (d / "summary.json").write_text(json.dumps({"peak_mpa": 1.5, "span_mm": 1.0, "auc_mpa_mm": 1.0}))


def test_cache_store_is_atomic(tmp_path):
    cache = ResultCache(tmp_path / "c")
    sc = Scene(thickness=1.0)
    with pytest.raises(OutputError, match="no space"):
        cache.store(sc, _Written(fail=True))
    assert not cache.has(sc) and not cache.path(sc).exists()
    assert list((tmp_path / "c").iterdir()) == []  # no staging debris
    cache.store(sc, _Written())
    rec = cache.load(sc)
    assert rec.summary["peak_mpa"] == 1.5 and np.allclose(rec.pressure, [1.5, 0.5])
    assert Scene.from_toml(cache.path(sc) / "scene.toml") == sc


def test_profile_distance_properties():
    s = np.linspace(0, 5, 101)
    p = np.exp(-s**2)
    assert profile_distance(s, p, s, p) == 0.0
    assert profile_distance(s, p, s, 2 * p) == pytest.approx(0.5, rel=1e-6)  # ||p|| / ||2p||
    assert profile_distance(s, p, s, np.zeros_like(p)) == pytest.approx(1.0)


def test_discriminate_verdict():
    s = np.linspace(0, 6, 301)
    wide, narrow = np.exp(-(s / 3) ** 2), np.exp(-(s / 0.7) ** 2)
    v = discriminate({"a": (s, wide), "b": (s, narrow)})
    assert v.distinguishable and v.min_distance > THRESHOLD
    v2 = discriminate({"a": (s, wide), "b": (s, 1.05 * wide)})
    assert not v2.distinguishable and v2.min_distance == pytest.approx(0.05 / 1.05, rel=1e-3)


def test_workers_get_their_pardiso_share_and_this_process_keeps_its_environment(monkeypatch):
    """A local cluster's workers read TACTILESKIN_THREADS = CPUs // workers; the nanny's
    pre-spawn variables must not land in this process (a later lone solve or sweep here
    would take a leftover MKL_NUM_THREADS=1 or thread share for the user's setting; dask's
    OMP_NUM_THREADS=1 and OPENBLAS_NUM_THREADS=1 stayed here after a sweep, and fe.blas_threads
    then took them for the user's choice and left a later solve's BLAS unlimited)."""
    import os

    from tactileskin.sweep import _Runner
    from tactileskin.threads import available_cpus

    blas = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS")
    for v in ("TACTILESKIN_THREADS", "MKL_NUM_THREADS", *blas):
        monkeypatch.delenv(v, raising=False)
    runner = _Runner([], [], serial=False, scheduler=None, workers=1)
    try:
        client = runner._start(1)
        seen = client.run(lambda: (os.environ.get("TACTILESKIN_THREADS"), os.environ.get("MKL_NUM_THREADS")))
        blas_seen = client.run(lambda: [os.environ.get(v) for v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS")])
        here_running = [os.environ.get(v) for v in blas]
    finally:
        runner.close()
    assert list(seen.values()) == [(str(available_cpus()), None)]
    assert "TACTILESKIN_THREADS" not in os.environ and "MKL_NUM_THREADS" not in os.environ
    assert list(blas_seen.values()) == [["1", "1"]]  # the workers keep one BLAS thread
    assert here_running == [None, None] and [os.environ.get(v) for v in blas] == [None, None]


def test_a_sweep_gives_dask_s_loggers_back_their_levels():
    """The local cluster's loggers are quiet while the sweep runs; they stayed at CRITICAL after
    it, so a notebook's own dask work later in the process lost its warnings and errors."""
    import logging

    from tactileskin.sweep import _Runner

    names = ("distributed", "distributed.scheduler", "distributed.worker")
    saved = {n: logging.getLogger(n).level for n in names}
    try:
        for n, level in zip(names, (logging.INFO, logging.WARNING, logging.NOTSET)):
            logging.getLogger(n).setLevel(level)
        runner = _Runner([], [], serial=False, scheduler=None, workers=1)
        try:
            runner._start(1)
            during = [logging.getLogger(n).level for n in names]
        finally:
            runner.close()
        after = [logging.getLogger(n).level for n in names]
    finally:
        for n, level in saved.items():
            logging.getLogger(n).setLevel(level)
    assert during == [logging.CRITICAL] * 3
    assert after == [logging.INFO, logging.WARNING, logging.NOTSET]


def test_a_sweep_starts_quietly_while_dask_s_port_8787_is_taken():
    """The cluster has no dashboard, but its scheduler's HTTP server took dask's port 8787: with a
    notebook's own dashboard (or another sweep) there, every sweep warned 'Port 8787 is already
    in use' in four lines on stderr."""
    import socket
    import warnings

    from tactileskin.sweep import _Runner

    held = socket.socket()
    try:
        held.bind(("127.0.0.1", 8787))
        held.listen()
    except OSError:  # taken already: as good
        pass
    try:
        runner = _Runner([], [], serial=False, scheduler=None, workers=1)
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            try:
                runner._start(1)
            finally:
                runner.close()
    finally:
        held.close()
    assert [str(w.message) for w in seen if "8787" in str(w.message)] == []


def test_a_cluster_interrupted_while_starting_is_closed_without_an_exit_traceback(monkeypatch):
    """Ctrl-C during LocalCluster's start left a cluster in Status.init, which dask's exit hook
    then closed with an AssertionError traceback after 'interrupted'."""
    import distributed
    from distributed.deploy.spec import SpecCluster

    from tactileskin import sweep

    made = []

    class Starting:
        shutdown_on_close = True

        def __init__(self, *a, **kw):
            made.append(self)
            SpecCluster._instances.add(self)
            raise KeyboardInterrupt

        def close(self, timeout=None):
            raise AssertionError("Status.init")

    import dask.distributed

    monkeypatch.setattr(dask.distributed, "LocalCluster", Starting)  # what _start imports
    monkeypatch.setattr(distributed, "LocalCluster", Starting)
    class Users:  # a cluster of the user's own (a notebook's): not ours to close
        shutdown_on_close = True

        def close(self, timeout=None):
            raise AssertionError("the user's cluster was closed")

    theirs = Users()
    SpecCluster._instances.add(theirs)
    runner = sweep._Runner([], [], serial=False, scheduler=None, workers=1)
    with pytest.raises(KeyboardInterrupt):
        runner._start(1)
    assert len(made) == 1 and made[0].shutdown_on_close is False  # the exit hook skips it
    assert theirs.shutdown_on_close is True
    SpecCluster._instances.discard(theirs)


@pytest.mark.parametrize("spec, name", [
    ("[sweep]\nthicknesses = [1.0, 3.0, 1.0]\n", "thicknesses"),
    ("[sweep]\nthicknesses = [1]\nmaterials = [\"silicone\", \"silicone\"]\n", "materials"),
    ("[sweep]\nthicknesses = [1]\nindenters = [\"flat\", \"flat\"]\n", "indenters"),
])
def test_a_value_listed_twice_in_a_sweep_is_refused_not_silently_dropped(tmp_path, capsys, spec, name):
    # [1, 3, 1] (meant [1, 3, 5]?) ran 2 cases and said "2 cases", the repeat dropped silently
    from tactileskin.cli import main

    f = tmp_path / "sweep.toml"
    f.write_text(spec)
    rc = main(["sweep", "--scene", str(f), "--out", str(tmp_path / "out"), "--serial", "--no-render"])
    err = capsys.readouterr().err
    assert rc == 2 and name in err and "listed twice" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_expand_grid_refuses_a_repeated_axis_value():
    with pytest.raises(ParameterError, match="thicknesses.*listed twice"):
        expand_grid(thicknesses=[1.0, 3.0, 1.0])
    assert len(expand_grid(thicknesses=[1.0, 3.0], materials=["silicone"], indenters=["flat"])) == 2


def _on_one_worker(fn) -> list:
    """fn's results on the one local worker of a sweep's cluster (client.run), cluster closed."""
    from tactileskin.sweep import _Runner

    runner = _Runner([], [], serial=False, scheduler=None, workers=1)
    try:
        return list(runner._start(1).run(fn).values())
    finally:
        runner.close()


def _worker_state():
    """(solver loaded before any case, BLAS threads, SIGINT ignored and Python's SIGTERM
    handling) of a sweep worker (run there by client.run)."""
    import signal
    import sys

    from threadpoolctl import threadpool_info

    blas = sorted({i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"})
    signals = (signal.getsignal(signal.SIGINT) == signal.SIG_IGN
               and signal.getsignal(signal.SIGTERM) == signal.SIG_DFL)
    return "tactileskin.fe" in sys.modules, blas, signals


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="fork()ed workers on Linux only")
def test_local_workers_are_forked_with_the_solver_loaded_and_one_blas_thread(monkeypatch):
    """Spawned workers each imported numpy, dask, numba, scikit-fem and the package again
    (~2 s CPU each on a loaded machine, ~4 of a preview sweep's ~20 s): they are fork()ed
    from this process, which loads the solver first. As the spawned ones, they keep one BLAS
    thread (OPENBLAS_NUM_THREADS=1 before numpy loaded), not this process's count, Python's
    own SIGTERM handling, not this process's handler (the CLI's), and SIGINT ignored (a
    terminal's Ctrl-C is the sweep process's to handle)."""
    import signal

    from threadpoolctl import threadpool_limits

    from tactileskin import sweep, threads
    from tactileskin.sweep import _Runner

    # as in a fresh process (another test here may have solved on threads: then it spawns)
    monkeypatch.setattr(threads, "threads_started", lambda: False)
    monkeypatch.setattr(sweep, "_other_threads", list)  # pytest-xdist's own threads
    monkeypatch.setattr("tactileskin.mesh._gmsh._meshed_3d_in", None)  # another test here may have meshed 3D
    before = signal.signal(signal.SIGTERM, lambda *a: None)
    runner = _Runner([], [], serial=False, scheduler=None, workers=2)
    try:
        with threadpool_limits(limits=2, user_api="blas"):
            client = runner._start(2)
        states = list(client.run(_worker_state).values())
    finally:
        runner.close()
        signal.signal(signal.SIGTERM, before)
    assert states == [(True, [1], True)] * 2, states


def test_spawned_workers_ignore_sigint_too(monkeypatch):
    """Spawned workers (a notebook's, a process that solved before its sweep, off Linux) died of
    a terminal's Ctrl-C with a KeyboardInterrupt traceback each, as the fork()ed ones did."""
    from tactileskin import sweep

    monkeypatch.setattr(sweep, "worker_start_method", lambda: "spawn")
    states = _on_one_worker(_worker_state)
    assert [st[2] for st in states] == [True], states


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="fork()ed workers on Linux only")
def test_a_process_that_started_solver_threads_spawns_its_workers(monkeypatch):
    """A fork()ed child of a process that had run numba's or MKL's threads (a notebook's lone 3D
    solve before its sweep) runs its compiled loops and PARDISO on one thread (threads.py):
    its 3D cases would lose their share of the cores, so such a process spawns its workers."""
    import types

    from tactileskin import sweep, threads

    # as a fresh process (another test here may have run numba's parallel loops)
    monkeypatch.setattr(threads, "_parent_threads", False)
    monkeypatch.delitem(sys.modules, "numba.np.ufunc.parallel", raising=False)
    monkeypatch.setattr(sweep, "_other_threads", list)  # pytest-xdist's own threads
    monkeypatch.setattr("tactileskin.mesh._gmsh._meshed_3d_in", None)  # another test here may have meshed 3D
    fresh = sweep.worker_start_method()
    monkeypatch.setattr(threads, "_parent_threads", True)  # PARDISO on threads
    after_pardiso = sweep.worker_start_method()
    monkeypatch.setattr(threads, "_parent_threads", False)
    monkeypatch.setitem(sys.modules, "numba.np.ufunc.parallel", types.SimpleNamespace(_is_initialized=True))
    assert (fresh, after_pardiso, sweep.worker_start_method()) == ("fork", "spawn", "spawn")


def test_a_process_that_made_a_3d_mesh_spawns_its_workers(monkeypatch):
    """A fork()ed child of a process that made a 3D mesh meshes each 3D case in a fresh Python
    (mesh._gmsh.in_fresh_process: gmsh's OpenCASCADE pool does not survive fork()): a t = 1
    preview dot's mesh then took 1.3 s CPU and ~4 s wall in place of 0.5 s and ~1 s, for every
    3D case, while fork() saves each worker's imports once (~1-2 s CPU): such a process spawns."""
    import os

    from tactileskin import sweep, threads
    from tactileskin.mesh import _gmsh

    monkeypatch.setattr(threads, "_parent_threads", False)
    monkeypatch.delitem(sys.modules, "numba.np.ufunc.parallel", raising=False)
    monkeypatch.setattr(_gmsh, "_meshed_3d_in", None)
    monkeypatch.setattr(sweep, "_other_threads", list)  # pytest-xdist's own threads
    monkeypatch.setattr("tactileskin.mesh._gmsh._meshed_3d_in", None)  # another test here may have meshed 3D
    fresh = sweep.worker_start_method()
    monkeypatch.setattr(_gmsh, "_meshed_3d_in", os.getpid())  # this process meshed in 3D
    here = sweep.worker_start_method()
    monkeypatch.setattr(_gmsh, "_meshed_3d_in", os.getpid() + 1)  # its parent did, before a fork()
    assert (fresh, here, sweep.worker_start_method()) == ("fork", "spawn", "spawn")


def test_a_process_with_a_thread_of_its_own_spawns_its_workers(monkeypatch):
    """fork() copies every lock another thread holds at that moment, held for good in the child:
    a user's thread meshing 2D sections in a loop while a 2-case sweep started hung a fork()ed
    worker at its first case in 3 of 6 runs (functools.cached_property's lock, taken by the
    thread in Fingertip.interface_length; spawned: 0 of 6). Such a process spawns its workers;
    an earlier sweep's idle dask pool and the sweep command's progress bar (rich's refresh
    thread, which the workers never call) leave it fork()ing."""
    import threading

    from rich.progress import Progress

    from tactileskin import sweep, threads
    from tactileskin.mesh import _gmsh

    monkeypatch.setattr(threads, "_parent_threads", False)
    monkeypatch.delitem(sys.modules, "numba.np.ufunc.parallel", raising=False)
    monkeypatch.setattr(_gmsh, "_meshed_3d_in", None)
    ours = set(threading.enumerate())  # pytest's (xdist's) threads, here before the test
    monkeypatch.setattr(threading, "enumerate",
                        lambda real=threading.enumerate: [t for t in real() if t not in ours or t is threading.main_thread()])
    stop = threading.Event()
    with Progress(auto_refresh=True):
        pool = threading.Thread(target=stop.wait, name="Dask-Offload_0", daemon=True)
        pool.start()
        ours_only = sweep.worker_start_method()
        user = threading.Thread(target=stop.wait, daemon=True)
        user.start()
        with_user = sweep.worker_start_method()
        stop.set()
        user.join()
        pool.join()
    assert (ours_only, with_user, sweep.worker_start_method()) == ("fork", "spawn", "fork")


def _worker_streams():
    import sys

    return [hasattr(s, "rich_proxied_file") for s in (sys.stdout, sys.stderr)]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="fork()ed workers on Linux only")
def test_forked_workers_write_past_the_progress_bars_stream_proxies(monkeypatch):
    """On a terminal the sweep command's progress bar (rich's Live) puts proxies in sys.stdout
    and sys.stderr that print through its console and redraw the bar. A fork()ed worker kept
    them: a worker's traceback on Ctrl-C (or any warning it printed) came out one line at a
    time, each followed by that worker's stale copy of the bar ('solving ... 0/6 0:00:00' 11
    times over, in a pty). The workers write to the files themselves, as spawned ones did."""
    import io

    from rich.console import Console
    from rich.file_proxy import FileProxy

    from tactileskin import sweep, threads

    monkeypatch.setattr(threads, "threads_started", lambda: False)
    monkeypatch.setattr(sweep, "_other_threads", list)  # pytest-xdist's own threads
    monkeypatch.setattr("tactileskin.mesh._gmsh._meshed_3d_in", None)  # another test here may have meshed 3D
    console = Console(file=io.StringIO())
    monkeypatch.setattr(sys, "stdout", FileProxy(console, sys.stdout))
    monkeypatch.setattr(sys, "stderr", FileProxy(console, sys.stderr))
    streams = _on_one_worker(_worker_streams)
    assert streams == [[False, False]], streams
    assert _worker_streams() == [True, True]  # this process's, the bar's, stay


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="process groups, fork()ed workers")
@pytest.mark.parametrize("when", ["starting", "solving"])
def test_ctrl_c_at_a_terminal_ends_a_sweep_with_workers_without_a_traceback(tmp_path, when):
    """A terminal's Ctrl-C reaches every process of the foreground group, the local workers too:
    each printed 'Process Dask Worker process (from Nanny):' and a KeyboardInterrupt traceback
    after 'interrupted'. The sweep's process alone handles Ctrl-C and closes its cluster."""
    import os
    import signal
    import subprocess
    import time

    import psutil

    env = dict(os.environ, TACTILESKIN_CACHE=str(tmp_path / "cache"), COLUMNS="100")
    p = subprocess.Popen([sys.executable, "-m", "tactileskin", "sweep", "--quality", "preview", "--no-render",
                          "--workers", "2", "--out", str(tmp_path / "out")],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, start_new_session=True)
    proc = psutil.Process(p.pid)
    deadline = time.monotonic() + 600  # a hang, not a loaded machine
    while len(proc.children()) < 2 and p.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    assert p.poll() is None, "the sweep ended before its workers started"
    workers = proc.children(recursive=True)
    if when == "solving":  # a first case stored: the workers are solving the next ones (a fixed
        # 1.5 s sleep caught them still starting on a loaded machine)
        while not list(tmp_path.glob("**/cache/[!.]*/cache.json")) and p.poll() is None \
                and time.monotonic() < deadline:
            time.sleep(0.05)
        assert p.poll() is None, "the sweep ended before Ctrl-C"
        workers = proc.children(recursive=True)
    os.killpg(p.pid, signal.SIGINT)  # what a terminal's Ctrl-C does
    try:
        out, err = p.communicate(timeout=60)
    finally:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)
    err = err.decode()
    assert p.returncode == 130, err
    assert "interrupted" in err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    gone, alive = psutil.wait_procs(workers, timeout=60)
    assert alive == []


def _idle_periods(dask_worker) -> dict:
    """A sweep worker's periodic monitors (client.run): {name: period s}."""
    pcs = dask_worker.periodic_callbacks
    return {name: pcs[name].callback_time / 1000 for name in ("tick", "monitor") if name in pcs}


def test_a_sweeps_local_cluster_idles_quietly():
    """Dask's servers sample their event loop every 20 ms (tick), the process every 0.5 s
    (system monitor) and each nanny its worker's memory every 0.1 s, for diagnostics and a
    dashboard a sweep has not: ~0.06 CPU s per s of sweep on 2 cores (main process and two
    workers, benchmarks/results/sweep_overhead.md). The sweep's cluster samples less often;
    the nanny still ends a worker that outgrows its memory (the case is then rerun)."""
    from tactileskin.sweep import _Runner

    runner = _Runner([], [], serial=False, scheduler=None, workers=1)
    try:
        client = runner._start(1)
        workers = list(client.run(_idle_periods).values())
        cluster = runner.cluster
        servers = [cluster.scheduler, *cluster.workers.values()]  # the scheduler, the nanny
        main = [{n: s.periodic_callbacks[n].callback_time / 1000 for n in ("tick", "monitor")} for s in servers]
        nanny_memory = [w.memory_manager.memory_monitor_interval for w in cluster.workers.values()]
    finally:
        runner.close()
    for periods in [*workers, *main]:
        assert periods["tick"] >= 1.0 and periods["monitor"] >= 5.0, periods
    assert nanny_memory and all(0.2 <= t <= 1.0 for t in nanny_memory), nanny_memory


def _loaded_loops() -> dict:
    """{compiled loop: its loaded type signatures} of the package's serial numba loops in
    this process (client.run on a worker)."""
    import importlib

    from numba.core.dispatcher import Dispatcher

    from tactileskin.sweep import COMPILED_MODULES

    return {f"{m}.{n}": sorted(map(str, d.overloads)) for m in COMPILED_MODULES
            for n, d in vars(importlib.import_module(m)).items()
            if isinstance(d, Dispatcher) and not d.targetoptions.get("parallel")}


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="fork()ed workers on Linux only")
def test_forked_workers_start_with_the_cached_compiled_loops_loaded(monkeypatch):
    """Each fork()ed worker loaded the compiled loops from numba's cache at its first case
    (~0.25 s CPU each); the sweep's process loads them once before the workers fork, so a
    worker has, before any case, every serial loop's signature numba's cache holds."""
    import subprocess

    from tactileskin import sweep, threads
    from tactileskin.fe import _kernels_nb
    from tactileskin.sweep import _Runner

    loop = _kernels_nb.kinematics_2_6
    if not any(key[1] == loop.targetctx.codegen().magic_tuple() for key in loop._cache._cache_file._load_index()):
        # numba's cache has no 2D loop yet (a fresh checkout): one 2D solve, in its own process, fills it
        subprocess.run([sys.executable, "-c", "from tactileskin import Scene, fe, planner; "
                        "fe.solve(planner.with_quality(Scene(thickness=1.0), 'preview'))"], check=True)
    monkeypatch.setattr(threads, "threads_started", lambda: False)
    monkeypatch.setattr(sweep, "_other_threads", list)
    monkeypatch.setattr("tactileskin.mesh._gmsh._meshed_3d_in", None)
    runner = _Runner([], [], serial=False, scheduler=None, workers=2)
    try:
        states = list(runner._start(2).run(_loaded_loops).values())
    finally:
        runner.close()
    assert len(states) == 2
    for loaded in states:
        assert loaded["tactileskin.fe._kernels_nb.kinematics_2_6"], loaded
        assert loaded["tactileskin.fe._kernels_nb.tangent_2_6"] and loaded["tactileskin.fe._sparse_nb.scatter_2_6"], loaded


def test_a_damaged_entry_of_numbas_cache_does_not_stop_a_sweep_from_starting(monkeypatch):
    """The sweep's process loads every signature numba's cache index holds before the workers
    fork, also those its cases never call (a 3D loop in a 2D sweep). An entry whose data file
    is damaged (cut short: numba raises UnpicklingError as it loads it) ended the sweep with
    that traceback before its first case; it is skipped, the workers load what they call."""
    import pickle

    from numba.core import types

    from tactileskin import sweep
    from tactileskin.fe import _kernels_nb

    loop = _kernels_nb.kinematics_2_6
    sig = (types.float32,)  # a signature the index names and this process has not loaded
    files = loop._cache._cache_file
    key = loop._cache._index_key(sig, loop.targetctx.codegen())
    monkeypatch.setattr(files, "_load_index", lambda: {key: "damaged.nbc"})

    def cut_short(name):
        raise pickle.UnpicklingError("pickle data was truncated")

    monkeypatch.setattr(files, "_load_data", cut_short)
    sweep._load_compiled_loops()
    assert tuple(sig) not in loop.overloads
