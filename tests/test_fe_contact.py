"""Contact: plane-strain Hertz (rigid cylinder on a thick block) and the AL tolerance."""

import numpy as np
import pytest
from skfem import MeshTri

from tactileskin.fe import Contact, Dirichlet, Model, SolverOptions, make_result, material_law, run
from tactileskin.materials import get_material


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
    hf = get_material("polyurethane").hyperfoam
    contact = Contact(Cylinder(R), boundary="top", rate=1.0, tol_penetration=tol_pen)
    model = Model(m, b, material_law(hf), [Dirichlet("bottom", (0, 1)), Dirichlet("sym", (0,))],
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


@pytest.fixture(scope="module")
def hertz():
    return hertz_block()


def test_hertz_plane_strain(hertz):
    """a/R = 0.02 and a/size = 0.035 keep finite-strain and finite-block corrections ~1 %.
    With ~4.5 P2 elements across the half-width (h = 0.08 mm) the fitted half-width and peak
    are within 3 % of Hertz (measured: +0.4 %, -0.2 %); the largest raw point pressure
    overshoots by 3.3 % here (less on finer meshes, `benchmarks/solve.py --hertz`), hence 5 %."""
    h = hertz
    assert h["a_h"] / h["R"] < 0.03
    assert h["a_fe"] == pytest.approx(h["a_h"], rel=0.03)
    assert h["p0_fe"] == pytest.approx(h["p0_h"], rel=0.03)
    assert h["pmax"] == pytest.approx(h["p0_h"], rel=0.05)


def test_contact_tolerance_does_not_change_the_answer(hertz):
    """Penetration below 1e-5 mm vs 1e-7 mm: the load and the subsurface pressure (the
    toolkit's output) agree to 1e-3; the error of the looser one is ~ penetration / travel =
    1e-5/0.012 ~ 1e-3 at most. The fingertip cases travel 0.2-1 mm, so their default 1e-4 mm
    is as tight relative to the travel (0.05 % or better). The point contact pressures agree
    to 1 % (the multipliers of the edge points redistribute as the penalty grows)."""
    tight = hertz_block(tol_pen=1e-7)
    g = tight["model"].surface
    a, b = hertz["res"], tight["res"]
    assert b.reaction == pytest.approx(a.reaction, rel=1e-3)
    # 2e-3 at the surface node itself (measured 1.4e-3), 1e-3 below it
    np.testing.assert_allclose(b.pressure[0], a.pressure[0], rtol=2e-3)
    np.testing.assert_allclose(b.pressure[1:], a.pressure[1:], atol=1e-3 * a.pressure.max())
    assert tight["pmax"] == pytest.approx(hertz["pmax"], rel=1e-2)
    # and the converged penetration really is below the tolerance
    x = g.X + g.displacement(tight["model"].u)
    gap, _ = Cylinder(20.0).gap(x, 0.012)
    assert -gap.min() < 1e-7
