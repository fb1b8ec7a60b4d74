"""Quality presets from tactileskin/data/presets.json (2D and 3D) and the helpers of the 3D
convergence study (benchmarks/convergence3d.py)."""

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

from tactileskin import presets
from tactileskin.errors import ParameterError
from tactileskin.planner import QUALITY, with_quality
from tactileskin.scene import DEFAULT_MESH, Scene, default_mesh

_spec = importlib.util.spec_from_file_location(
    "convergence3d", Path(__file__).resolve().parents[1] / "benchmarks" / "convergence3d.py")
cv = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(cv)


def test_preset_file_has_three_levels_per_dim_with_finite_errors():
    data = presets.load()
    for dim in ("2", "3"):
        assert set(presets.QUALITIES) <= set(data[dim])
        fine_sizes = [presets.mesh(int(dim), q)[0] / presets.mesh(int(dim), q)[1] for q in presets.QUALITIES]
        assert fine_sizes == sorted(fine_sizes, reverse=True)  # preview coarsest, fine finest
        fine_b = [presets.mesh(int(dim), q, True)[0] / presets.mesh(int(dim), q, True)[1] for q in presets.QUALITIES]
        assert fine_b == sorted(fine_b, reverse=True)
    for q in presets.QUALITIES:
        assert math.isfinite(QUALITY[q]["peak_error"])
        e = presets.preset_errors(q)
        assert e["cases"], f"3D {q}: no convergence case measured its level"
        assert math.isfinite(e["peak_error"]) and math.isfinite(e["map_l2"])
    assert presets.preset_errors("preview")["peak_error"] >= presets.preset_errors("fine")["peak_error"]


def test_3d_cases_in_the_file_are_consistent():
    for key, case in presets.load()["cases3d"].items():
        lv = case["levels"]
        assert len(lv) >= 3, key
        dofs = [v["dofs"] for v in lv]
        assert dofs == sorted(dofs) and len(set(dofs)) == len(dofs), key
        assert lv[-1]["map_l2"] == 0.0  # the map error is measured against the finest level


def test_with_quality_applies_the_dimensions_preset():
    s3 = Scene(dim=3, thickness=1.0, indenter="braille")
    for q in presets.QUALITIES:
        assert (with_quality(s3, q).mesh_size, with_quality(s3, q).refinement) == presets.mesh(3, q, braille=True)
        f3 = with_quality(s3.replace(indenter="flat"), q)
        assert (f3.mesh_size, f3.refinement) == presets.mesh(3, q)
        s2 = with_quality(s3.replace(dim=2), q)
        assert (s2.mesh_size, s2.refinement) == presets.mesh(2, q, braille=True)
    assert (s3.mesh_size, s3.refinement) == default_mesh(3, "braille") == presets.mesh(3, "default", braille=True)
    # from t = 3 mm the 3D default takes the coarser local plan the convergence study measured
    # within 2 % (peak) and 5 % (map) there; with_quality follows the thickness
    s5 = s3.replace(thickness=5.0)
    assert (s5.mesh_size, s5.refinement) == presets.mesh(3, "default", braille=True, thickness=5.0) == (1.6, 8.0)
    assert (with_quality(s5, "default").mesh_size, with_quality(s5, "fine").mesh_size) == (1.6, 0.8)
    e = presets.preset_errors("default")
    # every studied case (dots and full cells) measured the default, none by itself
    assert not e["reference_in"] and not e["not_measured"]
    levels = [presets.preset_level(k, c, "default") for k, c in presets.load()["cases3d"].items()]
    assert e["peak_error"] == max(abs(v["peak_error"]) for v in levels)
    assert e["map_l2"] == max(v["map_l2"] for v in levels)
    # against the issue-13 targets (peak 2 %, map 5 %), every studied case: worst map 4.07 % (the
    # t = 5 silicone dot with its 3x contact spot, mesh.sizing.spot_factor; 4.52 % at 1); the t = 1
    # full cells -1.90 % (silicone) and -1.79 % (polyurethane) from Richardson limits of order
    # 3.8 / 3.5 since the contact tolerance's travel cap (-2.0 / -2.04 % before); the t = 5 cells'
    # maps 3.75 / 2.76 % (3.2 / 2.2 % at spot factor 1; 7.5 / 5.4 % before the bone patches'
    # size cap, mesh.sizing.BONE_SCALE_MAX)
    for key, case in presets.load()["cases3d"].items():
        lv = presets.preset_level(key, case, "default")
        assert abs(lv["peak_error"]) <= 0.02, key
        assert lv["map_l2"] <= 0.05, key
    assert DEFAULT_MESH[3] == presets.mesh(3, "default")
    assert presets.mesh(3, "preview") != presets.mesh(3, "fine")
    with pytest.raises(ParameterError, match="quality"):
        with_quality(s3, "ultra")


