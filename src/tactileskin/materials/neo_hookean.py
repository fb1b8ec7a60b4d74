"""Compressible neo-Hookean law.

    W = mu/2 (I1b - 3) + kappa/2 (J - 1)^2,   I1b = J^(-2/3) tr C.

Volumetric term kappa/2 (J - 1)^2: Abaqus's (J - 1)^2 / D1 with D1 = 2/kappa, so
parameters fitted in Abaqus/ANSYS carry over; convex in J and finite for every J > 0
(J <= 0 is flagged inadmissible). Small strain: shear modulus mu0 = mu, bulk modulus
K0 = kappa (incompressible limit: Young's modulus 3 mu).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tactileskin.materials._isotropic import (InvariantLaw, isochoric_chain, kappa_from_nu, positive,
                                              read_table, volumetric)

__all__ = ["NeoHookean"]

_I1J = [0, 2]  # (I1, J) of (I1, I2, J): W does not depend on I2


@dataclass(frozen=True)
class NeoHookean(InvariantLaw):
    """mu: shear modulus (MPa, > 0); kappa: bulk modulus (MPa, > 0)."""

    mu: float
    kappa: float

    law: ClassVar[str] = "neo_hookean"
    fit_names: ClassVar[tuple] = ("mu",)

    def __post_init__(self):
        object.__setattr__(self, "mu", positive("mu", self.mu))
        object.__setattr__(self, "kappa", positive("kappa", self.kappa))

    @property
    def mu0(self) -> float:
        return self.mu

    @property
    def K0(self) -> float:
        return self.kappa

    @classmethod
    def from_dict(cls, d, what="neo_hookean"):
        d = read_table(d, ("mu", "kappa"), what)
        return cls(d["mu"], d["kappa"])

    def to_dict(self) -> dict:
        return {"mu": self.mu, "kappa": self.kappa}

    def _derivs(self, kin):
        I1, J = kin.I1, kin.J
        z = np.zeros_like(J)
        grad, hess, I1b, _ = isochoric_chain(I1, 0.0 * J, J, 0.5 * self.mu, z, z, z, z)
        U, dU, d2U = volumetric(self.kappa, J)
        W = 0.5 * self.mu * (I1b - 3.0) + U
        grad[:, 2] += dU
        hess[:, 2, 2] += d2U
        return ("I1", "J"), W, grad[:, _I1J], hess[:, _I1J][:, :, _I1J]

    # --- fitting (materials.fit) ------------------------------------------------------------
    @staticmethod
    def fit_start(mu0):
        return np.array([mu0]), (np.array([1e-12]), np.array([np.inf]))

    @classmethod
    def from_fit(cls, x, nu):
        return cls(x[0], kappa_from_nu(x[0], nu))
