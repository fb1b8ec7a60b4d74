"""`film analyze`'s pixel-noise warning (scan._row_noise) on its calibration sets, against the truth.

- rc_spots: Hertzian spots a = 0.5-3 mm, 0.05-0.9 MPa/mm, read --rows centre (one row keeps its pixel noise)
  at 8 px/mm and 300 dpi under 0, 1, 2 px blur; noisy (1.5 and 3 GS, 3 seeds) readings are binned by how
  far their peak reads above the same spot's noise-free reading (> 10 %, 5-10 %, < 5 %): the warning should
  flag those > 10 % high and not the noise-free ones.
- uniform strips: 5-10 mm wide, a Gaussian sd 1 mm along, 0.05-0.9 MPa/mm, 3 GS, 0-2 px blur, 5 seeds, at
  8 px/mm, found automatically and in a box exactly on them: no warning at all should be given.
- dots: the noise-free round spots of benchmarks/film_resolution.py (Hertzian and Gaussian, 0.2-3 mm at
  4-16 px/mm, --rows centre) and its lines (rows all): told 'pixel noise' though they have none.

    PYTHONPATH=src .venv/bin/python benchmarks/film_row_noise.py [--jobs 2]

Prints a markdown summary (benchmarks/results/film_row_noise.md holds a run's).
"""

from __future__ import annotations

import argparse
import datetime as _dt
import logging
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import film_resolution as fr  # noqa: E402  (its scans and cases)

RC_SIZES = (0.5, 0.75, 1.0, 1.5, 2.0, 3.0)
RC_PEAKS = (0.05, 0.1, 0.2, 0.5, 0.9)
RC_BLURS = (0.0, 1.0, 2.0)
RC_PPMS = (8.0, 300 / 25.4)
STRIPS = (5.0, 6.0, 8.0, 10.0)
STRIP_PEAKS = (0.05, 0.1, 0.2, 0.3, 0.5, 0.9)
BLURS = (0.0, 0.5, 1.0, 1.5, 2.0)


def _noise_said(fp) -> bool:
    return any("pixel noise" in w for w in fp.warnings)


def rc_spot(args):
    """[(kind, peak over the noise-free reading - 1, told 'pixel noise')]; a scan refused (too weak to
    activate a 3 x 3 block) is left out, ("refused", nan, False)."""
    from tactileskin.errors import ParameterError
    from tactileskin.film import analyze_scan

    a, peak, blur, ppm = args
    out = []
    try:
        clean = analyze_scan(fr.spot_scan(peak, a, "hertz", blur=blur, noise=0.0, seed=0, ppm=ppm), px_per_mm=ppm,
                             rows="centre")
    except ParameterError:
        return [("refused", float("nan"), False)] * 7
    out.append(("clean", 0.0, _noise_said(clean)))
    for noise in (1.5, 3.0):
        for seed in range(3):
            try:
                fp = analyze_scan(fr.spot_scan(peak, a, "hertz", blur=blur, noise=noise, seed=seed + 1, ppm=ppm),
                                  px_per_mm=ppm, rows="centre")
            except ParameterError:
                out.append(("refused", float("nan"), False))
                continue
            out.append(("noisy", fp.metrics["peak"] / clean.metrics["peak"] - 1, _noise_said(fp)))
    return out


def strip(args):
    from tactileskin.film import analyze_scan, paper_eq8
    from tactileskin.film.synthetic import gaussian_profile, render_scan

    width, peak, blur, seed = args
    img = render_scan(gaussian_profile(peak, 1.0), paper_eq8(), width_mm=width, noise_gs=3.0, blur_px=blur,
                      background_gs=245.0, seed=seed)
    out = []
    for box in (None, (0, 16, 160, 16 + round(8 * width))):
        ws = analyze_scan(img, box_px=box).warnings
        out.append((bool(ws), any("resolution is too coarse" in w for w in ws), any("pixel noise" in w for w in ws)))
    return out


def clean_case(c):
    from tactileskin.errors import ParameterError
    from tactileskin.film import analyze_scan

    img, _, _, rows = fr.scan_of(c)
    try:
        return _noise_said(analyze_scan(img, px_per_mm=c["ppm"], rows=rows))
    except ParameterError:
        return False


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--jobs", type=int, default=1)
    args = ap.parse_args(argv)
    logging.disable(logging.WARNING)
    rc = [(a, p, b, ppm) for a in RC_SIZES for p in RC_PEAKS for b in RC_BLURS for ppm in RC_PPMS]
    st = [(w, p, b, s) for w in STRIPS for p in STRIP_PEAKS for b in BLURS for s in range(5)]
    dots = [c for c in fr.cases() if c["noise"] == 0 and c["family"] in ("spot", "line")]
    with ProcessPoolExecutor(max(args.jobs, 1)) as ex:
        rc_out = [x for xs in ex.map(rc_spot, rc, chunksize=4) for x in xs]
        st_out = [n for ns in ex.map(strip, st, chunksize=10) for n in ns]
        dot_out = list(ex.map(clean_case, dots, chunksize=20))
    print("# film analyze: the pixel-noise warning on its calibration sets (benchmarks/film_row_noise.py)\n")
    print(f"{_dt.date.today()}: `benchmarks/film_row_noise.py` (see its docstring for the sets).\n")
    print("| rc_spots (--rows centre) | readings | told 'pixel noise' |")
    print("|---|---|---|")
    noisy = [(e, f) for k, e, f in rc_out if k == "noisy"]
    for name, sel in (("noisy, peak > 10 % above noise-free", lambda e: e > 0.10),
                      ("noisy, 5-10 % above", lambda e: 0.05 < e <= 0.10),
                      ("noisy, < 5 % above", lambda e: e <= 0.05)):
        got = [f for e, f in noisy if sel(e)]
        print(f"| {name} | {len(got)} | {sum(got)} |")
    clean = [f for k, _, f in rc_out if k == "clean"]
    print(f"| noise-free | {len(clean)} | {sum(clean)} |")
    print(f"\n({sum(1 for k, _, _ in rc_out if k == 'refused')} rc_spots scans refused: no activated 3 x 3 block.)")
    print(f"\nUniform strips (5-10 mm, found automatically and boxed): {len(st_out)} readings; the resolution "
          f"warning {sum(r for _, r, _ in st_out)}, 'pixel noise' {sum(n for _, _, n in st_out)} (any warning: "
          f"{sum(a for a, _, _ in st_out)}, the others those of a weak press's span under 3 GS).\n")
    spots = [f for c, f in zip(dots, dot_out) if c["family"] == "spot"]
    lines = [f for c, f in zip(dots, dot_out) if c["family"] == "line"]
    print(f"Noise-free scans of benchmarks/film_resolution.py told 'pixel noise': round spots (--rows centre) "
          f"{sum(spots)} of {len(spots)}, lines {sum(lines)} of {len(lines)}.")


if __name__ == "__main__":
    main()
