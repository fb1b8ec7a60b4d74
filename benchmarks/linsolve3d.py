"""3D linear solves in Newton: refactorise every iteration (before) against reusing the
factorisation as a GMRES preconditioner (after), on whole 3D Braille single-dot solves.

Variants (SolverOptions):
- direct:        linear_method="direct" (PARDISO refactorisation every Newton iteration)
- reuse 1e-8:    linear_method="reuse", linear_forcing=0 (GMRES to a relative residual 1e-8)
- reuse forcing: linear_method="reuse", linear_forcing=0.1 (GMRES to 0.1 |R| / scale,
                 between 1e-8 and 1e-3; what linear_method="auto" takes for 3D models
                 above SolverOptions.reuse_min_dofs free dofs)

With --tangents, the Newton systems (free-block tangent and right-hand side) of the direct
solve of the first mesh are kept and replayed: direct vs reuse on the same sequence, and
smoothed-aggregation AMG (pyamg, with the six rigid-body modes as near-null space; not a
dependency: `pip install pyamg`) as a CG / GMRES preconditioner on three of them.

Each variant solves the same scene and mesh in this process, one after the other (one heavy
solve at a time). CPU times are process time (the machine is shared: wall times vary with
the load); the linear-solve CPU is the solver's own (factorisations, triangular solves and
GMRES); phases are wall seconds from stats['phases_s']. BLAS and MKL run one thread, as
under the CLI.

    .venv/bin/python benchmarks/linsolve3d.py [--mesh 1.0/2 0.6/2] [--tangents] [--out benchmarks/results/linsolve3d.md]
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import logging  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402
from datetime import datetime, timezone  # noqa: E402
from pathlib import Path  # noqa: E402

VARIANTS = {
    "direct": dict(linear_method="direct"),
    "reuse 1e-8": dict(linear_method="reuse", linear_forcing=0.0),
    "reuse forcing": dict(linear_method="reuse", linear_forcing=0.1),
}


def load() -> str:
    try:
        return " / ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "?"


def run_case(h: float, r: float, t: float, material: str):
    from tactileskin import fe
    from tactileskin.fe.solver import SolverOptions
    from tactileskin.mesh import build_mesh
    from tactileskin.scene import Scene

    sc = Scene(dim=3, thickness=t, material=material, indenter="braille", mesh_size=h, refinement=r)
    mesh = build_mesh(sc)
    rows = []
    for name, kw in VARIANTS.items():
        load0 = load()
        c0 = time.process_time()
        res = fe.solve(sc, mesh, options=SolverOptions(**kw))
        cpu = time.process_time() - c0
        ls = res.stats["linear_solver"]
        rows.append(dict(variant=name, cpu=cpu, lin_cpu=ls["cpu_s"]["factor"] + ls["cpu_s"]["solve"], ls=ls,
                         phases=res.stats["phases_s"], newton=res.stats["newton_iterations"],
                         increments=res.stats["increments"], peak=res.peak, dofs=res.stats["dofs"],
                         free=res.stats["free_dofs"], load=f"{load0} -> {load()}"))
        print(f"  {sc.label()} h {h}/{r} {name}: {cpu:.1f} s CPU, linear {rows[-1]['lin_cpu']:.1f} s, "
              f"{rows[-1]['newton']} Newton, {ls['factorizations']} factorisations, "
              f"{ls['krylov_iterations']} Krylov, peak {res.peak:.8g}", flush=True)
    return sc, mesh, rows


def captured_systems(sc, mesh):
    """The Newton systems (free-block tangent, rhs) and dof data of a direct solve of sc."""
    import numpy as np

    from tactileskin import fe
    from tactileskin.fe import solver
    from tactileskin.fe.solver import SolverOptions

    systems, info = [], {}
    orig = solver._factor

    def capture(model, K, opts):
        ls = orig(model, K, opts)
        info.setdefault("doflocs", model.basis.doflocs)
        info.setdefault("free", model.free)
        info.setdefault("m", model.m)

        class Keep:
            def solve(self, b, rtol=None):
                systems.append((K.copy(), np.array(b)))
                return ls.solve(b, rtol)
        return Keep()

    solver._factor = capture
    try:
        fe.solve(sc, mesh, options=SolverOptions(linear_method="direct"))
    finally:
        solver._factor = orig
    return systems, info


def rigid_body_modes(info):
    """(n_free, 6): three translations and three rotations at the free dofs."""
    import numpy as np

    free, m = info["free"], info["m"]
    node, comp = free // m, free % m
    x = info["doflocs"][:, node]
    B = np.zeros((len(free), 6))
    for a in range(3):
        B[comp == a, a] = 1.0
    for k, (a, b) in enumerate(((0, 1), (1, 2), (0, 2))):  # rotation in the (a, b) plane
        B[comp == a, 3 + k] = -x[b, comp == a]
        B[comp == b, 3 + k] = x[a, comp == b]
    return B


def replay(sc, h, r, mesh) -> list[str]:
    import numpy as np

    from tactileskin.fe import linsolve

    systems, info = captured_systems(sc, mesh)
    n = systems[0][0].shape[0]
    out = [f"### Replayed Newton systems: {sc.label()}, mesh_size {h} / refinement {r}, {n} free dofs, "
           f"{len(systems)} systems", "",
           "| solver | CPU s (all systems) | CPU s per system | factorisations | Krylov its | worst rel. residual |",
           "|---|---|---|---|---|---|"]
    for method in ("direct", "reuse"):
        s = linsolve.SymmetricSolver(systems[0][0], "pardiso", method)
        worst = 0.0
        c0 = time.process_time()
        for K, b in systems:
            x = s.factor(K).solve(b)
            worst = max(worst, float(np.linalg.norm(K @ x - b) / np.linalg.norm(b)))
        c = time.process_time() - c0
        out.append(f"| PARDISO {method}{' (GMRES to 1e-8)' if method == 'reuse' else ''} | {c:.2f} | "
                   f"{c / len(systems):.3f} | {s.factorizations} | {s.krylov_iterations} | {worst:.1e} |")
        s.close()
    try:
        import pyamg
    except ImportError:
        out += ["", "pyamg is not installed: AMG not measured.", ""]
        return out
    B = rigid_body_modes(info)
    out += ["", f"pyamg {pyamg.__version__} smoothed aggregation (symmetric, max_coarse 500) as a preconditioner, "
            "to a relative residual 1e-8, on the first, middle and last system (setup per system):", "",
            "| system | near-null space | setup CPU s | accel | iterations | solve CPU s | rel. residual |",
            "|---|---|---|---|---|---|---|"]
    for i in (0, len(systems) // 2, len(systems) - 1):
        K, b = systems[i]
        for name, BB in (("6 rigid-body modes", B), ("3 translations", B[:, :3])):
            c0 = time.process_time()
            ml = pyamg.smoothed_aggregation_solver(K, B=BB, symmetry="symmetric", max_coarse=500)
            setup = time.process_time() - c0
            for accel in ("cg", "gmres"):
                res = []
                c0 = time.process_time()
                x = ml.solve(b, tol=1e-8, accel=accel, maxiter=500, residuals=res)
                c = time.process_time() - c0
                rr = np.linalg.norm(K @ x - b) / np.linalg.norm(b)
                out.append(f"| {i} | {name} | {setup:.2f} | {accel} | {len(res) - 1} | {c:.2f} | {rr:.1e} |")
    out.append("")
    return out


def table(sc, h, r, rows) -> list[str]:
    ref = rows[0]
    out = [f"### {sc.label()}, mesh_size {h} / refinement {r}: {ref['dofs']} dofs ({ref['free']} free)", "",
           "| variant | CPU total s | linear CPU s (factor + solve) | wall phases s: tangent / residual / contact / factor / solve / total "
           "| increments | Newton its | factorisations | Krylov its | peak MPa | peak rel. diff. | load (1/5/15 min) |",
           "|---|---|---|---|---|---|---|---|---|---|---|"]
    for w in rows:
        p = w["phases"]
        ph = " / ".join(f"{p.get(k, 0):.1f}" for k in ("tangent", "residual", "contact", "factor", "solve", "total"))
        rel = (w["peak"] - ref["peak"]) / ref["peak"]
        out.append(f"| {w['variant']} | {w['cpu']:.1f} | {w['lin_cpu']:.1f} ({w['ls']['cpu_s']['factor']:.1f} + "
                   f"{w['ls']['cpu_s']['solve']:.1f}) | {ph} | {w['increments']} | {w['newton']} | "
                   f"{w['ls']['factorizations']} | {w['ls']['krylov_iterations']} | {w['peak']:.8g} | {rel:.1e} | {w['load']} |")
    out.append("")
    return out


def main() -> None:
    from tactileskin import fileio
    from tactileskin.fe import linsolve

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", nargs="+", default=["1.0/2"], help="mesh_size/refinement pairs")
    ap.add_argument("--thickness", type=float, default=1.0)
    ap.add_argument("--material", default="silicone")
    ap.add_argument("--tangents", action="store_true",
                    help="also replay the first mesh's Newton systems (direct, reuse, pyamg AMG)")
    ap.add_argument("--out", default=None, help="write the table (markdown) here")
    a = ap.parse_args()
    logging.basicConfig(level=logging.WARNING)
    if not linsolve.pardiso_available():
        raise SystemExit("PARDISO (the mkl wheel) is needed: reuse is measured against it")
    lines = ["# 3D linear solves: refactorise every Newton iteration vs reuse the factorisation", "",
             f"`benchmarks/linsolve3d.py --mesh {' '.join(a.mesh)}`, {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC, "
             f"{platform.machine()}, {os.cpu_count()} cores shared with other jobs (load average given per row: "
             "compare CPU times, not wall). One BLAS / MKL thread. Single Braille dot, t = "
             f"{a.thickness:g} mm {a.material}, default quality otherwise.", ""]
    for i, m in enumerate(a.mesh):
        h, r = (float(x) for x in m.split("/"))
        sc, mesh, rows = run_case(h, r, a.thickness, a.material)
        tab = table(sc, h, r, rows)
        if a.tangents and i == 0:
            tab += replay(sc, h, r, mesh)
        print("\n".join(tab))
        lines += tab
    if a.out:
        fileio.atomic_write_text(Path(a.out), "\n".join(lines) + "\n")
        print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
