"""`film analyze`'s resolution and pixel-noise warnings against the truth of synthetic scans.

Presses a few pixels wide read low under the scanner's blur; the resolution warning
(scan._narrow) should flag those and few that read right. The pixel-noise warning (scan._row_noise)
should not be given on a noise-free scan. The set:

- lines: uniform across, 0.2-3 mm wide, a Gaussian sd 1 mm along (rows all, found automatically);
- presses: a 5 mm strip, a Gaussian sd 0.1-0.5 mm along (rows all);
- spots: Hertzian (radius a) and Gaussian (sd) round presses 0.2-3 mm, read --rows centre (the
  centre line), their centre off the pixel grid;

each at 4, 8, 11.8 (300 dpi) and 16 px/mm, blur 0-2 px (the grayscale, as film.synthetic), 0 or 3 GS
noise (8-bit), peaks 0.2, 0.5, 0.9 MPa/mm, paper's Eq. 8, white film at GS 245. The truth is the
press's own profile (the Gaussian along; a spot's centre line: peak p, area p pi a / 2 or p sqrt(2 pi) sd).
A reading is bad when its peak or area is more than 10 % low, good when both are within 10 %
(readings more than 10 % high, noise, are counted apart); flagged = the resolution warning.

    PYTHONPATH=src .venv/bin/python benchmarks/film_resolution.py [--csv out.csv] [--jobs 2]

Prints a markdown summary (benchmarks/results/film_resolution.md holds a run's).
"""

from __future__ import annotations

import argparse
import csv
import datetime as _dt
import logging
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from scipy import ndimage

PPMS = (4.0, 8.0, 300 / 25.4, 16.0)
BLURS = (0.0, 0.5, 1.0, 1.5, 2.0)
NOISES = (0.0, 3.0)
PEAKS = (0.2, 0.5, 0.9)
LINE_WIDTHS = (0.2, 0.3, 0.4, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0)
PRESS_SDS = (0.1, 0.15, 0.2, 0.3, 0.4, 0.5)
SPOTS = [("hertz", a) for a in (0.2, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0)] + \
        [("gauss", sd) for sd in (0.2, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0)]
LOW, GOOD = -0.10, 0.10


def cases():
    n = 0
    for ppm in PPMS:
        for blur in BLURS:
            for noise in NOISES:
                for peak in PEAKS:
                    for w in LINE_WIDTHS:
                        n += 1
                        yield dict(family="line", kind="gauss", size=w, ppm=ppm, blur=blur, noise=noise, peak=peak, seed=n)
                    for sd in PRESS_SDS:
                        n += 1
                        yield dict(family="press", kind="gauss", size=sd, ppm=ppm, blur=blur, noise=noise, peak=peak, seed=n)
                    for kind, size in SPOTS:
                        n += 1
                        yield dict(family="spot", kind=kind, size=size, ppm=ppm, blur=blur, noise=noise, peak=peak, seed=n)


def spot_scan(peak, size, kind, *, blur, noise, seed, ppm, dx=0.07, dy=0.05):
    """A round press on film, 20 x 12 mm, centred dx, dy mm off the middle (as tests/test_film_scan._spot)."""
    from tactileskin.film import paper_eq8

    cal = paper_eq8()
    x = (np.arange(round(20 * ppm)) + 0.5) / ppm - 10.0 - dx
    y = (np.arange(round(12 * ppm)) + 0.5) / ppm - 6.0 - dy
    r2 = x[None, :] ** 2 + y[:, None] ** 2
    p = peak * (np.exp(-0.5 * r2 / size ** 2) if kind == "gauss" else np.sqrt(np.clip(1 - r2 / size ** 2, 0, None)))
    gs = cal.grayscale(p)
    gs = np.where(np.abs(gs - cal.threshold_gs) < 0.5, 245.0, gs)
    if blur > 0:
        gs = ndimage.gaussian_filter(gs, blur, mode="nearest")
    if noise > 0:
        gs = gs + np.random.default_rng(seed).normal(0, noise, gs.shape)
    return np.clip(np.rint(gs), 0, 255).astype(np.uint8)


def scan_of(c):
    """(image, truth peak, truth area, rows) of a case."""
    from tactileskin.film import paper_eq8
    from tactileskin.film.synthetic import gaussian_profile, render_scan

    p, ppm = c["peak"], c["ppm"]
    kw = dict(px_per_mm=ppm, blur_px=c["blur"], noise_gs=c["noise"], background_gs=245.0, seed=c["seed"])
    if c["family"] == "line":
        img = render_scan(gaussian_profile(p, 1.0), paper_eq8(), width_mm=c["size"], **kw)
        return img, p, p * np.sqrt(2 * np.pi), "all"
    if c["family"] == "press":
        img = render_scan(gaussian_profile(p, c["size"]), paper_eq8(), width_mm=5.0, **kw)
        return img, p, p * c["size"] * np.sqrt(2 * np.pi), "all"
    img = spot_scan(p, c["size"], c["kind"], blur=c["blur"], noise=c["noise"], seed=c["seed"], ppm=ppm)
    area = p * np.pi * c["size"] / 2 if c["kind"] == "hertz" else p * c["size"] * np.sqrt(2 * np.pi)
    return img, p, area, "centre"


