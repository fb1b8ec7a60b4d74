"""The 2D solve per Newton iterate, before/after (issue 13 T10): the paper sweep's 18 2D cases
(t = 1, 3, 5 mm x silicone, polyurethane x flat, curved, braille) at --quality (preview).

Each run is a fresh process per source tree (--src, e.g. a `git worktree` of the old
revision), the trees alternating per round (old, new; new, old; ...), --repeat rounds. A run
builds the 18 meshes first (not timed), warms numba's cache with one solve, then solves the
18 cases; it reports the CPU seconds of the solves (process time, all threads), their wall
seconds, the summed phases (model residual / tangent / contact, factor, solve), the counts of
one run (law calls with S only, with S + D, D from kept data, states reused, tangents) and a
digest of every result (pressure profile, displacements, contact pressure, peak, reaction,
Newton count) so that the trees' results can be compared bit for bit.

--units: in one process, the CPU ms of one Newton iterate's model work on the t = 5 silicone
Braille case (the sweep's largest 2D preview solve) at its solved state: residual + tangent with
the law evaluated afresh for the tangent (Model.reuse_state False: S, then S + D) against D from
the stress evaluation's kept data, interleaved, medians of --repeat x 10; and the QLV trial
stress of a residual (QLVHistory.stress against the numpy expression it replaced); and the
contact part of a residual + tangent with the gaps and einsum path computed again or kept.

    .venv/bin/python benchmarks/state_reuse2d.py --src OLD/src NEW/src [--repeat 3] [--quality preview]
    .venv/bin/python benchmarks/state_reuse2d.py --units [--repeat 3]
"""

from __future__ import annotations

import argparse
import hashlib
import itertools
import json
import os
import subprocess
import sys
import time
from collections import Counter

import numpy as np

PHASES = ("residual", "tangent", "contact", "factor", "solve", "setup", "recovery")


def one(quality: str) -> dict:
    os.environ.setdefault("MKL_NUM_THREADS", "1")
    from tactileskin.fe import model as fem, solve
    from tactileskin.mesh import build_mesh
    from tactileskin.planner import with_quality
    from tactileskin.scene import Scene

    scenes = [with_quality(Scene(thickness=t, material=m, indenter=i), quality)
              for t, m, i in itertools.product((1.0, 3.0, 5.0), ("silicone", "polyurethane"),
                                                ("flat", "curved", "braille"))]
    meshes = [build_mesh(sc) for sc in scenes]
    solve(scenes[0], meshes[0])   # numba's cache loaded, first-call costs paid
    models, counts = [], Counter()
    init = fem.Model.__init__

    def w_init(self, *a, **k):
        init(self, *a, **k)
        models.append(self)

    fem.Model.__init__ = w_init
    phases, digest = Counter(), hashlib.sha256()
    c0, w0 = time.process_time(), time.perf_counter()
    for sc, sm in zip(scenes, meshes):
        r = solve(sc, sm)
        for k in PHASES:
            phases[k] += r.stats["phases_s"].get(k, 0.0)
        pd = (r.fields or {}).get("point_data") or {}
        for x in (r.pressure, r.contact_pressure, pd.get("displacement_mm"),
                  np.array([r.peak, r.reaction, r.stats["newton_iterations"]], float)):
            if x is not None:
                digest.update(np.ascontiguousarray(x, dtype=float).tobytes())
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    for m in models:
        counts.update({k: v for k, v in m.counts.items()})
    return dict(cpu=cpu, wall=wall, phases=dict(phases), counts=dict(counts), digest=digest.hexdigest()[:16])


