"""Scene planner: decisions for representative scenes, and the viscoelastic bound against
actual elastic and viscoelastic solves on coarse meshes."""

from __future__ import annotations

import math

import pytest

from tactileskin import planner
from tactileskin.errors import ParameterError
from tactileskin.fe import solve
from tactileskin.planner import QUALITY, plan, truncated_scene, viscoelastic_bound, with_quality
from tactileskin.scene import Scene

COARSE = dict(mesh_size=1.0, refinement=2.0)


def test_flat_and_curved_are_2d_half_models_and_keep_viscoelasticity():
    for ind in ("flat", "curved"):
        p = plan(Scene(thickness=3.0, indenter=ind, dim=3))
        assert p.scene.dim == 2                      # 3D asked, uniform indenter: 2D is exact
        assert p.choice("dimension").cost == 0.0
        assert p.choice("symmetry").decision.startswith("half model")
        # silicone over 0.6 s relaxes up to 8.3 % > 1 %: viscoelasticity stays
        assert p.scene.viscoelastic
        assert p.expected_error == 0.0
        assert "2D plane strain" in p.describe()


def test_viscoelastic_bound_closed_form():
    # 1 - g(T) with g(t) = g_inf + sum g_i exp(-t/tau_i), Table I silicone, T = 0.6 s
    g = [0.015, 0.044, 0.029]
    tau = [0.025, 0.150, 0.300]
    gT = 1 - sum(g) + sum(gi * math.exp(-0.6 / ti) for gi, ti in zip(g, tau))
    assert viscoelastic_bound(Scene(thickness=3.0)) == pytest.approx(1 - gT, rel=1e-12)
    # a fast loading relaxes little: 1 - exp(-x) <= x gives 1 - g(T) <= T sum(g_i / tau_i)
    T = 0.6 / 100.0
    b = viscoelastic_bound(Scene(thickness=3.0, rate=100.0))
    assert 0.0 < b <= T * sum(gi / ti for gi, ti in zip(g, tau))


def test_fast_loading_drops_viscoelasticity_within_tolerance():
    sc = Scene(thickness=1.0, material="silicone", rate=100.0)  # 2 ms of loading
    p = plan(sc, tolerance=0.01)
    assert not p.scene.viscoelastic
    c = p.choice("viscoelasticity")
    assert c.basis == "bound" and c.cost == pytest.approx(viscoelastic_bound(sc))
    assert p.expected_error <= 0.01
    # a tighter tolerance than the bound keeps it
    assert plan(sc, tolerance=0.5 * c.cost).scene.viscoelastic


def test_a_loading_history_keeps_its_relaxation():
    from tactileskin.materials import get_material
    from tactileskin.planner import history_time

    fast = Scene(thickness=1.0, material="polyurethane", indenter="curved", depth=0.1, rate=100.0)
    assert not plan(fast, tolerance=0.01).scene.viscoelastic        # 1 ms: relaxation negligible
    g = get_material("polyurethane").prony
    # a hold, then a second ramp: 1 ms + 10 s + 1 ms, and the bound of that whole time
    held = fast.replace(loading=({"hold": 10.0}, {"depth": 0.2, "rate": 100.0}))
    assert history_time(held) == pytest.approx(0.001 + 10.0 + 0.001)
    assert viscoelastic_bound(held) == pytest.approx(1.0 - g.relaxation(10.002), rel=1e-12)
    p = plan(held, tolerance=0.01)
    assert p.scene.viscoelastic and p.scene.loading == held.loading
    # a ramp whose start is known only after solving (force after depth): the whole relaxation
    mixed = fast.replace(loading=({"force": 0.01, "rate": 1.0},))
    assert history_time(mixed) == float("inf")
    assert plan(mixed, tolerance=0.01).scene.viscoelastic


def test_elastic_user_material_has_zero_bound(tmp_path):
    path = tmp_path / "gel.toml"
    path.write_text('name = "gel"\n[hyperfoam]\nmu = [0.02]\nalpha = [4.0]\nnu = 0.45\n')
    sc = Scene(material=str(path))
    assert viscoelastic_bound(sc) == 0.0
    assert not plan(sc).scene.viscoelastic


