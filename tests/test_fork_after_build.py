"""A child fork()ed after a `build` (multiprocessing's default start method on Linux: a user's
Pool.map of builds) builds too. build123d runs its booleans on OpenCASCADE's thread pool, whose
threads do not survive fork(): such a child waited forever in its first boolean (the mold's
intersect) until geometry.occ stopped the pool's threads across a fork. The case runs in its own
Python, and the child answers through a Queue with a timeout and is killed if it does not."""

import multiprocessing
import subprocess
import sys

import pytest

pytestmark = pytest.mark.skipif("fork" not in multiprocessing.get_all_start_methods(),
                                reason="no fork on this platform")

_SCRIPT = """
import multiprocessing as mp, sys
from tactileskin.geometry.parts import build_parts

def parts():
    return sorted((p.name, round(p.shape.volume, 6)) for p in build_parts(2.0, indenters=('flat',)))

def child(q):
    q.put(parts())

if __name__ == '__main__':
    mine = parts()
    from OCP.OSD import OSD_ThreadPool
    pool_before = OSD_ThreadPool.DefaultPool_s().NbThreads()
    ctx = mp.get_context('fork')
    q = ctx.Queue()
    p = ctx.Process(target=child, args=(q,), daemon=True)
    p.start()
    for _ in range(600):   # 600 s (a hang, not a loaded machine), or until the child dies without an answer
        try:
            theirs = q.get(timeout=1)
            break
        except Exception:
            if not p.is_alive():
                theirs = None
                break
    else:
        theirs = None
    if theirs is None:
        print('no answer from the forked child; exit code', p.exitcode, file=sys.stderr)
        p.kill()
        sys.exit(1)
    # the parent's pool is its own again after the fork (its next booleans run on its threads)
    print(mine == theirs, len(mine), OSD_ThreadPool.DefaultPool_s().NbThreads() == pool_before)
"""


def test_a_forked_child_of_a_build_builds_the_same_parts():
    r = subprocess.run([sys.executable, "-c", _SCRIPT], capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stderr[-2000:]
    same, n, restored = r.stdout.split()
    assert same == "True" and int(n) >= 4, r.stdout   # skin, bone base, flat indenter, mold halves
    assert restored == "True", r.stdout
