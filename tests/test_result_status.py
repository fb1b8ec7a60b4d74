"""Suspect results are flagged, never reported as 'ok': the status function's ranges, a
no-contact request refused, a lock-up solve flagged in summary.json / results.csv /
report.md with exit status 3, an inverted mesh refused."""

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from tactileskin import quality
from tactileskin.cli import main
from tactileskin.errors import MeshError, ParameterError
from tactileskin.results import Result
from tactileskin.scene import Scene

NORMAL = dict(peak_mpa=0.3, reaction_n_per_mm=0.5, contact_points=8, min_J=0.986, max_abs_stress_mpa=0.33)
# 1 mm silicone pressed 60 %: the Table I lock-up (coarse mesh: peak ~3e4 MPa, J 0.957)
LOCKUP = ["-t", "1", "--depth", "0.6", "--mesh-size", "1"]


# --- the status function --------------------------------------------------------------------

def test_normal_numbers_are_ok():
    assert quality.flags(NORMAL) == [] and quality.status(NORMAL) == "ok"


@pytest.mark.parametrize("change", [dict(contact_points=0), dict(peak_mpa=0.0), dict(reaction_n_per_mm=0.0)])
def test_no_contact_is_suspect(change):
    st = quality.status({**NORMAL, **change})
    assert st.startswith("suspect: no contact")
    assert [f.code for f in quality.flags({**NORMAL, **change})] == ["no_contact"]


def test_stress_threshold_on_both_sides():
    lim = quality.MAX_ABS_STRESS_MPA
    assert quality.status({**NORMAL, "max_abs_stress_mpa": 0.999 * lim}) == "ok"
    st = quality.status({**NORMAL, "max_abs_stress_mpa": 1.001 * lim})
    assert st.startswith("suspect: stress") and f"{lim:g} MPa" in st
    assert quality.flags({**NORMAL, "max_abs_stress_mpa": float("nan")})[0].code == "stress_range"


def test_volume_ratio_range_on_both_sides():
    lo, hi = quality.J_RANGE
    for J in (lo, 1.0, hi):
        assert quality.status({**NORMAL, "min_J": J}) == "ok"
    for J in (lo - 1e-3, hi + 1e-3):
        (f,) = quality.flags({**NORMAL, "min_J": J})
        assert f.code == "volume_range" and f"{J:.4g}" in f.reason


def test_several_reasons_are_all_given():
    st = quality.status({**NORMAL, "min_J": 0.8, "max_abs_stress_mpa": 1e5})
    assert st.startswith("suspect: ") and "stress" in st and "volume ratio" in st


def test_status_kinds():
    assert quality.kind("ok") == "ok"
    assert quality.kind("suspect: no contact") == "suspect"
    assert quality.kind(quality.failed_status("did not converge\ndetails")) == "failed"
    assert quality.failed_status("did not converge\ndetails") == "failed: did not converge"


def test_result_without_contact_is_not_ok():
    s = np.linspace(0.0, 5.0, 11)
    r = Result(s=s, pressure=np.zeros_like(s), contact_x=np.zeros(0), contact_pressure=np.zeros(0),
               reaction=0.0, stats={"min_J": 1.0, "max_abs_stress_mpa": 0.0})
    summ = r.summary()
    assert summ["status"].startswith("suspect: no contact") and r.status == summ["status"]
    assert summ["flags"][0]["code"] == "no_contact"


# --- no contact: refused before solving -------------------------------------------------------

@pytest.mark.parametrize("dim", [2, 3])
def test_braille_text_without_central_dot_is_refused(dim):
    from tactileskin.geometry.indenters import first_contact_travel, require_contact

    sc = Scene(thickness=1, indenter="braille", braille_text="ab", dim=dim)
    # 'ab' has its dots at |x| = 3.1 mm: only the base plate (dot height 0.48) reaches x = 0
    assert 0.4 < first_contact_travel(sc) <= 0.48 + 1e-9
    with pytest.raises(ParameterError, match="no contact") as e:
        require_contact(sc)
    assert e.value.name == "depth" and "x = 3.1 mm" in str(e.value)
    require_contact(sc.replace(depth=0.55))  # past the first touch: a normal request


def test_indenters_touching_at_the_centre_pass():
    from tactileskin.geometry.indenters import first_contact_travel, require_contact

    for kw in (dict(indenter="flat"), dict(indenter="curved"), dict(indenter="braille"),
               dict(indenter="braille", braille_text="l", dim=3)):
        sc = Scene(thickness=1, **kw)
        assert first_contact_travel(sc) < 1e-9
        require_contact(sc)


