"""fe.assembly.Pattern: the CSR scatter of element blocks and the added (contact) blocks."""

import numpy as np
import pytest
import scipy.sparse as sp

from tactileskin.fe.assembly import Pattern


def _dense(n, edofs, Ke):
    A = np.zeros((n, n))
    for d, K in zip(edofs, Ke):
        A[np.ix_(d, d)] += K
    return A


def test_pattern_scatter_and_added_blocks_equal_dense_assembly():
    """data() and add() against a dense assembly; add() keeps the positions of the dofs it last
    saw, and dofs of another shape or value (or changed in place) get their own."""
    rng = np.random.default_rng(2)
    n = 30
    edofs = np.array([rng.choice(n, 6, replace=False) for _ in range(25)])
    edofs[0] = np.arange(6)
    Ke = rng.standard_normal((25, 6, 6))
    p = Pattern(n, edofs, np.arange(n))
    data = p.data(Ke)
    A = _dense(n, edofs, Ke)
    assert np.allclose(p.matrix(data).toarray(), A)
    blocks = edofs[[3, 7, 7]]                        # inside the pattern; a repeated block
    for k in range(3):
        Kb = rng.standard_normal((3, 6, 6))
        d = data.copy()
        p.add(d, blocks, Kb)
        assert np.allclose(p.matrix(d).toarray(), A + _dense(n, blocks, Kb))
    other = edofs[[0, 1]][:, :3]
    Kb = rng.standard_normal((2, 3, 3))
    d = data.copy()
    p.add(d, other, Kb)
    assert np.allclose(p.matrix(d).toarray(), A + _dense(n, other, Kb))
    blocks2 = blocks.copy()
    p.add(data.copy(), blocks2, rng.standard_normal((3, 6, 6)))
    blocks2[0] = edofs[5]                           # the same array, changed in place
    Kb = rng.standard_normal((3, 6, 6))
    d = data.copy()
    p.add(d, blocks2, Kb)
    assert np.allclose(p.matrix(d).toarray(), A + _dense(n, blocks2, Kb))
    assert isinstance(p.free_matrix(d), sp.csr_matrix)


def _reference(n, edofs, Ke):
    """The former Pattern: np.unique of the dof-level (row, col) keys, one np.bincount per
    assembly: (keys, data)."""
    nd = edofs.shape[1]
    keys = (np.repeat(edofs, nd, axis=1).astype(np.int64) * n + np.tile(edofs, (1, nd))).ravel()
    keys, inv = np.unique(keys, return_inverse=True)
    return keys, np.bincount(inv.ravel(), weights=Ke.ravel(), minlength=len(keys))


def test_pattern_from_node_graph_equals_dof_level_bincount_2d_and_3d():
    """The node-graph pattern and the row-parallel scatter against the former dof-level
    np.unique + np.bincount, bit for bit (same additions in the same order), on P2 triangle
    and tet meshes (vector dofs m = 2, 3, and the scalar m = 1), on 1 and 2 numba threads,
    for a strided Ke too; and the free block and add() on top."""
    import numba
    from skfem import Basis, MeshTet, MeshTri
    from skfem.element import ElementTetP2, ElementTriP2

    from tactileskin.fe import _sparse_nb
    from tactileskin.fe.assembly import vector_dofs
    from tactileskin.threads import numba_threads

    rng = np.random.default_rng(5)
    for mesh, el in ((MeshTri().refined(3), ElementTriP2()), (MeshTet().refined(2), ElementTetP2())):
        b = Basis(mesh, el)
        sd = b.element_dofs.T
        for m in (mesh.dim(), 1):
            n, edofs = b.N * m, vector_dofs(sd, m).reshape(len(sd), -1)
            free = np.flatnonzero(rng.random(n) > 0.2)
            p = Pattern(n, edofs, free, m)
            nd = edofs.shape[1]
            # entries over 16 decades: any change of the order of additions shows in the bits
            Ke = rng.standard_normal((len(edofs), nd, nd)) * 10.0 ** rng.integers(-8, 8, (len(edofs), nd, nd))
            keys, ref = _reference(n, edofs, Ke)
            assert np.array_equal(p.keys, keys)
            assert np.array_equal(p.indices, keys % n)
            assert np.array_equal(p.indptr, np.concatenate([[0], np.cumsum(np.bincount(keys // n, minlength=n))]))
            KeT = np.swapaxes(Ke, 1, 2)                      # a strided view
            for threads in (1, min(2, numba.config.NUMBA_NUM_THREADS)):
                with numba_threads(threads):
                    assert np.array_equal(p.data(Ke), ref)
                    assert np.array_equal(p.data(KeT), _reference(n, edofs, np.ascontiguousarray(KeT))[1])
                    if (m, nd // m) == (3, 10):  # the threaded loop (Pattern's for large P2-tet models) adds alike
                        par = _sparse_nb.scatter_3_10_threads(Ke, p._nptr, p._ne, p._na, p._off, p.indptr,
                                                              np.empty(len(p.keys)))
                        assert np.array_equal(par, ref)
            A = p.matrix(p.data(Ke)).toarray()
            assert np.allclose(A, _dense(n, edofs, Ke), rtol=1e-12, atol=1e-12 * np.abs(Ke).max())
            assert np.array_equal(p.free_matrix(p.data(Ke)).toarray(), A[np.ix_(free, free)])
        try:
            Pattern(b.N * 3, vector_dofs(sd, 2).reshape(len(sd), -1), free, 3)
        except ValueError:
            pass
        else:
            raise AssertionError("non-interleaved element dofs accepted")


_FORK_AFTER_SOLVE = """
import multiprocessing as mp, sys
from tactileskin.fe import solve
from tactileskin.scene import Scene
sc = Scene(thickness=1, indenter='flat', material='silicone', mesh_size=1.0, refinement=2)
def child(q):
    q.put(float(solve(sc).peak))
if __name__ == '__main__':
    peak = float(solve(sc).peak)
    ctx = mp.get_context('fork')
    q = ctx.Queue()
    p = ctx.Process(target=child, args=(q,), daemon=True)  # a hung child goes with the parent
    p.start()
    got = q.get(timeout=60)
    p.join()
    sys.exit(0 if got == peak else 1)
"""


def test_a_forked_child_of_a_2d_solve_solves_too(tmp_path):
    """A 2D solve runs no numba parallel region: one had started numba's OpenMP pool, and a
    child fork()ed after it (multiprocessing's default on Linux: a user's Pool.map of solves)
    hung in its first solve."""
    import multiprocessing
    import os
    import subprocess
    import sys

    if "fork" not in multiprocessing.get_all_start_methods():
        pytest.skip("no fork on this platform")
    script = tmp_path / "fork_after_solve.py"
    script.write_text(_FORK_AFTER_SOLVE)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    r = subprocess.run([sys.executable, str(script)], env=env, capture_output=True, text=True, timeout=180)
    assert r.returncode == 0, r.stderr[-2000:]
