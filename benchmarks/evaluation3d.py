"""Where one 3D Newton iteration's element work goes (run: python benchmarks/evaluation3d.py).

Builds the 3D Braille dot model of a scene (default: t = 3 mm silicone at the `default` preset,
11,900 P2 tets) and times, at a random small displacement (median wall ms of --repeat calls,
on --threads numba threads for the compiled loops; PARDISO is not involved): kinematics, the
material law with and without its tangent, the Prony history, the residual kernel and its
assembly, the tangent kernel, the CSR scatter (Pattern.data), and the model's whole residual
and residual + tangent evaluations (contact included).

    .venv/bin/python benchmarks/evaluation3d.py [--thickness 3] [--quality default] [--threads 1]
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--thickness", type=float, default=3.0)
    ap.add_argument("--quality", default="default")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=7)
    a = ap.parse_args(argv)

    from tactileskin.fe import kernels, model_for_scene
    from tactileskin.fe.assembly import assemble_vector
    from tactileskin.planner import with_quality
    from tactileskin.scene import Scene
    from tactileskin.threads import numba_threads

    sc = with_quality(Scene(thickness=a.thickness, dim=3, indenter="braille"), a.quality)
    model, _ = model_for_scene(sc)
    model.threads = a.threads
    E, Q = model.w.shape
    print(f"t = {a.thickness:g} mm, {a.quality}: {model.ndof:,} dofs, {E:,} elements x {Q} points, "
          f"{a.threads} thread(s); median wall ms of {a.repeat}")
    u = 1e-3 * np.random.default_rng(0).standard_normal(model.ndof)
    m = model.m
    ue = u.reshape(-1, m)[model.sdofs]

    def ms(f):
        f()
        ts = []
        for _ in range(a.repeat):
            t0 = time.perf_counter()
            f()
            ts.append(time.perf_counter() - t0)
        return 1e3 * float(np.median(ts))

    with numba_threads(a.threads):
        kin = kernels.Kinematics(ue, model.G, model.w, model.mixed)
        S0, D0, _ = model._law(kin.C, True)
        S, g = model.history.stress(S0, 0.05)
        Sm = np.ascontiguousarray(S[..., :m, :m])
        Dm = np.ascontiguousarray(g * D0[..., :m, :m, :m, :m])
        fe = kernels.residual(kin, Sm)
        Ke = kernels.tangent(kin, Sm, Dm)
        rows = [
            ("kinematics", lambda: kernels.Kinematics(ue, model.G, model.w, model.mixed)),
            ("law S + D", lambda: model._law(kin.C, True)),
            ("law S", lambda: model._law(kin.C, False)),
            ("Prony history", lambda: model.history.stress(S0, 0.05)),
            ("residual kernel", lambda: kernels.residual(kin, Sm)),
            ("residual assembly", lambda: assemble_vector(model.ndof, model.edofs, fe)),
            ("tangent kernel", lambda: kernels.tangent(kin, Sm, Dm)),
            ("tangent scatter", lambda: model.pattern.data(Ke)),
        ]
        for name, f in rows:
            print(f"  {name:<22}{ms(f):8.1f}")
    print(f"  {'evaluate (residual)':<22}{ms(lambda: model.evaluate(u, 0.05, 0.05, tangent=False)):8.1f}")
    print(f"  {'evaluate (+ tangent)':<22}{ms(lambda: model.evaluate(u, 0.05, 0.05, tangent=True)):8.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
