"""Report plumbing on synthetic sweep records: verdict logic, figures, files."""

import re
from pathlib import Path

import numpy as np
import pytest

from tactileskin.report.markdown import paper_checks
from tactileskin.scene import Scene
from tactileskin.sweep import CaseRecord


def _records(widths):
    """Gaussian-like profiles with a given width per (material, t, indenter)."""
    recs, rows = [], []
    s = np.linspace(0, 8, 161)
    for (mat, t, ind), (peak, w) in widths.items():
        p = peak * np.exp(-(s / w) ** 2)
        sc = Scene(thickness=t, material=mat, indenter=ind)
        recs.append(CaseRecord(sc, s, p, {}, Path(".")))
        span = w * np.sqrt(np.log(10))
        rows.append(dict(status="ok", material=mat, thickness_mm=t, indenter=ind, braille_text="",
                         peak_mpa=peak, span_mm=span, auc_mpa_mm=float(np.trapezoid(p, s))))
    return recs, rows


def test_verdicts_follow_the_numbers():
    data = {}
    for t, scale in ((1.0, 1.0), (3.0, 0.6), (5.0, 0.3)):
        for ind, (pk, w) in {"flat": (0.5, 4.0), "curved": (0.4, 2.0), "braille": (0.3, 0.8)}.items():
            if t == 5.0:  # at 5 mm all three alike
                pk, w = 0.2, 1.55
            data[("silicone", t, ind)] = (pk * scale / (1 if t < 5 else 0.3), w / (1 + t / 10))
    recs, rows = _records(data)
    checks = {c["claim"]: c["verdict"] for c in paper_checks(rows, recs)}
    assert checks["peak, 1 mm silicone, flat ≈ 0.5 MPa/mm (agrees within ±25%)"] == "agrees"
    assert checks["silicone 1 mm: peak order flat > curved > Braille holds"] == "agrees"
    assert checks["silicone 5 mm: peak order flat > curved > Braille breaks down"] == "agrees"
    assert checks["silicone 1 mm: indenters distinguishable"] == "agrees"
    assert checks["silicone 5 mm: indenters indistinguishable"] == "agrees"
    assert checks["silicone 5 mm: AUC alike for the three indenters"] == "agrees"
    assert checks["silicone, flat: span shrinks as the skin thickens"] == "agrees"


def test_peak_far_from_paper_is_reported_with_its_size():
    recs, rows = _records({("polyurethane", 1.0, "flat"): (1.6, 3.0)})
    (c,) = [c for c in paper_checks(rows, recs) if "peak" in c["claim"] and "polyurethane" in c["claim"]]
    assert c["verdict"] == "differs by +100%"


def test_figures_written(tmp_path):
    from tactileskin.report.figures import all_figures

    recs, rows = _records({("silicone", 1.0, "flat"): (0.5, 3.0), ("silicone", 3.0, "curved"): (0.3, 2.0)})
    paths = all_figures(recs, rows, tmp_path)
    assert {p.name for p in paths} >= {"fig10_profiles.png", "fig11_peak.svg", "fig12_span.png", "fig13_auc.png"}
    assert all(p.stat().st_size > 1000 for p in paths)


def test_render_is_coloured_by_pressure(tmp_path):
    # Off-screen pyvista render of a small deformed mesh carrying a pressure field.
    import meshio
    from PIL import Image

    from tactileskin.report.render import render_case

    x, y = np.meshgrid(np.linspace(0, 4, 9), np.linspace(0, 1, 3))
    pts = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    tris = []
    for j in range(2):
        for i in range(8):
            a = j * 9 + i
            tris += [[a, a + 1, a + 10], [a, a + 10, a + 9]]
    vtu = tmp_path / "r.vtu"
    meshio.write(vtu, meshio.Mesh(pts, [("triangle", np.array(tris))], point_data={"pressure": pts[:, 0]}))
    png = render_case(vtu, tmp_path / "r.png", title="test")
    img = np.asarray(Image.open(png).convert("RGB")).reshape(-1, 3)
    # jet colours both ends of the range: a saturated blue and a saturated red must appear
    assert np.any((img[:, 2] > 120) & (img[:, 0] < 60)) and np.any((img[:, 0] > 120) & (img[:, 2] < 60))


