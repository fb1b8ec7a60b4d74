"""Fitting functions for the film calibration (mean grayscale GS -> pressure P).

The paper (Sec. IV-B) says it compared "different type[s] of fitting function" by their
statistical errors and kept the linear one; it does not name the others. We offer the
usual curve-fitting family: linear, quadratic, exponential, power and logarithmic.

Every model is y = f(x; theta) with an analytic Jacobian d f / d theta, so parameter
covariances and the confidence band of the mean response come from one formula
(exact for the models linear in their parameters, first-order/delta method otherwise):
cov = s^2 (J^T J)^-1, s^2 = SSR / (n - p).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from scipy import optimize, stats

log = logging.getLogger(__name__)

CONFIDENCE = 0.90  # the paper reports its fit "with the 90% confidence bounds"


@dataclass(frozen=True)
class Model:
    name: str
    formula: str
    param_names: tuple[str, ...]
    f: Callable[[np.ndarray, np.ndarray], np.ndarray]
    jac: Callable[[np.ndarray, np.ndarray], np.ndarray]
    needs_positive_x: bool = False
    needs_positive_y: bool = False
    linear_basis: Callable[[np.ndarray], np.ndarray] | None = None  # set if linear in theta

    @property
    def n_params(self) -> int:
        return len(self.param_names)


def _lin_f(x, t):
    return t[0] * x + t[1]


def _quad_f(x, t):
    return (t[0] * x + t[1]) * x + t[2]


def _exp_f(x, t):
    return t[0] * np.exp(t[1] * x)


def _pow_f(x, t):
    return t[0] * np.power(x, t[1])


def _log_f(x, t):
    return t[0] + t[1] * np.log(x)


MODELS: dict[str, Model] = {
    m.name: m for m in (
        Model("linear", "P = a*GS + b", ("a", "b"), _lin_f,
              lambda x, t: np.stack([x, np.ones_like(x)], -1),
              linear_basis=lambda x: np.stack([x, np.ones_like(x)], -1)),
        Model("quadratic", "P = a*GS^2 + b*GS + c", ("a", "b", "c"), _quad_f,
              lambda x, t: np.stack([x * x, x, np.ones_like(x)], -1),
              linear_basis=lambda x: np.stack([x * x, x, np.ones_like(x)], -1)),
        Model("exponential", "P = a*exp(b*GS)", ("a", "b"), _exp_f,
              lambda x, t: np.stack([np.exp(t[1] * x), t[0] * x * np.exp(t[1] * x)], -1),
              needs_positive_y=True),
        Model("power", "P = a*GS^b", ("a", "b"), _pow_f,
              lambda x, t: np.stack([np.power(x, t[1]), t[0] * np.power(x, t[1]) * np.log(x)], -1),
              needs_positive_x=True, needs_positive_y=True),
        Model("logarithmic", "P = a + b*ln(GS)", ("a", "b"), _log_f,
              lambda x, t: np.stack([np.ones_like(x), np.log(x)], -1),
              needs_positive_x=True,
              linear_basis=lambda x: np.stack([np.ones_like(x), np.log(x)], -1)),
    )
}


@dataclass
class FitResult:
    model: str
    params: np.ndarray
    cov: np.ndarray | None          # parameter covariance (p, p); None if dof == 0
    dof: int                        # n - p
    ssr: float
    r2: float
    r2_adj: float
    aicc: float | None              # None where undefined (n <= k + 1)
    residuals: np.ndarray           # y - f(x)
    ok: bool = True
    reason: str = ""
    extra: dict = field(default_factory=dict)

    @property
    def t_factor(self) -> float:
        """Two-sided Student-t quantile for the CONFIDENCE level with dof degrees of freedom."""
        return float(stats.t.ppf(0.5 + CONFIDENCE / 2, self.dof)) if self.dof > 0 else float("nan")

    def param_ci(self) -> np.ndarray | None:
        """(p, 2) array of CONFIDENCE-level bounds on the parameters (t-distribution)."""
        if self.cov is None:
            return None
        half = self.t_factor * np.sqrt(np.clip(np.diag(self.cov), 0, None))
        return np.stack([self.params - half, self.params + half], -1)


def aicc(ssr: float, n: int, p: int) -> float | None:
    """Small-sample corrected Akaike criterion for least squares with Gaussian errors.

    k = p + 1 counts the fitted parameters and the error variance. Undefined (None) when
    n - k - 1 <= 0, i.e. fewer than p + 3 points.
    """
    k = p + 1
    if n - k - 1 <= 0:
        return None
    return n * np.log(ssr / n) + 2 * k + 2 * k * (k + 1) / (n - k - 1)


def fit(model_name: str, x: np.ndarray, y: np.ndarray) -> FitResult:
    """Least-squares fit of one model; never raises on a numerical failure (ok=False)."""
    m = MODELS[model_name]
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    n, p = x.size, m.n_params
    fail = dict(model=model_name, params=np.full(p, np.nan), cov=None, dof=n - p, ssr=np.inf,
                r2=np.nan, r2_adj=np.nan, aicc=None, residuals=np.full(n, np.nan), ok=False)
    if n < p:
        return FitResult(**fail, reason=f"needs >= {p} points")
    if m.needs_positive_x and np.any(x <= 0):
        return FitResult(**fail, reason="needs GS > 0")
    if m.needs_positive_y and np.any(y <= 0):
        return FitResult(**fail, reason="needs P > 0")
    try:
        if m.linear_basis is not None:
            theta = np.linalg.lstsq(m.linear_basis(x), y, rcond=None)[0]
        else:
            theta = _nonlinear(m, x, y)
    except (np.linalg.LinAlgError, RuntimeError, ValueError) as e:
        return FitResult(**fail, reason=f"fit failed: {e}")
    yhat = m.f(x, theta)
    if not np.all(np.isfinite(yhat)):
        return FitResult(**fail, reason="non-finite fitted values")
    res = y - yhat
    # Floor the residual sum at round-off level so exact data do not make AICc -inf and
    # let round-off noise pick among models that all fit exactly.
    ssr = max(float(res @ res), n * (1e-12 * float(np.max(np.abs(y)))) ** 2)
    sst = float(((y - y.mean()) ** 2).sum())
    r2 = 1 - ssr / sst if sst > 0 else np.nan
    dof = n - p
    r2_adj = 1 - (1 - r2) * (n - 1) / dof if dof > 0 else np.nan
    cov = None
    if dof > 0:
        J = m.jac(x, theta)
        cov = (ssr / dof) * np.linalg.pinv(J.T @ J)
    return FitResult(model_name, theta, cov, dof, ssr, r2, r2_adj, aicc(ssr, n, p), res)


def _nonlinear(m: Model, x, y) -> np.ndarray:
    # Start from the log-linearised fit, then minimise the untransformed residuals.
    if m.name == "exponential":
        b, lna = np.polyfit(x, np.log(y), 1)
    elif m.name == "power":
        b, lna = np.polyfit(np.log(x), np.log(y), 1)
    else:  # pragma: no cover - every nonlinear model has a start above
        raise ValueError(m.name)
    t0 = np.array([np.exp(lna), b])
    sol = optimize.least_squares(lambda t: m.f(x, t) - y, t0, jac=lambda t: m.jac(x, t),
                                 method="lm", xtol=1e-14, ftol=1e-14, gtol=1e-14)
    if not sol.success:
        raise RuntimeError(sol.message)
    return sol.x


def band_halfwidth(model_name: str, params, cov, dof: int, x) -> np.ndarray:
    """Half-width of the CONFIDENCE-level band of the mean response at x (delta method)."""
    m = MODELS[model_name]
    x = np.asarray(x, float)
    J = m.jac(x, np.asarray(params, float))
    var = np.einsum("...i,ij,...j->...", J, np.asarray(cov, float), J)
    t = float(stats.t.ppf(0.5 + CONFIDENCE / 2, dof))
    return t * np.sqrt(np.clip(var, 0, None))
