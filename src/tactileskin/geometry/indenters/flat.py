"""flat: a rigid plate, the half-space y >= y0 - d (paper Sec. III-A)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tactileskin import params
from tactileskin.geometry.indenters.base import Indenter, stem_params
from tactileskin.geometry.indenters.registry import register


@register
@dataclass(frozen=True, eq=False)
class FlatIndenter(Indenter):
    thickness: float = 5.0

    name = "flat"
    order = 0
    paper = True

    @classmethod
    def from_params(cls, *, y0, dim, length, row=None, warn=True, **_):
        q = params.load("indenters")["flat"]
        return cls(kind=cls.name, y0=y0, dim=dim, width=float(q["width"]), length=length,
                   thickness=float(q["thickness"]), **stem_params())

    def _gap(self, p, d):
        g = (self.y0 - d) - p[:, 1]  # the plate occupies y >= y0 - d; points below are separated
        n = np.zeros_like(p)
        n[:, 1] = -1.0
        return g, n

    def _surface_y(self, x, z, d):
        return np.full(np.shape(x), self.y0 - d)

    def solid(self):
        from tactileskin.geometry import solids

        return solids.flat_indenter(self)

    def describe(self) -> str:
        return "flat plate indenter"