def test_a_grid_without_paper_claims_says_so_instead_of_a_table():
    """Flat only at 2 and 4 mm: no paper claim is about those skins (the paper's are 1, 3,
    5 mm and three indenters), so no table of n/a rows and no 'not run' 1 mm peak check."""
    from tactileskin.report.markdown import NO_CLAIM, NO_PAIRS, build_report

    recs, rows = _records({("polyurethane", 2.0, "flat"): (0.4, 3.0), ("polyurethane", 4.0, "flat"): (0.3, 2.0)})
    for r, rec in zip(rows, recs):
        r.update(case=f"t{r['thickness_mm']:g}", depth_mm=rec.scene.indentation, reaction_n_per_mm=0.1)
    assert paper_checks(rows, recs) == []
    md = build_report(rows, recs, [], [], [], 1.0, scenes=[r.scene for r in recs])
    assert NO_CLAIM in md and NO_PAIRS in md
    assert "| paper says |" not in md and "not run" not in md and "Known causes" not in md


def test_only_the_claims_of_the_run_cases_are_checked():
    recs, rows = _records({("silicone", 1.0, "flat"): (0.5, 3.0), ("silicone", 3.0, "flat"): (0.3, 2.0)})
    claims = [c["claim"] for c in paper_checks(rows, recs)]
    # the 1 mm silicone flat peak and the span trend over 1 -> 3 mm; nothing about
    # polyurethane, Braille, 5 mm or discrimination (one indenter)
    assert claims == ["peak, 1 mm silicone, flat ≈ 0.5 MPa/mm (agrees within ±25%)", "silicone, flat: span shrinks as the skin thickens"]


def test_a_distance_below_the_threshold_does_not_read_as_equal_and_one_profile_gets_no_verdict():
    from tactileskin.report.markdown import _discrimination_cells

    s = np.linspace(0.0, 5.0, 101)
    p = np.exp(-s**2)
    d, verdict = _discrimination_cells({"flat": (s, p), "curved": (s, 1.2 * p)})
    assert verdict == "not distinguishable" and re.search(r"0\.1\d\d\b", d)  # 1 - 1/1.2: 0.167, not "0.17"
    assert _discrimination_cells({"braille": (s, p)}) == ("n/a", "n/a (one indenter)")


def test_renders_of_cases_whose_names_clean_alike_do_not_overwrite_each_other(tmp_path):
    """Case ids that differ only in characters a file name cannot hold ('gel-ä', 'gel-ö') got
    one fig9 file, which report.md showed for both."""
    from tactileskin.cli import main

    for n in ("gel-ä", "gel-ö"):
        (tmp_path / f"{n}.toml").write_text(f'name = "{n}"\n[hyperfoam]\nmu = [0.05]\nalpha = [4.0]\nnu = 0.45\n')
    mats = ",".join(str(tmp_path / f"{n}.toml") for n in ("gel-ä", "gel-ö"))
    out = tmp_path / "o"
    assert main(["sweep", "-t", "1", "-m", mats, "-i", "flat", "--quality", "preview", "--serial",
                 "--out", str(out)]) == 0
    renders = sorted(p.name for p in out.glob("fig9_*.png"))
    assert len(renders) == 2
    report = (out / "report.md").read_text()
    assert all(r in report for r in renders)