def run_case(c):
    from tactileskin.errors import ParameterError
    from tactileskin.film import analyze_scan

    img, tp, ta, rows = scan_of(c)
    out = dict(c)
    try:
        fp = analyze_scan(img, px_per_mm=c["ppm"], rows=rows)
    except ParameterError as e:
        out.update(refused=str(e).splitlines()[0][:80], peak_err=np.nan, auc_err=np.nan, resolution=0, noise_flag=0,
                   other=0, warnings="")
        return out
    ws = fp.warnings
    out.update(refused="", peak_err=fp.metrics["peak"] / tp - 1, auc_err=fp.metrics["auc"] / ta - 1,
               resolution=int(any("resolution is too coarse" in w for w in ws)),
               noise_flag=int(any("pixel noise" in w for w in ws)),
               other=int(any("resolution is too coarse" not in w and "pixel noise" not in w for w in ws)),
               warnings=" | ".join(w[:60] for w in ws))
    return out


def summarise(rows) -> dict:
    r = [x for x in rows if not x["refused"]]
    lo = [x for x in r if min(x["peak_err"], x["auc_err"]) < LOW]
    good = [x for x in r if max(abs(x["peak_err"]), abs(x["auc_err"])) <= GOOD]
    high = [x for x in r if x not in lo and x not in good]
    return {
        "readings": len(rows), "refused": len(rows) - len(r),
        "bad": len(lo), "bad_flagged": sum(x["resolution"] for x in lo),
        "bad_unflagged": [x for x in lo if not x["resolution"] and not x["other"] and not x["noise_flag"]],
        "bad_unflagged_res": sum(1 for x in lo if not x["resolution"]),
        "good": len(good), "good_flagged": sum(x["resolution"] for x in good),
        "good_unwarned_flagged": sum(1 for x in good if x["resolution"]),
        "high": len(high),
        "clean_noise": [x for x in r if x["noise"] == 0 and x["noise_flag"]],
    }


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--csv", help="write every reading here")
    ap.add_argument("--jobs", type=int, default=1)
    args = ap.parse_args(argv)
    logging.disable(logging.WARNING)
    cs = list(cases())
    if args.jobs > 1:
        with ProcessPoolExecutor(args.jobs) as ex:
            rows = list(ex.map(run_case, cs, chunksize=20))
    else:
        rows = [run_case(c) for c in cs]
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    print(f"# film analyze: resolution and pixel-noise warnings on synthetic scans (benchmarks/film_resolution.py)\n")
    print(f"{_dt.date.today()}: `benchmarks/film_resolution.py`; {len(rows)} readings (see the script's docstring "
          "for the set). bad: peak or area > 10 % below the truth; good: both within 10 %; flagged: the "
          "resolution warning.\n")
    print("| family | readings | refused | bad | bad flagged | bad unflagged | good | good flagged | > 10 % high | "
          "noise-free told 'pixel noise' |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    fams = ("line", "press", "spot")
    for fam in fams + ("all",):
        s = summarise([x for x in rows if fam == "all" or x["family"] == fam])
        print(f"| {fam} | {s['readings']} | {s['refused']} | {s['bad']} | {s['bad_flagged']} | "
              f"{s['bad_unflagged_res']} | {s['good']} | {s['good_flagged']} | {s['high']} | {len(s['clean_noise'])} |")
    s = summarise(rows)
    print("\nBad readings without the resolution warning (family kind size ppm blur noise peak: peak / area error):\n")
    for x in [x for x in rows if not x["refused"] and min(x["peak_err"], x["auc_err"]) < LOW and not x["resolution"]]:
        print(f"- {x['family']} {x['kind']} {x['size']:g} mm, {x['ppm']:.3g} px/mm, blur {x['blur']:g} px, "
              f"{x['noise']:g} GS, {x['peak']:g}: {100 * x['peak_err']:+.1f} / {100 * x['auc_err']:+.1f} %"
              + (f" ({x['warnings']})" if x["warnings"] else ""))
    print("\nNoise-free readings told 'pixel noise':\n")
    for x in s["clean_noise"]:
        print(f"- {x['family']} {x['kind']} {x['size']:g} mm, {x['ppm']:.3g} px/mm, blur {x['blur']:g} px, "
              f"{x['peak']:g}: {100 * x['peak_err']:+.1f} / {100 * x['auc_err']:+.1f} %")


if __name__ == "__main__":
    main()