def test_braille_dots_go_3d_unless_the_measured_ridge_difference_fits(monkeypatch):
    sc = Scene(thickness=3.0, indenter="braille")
    monkeypatch.setattr(planner, "MEASURED_RIDGE_VS_DOTS", {})
    p = plan(sc)
    assert p.scene.dim == 3 and "not measured" in p.choice("dimension").reason
    assert p.choice("truncation").decision.startswith("not available")
    ridge = plan(sc, braille="ridge")
    assert ridge.scene.dim == 2 and ridge.expected_error is None  # cost unknown, said so
    monkeypatch.setattr(planner, "MEASURED_RIDGE_VS_DOTS", {(3.0, "silicone"): {"peak": 0.004, "span": 0.1}})
    p = plan(sc, tolerance=0.01)
    assert p.scene.dim == 2 and p.choice("dimension").cost == 0.004
    assert plan(sc, tolerance=0.003).scene.dim == 3


def test_asymmetric_braille_text_is_flagged():
    p = plan(Scene(indenter="braille", braille_text="e"), braille="ridge")  # dots 1, 5: not x-symmetric
    assert p.choice("symmetry").cost is None and p.expected_error is None
    assert plan(Scene(indenter="braille", braille_text="c"), braille="ridge").choice("symmetry").cost == 0.0


def test_truncation_only_where_there_is_skin_to_cut_and_only_when_measured(monkeypatch):
    sc = Scene(thickness=1.0)
    cut = truncated_scene(sc)
    keep = planner.WINDOW_S + planner.TRUNCATION_MARGIN + 1.0
    assert cut.section().interface_length == pytest.approx(keep, abs=1e-3)
    assert cut.section().interface(0.0) == pytest.approx(sc.section().interface(0.0))  # same near s = 0
    assert truncated_scene(Scene(thickness=5.0)) is None
    monkeypatch.setattr(planner, "MEASURED_TRUNCATION", {})
    assert plan(sc).scene == sc.replace()                          # unmeasured: not truncated
    monkeypatch.setattr(planner, "MEASURED_TRUNCATION", {(1.0, "silicone", "flat"): {"l2": 0.002, "peak": 0.001}})
    p = plan(sc, tolerance=0.01)
    assert p.scene.section().interface_length == pytest.approx(keep, abs=1e-3)
    assert p.choice("truncation").cost == 0.002
    assert plan(sc, tolerance=0.001).scene.section().interface_length > 13.0


def test_bad_arguments_raise_parameter_errors():
    with pytest.raises(ParameterError, match="tolerance"):
        plan(Scene(), tolerance=0.0)
    with pytest.raises(ParameterError, match="braille"):
        plan(Scene(), braille="cells")


@pytest.mark.parametrize("material, rate", [("polyurethane", 1.0), ("silicone", 100.0)])
def test_viscoelastic_bound_holds_against_solves(material, rate):
    # Relative change of the peak bone pressure between the elastic and the QLV solve on
    # the same coarse mesh must not exceed 1 - g(T); it must also be real (> 0) so the
    # comparison is not vacuous. Polyurethane at 1 mm/s: bound 1 - g(0.2 s) = 13 %;
    # silicone at 100 mm/s: bound 0.2 % (the planner drops viscoelasticity there).
    sc = Scene(thickness=1.0, material=material, indenter="curved", rate=rate, **COARSE)
    ve = solve(sc)
    el = solve(sc.replace(viscoelastic=False))
    diff = (el.peak - ve.peak) / el.peak
    assert 0.0 < diff <= viscoelastic_bound(sc)


def test_quality_presets_order_cost_and_error():
    sc = Scene(thickness=3.0)
    sizes = [with_quality(sc, q).mesh_size / with_quality(sc, q).refinement for q in ("preview", "default", "fine")]
    assert sizes == sorted(sizes, reverse=True)  # finer preset, smaller refined size
    errs = [QUALITY[q]["peak_error"] for q in ("preview", "default", "fine")]
    assert errs == sorted(errs, reverse=True)
    from tactileskin import presets

    for q in ("preview", "default", "fine"):  # 3D Braille: the 3D preset at the skin's thickness
        for t in (1.0, 3.0, 5.0):
            s3 = with_quality(sc.replace(dim=3, indenter="braille", thickness=t), q)
            assert (s3.mesh_size, s3.refinement) == presets.mesh(3, q, braille=True, thickness=t)
    assert with_quality(sc.replace(dim=3, indenter="braille", thickness=1.0), "default").mesh_size < \
        with_quality(sc.replace(dim=3, indenter="braille", thickness=3.0), "default").mesh_size
    f3 = with_quality(sc.replace(dim=3), "fine")  # flat / curved 3D: the strip plan's preset
    assert (f3.mesh_size, f3.refinement) == QUALITY["fine"]["mesh3d"]
    with pytest.raises(ParameterError, match="quality"):
        with_quality(sc, "ultra")