def test_a_claim_whose_case_failed_or_is_suspect_is_listed_untested_not_dropped():
    # t = 1 mm silicone, the curved case failed: the peak-order and discrimination claims at
    # 1 mm (and the span trend of the curved plate) vanished from the table, while the module
    # promises that a claim the sweep cannot test says so
    from tactileskin import quality
    from tactileskin.report.markdown import build_report

    data = {}
    for t in (1.0, 3.0):
        for ind, (pk, w) in {"flat": (0.5, 4.0), "curved": (0.4, 2.0), "braille": (0.3, 0.8)}.items():
            data[("silicone", t, ind)] = (pk / t, w)
    recs, rows = _records(data)
    for r, rec in zip(rows, recs):
        r.update(case=rec.scene.label(), depth_mm=rec.scene.indentation, reaction_n_per_mm=0.1)
        rec.case = r["case"]
    i = next(k for k, r in enumerate(rows) if (r["thickness_mm"], r["indenter"]) == (1.0, "curved"))
    rows[i] = dict(rows[i], status=quality.failed_status("did not converge"))
    del recs[i]
    checks = {c["claim"]: c for c in paper_checks(rows, recs)}
    for claim in ("silicone 1 mm: peak order flat > curved > Braille holds",
                  "silicone 1 mm: indenters distinguishable",
                  "silicone, curved: span shrinks as the skin thickens"):
        assert checks[claim]["verdict"] == "untested", claim
        assert checks[claim]["ours"] == "t1-silicone-curved-2d: failed", claim
    assert checks["silicone 3 mm: peak order flat > curved > Braille holds"]["verdict"] == "agrees"
    assert checks["silicone, flat: span shrinks as the skin thickens"]["verdict"] in ("agrees", "differs")
    md = build_report(rows, recs, [], [], [], 1.0)
    assert "| silicone 1 mm: indenters distinguishable | t1-silicone-curved-2d: failed | untested |" in md


def test_no_pairs_because_suspect_is_not_reported_as_one_indenter_per_group():
    # flat and curved both suspect: the report said "One indenter per material and thickness"
    from tactileskin.report.markdown import NO_PAIRS, discrimination_table

    s = np.linspace(0, 8, 81)
    recs = [CaseRecord(Scene(thickness=1.0, material="silicone", indenter=ind), s, pk * np.exp(-s ** 2),
                       {"max_abs_stress_mpa": 300.0}, Path(".")) for ind, pk in (("flat", 0.3), ("curved", 0.2))]
    lines = discrimination_table(recs)
    assert lines != [NO_PAIRS] and "suspect" in lines[0]
    assert discrimination_table(recs[:1]) == [NO_PAIRS]


def test_one_indenter_at_two_depths_one_suspect_is_no_pair_left_out():
    # flat at 0.2 and 0.4 mm (variants d0.2, d0.4), the deeper suspect: they were never a pair
    # to tell apart, but the table said the suspect results had been left out of one
    from tactileskin.report.markdown import NO_PAIRS, discrimination_table
    from tactileskin.sweep import case_variants

    s = np.linspace(0, 8, 81)
    recs = [CaseRecord(Scene(thickness=1.0, material="silicone", indenter="flat", depth=d), s, 0.3 * np.exp(-s ** 2),
                       summ, Path(".")) for d, summ in ((0.2, {}), (0.4, {"max_abs_stress_mpa": 300.0}))]
    for r, v in zip(recs, case_variants([r.scene for r in recs])):
        r.variant = v
    assert discrimination_table(recs) == [NO_PAIRS]


@pytest.mark.parametrize("curved, verdict", [
    ((0.4, 2.0), "n/a: t1-silicone-braille-2d (failed) left out (the ok cases alone: distinguishable)"),
    ((0.48, 3.9), "not distinguishable (already among the ok cases; left out: t1-silicone-braille-2d (failed))")])
