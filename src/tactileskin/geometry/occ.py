"""build123d, with OpenCASCADE's thread pool made safe to fork(): every module of this package
takes build123d from here (`from tactileskin.geometry.occ import bd`).

Why: build123d runs its booleans (SetRunParallel(True)) and our STL tessellation runs on OCC's
default thread pool, whose threads do not survive fork(): a child fork()ed after a `build`
(multiprocessing's default start method on Linux, a user's Pool.map of builds) waited forever
in its first boolean (molds.skin_mold's intersect). Just before a fork the pool is shrunk to the
calling thread (its threads stopped and joined), so the child inherits a pool without threads
and runs OCC on its own thread; the parent's pool is restored after the fork. A pool of one
thread throughout would also do, but made `build` 15 % slower (6.9 s against 6.0 s, 2 cores).
"""

import os

from OCP.OSD import OSD_ThreadPool

import build123d as bd

__all__ = ["bd"]

_threads: list[int] = []   # the parent's pool size across a fork


def _before_fork() -> None:
    pool = OSD_ThreadPool.DefaultPool_s()
    n = pool.NbThreads()
    _threads.append(n)
    if n > 1:
        pool.Init(1)   # stops and joins the pool's threads


def _after_fork_in_parent() -> None:
    n = _threads.pop() if _threads else 1
    if n > 1:
        OSD_ThreadPool.DefaultPool_s().Init(n)


if hasattr(os, "register_at_fork"):
    os.register_at_fork(before=_before_fork, after_in_parent=_after_fork_in_parent,
                        after_in_child=_threads.clear)