def test_observed_order_and_richardson_on_a_known_series():
    h = np.array([0.8, 0.5, 0.3])  # unequal ratios
    f = 1.0 + 0.3 * h ** 2
    assert cv.observed_order(h, f) == pytest.approx(2.0, abs=1e-6)
    r = cv.richardson(h, f)
    assert r["method"] == "richardson" and r["value"] == pytest.approx(1.0, abs=1e-9)
    g = 2.0 - 0.1 * h ** 1.5  # converging from below
    assert cv.richardson(h, g)["order"] == pytest.approx(1.5, abs=1e-6)
    assert cv.richardson(h, g)["value"] == pytest.approx(2.0, abs=1e-9)


def test_richardson_falls_back_to_the_finest_level():
    h = [0.8, 0.5, 0.3]
    wiggle = cv.richardson(h, [1.0, 1.02, 1.01])  # differences change sign
    assert wiggle["method"] == "finest" and wiggle["value"] == 1.01 and wiggle["order"] is None
    h_arr = np.array(h)
    steep = cv.richardson(h, 1.0 + h_arr ** 9)  # order 9: outside the trusted range
    assert steep["method"] == "finest" and steep["order"] == pytest.approx(9.0, abs=1e-4)
    with pytest.raises(ValueError):
        cv.observed_order([0.3, 0.5, 0.8], [1, 2, 3])


def test_map_l2_on_the_coarsest_grid():
    s = np.linspace(0.0, 6.0, 13)
    z = np.linspace(0.0, 2.0, 5)
    P = np.outer(1.0 + z, np.exp(-s))
    fine_s, fine_z = np.linspace(0.0, 7.0, 57), np.linspace(0.0, 2.0, 9)
    fine = {"s": fine_s, "z": fine_z, "pressure": 1.1 * np.outer(1.0 + fine_z, np.exp(-fine_s))}
    coarse = {"s": s, "z": z, "pressure": P}
    e = cv.map_l2([coarse, fine])
    assert e[1] == 0.0
    # on the coarse grid points the fine map (bilinear in z, exact there; linear in s on nodes
    # that include the coarse ones) is 1.1 P: relative difference 0.1 / 1.1
    assert e[0] == pytest.approx(0.1 / 1.1, rel=1e-9)


def test_map_l2_leaves_out_the_free_end():
    """A difference confined to z within z_margin of the far end (the slab's free end, where
    the bone pressure is singular) does not count with the margin, and counts without it."""
    s = np.linspace(0.0, 6.0, 13)
    z = np.linspace(0.0, 10.0, 21)
    P = np.outer(1.0 + 0.0 * z, np.exp(-s))
    bump = np.where(z[:, None] > 8.0, 0.5, 0.0) * np.ones_like(P)
    coarse = {"s": s, "z": z, "pressure": P + bump}
    fine = {"s": s, "z": z, "pressure": P}
    assert cv.map_l2([coarse, fine])[0] > 0.1
    assert cv.map_l2([coarse, fine], z_margin=2.0)[0] == pytest.approx(0.0, abs=1e-12)
    assert cv.map_l2([coarse, fine], z_margin=1.0)[0] > 0.1


def test_cheapest_level_within_the_targets():
    lv = [{"dofs": 10, "peak_error": -0.05, "map_l2": 0.03}, {"dofs": 20, "peak_error": -0.015, "map_l2": 0.04},
          {"dofs": 40, "peak_error": -0.005, "map_l2": 0.01}, {"dofs": 80, "peak_error": 0.0, "map_l2": 0.0}]
    assert cv.cheapest_within(lv)["dofs"] == 20
    assert cv.cheapest_within(lv, peak_tol=0.01)["dofs"] == 40
    assert cv.cheapest_within(lv, peak_tol=0.001) is None  # the finest level does not count


