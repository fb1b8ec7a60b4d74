"""Verification problems with closed-form answers, shared by the tests and benchmarks.

- `hertz_block`: plane-strain Hertz contact, a rigid cylinder pressed into a thick block
  (half model, symmetry x = 0), compared with a = sqrt(4 P R / (pi E*)), p0 = 2 P / (pi a).
"""

from __future__ import annotations

import numpy as np
from skfem import MeshTri

from tactileskin.fe.model import Contact, Dirichlet, Model
from tactileskin.fe.output import make_result
from tactileskin.fe.solver import SolverOptions, run


def _law(hf):
    from tactileskin.fe import material_law

    return material_law(hf)


class Cylinder:
    """Rigid cylinder of radius R whose lowest point starts at y = 0 and moves down by d."""

    def __init__(self, R):
        self.R = R

    def gap(self, x, d):
        c = np.array([0.0, self.R - d])
        r = np.linalg.norm(x - c, axis=-1)
        return r - self.R, (x - c) / r[..., None]


def graded(fine_end, h, total, ratio=1.3):
    """Nodes from 0: uniform size h up to fine_end, then growing geometrically to total."""
    xs = list(np.linspace(0.0, fine_end, int(round(fine_end / h)) + 1))
    step = h
    while xs[-1] < total:
        step *= ratio
        xs.append(min(xs[-1] + step, total))
    if total - xs[-2] < 0.5 * step:
        xs.pop(-2)
    return np.array(xs)


def hertz_block(h=0.08, R=20.0, d=0.012, size=10.0, tol_pen=1e-5):
    x = graded(1.0, h, size)
    y = -graded(1.0, h, size)[::-1]
    m = MeshTri.init_tensor(x, y)
    b = {"top": m.facets_satisfying(lambda p: p[1] > -1e-9),
         "bottom": m.facets_satisfying(lambda p: p[1] < -size + 1e-9),
         "sym": m.facets_satisfying(lambda p: p[0] < 1e-9)}
    from tactileskin.materials import get_material

    hf = get_material("polyurethane").hyperfoam
    contact = Contact(Cylinder(R), boundary="top", rate=1.0, tol_penetration=tol_pen)
    model = Model(m, b, _law(hf), [Dirichlet("bottom", (0, 1)), Dirichlet("sym", (0,))],
                  contact=contact, stiffness=2 * hf.mu0 * (1 + hf.nu))
    ev, stats = run(model, d, SolverOptions(dt0_fraction=0.5))
    # the subsurface mean pressure along the symmetry line, s = depth below the surface
    res = make_result(model, ev, stats, path="sym", s_of_point=lambda X: -X[:, 1])
    E = 2 * hf.mu0 * (1 + hf.nu)
    Estar = E / (1 - hf.nu ** 2)
    P = 2 * res.reaction  # full cylinder load per mm (the model is the half x >= 0)
    a_h = np.sqrt(4 * P * R / (np.pi * Estar))
    p0_h = 2 * P / (np.pi * a_h)
    # FE half-width and peak: least-squares fit of p^2 = p0^2 (1 - x^2/a^2) on the points
    # carrying more than 20 % of the peak (the last element at the contact edge smears p)
    xc, pc = res.contact_x, res.contact_pressure
    sel = pc > 0.2 * pc.max()
    A = np.column_stack([np.ones(sel.sum()), xc[sel] ** 2])
    c0, c1 = np.linalg.lstsq(A, pc[sel] ** 2, rcond=None)[0]
    return {"a_fe": np.sqrt(-c0 / c1), "p0_fe": np.sqrt(c0), "pmax": pc.max(), "a_h": a_h, "p0_h": p0_h,
            "R": R, "res": res, "model": model}
