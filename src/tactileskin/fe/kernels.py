"""Element kernels of total-Lagrangian finite strain, vectorised over elements and points.

Functions of arrays; nothing here knows about meshes or boundary conditions.

Shapes: E elements, Q quadrature points, A local scalar nodes, m the model dimension
(2: plane strain with F33 = 1; 3). Element dofs are interleaved: local dof a*m + i is
displacement component i of node a, so element vectors are (E, A*m).

Two formulations share one code path:

- displacement: F from the displacement gradient.
- mixed (three-field Hu-Washizu with element-constant dilatation theta and pressure, both
  condensed): F_bar = (theta/J)^(1/m) F with theta = volume average of J over the element.
  In plane strain only the in-plane block is scaled, so det F_bar = theta. With P2
  displacements and P0 dilatation/pressure this is inf-sup stable and free of volumetric
  locking. The condensed potential is sum_q w_q W(F_bar_q); its exact first and second
  derivatives are below (phi = ln(theta/J)/m, alpha = e^phi, tau = P_bar : F_bar):

      dW   = alpha P_bar : dF + tau dphi
      d2W  = dF_bar : AA_bar : dF_bar + tau (dphi^2 + d2phi) + 2 dphi alpha P_bar : dF
      dF_bar = alpha (dF + F dphi),   m dphi = dtheta/theta - tr(F^-1 dF)
      m d2phi = d2theta/theta - dtheta^2/theta^2 + tr(F^-1 dF F^-1 dF)
      d2theta = avg_q J [tr(F^-1 dF)^2 - tr(F^-1 dF F^-1 dF)]

  The same formulas hold with a stress that has a constant (history) part, as in QLV.

Kinematics, residual and tangent are compiled element loops (fe._kernels_nb, numba; its
docstring gives the regrouped algebra of the tangent). The oracle they are tested against
is a literal transcription of the formulas above in tests/reference_kernels.py.
"""

from __future__ import annotations

import numpy as np

from tactileskin.fe import _kernels_nb
from tactileskin.threads import numba_parallel_threads

# P2 tets from which the tangent runs on numba's threads (tactileskin.threads.numba_threads;
# fe.model sets them per solve): the default 3D dot at t = 3 mm, 11,900 elements, 67 -> 37 ms
# on 2 threads, the same bits
PARALLEL_MIN_ELEMENTS = 2000


def _c(x: np.ndarray) -> np.ndarray:
    """C-contiguous float64 (the compiled loops take no strided views)."""
    return np.ascontiguousarray(x, dtype=np.float64)


def embed3(M: np.ndarray, fill33: float = 1.0) -> np.ndarray:
    """Embed an in-plane (..., 2, 2) tensor in (..., 3, 3) with M33 = fill33; 3D passes through."""
    if M.shape[-1] == 3:
        return M
    out = np.zeros(M.shape[:-2] + (3, 3))
    out[..., :2, :2] = M
    out[..., 2, 2] = fill33
    return out


class Kinematics:
    """Kinematic quantities of one trial displacement, shared by residual, tangent and output:
    F, J (always), admissible (every J finite and > 0) and, if admissible, Finv, alpha,
    Fbar, C (C_bar as (E, Q, 3, 3)), Jbar and theta (mixed)."""

    def __init__(self, ue: np.ndarray, G: np.ndarray, w: np.ndarray, mixed: bool):
        self.m = ue.shape[-1]
        self.mixed = mixed
        G, w, m = _c(G), _c(w), self.m
        self.G, self.w = G, w
        E, Q = w.shape
        self.F = np.empty((E, Q, m, m))
        self.J = np.empty((E, Q))
        Finv, alpha, C = np.empty((E, Q, m, m)), np.empty((E, Q)), np.empty((E, Q, 3, 3))
        Fbar, theta = (np.empty((E, Q, m, m)), np.empty(E)) if mixed else (self.F, np.empty(0))
        loop = _kernels_nb.entry("kinematics", G)
        self.admissible = bool(loop(_c(ue), G, w, mixed, self.F, self.J, Finv, alpha, Fbar, C, theta))
        if not self.admissible:
            return
        self.Finv, self.alpha, self.Fbar, self.C = Finv, alpha, Fbar, C
        if mixed:
            self.theta = theta
            self.Jbar = np.broadcast_to(theta[:, None], self.J.shape)
        else:
            self.Jbar = self.J


def residual(kin: Kinematics, S: np.ndarray) -> np.ndarray:
    """Internal force element vectors (E, A*m) from the in-plane PK2 stress S (E, Q, m, m)."""
    E, Q, A, m = kin.G.shape
    theta = kin.theta if kin.mixed else np.empty(0)
    loop = _kernels_nb.entry("residual", kin.G)
    return loop(kin.G, kin.w, kin.Fbar, kin.Finv, kin.alpha, kin.J, _c(theta),
                _c(S), kin.mixed, np.empty((E, A * m)))


def tangent(kin: Kinematics, S: np.ndarray, D: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """Consistent element stiffness (E, A*m, A*m); S (E,Q,m,m), D = dS/dE (E,Q,m,m,m,m).
    out: a C-contiguous float64 (E, A*m, A*m) array to write it into (None: a new one).

    D must have minor symmetry (the material part is evaluated in Voigt pairs) and, in the
    mixed formulation, major symmetry (the rank-one terms use AA F for both sides); any
    D = 2 dS/dC of a hyperelastic S has both. The algebra: fe._kernels_nb. P2 tets run on
    numba's threads (threads.numba_parallel_threads()) from PARALLEL_MIN_ELEMENTS elements."""
    E, Q, A, m = kin.G.shape
    if out is not None and (out.shape != (E, A * m, A * m) or out.dtype != np.float64
                            or not out.flags.c_contiguous):   # the loops write without bounds checks
        raise ValueError(f"tangent out: a C-contiguous float64 {(E, A * m, A * m)} array, not {out.shape} {out.dtype}")
    theta = kin.theta if kin.mixed else np.empty(0)
    args = (kin.G, kin.w, kin.F, kin.Fbar, kin.Finv, kin.alpha, kin.J,
            _c(theta), _c(S), _c(D), kin.mixed, np.empty((E, A * m, A * m)) if out is None else out)
    threads = numba_parallel_threads()
    if (m, A) == (3, 10) and threads > 1 and E >= PARALLEL_MIN_ELEMENTS:
        return _kernels_nb.tangent_3_10_parallel(*args, 4 * threads)
    return _kernels_nb.entry("tangent", kin.G)(*args)


def cauchy(kin: Kinematics, S3: np.ndarray) -> np.ndarray:
    """Cauchy stress (E, Q, 3, 3) = F_bar S F_bar^T / J_bar from the full 3x3 PK2 S3."""
    Fb3 = embed3(kin.Fbar)
    return np.einsum("...iI,...IJ,...jJ->...ij", Fb3, S3, Fb3) / kin.Jbar[..., None, None]


def mean_pressure(sigma: np.ndarray) -> np.ndarray:
    """Abaqus PRESS: P = -(sxx + syy + szz)/3, positive in compression."""
    return -np.trace(sigma, axis1=-2, axis2=-1) / 3.0