def test_preset_errors_name_where_a_level_is_the_reference():
    for q in presets.QUALITIES:
        e = presets.preset_errors(q)
        assert set(e["reference_in"]) <= set(e["cases"])
        assert set(e["cases"]).isdisjoint(e["not_measured"])
        assert set(e["cases"]) | set(e["not_measured"]) == set(presets.load()["cases3d"])
        if e["cases"] and set(e["cases"]) - set(e["reference_in"]):
            assert e["map_l2"] > 0.0  # measured against a finer level somewhere


def test_a_level_meshed_with_another_bone_layout_does_not_count_for_the_preset():
    # a level records the bone patch scale it was meshed with; the same sizes with another
    # scale (a level solved before mesh.sizing.BONE_SCALE_MAX) are another mesh
    key = "t5-silicone-\u2801"
    case = presets.load()["cases3d"][key]
    now = presets.study_bone_scale(5.0)
    assert now == 2.3
    for q in presets.QUALITIES:
        lv = presets.preset_level(key, case, q)
        assert lv is not None and lv["bone_scale"] == now  # the t = 5 study is one capped family
        other = dict(case, levels=[dict(v, bone_scale=3.4722) if v is lv else v for v in case["levels"]])
        assert presets.preset_level(key, other, q) is None
    # below t = 3.3 mm the rule is unchanged: levels with or without a recorded scale count
    t1 = presets.load()["cases3d"]["t1-silicone-\u2801"]
    bare = dict(t1, levels=[{k: v for k, v in lv.items() if k != "bone_scale"} for lv in t1["levels"]])
    for case in (t1, bare):
        assert presets.preset_level("t1-silicone-\u2801", case, "fine")

def test_the_3d_preset_errors_say_which_thicknesses_they_cover():
    from tactileskin.planner import QUALITY

    # the study is t = 1-5 mm; at t = 0.5 the fingertip cell reads ~9 % low at default
    # (convergence3d.md), so no error may be claimed there
    assert QUALITY["default"]["cases3d_thickness_mm"] == (1.0, 5.0)


def test_a_user_geometry_that_refuses_the_studys_thickness_does_not_break_the_presets(tmp_path):
    """The preset table measures 3D sphere levels at t = 5; a fingertip override whose skins
    stop below 5 mm made every command fail at import ("thickness=5.0 is invalid")."""
    import shutil
    import subprocess
    import sys
    from pathlib import Path

    import tactileskin

    geo = tmp_path / "geometry"
    shutil.copytree(Path(tactileskin.__file__).parent / "data" / "geometry", geo)
    ft = geo / "fingertip.toml"
    ft.write_text(ft.read_text().replace("half_width = 8.0 ", "half_width = 9.0 ", 1))
    code = ("from tactileskin import planner; from tactileskin.scene import Scene; "
            "print(planner.with_quality(Scene(thickness=1), 'preview').mesh_size)")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                         env={**__import__("os").environ, "TACTILESKIN_GEOMETRY": str(geo)})
    assert run.returncode == 0, run.stderr[-500:]
    assert run.stdout.strip() == "1.0"


