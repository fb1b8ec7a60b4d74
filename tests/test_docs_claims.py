"""Numbers and statements of README.md and docs/ that the code can check, so a doc does not
go stale when the stored measurements or flags change."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _text(name: str) -> str:
    # whitespace-normalised: the docs wrap lines anywhere
    return " ".join((ROOT / name).read_text(encoding="utf-8").split())


def _ridge_ranges():
    from tactileskin.planner import MEASURED_RIDGE_VS_DOTS

    peaks = [1 + m["peak"] for m in MEASURED_RIDGE_VS_DOTS.values()]
    spans = [100 * m["span"] for m in MEASURED_RIDGE_VS_DOTS.values()]
    return (round(min(peaks), 1), round(max(peaks), 1)), (round(min(spans)), round(max(spans)))


def test_hard_cases_ridge_section_states_the_planners_measurements():
    """docs/hard_cases.md said MEASURED_RIDGE_VS_DOTS 'stays empty' and the ridge 'Not measured'
    long after the table was filled (t = 1, 3, 5 mm)."""
    (lo, hi), (slo, shi) = _ridge_ranges()
    doc = _text("docs/hard_cases.md")
    assert "MEASURED_RIDGE_VS_DOTS` stays empty" not in doc
    assert f"peak reads {lo}-{hi}x the dots', spans {slo} to +{shi} %" in doc


def test_architecture_and_readme_ridge_ranges_match_the_planner():
    """docs/architecture.md still gave the first coarse estimates (1.9-2.8x, spans -6..+20 %)
    after the planner's table was re-measured (1.9-3.1x, -7..+2 %); the README quotes the peak
    range twice."""
    (lo, hi), (slo, shi) = _ridge_ranges()
    assert f"peak is {lo}-{hi}x the dots', spans within {slo}..+{shi} %" in _text("docs/architecture.md")
    readme = _text("README.md")
    assert f"reads {lo}-{hi} times their bone pressure" in readme and f"reads {lo}-{hi}x their peak" in readme
