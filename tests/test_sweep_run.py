"""End-to-end sweep on a coarse mesh: Dask execution, cache reuse, outputs, failure handling."""

import csv

import pytest

from tactileskin.cli import main
from tactileskin.errors import ConvergenceError
from tactileskin.scene import Scene
from tactileskin.sweep import ResultCache, expand_grid, run_sweep

COARSE = dict(mesh_size=0.6, refinement=2.0)


@pytest.mark.slow
def test_cli_sweep_dask_then_cached_rerun(tmp_path, capsys):
    out = tmp_path / "out"
    args = ["sweep", "--out", str(out), "--thickness", "1", "--material", "polyurethane",
            "--indenter", "flat,curved", "--mesh-size", str(COARSE["mesh_size"]), "--workers", "2",
            "--no-render"]
    assert main(args) == 0
    with open(out / "results.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["status"] for r in rows] == ["ok", "ok"]
    peaks = {r["indenter"]: float(r["peak_mpa"]) for r in rows}
    assert all(p > 0 for p in peaks.values())
    assert (out / "report.md").read_text().count("| t1-polyurethane-") == 2
    assert (out / "fig10_profiles.png").is_file()
    capsys.readouterr()
    # rerun: everything comes from the cache, nothing is solved again
    assert main(args + ["--serial"]) == 0
    text = capsys.readouterr().out
    assert text.count("cached") == 2 and " done " not in text


def test_failed_case_is_reported_and_others_go_on(tmp_path, monkeypatch):
    # Inject a convergence failure for one scene (the solver's own failure paths are tested
    # in the solver's tests); the sweep must record it, keep going and cache only successes.
    import tactileskin.sweep as sw

    real = sw.solve_case
    bad = Scene(thickness=1.0, material="polyurethane", indenter="curved", **COARSE)

    def flaky(scene):
        if scene == bad:
            raise ConvergenceError("did not converge", {"time": 0.1, "residuals": [1.0, 0.5]})
        return real(scene)

    monkeypatch.setattr(sw, "solve_case", flaky)
    scenes = expand_grid(thicknesses=[1.0], materials=["polyurethane"], indenters=["flat", "curved"],
                         base=Scene(**COARSE))
    cache = ResultCache(tmp_path / "cache")
    outcomes = run_sweep(scenes, cache, serial=True)
    assert [o.status for o in outcomes] == ["done", "failed"]
    assert outcomes[1].diagnosis["residuals"] == [1.0, 0.5]
    assert cache.has(scenes[0]) and not cache.has(scenes[1])


def test_sweep_outputs_include_the_fig9_render_of_the_flat_case(tmp_path, caplog):
    # the render step runs only with render=True (the CLI default); a failure there is only
    # logged, so assert both the file and the absence of the warning
    from tactileskin.report.outputs import write_outputs

    scenes = expand_grid(thicknesses=[1.0], materials=["polyurethane"], indenters=["flat"],
                         base=Scene(**COARSE))
    cache = ResultCache(tmp_path / "cache")
    outcomes = run_sweep(scenes, cache, serial=True)
    with caplog.at_level("WARNING"):
        paths = write_outputs(tmp_path / "out", outcomes, cache, 1.0, render=True)
    assert [p.name for p in paths["renders"]] == ["fig9_t1-polyurethane-flat-2d.png"]
    assert paths["renders"][0].stat().st_size > 1000
    assert not [r for r in caplog.records if "render" in r.getMessage()]


def test_report_says_which_cases_this_run_solved_and_which_it_read_from_the_cache(tmp_path):
    """A rerun after a scene change solved only the new cases and read the rest from the cache,
    but report.md read as a fresh run: no word of which numbers were solved now, with each
    cached case's 'wall (s)' that of a solve in an earlier run ('wall time 6.2 s' over six
    cases of which four were cached). The header counts them and the Cases table marks each.
    That mark does not enter the figures' key: a cached rerun still copies its figures."""
    import re

    from tactileskin.report import figures
    from tactileskin.report.outputs import collect, write_outputs

    cache = ResultCache(tmp_path / "cache")
    one = expand_grid(thicknesses=[1.0], materials=["polyurethane"], indenters=["flat"], base=Scene(**COARSE))
    first = run_sweep(one, cache, serial=True)
    write_outputs(tmp_path / "a", first, cache, 1.0, render=False)
    assert "1 solved in this run, 0 read from the cache" in (tmp_path / "a" / "report.md").read_text()
    two = expand_grid(thicknesses=[1.0], materials=["polyurethane"], indenters=["flat", "curved"],
                      base=Scene(**COARSE))
    outcomes = run_sweep(two, cache, serial=True)
    assert [o.status for o in outcomes] == ["cached", "done"]
    write_outputs(tmp_path / "b", outcomes, cache, 1.0, render=False)
    md = (tmp_path / "b" / "report.md").read_text()
    assert "1 solved in this run, 1 read from the cache" in md
    rows = {m.group(1): m.group(2) for m in re.finditer(r"^\| (t1-polyurethane-\w+-2d) \|.*\| (\w+) \|$", md, re.M)}
    assert rows == {"t1-polyurethane-flat-2d": "cached", "t1-polyurethane-curved-2d": "solved"}
    # the first run's case, read from the cache now: the same figures' key as when it was solved
    recs_a, rows_a, _ = collect(first, cache)
    recs_b, rows_b, _ = collect(run_sweep(one, cache, serial=True), cache)
    assert rows_b[0]["source"] == "cached" and rows_a[0]["source"] == "solved"
    assert figures.figures_key(recs_a, rows_a) == figures.figures_key(recs_b, rows_b)
