"""Compressible Ogden law (Abaqus OGDEN form).

    W = sum_p 2 mu_p / alpha_p^2 (lb_1^alpha_p + lb_2^alpha_p + lb_3^alpha_p - 3) + kappa/2 (J - 1)^2,

lb_a = J^(-1/3) l_a the deviatoric principal stretches. Written as
sum_p 2 mu_p/alpha_p^2 (J^(-alpha_p/3) T_p - 3) with T_p = tr C^(alpha_p/2), whose second
derivative is the Daleckii-Krein formula (`_isotropic.Kinematics`). Volumetric term as the
neo-Hookean's (Abaqus D1 = 2/kappa). Small strain: mu0 = sum mu_p, K0 = kappa.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tactileskin import validate
from tactileskin.errors import ParameterError
from tactileskin.materials._isotropic import InvariantLaw, kappa_from_nu, positive, read_table, volumetric

__all__ = ["Ogden"]

MAX_TERMS = 6   # Abaqus's limit; published fits use 1-3 terms
MAX_ALPHA = 100.0  # as the hyperfoam's (materials.hyperfoam.MAX_ALPHA)


@dataclass(frozen=True)
class Ogden(InvariantLaw):
    """mu, alpha: one entry per term (mu_p MPa and alpha_p non-zero, sum mu_p > 0; as
    Abaqus, stability beyond small strain is the fit's business); kappa: bulk modulus (MPa, > 0)."""

    mu: tuple[float, ...]
    alpha: tuple[float, ...]
    kappa: float

    law: ClassVar[str] = "ogden"

    def __post_init__(self):
        mu = validate.number_list(list(np.atleast_1d(self.mu)), "mu", MAX_TERMS, min_len=1)
        alpha = validate.number_list(list(np.atleast_1d(self.alpha)), "alpha", MAX_TERMS, min_len=1)
        if len(alpha) != len(mu):
            raise ParameterError("alpha", alpha, f"{len(mu)} values (one per mu term)")
        for i, (m, a) in enumerate(zip(mu, alpha)):
            if m == 0.0:
                raise ParameterError(f"mu[{i}]", m, "a non-zero number (MPa)")
            if a == 0.0 or abs(a) > MAX_ALPHA:
                raise ParameterError(f"alpha[{i}]", a, f"a non-zero number in [-{MAX_ALPHA:g}, {MAX_ALPHA:g}]")
        if not sum(mu) > 0.0:
            raise ParameterError("mu", mu, "sum(mu_p) > 0 MPa (initial shear modulus)")
        object.__setattr__(self, "mu", tuple(float(m) for m in mu))
        object.__setattr__(self, "alpha", tuple(float(a) for a in alpha))
        object.__setattr__(self, "kappa", positive("kappa", self.kappa))

    @property
    def mu0(self) -> float:
        return float(sum(self.mu))

    @property
    def K0(self) -> float:
        return self.kappa

    @classmethod
    def from_dict(cls, d, what="ogden"):
        d = read_table(d, ("mu", "alpha", "kappa"), what)
        return cls(validate.number_list(d["mu"], "mu", MAX_TERMS, min_len=1),
                   validate.number_list(d["alpha"], "alpha", MAX_TERMS, min_len=1), d["kappa"])

    def to_dict(self) -> dict:
        return {"mu": list(self.mu), "alpha": list(self.alpha), "kappa": self.kappa}

    def _derivs(self, kin):
        J = kin.J
        m = len(self.mu)
        names = tuple(("T", a) for a in self.alpha) + ("J",)
        grad = np.zeros(J.shape + (m + 1,))
        hess = np.zeros(J.shape + (m + 1, m + 1))
        W = np.zeros_like(J)
        for p, (mu, a) in enumerate(zip(self.mu, self.alpha)):
            k = 2.0 * mu / a**2
            T = kin.T(a)
            Jp = J ** (-a / 3.0)
            W += k * (Jp * T - 3.0)
            grad[:, p] = k * Jp
            grad[:, m] += -k * a / 3.0 * Jp / J * T
            hess[:, p, m] = hess[:, m, p] = -k * a / 3.0 * Jp / J
            hess[:, m, m] += k * (a / 3.0) * (a / 3.0 + 1.0) * Jp / J**2 * T
        U, dU, d2U = volumetric(self.kappa, J)
        W += U
        grad[:, m] += dU
        hess[:, m, m] += d2U
        return names, W, grad, hess

    # --- fitting: `terms` pairs (mu_p, alpha_p) ----------------------------------------------
    @staticmethod
    def fit_start(mu0, terms=2):
        alphas = [2.0, -2.0, 5.0, -4.0, 8.0, 1.0][:terms]
        mus = [mu0 / terms] * terms
        x0 = np.array(mus + alphas)
        return x0, (np.full(2 * terms, -np.inf), np.full(2 * terms, np.inf))

    @classmethod
    def from_fit(cls, x, nu):
        n = len(x) // 2
        mu = tuple(x[:n])
        return cls(mu, tuple(x[n:]), kappa_from_nu(max(sum(mu), 1e-300), nu))
