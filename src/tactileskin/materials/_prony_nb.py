"""Compiled (numba) QLV trial stress of `prony.QLVHistory.stress`.

The numpy form built ~6 temporaries of the whole stress array per Prony term at every residual
evaluation (0.3 s of a 2D preview sweep's 5.3 s of solves); this loop does the same operations
in the same order per entry, so the same bits:

    S = gamma S0;  for each term i:  S = S + decay_i H_i - gain_i S0_old
                                      (if back_i != 0) S = S - back_i (S0_old - S0_prev)
"""

from __future__ import annotations

from tactileskin._jit import njit


@njit("void(float64[::1], float64[:, ::1], float64[::1], float64[::1], float64, float64[::1], "
     "float64[::1], float64[::1], float64[::1])", cache=True, nogil=True, error_model="numpy")
def qlv_stress(S0, H, S0_old, S0_prev, gamma, decay, gain, back, S):
    """S (n,) from S0, S0_old, S0_prev (n,), H (terms, n) and the step's factors."""
    for j in range(S0.shape[0]):
        s = gamma * S0[j]
        for i in range(decay.shape[0]):
            s = s + decay[i] * H[i, j] - gain[i] * S0_old[j]
            if back[i]:
                s = s - back[i] * (S0_old[j] - S0_prev[j])
        S[j] = s
