"""Solve the 18 paper cases (t = 1, 3, 5 mm x silicone, polyurethane x flat, curved, braille).

Prints, per case: DOFs, increments, Newton iterations, mesh and solve wall time, peak bone
pressure and where it sits, reaction. Usage:

    .venv/bin/python benchmarks/solve.py [--formulation mixed|displacement] [--only t1-silicone]
"""

from __future__ import annotations

import argparse
import itertools
import logging
import time

import numpy as np
from rich.console import Console
from rich.table import Table

from tactileskin.errors import TactileSkinError
from tactileskin.fe import solve
from tactileskin.mesh import build_mesh
from tactileskin.scene import Scene


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--formulation", default="mixed")
    ap.add_argument("--only", default="", help="substring of the case label")
    ap.add_argument("--mesh-size", type=float, default=None)
    ap.add_argument("--hertz", action="store_true", help="plane-strain Hertz refinement study instead")
    ap.add_argument("--locking", action="store_true",
                    help="mesh refinement study, mixed vs displacement (design.md hard case 4)")
    ap.add_argument("-v", action="store_true")
    a = ap.parse_args()
    logging.basicConfig(level=logging.INFO if a.v else logging.WARNING)
    if a.hertz:
        return hertz()
    if a.locking:
        return locking(a.only or "t1-silicone-flat")
    table = Table(title=f"paper cases, {a.formulation} formulation")
    for c in ("case", "dofs", "incr", "newton", "mesh s", "solve s", "peak MPa", "s_peak mm",
              "span mm", "reaction N/mm"):
        table.add_column(c, justify="right")
    total = time.perf_counter()
    for t, mat, ind in itertools.product((1.0, 3.0, 5.0), ("silicone", "polyurethane"),
                                         ("flat", "curved", "braille")):
        kw = {} if a.mesh_size is None else {"mesh_size": a.mesh_size}
        sc = Scene(thickness=t, material=mat, indenter=ind, formulation=a.formulation, **kw)
        if a.only and a.only not in sc.label():
            continue
        t0 = time.perf_counter()
        sm = build_mesh(sc)
        tm = time.perf_counter() - t0
        try:
            r = solve(sc, sm)
        except TactileSkinError as e:
            table.add_row(sc.label(), "-", "-", "-", f"{tm:.2f}", "failed", str(e)[:40], "", "", "")
            continue
        st = r.stats
        i = int(np.argmax(r.pressure))
        logging.getLogger("benchmark").warning("%s done: peak %.4f MPa, %d Newton, %.1f s", sc.label(),
                                               r.peak, st["newton_iterations"], st["wall_s"])
        table.add_row(sc.label(), str(st["dofs"]), str(st["increments"]), str(st["newton_iterations"]),
                      f"{tm:.2f}", f"{st['wall_s']:.2f}", f"{r.peak:.4f}", f"{r.s[i]:.2f}",
                      f"{r.span:.2f}", f"{r.reaction:.4f}")
    Console().print(table)
    Console().print(f"total wall time {time.perf_counter() - total:.1f} s")


def locking(label: str) -> None:
    """Peak bone pressure of one case at mesh sizes h, h/2 for both formulations."""
    t, mat, ind = label.split("-")[:3]
    base = Scene(thickness=float(t[1:]), material=mat, indenter=ind)
    table = Table(title=f"refinement study {label}")
    for c in ("formulation", "mesh size", "dofs", "peak MPa", "s_peak mm", "P(s=0) MPa", "change %"):
        table.add_column(c, justify="right")
    for form in ("mixed", "displacement"):
        prev = None
        for h in (base.mesh_size, base.mesh_size / 2):
            sc = base.replace(formulation=form, mesh_size=h)
            try:
                r = solve(sc)
            except TactileSkinError as e:
                table.add_row(form, f"{h:g}", "-", "failed", str(e)[:30], "", "")
                continue
            i = int(np.argmax(r.pressure))
            ch = "" if prev is None else f"{100 * (r.peak / prev - 1):+.2f}"
            table.add_row(form, f"{h:g}", str(r.stats["dofs"]), f"{r.peak:.4f}", f"{r.s[i]:.2f}",
                          f"{r.pressure[0]:.4f}", ch)
            prev = r.peak
    Console().print(table)


def hertz() -> None:
    """Rigid cylinder R = 20 mm on a 10 mm polyurethane block: FE vs Hertz on refined meshes."""
    from tactileskin.fe.verification import hertz_block

    table = Table(title="plane-strain Hertz (a/R = 0.018)")
    for c in ("h mm", "dofs", "newton", "a err %", "p0 (fit) err %", "p max err %", "cpu s"):
        table.add_column(c, justify="right")
    for h in (0.08, 0.04, 0.02):
        t0 = time.process_time()
        r = hertz_block(h=h)
        table.add_row(f"{h:g}", str(r["res"].stats["dofs"]), str(r["res"].stats["newton_iterations"]),
                      f"{100 * (r['a_fe'] / r['a_h'] - 1):+.2f}", f"{100 * (r['p0_fe'] / r['p0_h'] - 1):+.2f}",
                      f"{100 * (r['pmax'] / r['p0_h'] - 1):+.2f}", f"{time.process_time() - t0:.1f}")
    Console().print(table)


if __name__ == "__main__":
    main()
