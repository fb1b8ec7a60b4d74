"""The contact penetration tolerance follows the load as well as the mesh (fe.model.TOL_TRAVEL):
on a local 3D plan the facet size h is the coarse surface's, so a shallow press was held to a
penetration that is a few % of its travel."""

import pytest

import tactileskin.fe as fe
from tactileskin.fe import model as fe_model
from tactileskin.fe import model_for_scene, solve
from tactileskin.planner import with_quality
from tactileskin.scene import Scene


def _dot(depth, **kw):
    return with_quality(Scene(thickness=1.0, dim=3, indenter="braille", depth=depth, **kw), "preview")


def test_the_tolerance_is_capped_by_the_travel_not_below_its_floor():
    m, _ = model_for_scene(_dot(0.02))
    h_rule = fe_model.TOL_RELATIVE[3] * m.surface_size()
    assert fe_model.TOL_TRAVEL * 0.02 < h_rule  # the case is one the cap changes
    assert m.contact.tol_penetration == pytest.approx(fe_model.TOL_TRAVEL * 0.02)
    deep, _ = model_for_scene(with_quality(Scene(thickness=5.0, dim=3, indenter="flat"), "preview"))
    assert deep.contact.tol_penetration == pytest.approx(fe_model.TOL_RELATIVE[3] * deep.surface_size())
    tiny, _ = model_for_scene(_dot(1e-6))
    assert tiny.contact.tol_penetration == pytest.approx(fe_model.TOL_TRAVEL_FLOOR * h_rule)


@pytest.mark.parametrize("material", ["silicone", "polyurethane"])
def test_a_shallow_press_reads_the_peak_of_a_tight_tolerance(material, monkeypatch):
    # a 3D dot pressed 0.02 mm (a tenth of the paper's depth at t = 1). With the facet rule
    # alone (2.8e-3 of the travel) the peak read 0.26 % (silicone, preview) to 1.2 %
    # (polyurethane, default) below the one at a 100x tighter tolerance; the error scales with
    # the tolerance, so the travel cap (1e-3 of the travel, 28x tighter) leaves ~0.01-0.05 %.
    base = solve(_dot(0.02, material=material)).peak
    import functools

    monkeypatch.setattr(fe, "Contact", functools.partial(fe_model.Contact, tol_relative=1e-5))
    tight = solve(_dot(0.02, material=material)).peak
    assert base == pytest.approx(tight, rel=1e-3)