def units(repeat: int) -> None:
    os.environ.setdefault("MKL_NUM_THREADS", "1")
    from tactileskin.fe import model as fem, solve
    from tactileskin.mesh import build_mesh
    from tactileskin.planner import with_quality
    from tactileskin.scene import Scene

    sc = with_quality(Scene(thickness=5.0, material="silicone", indenter="braille"), "preview")
    models, init = [], fem.Model.__init__

    def w_init(self, *a, **k):
        init(self, *a, **k)
        models.append(self)

    fem.Model.__init__ = w_init
    solve(sc, build_mesh(sc))
    fem.Model.__init__ = init
    model = models[-1]
    u, t, dt = model.u.copy(), model.t, model.dt_prev   # the solved state, its last step

    def iterate(reuse):
        model.reuse_state, model._last = reuse, None
        ev = model.evaluate(u, t, dt, tangent=False)
        model.tangent(ev)
        return ev

    if not iterate(True).ok:
        raise SystemExit("the solved state evaluated inadmissible")
    K_new, K_old = iterate(True).K, iterate(False).K
    times = {False: [], True: []}
    for _ in range(10 * repeat):
        for reuse in (False, True):
            c0 = time.process_time()
            for _ in range(10):
                iterate(reuse)
            times[reuse].append((time.process_time() - c0) / 10 * 1e3)
    print(f"t5-silicone-braille-2d preview, {model.ndof} dofs, {model.w.size} law points; CPU ms per "
          f"iterate (residual + tangent), medians of {10 * repeat} x 10; load average {os.getloadavg()[0]:.2f}")
    print(f"  law again for the tangent (S, then S + D): {np.median(times[False]):.2f} ms")
    print(f"  D from the kept data:                       {np.median(times[True]):.2f} ms")
    print(f"  tangents bit for bit the same: {np.array_equal(K_new, K_old)}")
    # the QLV trial stress of every residual: QLVHistory.stress against the numpy expression
    h, S0 = model.history, iterate(True)._state.S0

    def numpy_stress():
        gamma, decay, gain, back = h.factors(dt)
        S = gamma * S0
        for i in range(len(decay)):
            S = S + decay[i] * h.H[i] - gain[i] * h.S0_old
            if back[i]:
                S = S - back[i] * (h.S0_old - h.S0_prev)
        return S

    qt = {0: [], 1: []}
    for _ in range(30 * repeat):
        for k, f in ((0, numpy_stress), (1, lambda: h.stress(S0, dt))):
            c0 = time.process_time()
            for _ in range(10):
                f()
            qt[k].append((time.process_time() - c0) / 10 * 1e3)
    print(f"  QLV trial stress ({h.prony.n_terms} terms): numpy expression {np.median(qt[0]):.3f} ms, "
          f"QLVHistory.stress {np.median(qt[1]):.3f} ms, the same bits: "
          f"{np.array_equal(numpy_stress(), h.stress(S0, dt)[0])}")
    # the contact part of a tangent at the residual's state: gaps evaluated again and the einsum
    # path planned again (as before) against the kept gaps and path
    surf, c = model.surface, model.contact
    d, eps, lam = model.travel(t), model.penalty(), surf.lam
    ct = {0: [], 1: []}

    def contact_tangent(keep):
        surf.evaluate(u, c.indenter, d, eps, lam, False)
        if not keep:
            surf._last_gap, surf._paths = None, {}
        return surf.evaluate(u, c.indenter, d, eps, lam, True)[1]

    for _ in range(30 * repeat):
        for k in (0, 1):
            c0 = time.process_time()
            for _ in range(10):
                contact_tangent(k)
            ct[k].append((time.process_time() - c0) / 10 * 1e3)
    print(f"  contact residual + tangent ({surf.w.size} points): gaps and path again {np.median(ct[0]):.3f} ms, "
          f"kept {np.median(ct[1]):.3f} ms, the same bits: {np.array_equal(contact_tangent(0), contact_tangent(1))}")


def run(src: str, quality: str) -> dict:
    env = dict(os.environ, PYTHONPATH=os.path.abspath(src), MKL_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    out = subprocess.run([sys.executable, __file__, "--one", quality], env=env, check=True,
                         capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--src", nargs="+", default=["src"])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quality", default="preview")
    ap.add_argument("--units", action="store_true")
    ap.add_argument("--one", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.units:
        units(a.repeat)
        return 0
    if a.one is not None:
        print(json.dumps(one(a.one)))
        return 0
    load0 = os.getloadavg()
    res = {s: [] for s in a.src}
    for i in range(a.repeat):
        for s in (a.src if i % 2 == 0 else a.src[::-1]):   # alternate which tree goes first
            res[s].append(r := run(s, a.quality))
            print(f"# round {i + 1}, {s}: CPU {r['cpu']:.2f} s, wall {r['wall']:.2f} s", flush=True)
    load1 = os.getloadavg()
    print(f"\n18 paper 2D cases at {a.quality}; {a.repeat} rounds, trees alternating; "
          f"load average at start {load0[0]:.2f}, at end {load1[0]:.2f}\n")
    print("| tree | CPU s (median) | CPU s (runs) | wall s (median) | " + " | ".join(PHASES)
          + " | result digest |")
    print("|---|---|---|---|" + "---|" * len(PHASES) + "---|")
    for s, rs in res.items():
        digests = {r["digest"] for r in rs}
        ph = " | ".join(f"{np.median([r['phases'].get(k, 0.0) for r in rs]):.2f}" for k in PHASES)
        cpus = ", ".join(format(r["cpu"], ".2f") for r in rs)
        print(f"| {s} | {np.median([r['cpu'] for r in rs]):.2f} | {cpus} | "
              f"{np.median([r['wall'] for r in rs]):.2f} | {ph} | {', '.join(sorted(digests))} |")
    print("\nphases: median wall s summed over the 18 solves (contact is part of residual and tangent)")
    for s, rs in res.items():
        print(f"counts ({s}, one run):", json.dumps(rs[0]["counts"], sort_keys=True))
    same = len({r["digest"] for rs in res.values() for r in rs}) == 1
    print(f"\nall runs' results bit for bit the same: {same}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
