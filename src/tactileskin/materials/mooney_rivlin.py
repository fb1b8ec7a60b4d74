"""Compressible Mooney-Rivlin law.

    W = c10 (I1b - 3) + c01 (I2b - 3) + kappa/2 (J - 1)^2,
    I1b = J^(-2/3) I1, I2b = J^(-4/3) I2.

Volumetric term as the neo-Hookean's (Abaqus D1 = 2/kappa). Small strain: mu0 = 2 (c10 + c01),
K0 = kappa. c01 may be negative (published fits often are) as long as c10 + c01 > 0.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tactileskin.errors import ParameterError
from tactileskin.materials._isotropic import (InvariantLaw, finite, isochoric_chain, kappa_from_nu, positive,
                                              read_table, volumetric)

__all__ = ["MooneyRivlin"]


@dataclass(frozen=True)
class MooneyRivlin(InvariantLaw):
    """c10, c01 (MPa, c10 + c01 > 0); kappa: bulk modulus (MPa, > 0)."""

    c10: float
    c01: float
    kappa: float

    law: ClassVar[str] = "mooney_rivlin"
    fit_names: ClassVar[tuple] = ("c10", "c01")

    def __post_init__(self):
        c10, c01 = finite("c10", self.c10), finite("c01", self.c01)
        if not c10 + c01 > 0.0:
            raise ParameterError("c10 + c01", c10 + c01, "> 0 MPa (initial shear modulus 2 (c10 + c01))")
        object.__setattr__(self, "c10", c10)
        object.__setattr__(self, "c01", c01)
        object.__setattr__(self, "kappa", positive("kappa", self.kappa))

    @property
    def mu0(self) -> float:
        return 2.0 * (self.c10 + self.c01)

    @property
    def K0(self) -> float:
        return self.kappa

    @classmethod
    def from_dict(cls, d, what="mooney_rivlin"):
        d = read_table(d, ("c10", "c01", "kappa"), what)
        return cls(d["c10"], d["c01"], d["kappa"])

    def to_dict(self) -> dict:
        return {"c10": self.c10, "c01": self.c01, "kappa": self.kappa}

    def _derivs(self, kin):
        I1, I2, J = kin.I1, kin.I2, kin.J
        z = np.zeros_like(J)
        grad, hess, I1b, I2b = isochoric_chain(I1, I2, J, self.c10 + z, self.c01 + z, z, z, z)
        U, dU, d2U = volumetric(self.kappa, J)
        W = self.c10 * (I1b - 3.0) + self.c01 * (I2b - 3.0) + U
        grad[:, 2] += dU
        hess[:, 2, 2] += d2U
        return ("I1", "I2", "J"), W, grad, hess

    @staticmethod
    def fit_start(mu0):
        return np.array([0.4 * mu0, 0.1 * mu0]), (np.array([-np.inf, -np.inf]), np.array([np.inf, np.inf]))

    @classmethod
    def from_fit(cls, x, nu):
        mu0 = 2.0 * (x[0] + x[1])
        return cls(x[0], x[1], kappa_from_nu(max(mu0, 1e-300), nu))
