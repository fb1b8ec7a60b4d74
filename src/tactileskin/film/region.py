"""Finding the activated film strip on a scan when no region is given.

A scan shows white (unactivated) film, often on a white scanner lid, and the band the
indenter darkened. Averaging the white rows beside the band into the profile lowers every
reading (a 5 mm band in a 9 mm crop reads 5/9 of its pressure), so without a box we find
the band:

1. activated pixels: pressure above the calibration's lower clip (lighter pixels read as
   unactivated film); a 3 x 3 opening drops isolated noise pixels (none left: the scan is blank);
2. connected regions (4-neighbour), each weighted by its summed pressure; the heaviest is
   the strip. If another region weighs at least half as much, the choice is ambiguous and
   we refuse (the user gives --box-px / --box-mm);
3. across the strip: the contiguous rows whose mean pressure (over the region's length)
   is at least half the largest row mean (the half-maximum of a blurred edge sits on the
   edge itself), less the rows the scanner blurred into the white beside it: each edge's
   width from 10 % to 90 % of that maximum (to the outermost 90 % row: noise dips rows
   inside; 90 % at most the run's median: weak strips' rows scatter ~10 %) is measured,
   and rows closer than half that width inward of the 90 % row are dropped (for a Gaussian
   blur of sd b this keeps rows >= 2.6 b inside the edge, which read within 0.5 % of the
   band). A sharp edge loses nothing. Rows left that hold under a quarter of the half-maximum
   run (or under 3 rows) of a region about as long as wide (<= 1.4 x) mean no flat top across,
   a round press: the run is kept (its fall-off is flagged);
4. along the strip: the region's extent plus 1 mm on each side (clipped to the image), so
   the profile shows its return to zero; what lies beyond read as unactivated film.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

from tactileskin.errors import ParameterError

AMBIGUOUS = 0.5     # a second region this heavy relative to the first: refuse
HALF = 0.5          # across-strip band: rows at >= half the largest row mean
EDGE = (0.1, 0.9)   # an edge's width: from 10 % to 90 % of the largest row mean
PAD_MM = 1.0        # along-strip margin kept around the activated region
FLAT = 0.25         # the edges are dropped if the rows left hold this share of the half-maximum run,
ROUND_ASPECT = 1.4  # or if the activated region is longer than this x its width: not a round press
RULE = ("auto: heaviest connected activated region (pressure above the lower clip, 3x3 "
        "opening); across the strip the rows at >= 50 % of the largest row-mean pressure, "
        "less the blurred edge rows (half the 10-90 % edge width inward of the outermost 90 % row, "
        "90 % at most the run's median; none if that leaves < 1/4 of the run or < 3 rows and the region "
        "is <= 1.4 x as long as wide: a round press); "
        "along it the region's extent + 1 mm each side")


def pressed(pmap: np.ndarray, p_lo: float) -> np.ndarray:
    """The activated pixels (pressure above p_lo) that a 3 x 3 block of activated pixels holds
    (a 3 x 3 opening): a press darkens an area; isolated pixels and 1-2 px lines are scan noise,
    dust or scratches."""
    return ndimage.binary_opening(pmap > p_lo, structure=np.ones((3, 3), bool))


def find_strip(pmap: np.ndarray, p_lo: float, px_per_mm: float) -> tuple[int, int, int, int]:
    """Box (c0, r0, c1, r1), half-open, of the strip in a pressure map whose strip runs
    along axis 1 (columns). Raises ParameterError if nothing or several strips qualify."""
    active = pressed(pmap, p_lo)
    if not active.any():  # a blank scan (or noise and dust only): the caller reports it for the whole image
        return 0, 0, pmap.shape[1], pmap.shape[0]
    labels, n = ndimage.label(active)
    weight = np.asarray(ndimage.sum(pmap - p_lo, labels, index=np.arange(1, n + 1)), float)
    order = np.argsort(weight)[::-1]
    k = int(order[0])
    if n > 1 and weight[order[1]] >= AMBIGUOUS * weight[k]:
        boxes = ndimage.find_objects(labels)
        where = "; ".join(f"columns {b[1].start}-{b[1].stop}, rows {b[0].start}-{b[0].stop}"
                          for b in (boxes[int(i)] for i in order[:2]))
        raise ParameterError("region", "not given", "--box-px X0 Y0 X1 Y1 or --box-mm ...",
                             hint=f"{n} separate activated regions of similar weight "
                                  f"({where} px, along x across y of the strip); say which "
                                  "one to analyse")
    rows, cols = ndimage.find_objects(labels)[k]
    c0, c1 = cols.start, cols.stop
    row_mean = pmap[:, c0:c1].mean(axis=1)
    i = rows.start + int(np.argmax(row_mean[rows]))
    top = row_mean[i]

    def run(frac):  # contiguous rows around i at >= frac of the top
        a = b = i
        while a > 0 and row_mean[a - 1] >= frac * top:
            a -= 1
        while b < row_mean.size - 1 and row_mean[b + 1] >= frac * top:
            b += 1
        return a, b

    a, b = run(HALF)
    a10, b10 = run(EDGE[0])
    # the outermost 90 % rows of the half-maximum run, not a contiguous run from the largest: noise
    # dips rows inside a strip below 90 % of its largest, and the run's 'edges' read wide (3 GS of
    # noise on a sharp 40-row strip kept 3 of its rows); the same rows for a noise-free strip. At
    # most the run's median: where row noise is ~10 % of the top (a weak narrow ridge) few rows
    # reach 90 % of the noisiest one, and their spread read as wide edges (3 of 40 rows kept)
    level = min(EDGE[1] * top, float(np.median(row_mean[a:b + 1])))
    inner = np.flatnonzero(row_mean[a:b + 1] >= level) + a
    a90, b90 = int(inner[0]), int(inner[-1])
    # drop the blurred edge rows: inward of the 90 % row by half the 10-90 % edge width
    core = a90 + -(-(a90 - a10) // 2), b90 - -(-(b10 - b90) // 2)
    # a round press has no flat top across (a Hertzian spot's row means fall off as 1 - y^2/a^2) and no
    # blurred edge to drop: the 'edges' met in the middle and left 1-2 of its 10-66 half-maximum rows
    # (a = 0.5-4 mm), read as an unflagged centre line, or, where noise kept them all, as a strip along y
    # beside the other axis's 1-2 rows. A blurred strip keeps >= 0.43 of them noise-free, but a 2 mm one
    # (16 rows at 8 px/mm, 1.5-2 px blur) under 3 GS kept 1-3 of 12-14 (9 of 600 2-3 mm strips): it is
    # longer than wide (activated 1.7-2.5 x), a round spot is not (0.8-1.16 x: a = 0.5-4 mm, 0-7.65 GS)
    # and 1-2 rows are no flat top either: a dot of radius 0.5 mm (4 px at 8 px/mm) kept 2 of its 6
    flat = core[0] <= core[1] and core[1] - core[0] + 1 >= max(FLAT * (b - a + 1), 3)
    if core[0] <= core[1] and (flat or c1 - c0 > ROUND_ASPECT * (rows.stop - rows.start)):
        a, b = max(a, core[0]), min(b, core[1])
    pad = int(round(PAD_MM * px_per_mm))
    return max(c0 - pad, 0), a, min(c1 + pad, pmap.shape[1]), b + 1