def test_own_map_errors_recover_independent_errors():
    """benchmarks/spot_scale_t5.own_map_errors: maps m* + a_i phi_i with phi_i on disjoint
    supports (so mutually orthogonal, and orthogonal to m*'s own support) have pairwise
    distances sqrt(a_i^2 + a_j^2) |phi| / |m_j|; the fit returns each a_i |phi| / |m*| to the
    relative size of the bumps' share of the norms (|b_j|^2 / |m*|^2 < 1e-5 here)."""
    spec = importlib.util.spec_from_file_location(
        "spot_scale_t5", Path(__file__).resolve().parents[1] / "benchmarks" / "spot_scale_t5.py")
    ss = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ss)
    s = np.linspace(0.0, 8.0, 81)
    z = np.linspace(0.0, 12.0, 121)  # the last 2 mm (t) are left out by map_l2's margin
    base = np.zeros((z.size, s.size))
    base[:, :20] = 1.0
    amps = [0.01, 0.03, 0.02, 0.0]
    levels = []
    for i, a in enumerate(amps):
        p = base.copy()
        p[5 + 10 * i:15 + 10 * i, 40:60] += a  # disjoint interior rows: orthogonal bumps
        levels.append({"thickness": 2.0, "map": {"s": s, "z": z, "pressure": p}})
    d, e, misfit = ss.own_map_errors(levels)
    W = np.outer(np.r_[0.05, np.full(99, 0.1), 0.05], np.r_[0.05, np.full(19, 0.1)])  # trapezoid, z <= 10
    ref = math.sqrt(float(np.sum(W * 1.0)))
    phi = math.sqrt(10 * 0.1 * 20 * 0.1)  # one bump of height a over 10 x 20 grid points
    expected = np.array(amps) * phi / ref
    # a zero error reads sqrt(e^2 |m_j|-share) ~ e * 1e-2 ~ 3e-5: the norms differ by the bumps
    assert e == pytest.approx(expected, rel=1e-4, abs=5e-5)
    assert misfit < 1e-6
    assert d[1, 2] == pytest.approx(math.hypot(expected[1], expected[2]), rel=1e-4)