def test_cli_solve_refuses_no_contact_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "ab"
    rc = main(["solve", "-i", "braille", "--braille-text", "ab", "-t", "1", "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and "no contact" in err and "Traceback" not in err
    assert not out.exists()


# --- lock-up: flagged everywhere ---------------------------------------------------------------

def test_cli_solve_lockup_is_flagged_with_exit_3(tmp_path, capsys):
    out = tmp_path / "lock"
    rc = main(["solve", *LOCKUP, "--refinement", "2", "--out", str(out)])
    text = capsys.readouterr().out
    summ = json.loads((out / "summary.json").read_text())
    assert rc == 3
    assert summ["status"].startswith("suspect: stress") and summ["max_abs_stress_mpa"] > quality.MAX_ABS_STRESS_MPA
    assert summ["flags"][0]["code"] == "stress_range" and 0.9 < summ["min_J"] < 1.0
    assert "suspect" in text and "warning" in text


def test_cli_sweep_lockup_in_results_csv_and_report(tmp_path, capsys):
    out = tmp_path / "sw"
    # polyurethane pressed 60 % (coarse: ~100 MPa, J 0.88): both ranges left, a fast solve
    rc = main(["sweep", "--serial", "--no-render", "-m", "polyurethane", "-i", "flat", *LOCKUP, "--out", str(out)])
    text = capsys.readouterr().out
    assert rc == 3
    with open(out / "results.csv") as fh:
        (row,) = list(csv.DictReader(fh))
    assert row["status"].startswith("suspect: stress") and "volume ratio J" in row["status"]
    assert float(row["max_abs_stress_mpa"]) > quality.MAX_ABS_STRESS_MPA and float(row["min_J"]) < quality.J_RANGE[0]
    report = (out / "report.md").read_text()
    assert "## Failed and suspect cases" in report
    assert report.index("suspect: stress") < report.index("## Cases")
    assert "suspect" in text


def _help(cmd):
    from click.testing import CliRunner

    from tactileskin.cli import cli

    return CliRunner().invoke(cli, [cmd, "--help"]).output


def test_help_states_exit_codes():
    for cmd in ("solve", "sweep"):
        h = _help(cmd)
        assert "Exit status" in h and "3" in h and "suspect" in h


# --- report ordering (synthetic rows) ---------------------------------------------------------

def test_report_lists_failed_and_suspect_first_and_keeps_suspect_out_of_checks():
    from tactileskin.report.markdown import build_report, paper_checks
    from tactileskin.sweep import CaseRecord

    s = np.linspace(0, 8, 81)
    recs, rows = [], []
    for ind, peak, extra in (("flat", 9e4, {"max_abs_stress_mpa": 9e4}), ("curved", 0.2, {}), ("braille", 0.1, {})):
        sc = Scene(thickness=1.0, material="silicone", indenter=ind)
        summ = {**NORMAL, "peak_mpa": peak, **extra}
        recs.append(CaseRecord(sc, s, peak * np.exp(-s ** 2), summ, Path(".")))
        rows.append(dict(case=sc.label(), status=quality.status(summ), material="silicone", thickness_mm=1.0,
                         indenter=ind, braille_text="", depth_mm=0.2, peak_mpa=peak, span_mm=1.0, auc_mpa_mm=0.1,
                         reaction_n_per_mm=0.1))
    rows.append(dict(case="t3-x", status=quality.failed_status("did not converge"), material="silicone",
                     thickness_mm=3.0, indenter="flat", braille_text=""))
    checks = {c["claim"]: c for c in paper_checks(rows, recs)}
    flat = checks["peak, 1 mm silicone, flat ≈ 0.5 MPa/mm (agrees within ±25%)"]
    assert flat["verdict"] == "untested" and flat["ours"] == "suspect result"
    # 2 trusted profiles only: no verdict, but the claim is listed as untested, naming the suspect case
    dist = checks["silicone 1 mm: indenters distinguishable"]
    assert dist["verdict"] == "untested" and dist["ours"] == "t1-silicone-flat-2d: suspect"
    md = build_report(rows, recs, [], [], [], 1.0)
    top = md[: md.index("## Cases")]
    assert "t3-x: failed: did not converge" in top and "t1-silicone-flat-2d: suspect: stress" in top
    table = md[md.index("## Cases"):]
    assert table.index("t3-x") < table.index("t1-silicone-flat") < table.index("t1-silicone-curved")
    assert "Left out as suspect: t1-silicone-flat-2d." in md


# --- inverted mesh: refused --------------------------------------------------------------------

def test_inverted_mesh_is_refused():
    from tactileskin.mesh import build_mesh

    with pytest.raises(MeshError, match="min scaled Jacobian -0.2") as e:
        build_mesh(Scene(thickness=1, mesh_size=5, refinement=1))
    assert "--mesh-size" in str(e.value)


def test_cli_solve_inverted_mesh_exit_2(tmp_path, capsys):
    rc = main(["solve", "-t", "1", "--mesh-size", "5", "--refinement", "1", "--out", str(tmp_path / "m")])
    err = capsys.readouterr().err
    assert rc == 2 and "inverted" in err and not (tmp_path / "m").exists()


def test_jacobian_ratio_sees_a_fold_between_quadrature_points():
    """One P2 triangle whose hypotenuse mid-node is pulled towards the right-angle vertex:
    det J turns negative at the other two vertices while it is still positive at every
    degree-4 quadrature point (what the check looked at before)."""
    import dataclasses

    from skfem import MeshTri1, MeshTri2
    from skfem.quadrature import get_quadrature

    from tactileskin.mesh.skinmesh import MIN_SCALED_JACOBIAN, check_quality, jacobian_ratio

    m = MeshTri2.from_mesh(MeshTri1(np.array([[0.0, 1, 0], [0, 0, 1]]), np.array([[0], [1], [2]])))
    assert jacobian_ratio(m) == pytest.approx(1.0)
    dl = m.doflocs.copy()
    k = int(np.argmin(np.linalg.norm(dl.T - [0.5, 0.5], axis=1)))
    dl[:, k] = (1 - 0.53) * np.array([0.5, 0.5])
    bent = dataclasses.replace(m, doflocs=dl)
    Xq, _ = get_quadrature(bent.elem.refdom, 4)
    assert bent._mapping().detDF(Xq).min() > 0
    q = jacobian_ratio(bent)
    assert q == pytest.approx(-0.06, abs=1e-9)
    with pytest.raises(MeshError, match="inverted"):
        check_quality({"min_scaled_jacobian": q}, {"coarse": 2.0})
    with pytest.raises(MeshError, match="nearly folded"):
        check_quality({"min_scaled_jacobian": 0.5 * MIN_SCALED_JACOBIAN}, {})
    check_quality({"min_scaled_jacobian": MIN_SCALED_JACOBIAN}, {})


def test_result_without_contact_writes_its_files(tmp_path):
    """A result without contact points (positions of shape (0, dim)) writes an empty contact.csv
    (it ended in a reshape traceback that also aborted a sweep)."""
    s = np.linspace(0.0, 5.0, 11)
    for dim in (2, 3):
        r = Result(s=s, pressure=np.zeros_like(s), contact_x=np.zeros(0), contact_pressure=np.zeros(0),
                   contact_points=np.zeros((0, dim)), reaction=0.0,
                   stats={"min_J": 1.0, "max_abs_stress_mpa": 0.0})
        text = r._contact_csv()
        assert text.splitlines() == [",".join(["x_mm", "y_mm", "z_mm"][:dim] + ["contact_pressure_mpa"])]


def test_cli_solve_touching_nothing_is_suspect_with_exit_3(tmp_path, capsys):
    out = tmp_path / "graze"
    rc = main(["solve", "-i", "curved", "-t", "1", "--depth", "0.0001", "--quality", "preview", "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 3 and "Traceback" not in err
    summ = json.loads((out / "summary.json").read_text())
    assert summ["status"].startswith("suspect: no contact")
    assert (out / "contact.csv").read_text().startswith("x_mm,y_mm,contact_pressure_mpa")


# --- the law's compressibility, the element, the mesh, the skin's edge ------------------------

def test_volume_range_is_judged_for_solid_elastomers_only():
    squashed = {**NORMAL, "min_J": 0.8}
    assert [f.code for f in quality.flags(squashed)] == ["volume_range"]          # law unknown
    assert [f.code for f in quality.flags({**squashed, "material_nu0": 0.49})] == ["volume_range"]
    # a foam's law (nu0 = 0: J = lambda in uniaxial compression) changes volume as its response
    assert quality.flags({**squashed, "material_nu0": 0.0}) == []


def test_linear_displacement_elements_of_an_elastomer_are_flagged_as_locking():
    solve = pytest.importorskip("tactileskin.fe").solve
    p2 = solve(Scene(thickness=1, indenter="flat", mesh_size=1, refinement=5))
    p1 = solve(Scene(thickness=1, indenter="flat", mesh_size=1, refinement=5, order=1, formulation="displacement"))
    assert p1.peak > 2.5 * p2.peak                      # measured 2.9x: the locking flagged
    assert p2.status == "ok"
    assert [f["code"] for f in p1.summary()["flags"]] == ["locking"]
    assert p1.summary()["material_nu0"] == pytest.approx(0.49, abs=0.02)
    assert quality.flags({**NORMAL, "element_order": 1, "material_nu0": 0.3}) == []


@pytest.mark.parametrize("sizes, coarse", [((1.0, 5.0), False), ((0.6, 2.0), False),   # refined 0.3: 1.5x
                                           ((1.0, 2.0), True), ((3.0, 1.0), True), ((2.5, 12.5), True)])
def test_meshes_coarser_than_preview_are_flagged(sizes, coarse):
    from tactileskin.fe import solve

    r = solve(Scene(thickness=1, indenter="flat", mesh_size=sizes[0], refinement=sizes[1]))
    codes = [f["code"] for f in r.summary()["flags"]]
    assert codes == (["coarse_mesh"] if coarse else [])
    assert r.summary()["mesh_sizes_mm"]["preview_refined"] == pytest.approx(0.2)


def test_a_contact_zone_narrower_than_the_mesh_is_flagged():
    # a 1e-3 mm press: the presets' refined sizes are absolute, so one contact point carried the
    # whole contact and the peak read 8-13 % low with status "ok" (quality.MIN_CONTACT_POINTS)
    from tactileskin.fe import solve

    assert [f.code for f in quality.flags({**NORMAL, "contact_points": 1})] == ["coarse_mesh"]
    assert quality.flags({**NORMAL, "contact_points": 2}) == []
    tiny = Scene(thickness=1, indenter="flat", depth=1e-3, viscoelastic=False)
    coarse = solve(tiny.replace(mesh_size=1.0, refinement=5.0))      # preview
    fine = solve(tiny.replace(mesh_size=0.177, refinement=3.0))      # fine: 3 points
    assert coarse.summary()["contact_points"] == 1 and fine.summary()["contact_points"] >= 2
    assert fine.peak > 1.08 * coarse.peak                             # measured +12.3 %
    assert [f["code"] for f in coarse.summary()["flags"]] == ["coarse_mesh"]
    assert "contact point" in coarse.status and fine.status == "ok"


def test_a_3d_contact_zone_of_fewer_points_than_a_facet_is_flagged():
    # a 3D P2 contact facet has 3 points: an R 2.5 sphere 1e-3 mm into a 1 mm pad touched at 2 and
    # read the reaction 58 % (preview) and 9 % (default) below the bonded-layer Hertz law, status ok
    from tactileskin.fe import solve
    from tactileskin.materials.indentation import bonded_sphere_force

    normal3 = {k: v for k, v in NORMAL.items() if k != "reaction_n_per_mm"} | {"reaction_n": 0.5}
    assert [f.code for f in quality.flags({**normal3, "contact_points": 2})] == ["coarse_mesh"]
    assert quality.flags({**normal3, "contact_points": 3}) == []
    ball = Scene(skin="pad", dim=3, thickness=1.0, indenter="sphere", indenter_radius=2.5, depth=1e-3,
                 viscoelastic=False, mesh_size=1.6, refinement=8.0)                # preview
    r = solve(ball)
    assert r.reaction < 0.6 * bonded_sphere_force(0.27, 1e-3, 2.5, 1.0)              # measured 0.42
    assert r.summary()["contact_points"] == 2 and [f["code"] for f in r.summary()["flags"]] == ["coarse_mesh"]


def test_peak_at_the_bonded_edge_is_flagged_with_the_interior_peak():
    from tactileskin.results import edge_peak

    s = np.linspace(0.0, 10.0, 101)
    p = 0.17 - 0.001 * s
    p[-1] = 0.3                                     # the corner's singular value
    assert edge_peak(s, p, 2.0) == (0.3, 10.0, 0.17, 0.0)
    assert edge_peak(s, p, 0.0) is None
    assert edge_peak(s, np.where(s < 9.99, p, 0.1), 2.0) is None             # max inside
    # a two-sided profile's left end is an edge too; one starting at 0 is a symmetry line
    s2 = np.linspace(-10.0, 10.0, 201)
    p2 = 0.17 - 0.001 * np.abs(s2)
    p2[0] = 0.25
    assert edge_peak(s2, p2, 2.0)[:2] == (0.25, -10.0)
    r = Result(s=s, pressure=p, contact_x=np.array([0.0, 0.1]), contact_pressure=np.array([0.2, 0.1]), reaction=1.0,
               stats={"min_J": 0.99, "max_abs_stress_mpa": 0.3}, scene={"thickness": 2.0, "skin": "pad"})
    summ = r.summary()
    assert [f["code"] for f in summ["flags"]] == ["edge_peak"]
    assert summ["peak_interior_mpa"] == pytest.approx(0.17) and summ["peak_edge_s_mm"] == 10.0
    # the fingertip's bone runs on into the bonded nail: its profile's end is no free edge
    r.scene = {"thickness": 2.0}
    assert r.summary()["flags"] == []


def test_a_z_half_model_of_a_z_asymmetric_indenter_is_flagged():
    assert [f.code for f in quality.flags({**NORMAL, "mirrored_z": True})] == ["mirrored_z"]


def test_a_map_plane_chosen_away_from_a_load_at_the_skins_end_is_flagged():
    """A file indenter near the end of the slab: the profile plane came from the map's interior
    (>= t from the ends), 1.5-3 mm from the load, and read it 3-13x low with status ok."""
    summ = {**NORMAL, "profile_plane_from_map": True, "profile_plane_z": 7.97, "peak_map_edge_mpa": 0.06,
            "peak_map_edge_s_mm": 0.0, "peak_map_edge_z_mm": 10.0}
    assert [f.code for f in quality.flags(summ)] == ["edge_peak"]
    # a built-in indenter's plane is known (through its dots): the map's edge band is only shown
    assert quality.flags({k: v for k, v in summ.items() if k != "profile_plane_from_map"}) == []


def test_the_domes_tip_end_of_the_map_is_no_edge():
    """On the dome the bone runs on past z = 0 into the tip: a load there was called a corner
    singularity and the map's peak taken 2 mm away (5.7x low)."""
    from tactileskin.results import BoneMap, skin_says

    s, z = np.linspace(0.0, 6.0, 13), np.linspace(-10.0, 0.0, 21)
    P = np.exp(-(s[None, :] ** 2 + z[:, None] ** 2))
    m = BoneMap(s, z, P, 0.0)
    assert m.interior_peak(2.0, z_end_free=True)[2] == pytest.approx(-2.0)
    assert m.interior_peak(2.0, z_end_free=False)[2] == 0.0
    # the fingertip's bone runs on into the nail at its s end: no edge band there either
    Ps = np.exp(-((s[None, :] - 6.0) ** 2 + (z[:, None] + 5.0) ** 2))
    edge = BoneMap(s, z, Ps, 0.0)
    assert edge.interior_peak(2.0)[1] == pytest.approx(4.0)
    assert edge.interior_peak(2.0, s_end_free=False)[1] == 6.0
    assert not skin_says({"skin": "dome"}, "map_z_end_free") and skin_says({"skin": "pad"}, "map_z_end_free")
    assert not skin_says({}, "profile_ends_free") and skin_says({"skin": "nonesuch"}, "profile_ends_free")


def test_a_file_indenter_on_a_skin_file_without_a_map_is_flagged():
    # the fingertip written as a 3D .msh: s = x - x_top folds where the bone curves back, so
    # there is no (s, z) map (the solve ended in a ParameterError after solving); without it a
    # file indenter's profile plane cannot follow the load
    assert [f.code for f in quality.flags({**NORMAL, "bone_map_missing": True, "profile_plane_unknown": True})] \
        == ["no_bone_map"]
    assert quality.flags({**NORMAL, "bone_map_missing": True}) == []  # a built-in indenter's plane is known


def test_the_figures_of_a_suspect_solve_say_so(tmp_path, monkeypatch):
    """sensors.png (and a 3D bone_map.png) of a suspect result were titled as any other."""
    import tactileskin.report.sensors as rs
    from tactileskin.cli import main

    titles = []
    monkeypatch.setattr(rs, "write_sensors_figure", lambda data, png, title="": titles.append(title))
    (tmp_path / "s.toml").write_text('[[sensors]]\nkind = "points"\ns = [0.0, 1.0]\ndepth = 0.5\n')
    out = tmp_path / "o"
    # no contact: the depth is far below the contact tolerance
    assert main(["solve", "-t", "3", "-i", "curved", "--quality", "preview", "--depth", "1e-6",
                 "--sensors", str(tmp_path / "s.toml"), "--out", str(out)]) == 3
    assert len(titles) == 1 and "SUSPECT: no contact" in titles[0], titles


@pytest.mark.parametrize("figure", ["bone_map", "sensors"])
def test_a_suspect_figure_title_fits_its_figure(tmp_path, monkeypatch, figure):
    """The SUSPECT line of a figure's title was one line of up to 100 characters, centred: on
    the 8-inch bone map of a 3D pad's edge peak it ran past both sides, its "SUSPECT" cut off."""
    import types

    import matplotlib.pyplot as plt

    from tactileskin.cli.solve import _figure_title
    from tactileskin.results import BoneMap
    from tactileskin.sensors import SensorReadings

    why = ("the peak 0.02813 MPa is at s = 2 mm, within one skin thickness of where the bonded skin "
           "ends: a corner singularity that grows with mesh refinement, and the interior peak is 0.02262 MPa at s = 0 mm")
    bm = BoneMap(s=np.linspace(0, 2, 5), z=np.linspace(0, 2, 5), pressure=np.ones((5, 5)))
    res = types.SimpleNamespace(bone_map=bm, sensors=None, summary=lambda: {"status": "suspect: " + why})
    title = _figure_title(res, "bone pressure, pad4x4-t2-polyurethane-flat-3d")
    seen = []  # (suptitle text, its extent, figure width) as drawn, before the figure is closed
    close = plt.close

    def measure(fig=None):
        seen.append((fig._suptitle.get_text(), fig._suptitle.get_window_extent(fig.canvas.get_renderer()),
                     fig.bbox.width))
        close(fig)

    monkeypatch.setattr(plt, "close", measure)
    if figure == "bone_map":
        from tactileskin.report.bone_map import write_bone_map_figure
        write_bone_map_figure(bm, tmp_path / "m.png", title=title)
    else:
        from tactileskin.report.sensors import write_sensors_figure
        n = 3
        rd = SensorReadings(ids=[f"a-{i}" for i in range(n)], layout=["a"] * n,
                            xyz=np.c_[np.arange(n), np.zeros(n), np.zeros(n)], s=np.arange(n, dtype=float),
                            depth=np.full(n, 0.5), normal=np.tile([0.0, 1.0, 0.0], (n, 1)),
                            pressure=np.ones(n), sigma_nn=-np.ones(n),
                            tau_1=np.zeros(n), tau_2=np.zeros(n), taxel_points=np.ones(n, int))
        write_sensors_figure(rd, tmp_path / "s.png", title=title)
    text, box, width = seen[-1]
    assert "SUSPECT" in text
    assert box.x0 >= 0 and box.x1 <= width, (box, width)   # every line of it is on the figure
    assert "refinement" in title                  # the reason is kept, not cut at 100 characters


# --- the law's range scales with the material's own modulus -----------------------------------

def test_lockup_of_a_soft_material_is_flagged_relative_to_its_modulus(tmp_path):
    # Table I silicone with every mu 1000x smaller (mu0 = 90 Pa): the same 60 % press reaches
    # the same lock-up state (max |stress| 4.3e5 mu0, J 0.956), each stress 1000x smaller:
    # 38.5 MPa read "ok" against the absolute 50 MPa, while the silicone itself (38,460 MPa)
    # was suspect
    from tactileskin.fe import solve

    mat = tmp_path / "soft.toml"
    mat.write_text("[hyperfoam]\nmu = [0.00008, 0.00001]\nalpha = [0.001, 15.5]\nnu = 0.49\n")
    r = solve(Scene(thickness=1, indenter="flat", depth=0.6, material=str(mat), viscoelastic=False,
                    mesh_size=1, refinement=5))
    summ = r.summary()
    assert summ["max_abs_stress_mpa"] < quality.MAX_ABS_STRESS_MPA          # 38.5 MPa
    assert summ["material_mu0_mpa"] == pytest.approx(9e-5)
    assert "stress_range" in [f["code"] for f in summ["flags"]]
    assert summ["status"].startswith("suspect: stress")
    # the ratio threshold keeps Table I's results as they were (50 MPa is 556 mu0 of silicone)
    lim = quality.MAX_STRESS_OVER_MU0
    assert quality.status({**NORMAL, "material_mu0_mpa": 0.09, "max_abs_stress_mpa": 45.0}) == "ok"
    assert quality.status({**NORMAL, "material_mu0_mpa": 1e-3, "max_abs_stress_mpa": 0.999 * lim * 1e-3}) == "ok"
    (f,) = quality.flags({**NORMAL, "material_mu0_mpa": 1e-3, "max_abs_stress_mpa": 1.001 * lim * 1e-3})
    assert f.code == "stress_range" and "mu0" in f.reason


def test_braille_dots_pressed_less_than_their_patch_resolves_are_flagged():
    # the t = 0.5 mm full cell on the fingertip: its dots, off the crown, touch after 0.069 of the
    # 0.1 mm travel; at preview (dot patch 0.2 mm) the peak read 0.00691 MPa against the Richardson
    # limit 0.00848 (-18 %), status ok
    from tactileskin.fe import solve

    cell = solve(Scene(thickness=0.5, indenter="braille", braille_text="\u283f", dim=3, mesh_size=1.6, refinement=8))
    summ = cell.summary()
    assert summ["mesh_sizes_mm"]["dot_indentation"] == pytest.approx(0.031, abs=0.002)
    assert cell.peak < 0.85 * 0.00848
    assert [f["code"] for f in summ["flags"]] == ["coarse_mesh"] and "Braille dots" in cell.status
    # a centred dot touches at once: not judged (pressed 0.05 mm at t = 1, preview read -2.9 % from fine)
    dot = solve(Scene(thickness=1, indenter="braille", dim=3, depth=0.05, mesh_size=1.6, refinement=8))
    assert "dot_indentation" not in dot.summary()["mesh_sizes_mm"] and dot.status == "ok"
    # nor a cell on the flat pad, whose dots all touch at the start (sampled first touch 5e-8 mm)
    pad = solve(Scene(skin="pad", pad_width=10, pad_length=10, thickness=1, indenter="braille", braille_text="\u283f",
                      dim=3, depth=0.05, mesh_size=1.6, refinement=8))
    assert "dot_indentation" not in pad.summary()["mesh_sizes_mm"]
    sizes = {"global": 1.6, "refined": 0.2, "preview_global": 1.6, "preview_refined": 0.2, "thickness": 1.0}
    normal3 = {k: v for k, v in NORMAL.items() if k != "reaction_n_per_mm"} | {"reaction_n": 0.5}
    assert quality.flags({**normal3, "mesh_sizes_mm": {**sizes, "dot_indentation": 0.131}}) == []  # t = 1 cell
    assert [f.code for f in quality.flags({**normal3, "mesh_sizes_mm": {**sizes, "dot_indentation": 0.08}})] \
        == ["coarse_mesh"]


def test_late_dots_are_judged_against_the_dot_patch_size_meshed():
    # mesh.sizing.spot_factor meshes a t >= 5 dot's spot at 3x the refined size at `default`
    # (1.6 / 8: 0.6 mm, not 0.2): the flag and its message must use the 0.6 mm
    sizes = {"global": 1.6, "refined": 0.2, "preview_global": 1.6, "preview_refined": 0.2, "thickness": 5.0}
    normal3 = {k: v for k, v in NORMAL.items() if k != "reaction_n_per_mm"} | {"reaction_n": 0.5}
    (f,) = quality.flags({**normal3, "mesh_sizes_mm": {**sizes, "dot_indentation": 0.18, "dot_patch": 0.6}})
    assert f.code == "coarse_mesh" and "0.6 mm elements" in f.reason
    assert quality.flags({**normal3, "mesh_sizes_mm": {**sizes, "dot_indentation": 0.28, "dot_patch": 0.6}}) == []
    # results written before dot_patch was recorded keep the refined size
    assert quality.flags({**normal3, "mesh_sizes_mm": {**sizes, "dot_indentation": 0.18}}) == []


def test_a_t5_cell_records_the_dot_patch_size_it_meshed():
    # t = 5 full cell on the fingertip at default (1.6 / 8): its dots touch after 0.069 mm; pressed
    # 0.25 mm they go 0.18 mm past it, less than 0.45 of the 0.6 mm patch
    from tactileskin.fe import solve

    r = solve(Scene(thickness=5, indenter="braille", braille_text="\u283f", dim=3, depth=0.25, mesh_size=1.6,
                    refinement=8))
    sizes = r.summary()["mesh_sizes_mm"]
    assert sizes["dot_patch"] == pytest.approx(0.6) and sizes["dot_indentation"] == pytest.approx(0.18, abs=0.01)
    assert "coarse_mesh" in [f["code"] for f in r.summary()["flags"]] and "0.6 mm elements" in r.status


def test_a_3d_lockup_the_mesh_does_not_resolve_is_flagged():
    # an R 2.5 sphere 0.6 mm into 1 mm silicone locks the law up (max |stress| ~50 mu0): on the
    # fingertip the peak read 4.09 / 3.79 / 3.57 MPa at preview / default / fine, on this pad 4.32 /
    # 3.83 (preview / default), status ok; 3D meshes resolve 0.4 mm (4.5 mu0: preview and default within 1 %)
    from tactileskin.fe import solve

    ball = Scene(skin="pad", pad_width=10, pad_length=10, dim=3, thickness=1.0, indenter="sphere",
                 indenter_radius=2.5, depth=0.6, viscoelastic=False, mesh_size=1.6, refinement=8.0)  # preview
    summ = solve(ball).summary()
    assert summ["max_abs_stress_mpa"] > 30 * 0.09
    assert [f["code"] for f in summ["flags"]] == ["stress_range"] and "in 3D" in summ["status"]
    normal3 = {k: v for k, v in NORMAL.items() if k != "reaction_n_per_mm"} | {"reaction_n": 0.5}
    assert quality.flags({**normal3, "max_abs_stress_mpa": 0.41, "material_mu0_mpa": 0.09}) == []  # 0.4 mm
    # 2D meshes resolve it: 3 mm silicone at 40 % (57 mu0) moved 0.47 % from h = 1 to 0.5
    assert quality.flags({**NORMAL, "max_abs_stress_mpa": 5.11, "material_mu0_mpa": 0.09}) == []


# --- elements through the skin -----------------------------------------------------------------

def test_a_skin_thinner_than_the_presets_elements_is_flagged():
    # a 0.1 mm pad at `preview` (refined 0.2 mm, twice the skin): peak 0.711 and reaction 0.151
    # N/mm against 0.811 / 0.203 mesh-converged (-12 %, -26 %), status "ok" before
    from tactileskin.fe import solve

    r = solve(Scene(skin="pad", pad_width=1, thickness=0.1, indenter="cylinder", indenter_radius=2,
                    viscoelastic=False, mesh_size=1.0, refinement=5))
    summ = r.summary()
    assert [f["code"] for f in summ["flags"]] == ["coarse_mesh"]
    assert "thickness" in summ["flags"][0]["reason"]
    assert summ["mesh_sizes_mm"]["thickness"] == pytest.approx(0.1)
    # at half the skin's thickness (and below) it is not
    assert quality.flags({**NORMAL, "mesh_sizes_mm": {"global": 0.25, "refined": 0.05, "preview_global": 1.0,
                                                      "preview_refined": 0.2, "thickness": 0.1}}) == []
    assert quality.flags({**NORMAL, "mesh_sizes_mm": {"global": 1.0, "refined": 0.2, "preview_global": 1.0,
                                                      "preview_refined": 0.2, "thickness": 0.4}}) == []


def test_a_press_too_shallow_for_the_mesh_says_so_not_that_the_indenter_never_pressed():
    # the scene is made only if the dot reaches the skin within the depth; at 1e-3 mm its
    # contact is narrower than the preview mesh's contact points. The flag said "the indenter
    # never pressed the skin within the indentation depth", which the scene's own check denies
    from tactileskin.fe import solve
    from tactileskin.planner import with_quality

    r = solve(with_quality(Scene(thickness=1.0, indenter="braille", depth=1e-3), "preview"))
    (flag,) = [f for f in quality.flags(r.summary()) if f.code == "no_contact"]
    assert "never pressed" not in flag.reason and "shallower than the mesh resolves" in flag.reason


def test_a_bone_pulled_in_tension_under_the_load_is_flagged_not_its_noise_peak(tmp_path):
    # an auxetic hyperfoam (nu = -0.99, a value Hyperfoam accepts): under the 20 % press of the
    # flat plate (contact pressure 0.023 MPa, reaction 0.028 N/mm) the bone's mean pressure is
    # tensile, -0.0021 MPa at s = 0, and the profile's largest value is 4e-10 MPa far from the
    # load: peak, span (2.5 mm) and area (negative) described nothing, status "ok"
    from tactileskin.fe import solve

    assert quality.status({**NORMAL, "profile_min_mpa": -0.29}) == "ok"     # compressive under the load
    (f,) = quality.flags({**NORMAL, "profile_min_mpa": -0.31})
    assert f.code == "tensile_bone" and "-0.31" in f.reason
    mat = tmp_path / "auxetic.toml"
    mat.write_text("[hyperfoam]\nmu = [0.09]\nalpha = [2.0]\nnu = -0.99\n")
    r = solve(Scene(thickness=1, material=str(mat), mesh_size=1, refinement=5))
    summ = r.summary()
    assert summ["reaction_n_per_mm"] > 0.01 and summ["contact_points"] > 5
    assert summ["profile_min_mpa"] < -1e3 * summ["peak_mpa"]
    assert [f["code"] for f in summ["flags"]] == ["tensile_bone"]
    assert summ["status"].startswith("suspect: ")
