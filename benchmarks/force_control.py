"""Force control against displacement control on the same mesh: each case is solved to its
depth, then asked for that depth's reaction as a force (fe.loading.ForceIncrement). Prints
increments, Newton iterations and trial solves of both, the force reached against the
target, and how far the force-controlled travel and peak sit from the depth-controlled
ones (the load histories differ: a force ramp is linear in force, a depth ramp in travel,
so a viscoelastic skin relaxes differently on the way; the elastic rows compare like with
like; both ramps take the same time). Counts are what compare; seconds are of one run on a shared machine.

    PYTHONPATH=src .venv/bin/python benchmarks/force_control.py [--set 2d|3d|all] [--out FILE]
"""

from __future__ import annotations

import argparse
import time

CASES = {
    "2d": {f"t{t:g}-{m}-{i}-2d{'-elastic' if not ve else ''}": dict(thickness=t, material=m, indenter=i,
                                                                   viscoelastic=ve)
           for t in (1.0, 3.0, 5.0) for m in ("silicone", "polyurethane") for i in ("flat", "curved")
           for ve in (True, False) if ve or (t == 3.0 and i == "curved")},
    "3d": {f"t2-{m}-sphere2.5-3d": dict(thickness=2.0, material=m, dim=3, indenter="sphere", indenter_radius=2.5,
                                        depth=0.3)
           for m in ("silicone", "polyurethane")},
}


def one(name: str, kw: dict) -> dict:
    from tactileskin.fe import solve
    from tactileskin.mesh import build_mesh
    from tactileskin.scene import Scene, preset_mesh

    ms, rf = preset_mesh("preview", kw.get("dim", 2), kw["indenter"], kw["thickness"])
    base = Scene(mesh_size=ms, refinement=rf, **kw)
    mesh = build_mesh(base)
    t0 = time.perf_counter()
    rd = solve(base, mesh=mesh)
    t1 = time.perf_counter()
    rf_ = solve(base.replace(force=rd.reaction, depth=None, load_time=base.duration), mesh=mesh)
    t2 = time.perf_counter()
    lo = rf_.loading
    return {"case": name, "dofs": rd.stats["dofs"],
            "depth": f"{rd.stats['increments']} / {rd.stats['newton_iterations']}",
            "force": f"{rf_.stats['increments']} / {rf_.stats['newton_iterations']} / {rf_.stats['force_trials']}",
            "force_err": (lo["reached_force"] - rd.reaction) / rd.reaction,
            "travel_diff": (lo["profile_travel_mm"] - base.indentation) / base.indentation,
            "peak_diff": (rf_.peak - rd.peak) / rd.peak, "s_depth": t1 - t0, "s_force": t2 - t1}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--set", choices=("2d", "3d", "all"), default="all")
    ap.add_argument("--out")
    a = ap.parse_args(argv)
    names = ("2d", "3d") if a.set == "all" else (a.set,)
    lines = ["| case | dofs | depth control: incr. / Newton | force control: incr. / Newton / trials "
             "| reached - target | travel (force - depth) | peak (force - depth) | wall s depth / force |",
             "|---|---|---|---|---|---|---|---|"]
    print("\n".join(lines), flush=True)
    for set_ in names:
        for name, kw in CASES[set_].items():
            r = one(name, kw)
            row = (f"| {r['case']} | {r['dofs']:,} | {r['depth']} | {r['force']} | {100 * r['force_err']:+.4f} % "
                   f"| {100 * r['travel_diff']:+.3f} % | {100 * r['peak_diff']:+.3f} % "
                   f"| {r['s_depth']:.1f} / {r['s_force']:.1f} |")
            print(row, flush=True)
            lines.append(row)
    if a.out:
        with open(a.out, "w") as f:
            f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