def test_a_discrimination_group_missing_a_failed_case_has_no_verdict_on_the_set(curved, verdict):
    # t = 1 mm silicone with the Braille case failed: the table read "distinguishable" from flat
    # against curved alone, a verdict on a set of three that judged two
    from tactileskin import quality
    from tactileskin.report.markdown import build_report, discrimination_table

    data = {("silicone", 1.0, ind): v for ind, v in
            {"flat": (0.5, 4.0), "curved": curved, "braille": (0.3, 0.8)}.items()}
    recs, rows = _records(data)
    for r, rec in zip(rows, recs):
        r.update(case=rec.scene.label(), variant="", depth_mm=rec.scene.indentation, reaction_n_per_mm=0.1)
        rec.case, rec.variant = r["case"], ""
    whole = discrimination_table(recs, rows)[2]
    assert whole.endswith("| not distinguishable |" if verdict.startswith("not") else "| distinguishable |")
    rows[2] = dict(rows[2], status=quality.failed_status("did not converge"))
    del recs[2]
    line = discrimination_table(recs, rows)[2]
    assert line.startswith("| silicone | 1 | – | curved–flat ") and line.endswith(f"| {verdict} |")
    assert f"| {verdict} |" in build_report(rows, recs, [], [], [], 1.0)


def test_paper_claims_are_not_checked_on_a_material_the_paper_did_not_test():
    # sweep -t 1,3 -m lock.toml,silicone: the report's "paper says" table had 'lock.toml 1 mm:
    # peak order flat > curved > Braille holds', 'lock.toml, flat: span shrinks as the skin
    # thickens' (differs) and 'lock.toml 1 mm: indenters distinguishable', claims the paper
    # makes about its Table I silicone and polyurethane only
    data = {}
    for mat in ("gel.toml", "silicone"):
        for t in (1.0, 3.0, 5.0):
            for ind, (pk, w) in {"flat": (0.5, 4.0), "curved": (0.4, 2.0), "braille": (0.3, 0.8)}.items():
                data[(mat, t, ind)] = (pk / t, w)
    recs, rows = _records(data)
    claims = [c["claim"] for c in paper_checks(rows, recs)]
    assert claims and not [c for c in claims if "gel" in c]
    assert any(c.startswith("silicone 5 mm: indenters") for c in claims)
    recs, rows = _records({k: v for k, v in data.items() if k[0] == "gel.toml"})
    assert paper_checks(rows, recs) == []


def test_the_suspect_section_names_the_kinds_of_suspect_result_a_sweep_reports():
    # sweep -t 1,3 --mesh-size 3: all six cases suspect for their coarse mesh, under a heading
    # that said suspect meant "no contact, or the material law outside its range"
    from tactileskin.report.markdown import build_report

    recs, rows = _records({("silicone", 1.0, "flat"): (0.5, 3.0)})
    rows[0].update(case="t1-silicone-flat-2d", depth_mm=0.2, reaction_n_per_mm=0.1,
                   status="suspect: mesh coarser than the preview preset's (refined size 1 mm against 0.2)")
    md = build_report(rows, recs, [], [], [], 1.0, scenes=[recs[0].scene])
    intro = md.split("## Failed and suspect cases")[1].split("\n- ")[0]
    for kind in ("no contact", "outside its range", "locking", "mesh coarser", "edge"):
        assert kind in intro, kind


def test_cases_table_gives_long_wall_times_in_seconds_not_in_exponent_form():
    """The default paper sweep's Cases table read the 3D dots' wall times as '1.2e+02',
    '1.5e+02' and '2e+02' (119.0, 153.2 and 200.5 s: the last one's three digits lost to '2e+02')."""
    from tactileskin.report.markdown import build_report

    recs, rows = _records({("polyurethane", 2.0, "flat"): (0.4, 3.0), ("polyurethane", 4.0, "flat"): (0.3, 2.0)})
    for r, rec, wall in zip(rows, recs, (153.2, 0.63)):
        r.update(case=f"t{r['thickness_mm']:g}", depth_mm=rec.scene.indentation, reaction_n_per_mm=0.1, wall_s=wall)
    md = build_report(rows, recs, [], [], [], 1.0, scenes=[r.scene for r in recs])
    walls = [ln.split("|")[12].strip() for ln in md.splitlines() if ln.startswith("| t")]
    assert walls == ["153", "0.63"]
    assert "e+0" not in md
