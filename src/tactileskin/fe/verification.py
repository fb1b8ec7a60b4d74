"""Verification problems with closed-form answers, shared by the tests and benchmarks.

- `hertz_block`: plane-strain Hertz contact, a rigid cylinder pressed into a thick block
  (half model, symmetry x = 0), compared with a = sqrt(4 P R / (pi E*)), p0 = 2 P / (pi a).
- `hertz_sphere`: 3D Hertz contact, a rigid sphere pressed into a thick block (quarter
  model, symmetry x = 0 and z = 0, P2 tetrahedra graded towards the contact point),
  compared with a = (3 P R / (4 E*))^(1/3), p0 = 3 P / (2 pi a^2) and the indentation
  force P = (4/3) E* R^(1/2) d^(3/2).

Both use the polyurethane hyperfoam (nu = 0.47) as a compressible Neo-Hookean-like solid
at small strain: E = 2 mu0 (1 + nu), E* = E / (1 - nu^2).
"""

from __future__ import annotations

import numpy as np
from skfem import MeshTri

from tactileskin.fe.model import Contact, Dirichlet, Model
from tactileskin.fe.output import make_result, reaction
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


class Sphere:
    """Rigid sphere of radius R whose lowest point starts at the origin and moves down (-y) by d."""

    def __init__(self, R):
        self.R = R

    def gap(self, x, d):
        c = np.array([0.0, self.R - d, 0.0])
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


def fit_hertz_pressure(r, p, w):
    """(a, p0) of the area-weighted least-squares fit of p = p0 sqrt(1 - r^2/a^2) to the
    contact-point pressures p at radii r (w: the points' areas), on the points within 1.5
    times the moment estimate of a (so the fit sees where the pressure ends).

    Fitting p itself, not p^2 as `hertz_block` does: in 3D the point pressures of 3 points
    per P2 triangle scatter by +-30 % about the mean at the same radius, which a fit of p^2
    weighs quadratically (h = a/5, a/R = 0.05: p^2 fit a +3.6 %, p0 -2.2 %; this fit
    +0.7 %, -1.9 %; tests/test_verification3d.py shows the bias on synthetic data)."""
    from scipy.optimize import least_squares

    load = np.sum(w * p)
    a_m = np.sqrt(2.5 * np.sum(w * p * r ** 2) / load)  # Hertz: int p r^2 dA = (2/5) a^2 P
    sel = r < 1.5 * a_m
    rs, ps, sw = r[sel], p[sel], np.sqrt(w[sel])

    def resid(q):
        return sw * (q[1] * np.sqrt(np.clip(1.0 - (rs / q[0]) ** 2, 0.0, None)) - ps)

    a, p0 = least_squares(resid, [a_m, float(ps.max())]).x
    return float(a), float(p0), float(a_m)


def hertz_sphere(h=0.1, R=10.0, d=0.025, size=40.0, r_fine=None, grade=0.3, tol_pen=1e-5,
                 options: SolverOptions | None = None):
    """Rigid sphere (radius R, travel d) on a quarter block of edge `size`, meshed with P2
    tetrahedra of size h within r_fine (default 1.4 sqrt(R d), i.e. 1.4 a) of the contact
    point; returns the FE and Hertz contact radius, peak pressure and load (dict).

    Defaults: a/R = 0.05 (finite-strain corrections small), a/size = 0.0125: the fixed
    bottom stiffens P(d) by ~ 0.4 a/size (measured at h = a/5: P/P_Hertz - 1 = +1.0 % with
    size 20, -0.1 % with 40); a and p0 at a given P move much less (0.4 % at most).
    The block is elastic, so one load increment gives the answer (the same to 0.1 % as 4).

    FE measures: `a_fe`, `p0_fe` from `fit_hertz_pressure` on the contact points (the
    load they carry equals the reaction to 5e-4); `a_moment` from the second moment of the
    contact pressure; `p_axis_stress` = -sigma_yy at the surface node on the axis (the
    L2-projected Cauchy stress, independent of the contact points); `pmax` the largest
    point pressure (scatter included). Hertz from the FE load P: `a_h`, `p0_h`; from the
    travel d: `P_h`."""
    from tactileskin.fe.output import nodal_fields
    from tactileskin.materials import get_material
    from tactileskin.mesh.block3d import build_quarter_block  # gmsh only here

    r_fine = 1.4 * np.sqrt(R * d) if r_fine is None else r_fine
    mesh, b = build_quarter_block(size, h, r_fine, grade=grade)
    hf = get_material("polyurethane").hyperfoam
    E = 2 * hf.mu0 * (1 + hf.nu)
    Estar = E / (1 - hf.nu ** 2)
    contact = Contact(Sphere(R), boundary="top", rate=1.0, tol_penetration=tol_pen)
    model = Model(mesh, b, _law(hf), [Dirichlet("bottom", (0, 1, 2)), Dirichlet("sym_x", (0,)),
                                       Dirichlet("sym_z", (2,))],
                  contact=contact, stiffness=E)
    ev, stats = run(model, d, options or SolverOptions(dt0_fraction=1.0, dt_max_fraction=1.0))
    P = 4 * float(reaction(model, ev)[1])  # full sphere load (the model is the quarter x, z >= 0)
    g, lamN, x, _ = ev.contact
    r = np.hypot(x[..., 0], x[..., 2]).ravel()
    p = model.surface.current_pressure(model.u, lamN).ravel()
    a_fe, p0_fe, a_m = fit_hertz_pressure(r, p, model.surface.w.ravel())
    top = model.facet_scalar_dofs("top")
    axis = top[np.argmin(np.hypot(*model.basis.doflocs[[0, 2]][:, top]))]
    syy = nodal_fields(model, ev)["syy"]
    a_h = (3 * P * R / (4 * Estar)) ** (1 / 3)
    return {"a_fe": a_fe, "p0_fe": p0_fe, "a_moment": a_m, "p_axis_stress": float(-syy[axis]),
            "pmax": float(p.max()), "P": P, "a_h": a_h, "p0_h": 3 * P / (2 * np.pi * a_h ** 2),
            "P_h": float(4 / 3 * Estar * np.sqrt(R) * d ** 1.5), "R": R, "d": d, "size": size, "h": h,
            "Estar": Estar, "dofs": int(model.ndof), "elements": int(mesh.nelements),
            "increments": stats.increments, "newton": stats.newton_iterations,
            "penetration": float(max(0.0, -g[lamN > 0].min())) if np.any(lamN > 0) else 0.0,
            "model": model, "ev": ev}
