"""Compressible Yeoh law (Abaqus's reduced polynomial, N <= 3, one volumetric term).

    W = sum_i c_i0 (I1b - 3)^i + kappa/2 (J - 1)^2,   I1b = J^(-2/3) tr C.

Volumetric term as the neo-Hookean's (Abaqus D1 = 2/kappa). Small strain: mu0 = 2 c10,
K0 = kappa. c20 is usually negative (softening) and c30 positive (stiffening) in fits.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tactileskin import validate
from tactileskin.errors import ParameterError
from tactileskin.materials._isotropic import (InvariantLaw, isochoric_chain, kappa_from_nu, positive,
                                              read_table, volumetric)

__all__ = ["Yeoh"]

_I1J = [0, 2]


@dataclass(frozen=True)
class Yeoh(InvariantLaw):
    """c = (c10, c20, c30) (MPa; 1 to 3 terms, c10 > 0); kappa: bulk modulus (MPa, > 0)."""

    c: tuple[float, ...]
    kappa: float

    law: ClassVar[str] = "yeoh"
    fit_names: ClassVar[tuple] = ("c10", "c20", "c30")

    def __post_init__(self):
        c = validate.number_list(list(self.c) if isinstance(self.c, (list, tuple, np.ndarray)) else self.c,
                                 "c", 3, min_len=1)
        if not c[0] > 0.0:
            raise ParameterError("c[0]", c[0], "> 0 MPa (c10; initial shear modulus 2 c10)")
        object.__setattr__(self, "c", tuple(c))
        object.__setattr__(self, "kappa", positive("kappa", self.kappa))

    @property
    def mu0(self) -> float:
        return 2.0 * self.c[0]

    @property
    def K0(self) -> float:
        return self.kappa

    @classmethod
    def from_dict(cls, d, what="yeoh"):
        d = read_table(d, ("c", "kappa"), what)
        return cls(validate.number_list(d["c"], "c", 3, min_len=1), d["kappa"])

    def to_dict(self) -> dict:
        return {"c": list(self.c), "kappa": self.kappa}

    def _derivs(self, kin):
        I1, J = kin.I1, kin.J
        x = J ** (-2.0 / 3.0) * I1 - 3.0
        w = w1 = w11 = 0.0
        for i, ci in enumerate(self.c, start=1):
            w = w + ci * x**i
            w1 = w1 + i * ci * x ** (i - 1)
            if i >= 2:
                w11 = w11 + i * (i - 1) * ci * x ** (i - 2)
        z = np.zeros_like(J)
        grad, hess, _, _ = isochoric_chain(I1, z, J, w1 + z, z, w11 + z, z, z)
        U, dU, d2U = volumetric(self.kappa, J)
        grad[:, 2] += dU
        hess[:, 2, 2] += d2U
        return ("I1", "J"), w + U, grad[:, _I1J], hess[:, _I1J][:, :, _I1J]

    @staticmethod
    def fit_start(mu0):
        return np.array([0.5 * mu0, 0.0, 0.0]), (np.array([1e-12, -np.inf, -np.inf]), np.array([np.inf] * 3))

    @classmethod
    def from_fit(cls, x, nu):
        return cls(tuple(x), kappa_from_nu(2.0 * x[0], nu))
