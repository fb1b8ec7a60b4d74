"""Pressure-film round trip on synthetic data (runs in a couple of seconds).

1. Eight calibration presses (1-30 N on a 100 mm^2 cylinder, paper Sec. IV-B) are
   "scanned" as small PNGs through a known film response, with 1 gray level of noise.
2. The calibration is fitted from that CSV (Eq. 7, AICc model choice, 90 % bounds).
3. A simulated half profile (s >= 0) is written as a solver result directory would be.
4. A film scan is rendered from it (mirrored, 8 px/mm, blur, noise, white background)
   through the known film response, and analysed with the fitted calibration.
5. Film and simulation are compared (percent differences, overlay plot).

Prints the recovered peak against the true (scanner-blurred) peak and checks that they
agree within the calibration's 90 % band plus five column-noise sd; exits 1 otherwise.

EXPECT peak_error_over_tolerance 0 1

    python examples/film_roundtrip.py [OUT_DIR]
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

from tactileskin.film import analyze_scan, calibrate_csv, compare
from tactileskin.film.calibration import Calibration
from tactileskin.film.synthetic import blurred_gaussian_profile, gaussian_profile, mirrored, render_scan

PPM, NOISE, BLUR = 8.0, 2.0, 1.0
# the "true" film: linear, 0.01 MPa at GS 223, 0.30 MPa at GS 30
TRUE = Calibration(name="true film", model="linear", params=(-0.0015, 0.345),
                   gs_range=(0.0, 255.0), p_range=(0.0, 0.345))
P0, W = 0.2, 1.2  # simulated profile: P0 exp(-s^2 / 2 W^2), MPa, mm


def main(out: Path) -> int:
    rng = np.random.default_rng(0)
    out.mkdir(parents=True, exist_ok=True)

    # 1-2. calibration presses and fit
    forces = np.linspace(1, 30, 8)
    rows = ["force_n,area_mm2,image"]
    for i, f in enumerate(forces):
        g = TRUE.grayscale(f / 100.0) + rng.normal(0, 1.0)
        px = np.clip(np.rint(g + rng.normal(0, NOISE, (16, 16))), 0, 255).astype(np.uint8)
        Image.fromarray(px).save(out / f"press_{i}.png")
        rows.append(f"{f:g},100,press_{i}.png")
    (out / "calibration.csv").write_text("\n".join(rows) + "\n")
    cal = calibrate_csv(out / "calibration.csv")
    cal.save(out / "calibration.json")

    # 3. a simulated half profile, as `Result.write` lays it out
    sim = out / "sim"
    sim.mkdir(exist_ok=True)
    s = np.linspace(0, 6, 121)
    np.savetxt(sim / "profile.csv", np.column_stack([s, gaussian_profile(P0, W)(s)]),
               delimiter=",", header="s_mm,pressure_mpa", comments="", fmt="%.10g")
    (sim / "summary.json").write_text(json.dumps({"note": "analytic stand-in"}))

    # 4. scan and analysis
    img = render_scan(mirrored(s, gaussian_profile(P0, W)(s)), TRUE, px_per_mm=PPM,
                      length_mm=16, blur_px=BLUR, noise_gs=NOISE, background_gs=245, seed=1)
    Image.fromarray(img).save(out / "scan.png")
    fp = analyze_scan(out / "scan.png", cal, px_per_mm=PPM, box_mm=(0, 3, 16, 6))
    fp.write(out / "film")

    # 5. comparison
    comp = compare(out / "film", sim)
    comp.write(out / "film")

    true_peak = float(blurred_gaussian_profile(P0, W, BLUR / PPM)(0.0))
    got = fp.metrics["peak"]
    lo, hi = cal.band(cal.grayscale(got))
    width_px = fp.pressure_map.shape[0]
    tol = (hi - lo) / 2 + 5 * abs(TRUE.params[0]) * np.sqrt((NOISE ** 2 + 1 / 12) / width_px)
    print(f"calibration: {cal.model}, a = {cal.params[0]:.5g}, b = {cal.params[1]:.5g}")
    print(f"percent differences (sim vs film): " +
          ", ".join(f"{k} {v:+.1f} %" for k, v in comp.percent_diff.items()))
    print(f"recovered peak {got:.4f} MPa vs true (blurred) {true_peak:.4f} MPa: "
          f"error {got - true_peak:+.4f}, tolerance {tol:.4f}")
    print(f"RESULT peak_error_over_tolerance={abs(got - true_peak) / tol:.4f}")
    return 0 if abs(got - true_peak) <= tol else 1


if __name__ == "__main__":
    if len(sys.argv) > 1:
        sys.exit(main(Path(sys.argv[1])))
    with tempfile.TemporaryDirectory() as d:
        sys.exit(main(Path(d)))
