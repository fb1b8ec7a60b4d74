"""Prony-series relaxation and quasi-linear viscoelasticity (QLV) on the PK2 stress.

g(t) = g_inf + sum_i g_i exp(-t / tau_i),  g_inf = 1 - sum_i g_i  (paper Eq. 6).

Abaqus applies the Prony series to the whole hyperfoam stress (deviatoric and volumetric
alike), so the viscoelastic PK2 stress is the hereditary integral of the instantaneous
(elastic) stress S0:

    S(t) = g_inf S0(t) + sum_i H_i(t),   H_i(t) = g_i int_0^t exp(-(t - s)/tau_i) dS0/ds ds,

with S0(0) = 0 (the undeformed start). The recursive update

    H_i^{n+1} = exp(-h_i) H_i^n + g_i (1 - exp(-h_i)) / h_i (S0^{n+1} - S0^n),  h_i = dt / tau_i,

is exact when S0 varies linearly over the increment. dS^{n+1}/dS0^{n+1} is the scalar
g_inf + sum_i gain_i (the consistent tangent factor). Internal variables H have the shape
(n_terms, ...) + S.shape[-2:], term axis first.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tactileskin.errors import ParameterError

__all__ = ["Prony", "QLVHistory"]


# One term per decade of time is the usual fit; 12 cover 1 ms to 1e9 s, far beyond any
# indentation. Each term keeps a stress history at every quadrature point (memory and one
# update per increment), so the count is bounded.
MAX_TERMS = 12
# relaxation times (s) a series may hold: 1 fs to 30,000 years. A fit to a DMA master curve
# carries terms far below 1 ns (the glassy relaxation at room temperature), which relax within
# any step and solve (1e-15 s checked); past about 1e154 s tau**2 overflows in the quadratic
# update and every solve failed as 'no convergence', down at 1e-320 s dt/tau does; the range
# names the value instead.
TAU_RANGE = (1e-15, 1e12)


@dataclass(frozen=True)
class Prony:
    """Prony series: relative moduli g (each >= 0, sum < 1) and relaxation times tau (s, > 0)."""

    g: tuple[float, ...]
    tau: tuple[float, ...]

    def __post_init__(self):
        try:
            g = tuple(float(v) for v in np.atleast_1d(np.asarray(self.g, dtype=float)).ravel())
            tau = tuple(float(v) for v in np.atleast_1d(np.asarray(self.tau, dtype=float)).ravel())
        except (TypeError, ValueError):
            raise ParameterError("prony", (self.g, self.tau), "sequences of finite numbers") from None
        if len(g) > MAX_TERMS:
            raise ParameterError("g", f"{len(g)} terms", f"at most {MAX_TERMS} terms")
        if len(tau) != len(g):
            raise ParameterError("tau", self.tau, f"{len(g)} values (one per g term)")
        for i, (gi, ti) in enumerate(zip(g, tau)):
            if not (math.isfinite(gi) and gi >= 0.0):
                raise ParameterError(f"g[{i}]", gi, ">= 0")
            if not (math.isfinite(ti) and ti > 0.0):
                raise ParameterError(f"tau[{i}]", ti, "> 0 s")
            if not TAU_RANGE[0] <= ti <= TAU_RANGE[1]:
                raise ParameterError(f"tau[{i}]", ti, f"[{TAU_RANGE[0]:g}, {TAU_RANGE[1]:g}] s")
        if not sum(g) < 1.0:
            raise ParameterError("g", g, "sum(g_i) < 1 (long-term modulus g_inf > 0)")
        object.__setattr__(self, "g", g)
        object.__setattr__(self, "tau", tau)

    @classmethod
    def elastic(cls) -> "Prony":
        """No relaxation (g_inf = 1)."""
        return cls((), ())

    @property
    def n_terms(self) -> int:
        return len(self.g)

    @property
    def g_inf(self) -> float:
        """Long-term relative modulus 1 - sum(g_i)."""
        return 1.0 - float(sum(self.g))

    def relaxation(self, t):
        """g(t) = g_inf + sum g_i exp(-t/tau_i) for t >= 0 (array-like)."""
        t = np.asarray(t, dtype=float)
        out = np.full(t.shape, self.g_inf)
        for gi, ti in zip(self.g, self.tau):
            out = out + gi * np.exp(-t / ti)
        return out

    def step_factors(self, dt: float):
        """(decay, gain), each shape (n_terms,): exp(-h), g_i (1 - exp(-h))/h, h = dt/tau_i.

        Via expm1, so gain -> g_i smoothly as dt -> 0 (dt = 0 allowed).
        """
        dt = float(dt)
        if not (math.isfinite(dt) and dt >= 0.0):
            raise ParameterError("dt", dt, ">= 0 s")
        g = np.asarray(self.g, dtype=float)
        h = dt / np.asarray(self.tau, dtype=float)
        em = np.expm1(-h)                                    # exp(-h) - 1, accurate for small h
        decay = 1.0 + em
        with np.errstate(invalid="ignore", divide="ignore"):
            ratio = np.where(h > 0.0, -em / np.where(h > 0.0, h, 1.0), 1.0)
        return decay, g * ratio

    def step_factors_quadratic(self, dt: float, dt_prev: float):
        """(decay, gain, back), each (n_terms,), of the update with S0 interpolated by the
        parabola through the last three states (t_{n-1}, t_n, t_{n+1}):

            H_i <- decay_i H_i + gain_i (S0_{n+1} - S0_n) - back_i (S0_n - S0_{n-1}).

        Why: the linear interpolation of `step_factors` is first order in dt once dt ~ tau
        (the kernel weights the end of the step, where the chord's slope is off by O(dt));
        the parabola's slope there is off by O(dt^2). With q = 2 I1 - dt I0, I0 = int_0^dt
        e^-(dt-x)/tau dx, I1 = int_0^dt e^-(dt-x)/tau x dx (exact integrals of the parabola's
        slope against the kernel): gain_i = g_i [I0/dt + q/(dt (dt + dt_prev))],
        back_i = g_i q / (dt_prev (dt + dt_prev)). For dt << tau, q -> dt^3/(6 tau) and
        the update tends to the linear one.
        """
        dt, dt_prev = float(dt), float(dt_prev)
        if not (math.isfinite(dt) and dt >= 0.0):
            raise ParameterError("dt", dt, ">= 0 s")
        if not (math.isfinite(dt_prev) and dt_prev > 0.0):
            raise ParameterError("dt_prev", dt_prev, "> 0 s")
        decay, gain = self.step_factors(dt)
        g = np.asarray(self.g, dtype=float)
        tau = np.asarray(self.tau, dtype=float)
        x = dt / tau
        # q / tau^2 = 2x - (2 + x)(1 - e^-x); its series x^3/6 - x^4/12 + x^5/40 below 0.02
        # (the closed form cancels there: relative error ~12 eps / x^2)
        with np.errstate(over="ignore"):
            closed = 2.0 * x + (2.0 + x) * np.expm1(-x)
        series = x**3 / 6.0 - x**4 / 12.0 + x**5 / 40.0
        q = tau**2 * np.where(x < 0.02, series, closed)
        s = dt + dt_prev
        gain = gain + g * q / (dt * s) if dt > 0.0 else gain
        back = g * q / (dt_prev * s)
        return decay, gain, back

    def tangent_factor(self, dt: float) -> float:
        """dS^{n+1}/dS0^{n+1} = g_inf + sum(gain_i): scales the elastic tangent."""
        return self.g_inf + float(np.sum(self.step_factors(dt)[1]))

    def initial_state(self, stress_shape) -> np.ndarray:
        """Zero internal variables H for stresses of shape stress_shape."""
        return np.zeros((self.n_terms,) + tuple(stress_shape))

    def update(self, H, S0_old, S0_new, dt: float):
        """One increment: returns (S, H_new) with S = g_inf S0_new + sum_i H_new_i.

        H: (n_terms, *S0.shape); S0_old/S0_new: elastic PK2 at the start/end of the increment.
        Pure: H is not modified.
        """
        decay, gain = self.step_factors(dt)
        S0_old = np.asarray(S0_old, dtype=float)
        S0_new = np.asarray(S0_new, dtype=float)
        H = np.asarray(H, dtype=float)
        if H.shape != (self.n_terms,) + S0_new.shape:
            raise ParameterError("H.shape", H.shape, f"{(self.n_terms,) + S0_new.shape}")
        bshape = (self.n_terms,) + (1,) * S0_new.ndim
        dS0 = S0_new - S0_old
        H_new = decay.reshape(bshape) * H + gain.reshape(bshape) * dS0[None]
        S = self.g_inf * S0_new + H_new.sum(axis=0)
        return S, H_new

    def to_dict(self) -> dict:
        return {"g": list(self.g), "tau": list(self.tau)}

    def history(self, shape, order: int = 2) -> "QLVHistory":
        """The viscoelastic state of this series at points whose stresses have `shape`
        (e.g. (elements, quadrature points, 3, 3)): wraps the elastic PK2 S0 of any law."""
        return QLVHistory(self, tuple(shape), order)


class QLVHistory:
    """Internal variables of the QLV update at a set of points, with the update rule.

    State: H (n_terms, *shape), the elastic stresses S0 of the last two committed states and
    the previous step. `stress(S0, dt)` is the trial stress for a step dt (pure: the state
    is not changed; Newton calls it at every iterate), `commit(S0, dt)` accepts the step.
    order 2: S0 interpolated by the parabola through the last three states
    (`Prony.step_factors_quadratic`) once a previous step exists; order 1 (or the first
    step): the chord (`Prony.step_factors`)."""

    def __init__(self, prony: Prony, shape: tuple, order: int = 2):
        if order not in (1, 2):
            raise ParameterError("qlv_order", order, "1 (linear S0 per increment) or 2 (parabola)")
        self.prony, self.order = prony, order
        self.S0_old = np.zeros(shape)
        self.S0_prev = self.S0_old       # S0 one increment before S0_old
        self.dt_prev = None
        self.H = np.zeros((prony.n_terms,) + tuple(shape))
        self.commits = 0   # commit() calls: H changes in place, so identity cannot tell states apart

    def factors(self, dt: float):
        """(gamma, decay, gain, back) for a step dt from the committed state; gamma =
        g_inf + sum(gain) scales the elastic tangent."""
        if self.order == 2 and self.dt_prev is not None and dt > 0.0:
            decay, gain, back = self.prony.step_factors_quadratic(dt, self.dt_prev)
        else:
            decay, gain = self.prony.step_factors(dt)
            back = np.zeros_like(np.atleast_1d(gain))
        decay, gain, back = np.atleast_1d(decay), np.atleast_1d(gain), np.atleast_1d(back)
        return float(self.prony.g_inf + gain.sum()), decay, gain, back

    def stress(self, S0, dt: float):
        """(S, gamma): the viscoelastic PK2 at the end of a trial step dt with elastic S0
        (S = gamma S0 + sum_i [decay_i H_i - gain_i S0_old - back_i (S0_old - S0_prev)], term by
        term in that order; a compiled loop, `_prony_nb.qlv_stress`, for float64 stresses of the
        history's shape)."""
        gamma, decay, gain, back = self.factors(dt)
        S0 = np.asarray(S0)
        if S0.dtype == np.float64 and S0.shape == self.S0_old.shape:
            # imported on first use, as the law's loops (numba's start-up)
            from tactileskin.materials._prony_nb import qlv_stress

            def flat(x):
                return np.ascontiguousarray(x, dtype=np.float64).reshape(-1)

            S = np.empty(S0.shape)
            qlv_stress(flat(S0), np.ascontiguousarray(self.H, dtype=np.float64).reshape(len(self.H), S0.size),
                       flat(self.S0_old), flat(self.S0_prev), float(gamma), flat(decay), flat(gain), flat(back),
                       S.reshape(-1))
            return S, gamma
        S = gamma * S0
        for i in range(len(decay)):
            S = S + decay[i] * self.H[i] - gain[i] * self.S0_old
            if back[i]:
                S = S - back[i] * (self.S0_old - self.S0_prev)
        return S, gamma

    def commit(self, S0, dt: float) -> None:
        _, decay, gain, back = self.factors(dt)
        for i in range(len(decay)):
            self.H[i] = decay[i] * self.H[i] + gain[i] * (S0 - self.S0_old)
            if back[i]:
                self.H[i] -= back[i] * (self.S0_old - self.S0_prev)
        self.S0_prev, self.S0_old = self.S0_old, S0
        if dt > 0.0:
            self.dt_prev = dt
        self.commits += 1
