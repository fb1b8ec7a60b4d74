"""A child fork()ed after a 3D solve (multiprocessing's default start method on Linux: a user's
Pool.map of solves) solves 3D too, with the parent's results. Each case runs in its own Python
(a broken child must not take the test session with it); the child answers through a Queue
with a timeout and is killed if it does not."""

import multiprocessing
import os
import subprocess
import sys

import pytest

pytestmark = pytest.mark.skipif("fork" not in multiprocessing.get_all_start_methods(),
                                reason="no fork on this platform")

_COMMON = """
import multiprocessing as mp, sys
import numba
from tactileskin.scene import Scene
from tactileskin.mesh import build_mesh
from tactileskin.fe import solve
from tactileskin.fe.solver import SolverOptions
SC = Scene(dim=3, thickness=1, material='silicone', indenter='braille', braille_text='',
           mesh_size=1.0, refinement=2)

def in_child(target, *args):
    ctx = mp.get_context('fork')
    q = ctx.Queue()
    p = ctx.Process(target=target, args=(q,) + args, daemon=True)
    p.start()
    for _ in range(600):   # 600 s (a hang, not a loaded machine), or until the child dies without an answer
        try:
            return q.get(timeout=1)
        except Exception:
            if not p.is_alive():
                break
    print('no answer from the forked child; exit code', p.exitcode, file=sys.stderr)
    p.kill()
    sys.exit(1)
"""

# The threaded compiled loops (from 0 elements / points here: the coarse mesh, ~1,350 tets,
# is below their thresholds) and PARDISO on 2 threads in the parent; the child gets the
# parent's mesh, so only its solve is tested. Numba terminated such a child at its first
# parallel region ("fork() called from a process already using GNU OpenMP"), and PARDISO on
# MKL's GNU threading layer waited forever for the parent's threads.
_THREADS = _COMMON + """
from tactileskin.fe import kernels
from tactileskin.materials import hyperfoam
kernels.PARALLEL_MIN_ELEMENTS = 0
hyperfoam.PARALLEL_MIN_POINTS = 0
OPTS = SolverOptions(threads=2)

def child(q, mesh):
    r = solve(SC, mesh, options=OPTS)
    q.put((float(r.peak), r.stats['newton_iterations']))

if __name__ == '__main__':
    if numba.config.NUMBA_NUM_THREADS < 2:
        sys.exit(3)
    mesh = build_mesh(SC)
    r = solve(SC, mesh, options=OPTS)
    peak, newton = in_child(child, mesh)
    # the same Newton path; PARDISO's rounding on 1 thread instead of 2
    ok = newton == r.stats['newton_iterations'] and abs(peak - r.peak) <= 1e-12 * abs(r.peak)
    print(r.peak, peak, r.stats['newton_iterations'], newton, file=sys.stderr)
    sys.exit(0 if ok else 1)
"""


def _run(tmp_path, script: str):
    path = tmp_path / "fork_after_3d.py"
    path.write_text(script)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    r = subprocess.run([sys.executable, str(path)], env=env, capture_output=True, text=True, timeout=900)
    if r.returncode == 3:
        pytest.skip("numba has one thread here")
    assert r.returncode == 0, r.stderr[-2000:]


def test_a_forked_child_of_a_threaded_3d_solve_solves_on_one_thread(tmp_path):
    _run(tmp_path, _THREADS)


# gmsh's OpenCASCADE starts a thread pool in the parent's 3D meshing (the surface
# triangulations behind the Distance size fields); the child's own 3D meshing waited forever
# for the parent's pool thread (mesh._gmsh: the child meshes in a fresh Python instead)
_MESH = _COMMON + """
import numpy as np

def child(q):
    m = build_mesh(SC)
    q.put((m.mesh.doflocs, m.mesh.t, {k: v for k, v in m.boundaries.items()}))

if __name__ == '__main__':
    m = build_mesh(SC)
    p, t, b = in_child(child)
    same = (np.array_equal(p, m.mesh.doflocs) and np.array_equal(t, m.mesh.t)
            and b.keys() == m.boundaries.keys() and all(np.array_equal(b[k], m.boundaries[k]) for k in b))
    sys.exit(0 if same else 1)
"""


def test_a_forked_child_of_a_3d_mesh_meshes_the_same_3d_mesh(tmp_path):
    _run(tmp_path, _MESH)


def test_a_fresh_process_raises_the_typed_error_with_its_fields():
    from tactileskin.errors import ParameterError, check_range
    from tactileskin.mesh import _gmsh

    with pytest.raises(ParameterError) as e:
        _gmsh.in_fresh_process(check_range, "depth", 5.0, 0.0, 1.0, unit="mm")
    assert (e.value.name, e.value.value) == ("depth", 5.0) and "depth=5.0" in str(e.value)
    assert _gmsh.in_fresh_process(check_range, "depth", 0.5, 0.0, 1.0) == 0.5


def test_a_fresh_process_raises_an_os_error_with_its_errno_and_file_name(tmp_path):
    # an OSError's errno, strerror and file name are not in its __dict__: they were lost
    # (errno None), and code that tells a missing file by errno could not here
    import errno

    from tactileskin.mesh import _gmsh

    missing = str(tmp_path / "no_such.msh")
    with pytest.raises(FileNotFoundError) as e:
        _gmsh.in_fresh_process(open, missing)
    assert (e.value.errno, e.value.filename) == (errno.ENOENT, missing)
    assert e.value.strerror and str(e.value) == f"[Errno {errno.ENOENT}] {e.value.strerror}: {missing!r}"