def test_spot_scale_against_the_level_itself_fits_no_own_errors(tmp_path):
    """spot_scale_t5 with --reference equal to --level: the reference is the k = s = 1 variant
    itself, so a fit of per-mesh errors over them would read both as error-free and put the
    whole distance on the other mesh; the file has the distances only."""
    import json

    spec = importlib.util.spec_from_file_location(
        "spot_scale_t5", Path(__file__).resolve().parents[1] / "benchmarks" / "spot_scale_t5.py")
    ss = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ss)
    s = np.linspace(0.0, 8.0, 41)
    z = np.linspace(0.0, 12.0, 61)
    for k, bump in ((1.0, 0.0), (3.0, 0.05)):
        p = np.outer(np.ones(z.size), np.exp(-s))
        p[10:20, 5:10] += bump
        rec = {"thickness": 5.0, "mesh_size": 1.6, "refinement": 8.0, "dofs": 100, "cpu_s": 1.0,
               "wall_s": 1.0, "increments": 1, "newton_iterations": 2 if k == 1.0 else 1, "peak": 1.0 + bump,
               "span": 2.0, "map": {"s": s.tolist(), "z": z.tolist(), "pressure": p.tolist()}}
        path = ss.raw_path(tmp_path, 5.0, "silicone", "\u283f", 1.6, 8.0, k, 1.0)
        path.write_text(json.dumps(rec), encoding="utf-8")
    out = tmp_path / "out.md"
    assert ss.main(["--thickness", "5", "--materials", "silicone", "--text", "\u283f", "--level", "1.6/8",
                    "--reference", "1.6/8", "--variants", "1/1,3/1", "--raw", str(tmp_path), "--out", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    assert "| 3 / 1 | 100 |" in text and "+5.00%" in text
    assert "every mesh against every other" not in text and "own error" not in text


def test_the_t5_default_is_measured_with_its_coarse_contact_spot():
    """At t = 5 mm the `default` (1.6 / 8) meshes the dots' contact spots at 3x their fine size
    (mesh.sizing.spot_factor): its errors are those of the levels stored with "spot_factor" 3,
    not of the study's 1.6 / 8 at factor 1 (which no preset meshes now); `fine` (0.8 / 8) is
    still the study's reference. Without the factor-3 levels the default is not measured there."""
    cases = presets.load()["cases3d"]
    t5 = [k for k in cases if k.startswith("t5-") and "sphere" not in k]
    assert len(t5) == 4
    for key in t5:
        case = cases[key]
        lv = presets.preset_level(key, case, "default")
        assert lv["spot_factor"] == 3.0 and (lv["mesh_size"], lv["refinement"]) == (1.6, 8.0)
        assert abs(lv["peak_error"]) <= 0.02 and lv["map_l2"] <= 0.05
        assert presets.preset_level(key, case, "fine") is case["levels"][-1]
        k1 = [v for v in case["levels"] if (v["mesh_size"], v.get("spot_factor", 1.0)) == (1.6, 1.0)]
        assert len(k1) == 1 and lv["dofs"] < k1[0]["dofs"]
        bare = dict(case, levels=[v for v in case["levels"] if v is not lv])
        assert presets.preset_level(key, bare, "default") is None
        assert key in presets.preset_errors("default")["cases"]
    # below t = 5 every stored level was meshed at factor 1, recorded or not
    for key, case in cases.items():
        if not key.startswith("t5-"):
            assert all(v.get("spot_factor", 1.0) == 1.0 for v in case["levels"]), key


def test_rewriting_a_t5_case_keeps_its_stored_default_level(tmp_path, capsys):
    """convergence3d.write_presets rewrites a case from the study's levels (spot factor 1); the
    t = 5 `default`'s level (1.6 / 8 at spot factor 3, spot_scale_t5.py --store) is not one of
    them and was dropped: the t = 5 default then read as not measured."""
    import json

    key = "t5-silicone-\u2801"
    case = presets.load()["cases3d"][key]
    path = tmp_path / "presets.json"
    path.write_text(json.dumps({"cases3d": {key: case}}), encoding="utf-8")
    k1 = [v for v in case["levels"] if v.get("spot_factor", 1.0) == 1.0]
    # the study's raw levels: no "spot_factor" (solved before it was recorded: factor 1)
    levels = [{**v, "peak": 1.0} for v in k1]
    ref = {"value": case["reference_peak"], "method": case["reference_method"], "order": case["observed_order"]}
    cv.write_presets(path, key, {"levels": levels, "reference": ref})
    got = json.loads(path.read_text(encoding="utf-8"))["cases3d"][key]
    assert [(v["mesh_size"], v.get("spot_factor")) for v in got["levels"]] == \
        [(1.6, 3.0), (1.6, 1.0), (1.2, 1.0), (0.8, 1.0)]
    assert presets.preset_level(key, got, "default") == presets.preset_level(key, case, "default")
    assert capsys.readouterr().err == ""
    # a study with another reference keeps it too, and says its errors are against the former one
    cv.write_presets(path, key, {"levels": levels, "reference": dict(ref, value=1.01 * ref["value"])})
    got = json.loads(path.read_text(encoding="utf-8"))["cases3d"][key]
    assert [v.get("spot_factor") for v in got["levels"]] == [3.0, 1.0, 1.0, 1.0]
    assert "former references" in capsys.readouterr().err
    # a study without its 1.2 / 8 drops that level (the study's levels are its own)
    cv.write_presets(path, key, {"levels": [v for v in levels if v["mesh_size"] != 1.2], "reference": ref})
    got = json.loads(path.read_text(encoding="utf-8"))["cases3d"][key]
    assert [(v["mesh_size"], v.get("spot_factor")) for v in got["levels"]] == [(1.6, 3.0), (1.6, 1.0), (0.8, 1.0)]


def test_the_study_solves_its_levels_at_spot_factor_1(tmp_path, monkeypatch):
    """convergence3d --one solves a level of the study's h-family: at t = 5 mm its 1.6 / 8 was
    meshed with the 3x contact spot of the `default` (mesh.sizing.spot_factor) and its
    1.2 / 8 and 0.8 / 8 without, so a re-run study mixed two plans in one Richardson family."""
    import json
    import types

    from tactileskin import fe
    from tactileskin.mesh import sizing, slab3d

    monkeypatch.setattr(sizing, "SPOT_FACTOR", None)
    seen = []

    class Map:
        s, z, pressure = np.zeros(2), np.zeros(2), np.zeros((2, 2))

        def peak(self):
            return 0.0, 0.0, 0.0

    def fake_solve(scene, mesh=None, **kw):
        seen.append(sizing.spot_factor(scene.thickness, 0.72, scene.mesh_size / scene.refinement))
        return types.SimpleNamespace(stats={"dofs": 1}, bone_map=Map(), peak=1.0, span=1.0)

    monkeypatch.setattr(fe, "solve", fake_solve)
    monkeypatch.setattr(slab3d, "build_slab_mesh", lambda scene, local=True: None)
    assert cv.main(["--one", "1.6/8", "--thickness", "5", "--material", "silicone", "--text", "",
                    "--raw", str(tmp_path)]) == 0
    assert seen == [1.0]
    rec = json.loads(next(tmp_path.glob("*.json")).read_text(encoding="utf-8"))
    assert rec["spot_factor"] == 1.0
