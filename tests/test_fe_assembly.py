"""fe.assembly.Pattern: the CSR scatter of element blocks and the added (contact) blocks."""

import numpy as np
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
