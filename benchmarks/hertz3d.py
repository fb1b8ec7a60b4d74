"""3D Hertz verification: a rigid sphere on a thick block (fe.verification.hertz_sphere).

Refinement series of the P2-tetrahedral quarter model (element size h at the contact, a/h
from ~3 to ~10, ratio sqrt(2) between levels), each level solved in this process one after
the other. Prints per level the FE/Hertz errors of the contact radius and peak pressure
(fitted semi-ellipse on the contact points; Hertz from the FE load), of the load at the
given travel (P = 4/3 E* R^1/2 d^3/2), two independent measures (the second-moment radius
and -sigma_yy at the axis from the projected stress) and the CPU time (process time: the
machine is shared), then the observed order of convergence and the Richardson limit of
each error from the finest three levels (the part the mesh cannot remove: finite block,
finite strain, sphere vs paraboloid).

    MKL_NUM_THREADS=1 PYTHONPATH=src .venv/bin/python benchmarks/hertz3d.py [--levels 4] \
        [--out benchmarks/results/hertz3d.md]
"""

from __future__ import annotations

import argparse
import datetime
import logging
import subprocess
import time

import numpy as np

from tactileskin.fe.verification import hertz_sphere
from tactileskin.fileio import atomic_write_text

H0 = 0.15  # mm: a/h = 3.3 at a = 0.5 mm (the level tests/test_verification3d.py solves)

QUANTITIES = [  # (column, key of the FE value, key of the Hertz value)
    ("a / a_H - 1", "a_fe", "a_h"),
    ("p0 / p0_H - 1", "p0_fe", "p0_h"),
    ("P / P_H(d) - 1", "P", "P_h"),
    ("a_moment / a_H - 1", "a_moment", "a_h"),
    ("-syy(axis) / p0_H - 1", "p_axis_stress", "p0_h"),
    ("max point p / p0_H - 1", "pmax", "p0_h"),
]


def order_and_limit(e: np.ndarray, ratio: float) -> tuple[float, float]:
    """Observed order and Richardson limit of the last three values of a sequence on meshes
    refined by `ratio`; (nan, nan) when the changes do not shrink monotonically."""
    d1, d2 = e[-2] - e[-3], e[-1] - e[-2]
    if d1 == 0 or d2 / d1 <= 0 or abs(d2) >= abs(d1):
        return float("nan"), float("nan")
    p = np.log(d1 / d2) / np.log(ratio)
    return float(p), float(e[-1] + d2 / (ratio ** p - 1))


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--levels", type=int, default=4, help="number of meshes (h = 0.15 / sqrt(2)^k mm)")
    ap.add_argument("--out", default=None, help="markdown file for the table")
    a = ap.parse_args(argv)
    logging.basicConfig(level=logging.WARNING)
    ratio = np.sqrt(2.0)
    rows = []
    for k in range(a.levels):
        h = H0 / ratio ** k
        c0, w0 = time.process_time(), time.perf_counter()
        r = hertz_sphere(h=h)
        r["cpu"], r["wall"] = time.process_time() - c0, time.perf_counter() - w0
        r["err"] = {col: r[fe] / r[hz] - 1 for col, fe, hz in QUANTITIES}
        rows.append(r)
        print(f"h = {h:.4f} mm (a/h = {r['a_h'] / h:.1f}): {r['dofs']} dofs, {r['newton']} Newton, "
              + ", ".join(f"{c} {v:+.2%}" for c, v in r["err"].items())
              + f", cpu {r['cpu']:.1f} s, wall {r['wall']:.1f} s", flush=True)
    r0 = rows[0]
    head = ["h (mm)", "a_H / h", "dofs", "Newton"] + [c for c, _, _ in QUANTITIES] + ["CPU s", "wall s"]
    lines = ["| " + " | ".join(head) + " |", "|---" * len(head) + "|"]
    for r in rows:
        lines.append(f"| {r['h']:.4f} | {r['a_h'] / r['h']:.1f} | {r['dofs']} | {r['newton']} | "
                     + " | ".join(f"{v:+.2%}" for v in r["err"].values())
                     + f" | {r['cpu']:.1f} | {r['wall']:.1f} |")
    if len(rows) >= 3:
        orders, limits = [], []
        for col, _, _ in QUANTITIES:
            p, lim = order_and_limit(np.array([r["err"][col] for r in rows]), ratio)
            orders.append("-" if np.isnan(p) else f"{p:.2f}")
            limits.append("-" if np.isnan(lim) else f"{lim:+.2%}")
        lines.append("| observed order (finest 3) | | | | " + " | ".join(orders) + " | | |")
        lines.append("| Richardson limit (finest 3) | | | | " + " | ".join(limits) + " | | |")
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    stamp = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    title = (f"# 3D Hertz: rigid sphere on a thick block (benchmarks/hertz3d.py, {stamp}, commit {commit})\n\n"
             f"R = {r0['R']:g} mm, travel d = {r0['d']:g} mm, quarter block {r0['size']:g} mm, polyurethane "
             f"hyperfoam (E* = {r0['Estar']:.4f} MPa), P2 tetrahedra graded from h at the contact point, "
             f"one load increment. a_H = {r0['a_h']:.4f} mm (a/R = {r0['a_h'] / r0['R']:.3f}). "
             "Hertz radius and peak from the FE load P; P_H(d) from the travel. CPU = process time "
             "(all threads; shared 2-core machine), wall for reference.\n")
    table = "\n".join(lines)
    print(table)
    if a.out:
        atomic_write_text(a.out, title + "\n" + table + "\n")


if __name__ == "__main__":
    main()
