"""Compiled (numba) loops behind fe.assembly: the CSR pattern of interleaved vector dofs and
the scatter of the element matrices into its data, by node rows (on numba's threads for P2 tets).

The vector pattern is the node graph's with each entry an m x m block: the row of dof
s*m + i holds the columns t*m + k of the nodes t adjacent to s, so the data position of
element e's entry (a, i; b, k) is indptr[s*m + i] + off[e, a, b] * m + k, with off the
position of node b in node a's row of the node graph (E x A x A small integers instead of
the E x (A m)^2 positions of a dof-level np.unique). np.bincount over those positions wrote
at random, one thread (the 3D t = 5 dot: 7.4 M entries into 3.1 M, 30 ms per tangent). Here
each node's rows are summed by one thread from the elements around the node, in ascending
element order from 0.0: the order in which np.bincount adds them, so the same bits.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from tactileskin._jit import njit

# m (components per node) and A (nodes per element) as constants for P2 triangles (2, 6)
# and P2 tets (3, 10), so LLVM unrolls the short loops (as in fe._kernels_nb)
_impl = njit(cache=True, error_model="numpy", inline="always")
_jit = njit(cache=True, error_model="numpy")


@_jit
def vector_pattern(sindptr, sindices, m):
    """CSR indptr, indices of the vector pattern from the node graph's (each entry m x m)."""
    ns = sindptr.shape[0] - 1
    indptr = np.empty(ns * m + 1, np.int64)
    indices = np.empty(m * m * sindptr[ns], np.int32)
    p = 0
    for s in range(ns):
        for i in range(m):
            indptr[s * m + i] = p
            for q in range(sindptr[s], sindptr[s + 1]):
                for k in range(m):
                    indices[p] = sindices[q] * m + k
                    p += 1
    indptr[ns * m] = p
    return indptr, indices


@_impl
def _scatter(Ke, nptr, ne, na, off, indptr, out, m, A):
    """out (CSR data) from Ke (E, A*m, A*m); node s's elements and local numbers are
    ne, na[nptr[s]:nptr[s + 1]] in ascending element order. Threads own disjoint rows."""
    for s in nb.prange(nptr.shape[0] - 1):
        for j in range(indptr[s * m], indptr[s * m + m]):
            out[j] = 0.0
        for q in range(nptr[s], nptr[s + 1]):
            e = ne[q]
            a = na[q]
            for i in range(m):
                r = indptr[s * m + i]
                for b in range(A):
                    base = r + off[e, a, b] * m
                    for k in range(m):
                        out[base + k] += Ke[e, a * m + i, b * m + k]
    return out


@_jit
def scatter_2_6(Ke, nptr, ne, na, off, indptr, out):
    return _scatter(Ke, nptr, ne, na, off, indptr, out, 2, 6)


@_jit
def scatter_3_10(Ke, nptr, ne, na, off, indptr, out):
    return _scatter(Ke, nptr, ne, na, off, indptr, out, 3, 10)


@_jit
def scatter_any(Ke, nptr, ne, na, off, indptr, out):
    A = off.shape[2]
    return _scatter(Ke, nptr, ne, na, off, indptr, out, Ke.shape[1] // A, A)


# on numba's threads for the large P2-tet models only, as the tangent kernel: a parallel region
# starts numba's OpenMP pool, after which a fork()ed child (multiprocessing's default on Linux)
# hangs in its first parallel region, so 2D solves stay on this thread
@njit(cache=True, error_model="numpy", parallel=True)
def scatter_3_10_threads(Ke, nptr, ne, na, off, indptr, out):
    return _scatter(Ke, nptr, ne, na, off, indptr, out, 3, 10)


def scatter(m: int, A: int):
    """The scatter loop (on this thread) for m components and A nodes per element."""
    return {(2, 6): scatter_2_6, (3, 10): scatter_3_10}.get((m, A), scatter_any)
