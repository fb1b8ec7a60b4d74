"""Scene planner: the cheapest model that answers a scene within a tolerance, and why.

`plan(scene, tolerance=0.01) -> Plan`. The plan's `scene` is what to solve; `choices`
say, one model aspect at a time, what was chosen, why, and what it costs in relative error
of the bone-pressure peak (0 for exact reductions, a bound or a measured value otherwise,
None where nothing is known). The costs of the simplifications it accepts add up to at
most `tolerance` (the discretisation error is not part of the plan: see
docs/speed_vs_error.md for the quality presets).

Aspects:

- symmetry: the solver models the half x >= 0 (2D section, 3D slab) and, in 3D, the
  quarter z >= 0 when the indenter is mirror-symmetric about z = 0. Exact for indenters
  symmetric about the plane(s); for an asymmetric Braille text the half model is an
  approximation the solver cannot avoid (no full model exists), and the plan says so.
- dimension: plane strain (2D) is exact for an indenter uniform along the finger (flat
  plate, cylinder) on the paper's idealisation of a long finger. Braille dots are not:
  the exact model is the 3D slab; the 2D model treats the dot row as a ridge (as the
  paper does), whose difference to 3D is stated where it has been measured
  (`MEASURED_RIDGE_VS_DOTS`) and accepted only when below the tolerance.
- truncation: the skin far from contact carries negligible pressure (the paper reports
  P within 6 mm of s = 0). The section is truncated by moving its clamped end (the nail
  edge, `fingertip.nail_angle_deg`) so that the bone interface keeps `WINDOW_S` plus a
  margin. The cost is measured: `check_truncation` solves the truncated and the full
  section on a coarse mesh and compares P(s) on s <= 6 mm. Without a measurement
  (`verify=False` and no entry in `MEASURED_TRUNCATION`) the plan does not truncate.
  Measured: it costs < 0.25 % but also saves little time in 2D (the far skin is meshed
  coarsely already); the 3D slab has no truncation parameter.
- viscoelasticity: QLV gives S(T) = int_0^T g(T - s) dS0(s). For a stress that grows
  monotonically during loading, g(T - s) >= g(T) and so
  (1 - g(T)) S0(T) >= S0(T) - S(T) >= 0: the relaxed fraction is at most
  `viscoelastic_bound = 1 - g(T)` with T = depth / rate the loading time; with a loading
  history (holds, further ramps) T is the whole history's time (`history_time`): a hold keeps
  S0 constant and lets S relax towards g(T) S0. The elastic model is used only when that
  bound is within the tolerance left.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

import numpy as np

from tactileskin.errors import ParameterError, check_range
from tactileskin.scene import Scene

log = logging.getLogger(__name__)

WINDOW_S = 6.0          # mm: bone-pressure window of the paper (s <= 6 mm)
TRUNCATION_MARGIN = 2.0  # mm of interface kept beyond the window (plus one skin thickness)

# Measured relative differences (2D ridge - 3D dots) / 3D dots of the peak bone pressure
# ("peak") and span ("span", results.span), signed, keyed by (thickness, material, dot
# pattern) with the pattern as Unicode braille ("\u2801": one dot, the paper's section;
# "\u283f": the full cell); a key without pattern means the single dot. The planner's cost
# is |peak|. Filled from benchmarks/results/convergence3d.md (see there for meshes and
# caveats).
# Source (2026-11-25): the 3D reference is the finest level of the local-plan convergence
# study with the bone pressure from the local fit (benchmarks/results/convergence3d.md: 0.6 / 8
# at t = 1 silicone, 0.8 / 8 at t = 1 polyurethane and at t = 3; peaks 0.039481,
# 0.054248, 0.023831 MPa; t = 5 (the capped family, eighth session): silicone Richardson
# 0.034907, polyurethane 0.049073 at 0.8 / 8), the 2D ridge the `default` preset (0.10264,
# 0.14841, 0.07188; t = 5 0.066442, 0.091321 MPa): the ridge reads 1.9-3.1 times the bone
# pressure of a real dot (1.9 at t = 5, where the plate presses too). The full cells are the
# earlier measurements with the nodal projection (2-3 % low in 3D, tests/test_bone_map.py):
# t = 1 the finest local level (0.019166 MPa), t = 3 a coarse one (braille_2d_vs_3d.py
# --contact-rule 2, 3D mesh 1.0 / 2, 2D on the same mesh); t = 3 polyurethane: 0.032392 (0.8 / 8)
# against 0.09913.
MEASURED_RIDGE_VS_DOTS: dict[tuple, dict] = {
    (1.0, "silicone", "\u2801"): {"peak": 1.600, "span": -0.016,
                                  "note": "3D converged (local plan, finest two levels within 0.3 %) vs 2D default"},
    (1.0, "polyurethane", "\u2801"): {"peak": 1.736, "span": 0.021,
                                      "note": "3D finest level (local plan, 0.8 / 8) vs 2D default"},
    (1.0, "silicone", "\u283f"): {"peak": 1.505, "span": -0.000,
                                  "note": "3D finest level (nodal projection; peak not shown converged to 2 %) vs 2D default"},
    (3.0, "silicone", "\u2801"): {"peak": 2.016, "span": -0.069,
                                  "note": "3D converged (local plan, finest two levels within 0.1 %) vs 2D default"},
    (3.0, "polyurethane", "\u2801"): {"peak": 2.060, "span": -0.040,
                                      "note": "3D converged (local plan, finest two levels within 0.01 %) vs 2D default"},
    (5.0, "silicone", "\u2801"): {"peak": 0.903, "span": -0.045,
                                  "note": "3D Richardson limit (local plan, capped bone patches, 1.6 / 1.2 / 0.8 / 8, "
                                          "order 1.85; span: the finest level) vs 2D default"},
    (5.0, "polyurethane", "\u2801"): {"peak": 0.861, "span": -0.023,
                                      "note": "3D finest level (local plan, capped bone patches, 0.8 / 8; the three "
                                              "levels within 0.1 %) vs 2D default"},
    (3.0, "silicone", "\u283f"): {"peak": 1.178, "span": 0.013,
                                  "note": "coarse 3D (nodal projection); vs 2D default quality: peak +132%, span -0.6%"},
}

SINGLE_DOT = "\u2801"


def dot_pattern(text: str) -> str:
    """The Unicode braille pattern of a Braille text ("" is the paper's single dot)."""
    from tactileskin.geometry.braille import cells_to_unicode, text_to_cells

    return SINGLE_DOT if text == "" else cells_to_unicode(text_to_cells(text))


def measured_ridge_vs_dots(scene: Scene) -> dict | None:
    """The stored 2D-ridge vs 3D-dots difference for the scene's thickness, material and
    dot pattern (None when not measured)."""
    t, mat, pat = float(scene.thickness), scene.material, dot_pattern(scene.braille_text)
    meas = MEASURED_RIDGE_VS_DOTS.get((t, mat, pat))
    if meas is None and pat == SINGLE_DOT:
        meas = MEASURED_RIDGE_VS_DOTS.get((t, mat))
    return meas

# Measured truncation errors (relative L2 of P(s) on s <= 6 mm, relative to the peak; and
# the relative peak change), keyed by (thickness, material, indenter): `check_truncation`
# at h = 0.5 mm, refinement 3 (benchmarks/hard_cases.py --planner --h0 0.5 --refinement 3,
# docs/hard_cases.md). The numbers include the mesh-to-mesh difference of two gmsh meshes,
# so they are upper estimates of the truncation effect. Only t = 1 mm has skin to cut.
MEASURED_TRUNCATION: dict[tuple[float, str, str], dict] = {
    (1.0, "silicone", "flat"): {"l2": 0.00218, "peak": 0.00014},
    (1.0, "silicone", "curved"): {"l2": 0.00236, "peak": 0.00009},
    (1.0, "silicone", "braille"): {"l2": 0.00081, "peak": 0.00112},
    (1.0, "polyurethane", "flat"): {"l2": 0.00209, "peak": 0.00021},
    (1.0, "polyurethane", "curved"): {"l2": 0.00204, "peak": 0.00101},
    (1.0, "polyurethane", "braille"): {"l2": 0.00079, "peak": 0.00057},
}


@dataclass(frozen=True)
class Choice:
    aspect: str            # symmetry | dimension | truncation | viscoelasticity
    decision: str          # short text of what the plan does
    reason: str
    cost: float | None     # relative peak error it costs (0: exact; None: unknown)
    basis: str = "exact"   # exact | bound | measured | unknown

    def __str__(self) -> str:
        c = "unknown" if self.cost is None else f"{self.cost:.2%}"
        return f"{self.aspect}: {self.decision} (cost {c}, {self.basis}) - {self.reason}"


@dataclass(frozen=True)
class Plan:
    requested: Scene
    scene: Scene                       # the model to solve
    tolerance: float
    choices: tuple[Choice, ...] = field(default_factory=tuple)

    @property
    def expected_error(self) -> float | None:
        """Sum of the costs of the accepted simplifications (None if one is unknown)."""
        costs = [c.cost for c in self.choices]
        return None if any(c is None for c in costs) else float(sum(costs))

    def choice(self, aspect: str) -> Choice:
        for c in self.choices:
            if c.aspect == aspect:
                return c
        raise ParameterError("aspect", aspect, ", ".join(c.aspect for c in self.choices))

    def describe(self) -> str:
        e = self.expected_error
        head = (f"plan for {self.requested.label()} (tolerance {self.tolerance:.2%}): solve "
                f"{self.scene.label()}, expected model error "
                f"{'unknown' if e is None else format(e, '.2%')}")
        return "\n".join([head] + ["  - " + str(c) for c in self.choices])


# Quality presets (tactileskin/data/presets.json, read by tactileskin.presets; `default` is
# the Scene default, scene.default_mesh). 2D: (mesh_size mm, refinement) for flat / curved
# indenters and for Braille (the dot needs the finer size), with the relative peak error
# measured against Richardson-extrapolated references of the 18 paper cases
# (benchmarks/preset_accuracy.py, benchmarks/results/preset_accuracy_fit.md): preview
# -0.12..-3.18 %, default -0.10..-0.47 %, fine +0.03..-0.17 %, every preset reading low;
# against 5-level series the t = 1 cases read lower still (preset_accuracy_fit_t1.md).
# 3D: "mesh3d" for flat / curved (the strip plan); spot contacts (Braille dots, spheres, file
# indenters: the kind's local_3d, on a skin with the local plan) mesh on the local plan at
# their spots (mesh.sizing.local_plan) at sizes that follow the skin thickness, so only
# quality_mesh (presets.mesh(..., thickness=)) gives them; the levels of the 3D convergence
# study (Braille dots and cells, the R 2.5 sphere; benchmarks/convergence3d.py,
# benchmarks/results/convergence3d.md) with their worst measured peak error and bone-map L2
# over the studied cases ("peak_error3d", "map_l2_3d"; None where no case measured them,
# "cases3d_not_measured" names the studied cases without that level, "cases3d_reference"
# those where it is the finest level, i.e. the reference, so its error there is 0 by
# construction; "cases3d_thickness_mm" the thicknesses studied, 1-5 mm: not below).
def _thickness_span(keys) -> tuple[float, float] | None:
    from tactileskin import presets

    ts = [t for t in (presets.case_thickness(k) for k in keys) if t is not None]
    return (min(ts), max(ts)) if ts else None


def _quality_table() -> dict[str, dict]:
    from tactileskin import presets

    out = {}
    for q in presets.QUALITIES:
        e3 = presets.preset_errors(q)
        out[q] = {"mesh": presets.mesh(2, q), "braille_mesh": presets.mesh(2, q, braille=True),
                  "peak_error": float(presets.load()["2"][q]["peak_error"]),
                  "mesh3d": presets.mesh(3, q),
                  "peak_error3d": e3["peak_error"], "map_l2_3d": e3["map_l2"],
                  "cases3d": tuple(e3["cases"]), "cases3d_not_measured": tuple(e3["not_measured"]),
                  "cases3d_reference": tuple(e3["reference_in"]),
                  # the skin thicknesses the 3D errors were measured at: none outside them is claimed
                  "cases3d_thickness_mm": _thickness_span(e3["cases"] + e3["not_measured"])}
    return out


QUALITY: dict[str, dict] = _quality_table()


def quality_mesh(quality: str, indenter, dim: int = 2, thickness: float | None = None,
                 skin: str = "fingertip") -> tuple[float, float]:
    """(mesh_size, refinement) of a quality preset for an indenter kind, dimension, skin
    thickness and skin (3D spot contacts on a skin with the local plan, e.g. Braille: the
    local sizes, thick-skin ones from their thickness on)."""
    if quality not in QUALITY:
        raise ParameterError("quality", quality, "one of " + ", ".join(QUALITY))
    from tactileskin.scene import preset_mesh

    return preset_mesh(quality, dim, indenter, thickness, skin)


def with_quality(scene: Scene, quality: str) -> Scene:
    """The scene meshed at a quality preset of its dimension."""
    size, ref = quality_mesh(quality, scene.indenter, scene.dim, scene.thickness, scene.skin)
    return scene.replace(mesh_size=size, refinement=ref)


# --- individual estimates (pure) ----------------------------------------------------------

def viscoelastic_bound(scene: Scene) -> float:
    """1 - g(T), T = the whole loading history's time (`history_time`): upper bound of the
    relative stress relaxed by its end (see the module docstring). 0 for an elastic material."""
    from tactileskin.materials import get_material

    prony = get_material(scene.material).prony
    if prony is None or prony.n_terms == 0:
        return 0.0
    return float(1.0 - prony.relaxation(history_time(scene)))


def history_time(scene: Scene) -> float:
    """Time (s) of the scene's whole loading history: the first ramp, then every `loading`
    segment (holds too: a hold is where a skin relaxes). A ramp of the quantity the previous
    segment did not control starts at a value known only after solving: then infinity, so that
    the bound above is the whole relaxation 1 - g(inf)."""
    program = scene.program()
    total, last = scene.duration, {program[0].kind: program[0].target}
    for seg in program[1:]:
        if seg.kind == "hold" or seg.rate is None:
            total += float(seg.time)
        elif seg.kind in last:
            total += seg.duration(last[seg.kind])
        else:
            return math.inf
        if seg.kind != "hold":
            last = {seg.kind: seg.target}
    return total


def symmetric(scene: Scene) -> tuple[bool, bool]:
    """(about x = 0, about z = 0) mirror symmetry of the indenter."""
    from tactileskin.geometry.indenters import indenter_symmetry

    return indenter_symmetry(scene)


def truncated_scene(scene: Scene, keep_s: float | None = None) -> Scene | None:
    """The scene with its section ending (clamped, as at the nail) where the bone interface
    reaches s = keep_s (default WINDOW_S + TRUNCATION_MARGIN + thickness); None if the
    section is not longer than that (nothing to cut)."""
    keep = WINDOW_S + TRUNCATION_MARGIN + scene.thickness if keep_s is None else keep_s
    keep = check_range("keep_s", keep, 0.0, None, lo_open=True, unit="mm")
    if scene.skin != "fingertip":  # only the fingertip's section is truncated (at a nail angle)
        return None
    section = scene.section()
    if keep >= section.interface_length - 0.5:
        return None
    x, y = section.point_at_s(keep)
    angle = math.degrees(math.atan2(float(x), float(y)))  # polar angle from +y (ellipse centre)
    ft = dict(scene.fingertip)
    ft["nail_angle_deg"] = round(angle, 6)
    return scene.replace(fingertip=ft)


def profile_difference(a, b, window: float = WINDOW_S) -> dict:
    """Compare two Results on s <= window: relative L2 (RMS over the window, divided by the
    peak of b) and relative peak difference (b is the reference)."""
    hi = min(window, a.s[-1], b.s[-1])
    x = np.linspace(0.0, hi, 400)
    pa = np.interp(x, a.s, a.pressure)
    pb = np.interp(x, b.s, b.pressure)
    ref = float(np.max(pb))
    if not ref > 0:
        raise ParameterError("reference peak", ref, "> 0 MPa")
    return {"l2": float(np.sqrt(np.trapezoid((pa - pb) ** 2, x) / hi) / ref),
            "peak": float(abs(np.max(pa) - ref) / ref)}


def check_truncation(scene: Scene, *, mesh_size: float = 0.5, refinement: float = 3.0) -> dict:
    """Solve the full and the truncated section (h = 0.5 mm, refinement 3 by default: on
    h = 1 mm the difference between the two gmsh meshes, ~1 %, hides the truncation
    effect); return the kept length and the relative L2 and peak differences on
    s <= WINDOW_S."""
    from tactileskin.fe import solve

    cut = truncated_scene(scene)
    if cut is None:
        return {"available": False, "l2": 0.0, "peak": 0.0}
    coarse = dict(mesh_size=mesh_size, refinement=refinement)
    full = solve(scene.replace(**coarse))
    part = solve(cut.replace(**coarse))
    d = profile_difference(part, full)
    d.update(available=True, keep_s=float(cut.section().interface_length),
             full_s=float(scene.section().interface_length),
             wall_full=full.stats["wall_s"], wall_truncated=part.stats["wall_s"])
    return d


# --- the plan -----------------------------------------------------------------------------

def plan(scene: Scene, tolerance: float = 0.01, *, braille: str = "dots", verify: bool = False) -> Plan:
    """Choose the cheapest model of `scene` whose simplifications cost at most `tolerance`
    (relative peak bone pressure). braille: 'dots' (the real indenter: 3D unless the
    measured ridge difference fits the tolerance) or 'ridge' (the paper's 2D model, cost
    stated). verify: run `check_truncation` when no measurement is stored (two coarse
    solves)."""
    tolerance = check_range("tolerance", tolerance, 0.0, 1.0, lo_open=True)
    if braille not in ("dots", "ridge"):
        raise ParameterError("braille", braille, "'dots' or 'ridge'")
    budget = tolerance
    choices: list[Choice] = []
    out = scene

    # symmetry ---------------------------------------------------------------------------
    sx, sz = symmetric(scene)
    if sx:
        choices.append(Choice("symmetry", "half model (x >= 0)" + (", quarter in 3D (z >= 0)" if sz else ""),
                              "the indenter is mirror-symmetric about x = 0"
                              + (" and z = 0" if sz else ""), 0.0))
    else:
        choices.append(Choice("symmetry", "half model (x >= 0), the only model the solver has",
                              f"the {scene.indenter_label()} indenter is not symmetric about x = 0: "
                              "the half model mirrors it; no full model is available", None, "unknown"))

    # dimension --------------------------------------------------------------------------
    model_2d = scene.indenter_kind.model_2d(scene)
    if model_2d == "exact":
        if scene.dim == 3:
            out = out.replace(dim=2)
        choices.append(Choice("dimension", "2D plane strain",
                              f"the {scene.indenter.value} indenter is uniform along the finger", 0.0))
    elif model_2d is None:
        choices.append(Choice("dimension", "3D slab",
                              f"the {scene.indenter_label()} indenter is not uniform along the finger and "
                              "has no 2D model", 0.0))
    else:  # "ridge": the Braille dot row as a ridge
        meas = measured_ridge_vs_dots(scene)
        if braille == "ridge":
            out = out.replace(dim=2)
            cost = None if meas is None else abs(meas["peak"])
            choices.append(Choice("dimension", "2D plane strain, dot row as a ridge (the paper's model)",
                                  "asked for the ridge model; " + (
                                      "2D vs 3D difference not measured for this thickness and material"
                                      if meas is None else f"measured 2D vs 3D: {_meas_text(meas)}"),
                                  cost, "unknown" if meas is None else "measured"))
        elif meas is not None and abs(meas["peak"]) <= budget:
            out = out.replace(dim=2)
            choices.append(Choice("dimension", "2D plane strain, dot row as a ridge",
                                  f"measured 2D vs 3D difference within tolerance: {_meas_text(meas)}",
                                  abs(meas["peak"]), "measured"))
        else:
            out = out.replace(dim=3)
            why = ("2D vs 3D difference not measured for this thickness and material" if meas is None
                   else f"measured 2D vs 3D difference exceeds the tolerance: {_meas_text(meas)}")
            choices.append(Choice("dimension", "3D slab (real dots)",
                                  "Braille dots are not uniform along the finger; " + why, 0.0))
    budget -= sum(c.cost for c in choices if c.cost is not None)

    # viscoelasticity --------------------------------------------------------------------
    if scene.viscoelastic:
        bound = viscoelastic_bound(scene)
        if bound <= budget:
            out = out.replace(viscoelastic=False)
            budget -= bound
            choices.append(Choice("viscoelasticity", "elastic (relaxation dropped)",
                                  f"loading time {history_time(scene):.3g} s: relaxed fraction <= 1 - g(T) = "
                                  f"{bound:.3%}", bound, "bound"))
        else:
            choices.append(Choice("viscoelasticity", "kept (QLV Prony series)",
                                  f"loading time {history_time(scene):.3g} s: the bound 1 - g(T) = {bound:.2%} "
                                  f"exceeds the tolerance left ({max(budget, 0):.2%})", 0.0))
    else:
        choices.append(Choice("viscoelasticity", "elastic (as the scene asks)", "scene.viscoelastic is False",
                              0.0))

    # truncation -------------------------------------------------------------------------
    choices.append(_truncation_choice(scene, out, budget, verify))
    if choices[-1].decision.startswith("truncate"):
        out = truncated_scene(out)

    p = Plan(requested=scene, scene=out, tolerance=tolerance, choices=tuple(choices))
    log.info("%s", p.describe())
    return p


def _meas_text(meas: dict) -> str:
    parts = [f"peak {meas['peak']:+.1%}"]
    if "span" in meas:
        parts.append(f"span {meas['span']:+.1%}")
    if "note" in meas:
        parts.append(meas["note"])
    return ", ".join(parts)


def _truncation_choice(scene: Scene, out: Scene, budget: float, verify: bool) -> Choice:
    if out.dim == 3:
        return Choice("truncation", "not available in 3D",
                      "the 3D slab has no truncation parameter (its z length is the cast sample's)", 0.0)
    cut = truncated_scene(out)
    if cut is None:
        L = out.section().interface_length
        return Choice("truncation", "none (nothing to cut)",
                      f"the bone interface ({L:.1f} mm) is not longer than the window plus margin", 0.0)
    key = (float(scene.thickness), scene.material, scene.indenter.value)
    meas = MEASURED_TRUNCATION.get(key)
    if meas is None and verify:
        meas = check_truncation(out)
    keep = cut.section().interface_length
    if meas is None:
        return Choice("truncation", "none (unverified)",
                      f"truncating at s = {keep:.1f} mm is possible but its error is not measured "
                      "for this case (plan(..., verify=True) measures it)", 0.0)
    err = max(meas["l2"], meas["peak"])
    if err <= budget:
        return Choice("truncation", f"truncate the section at s = {keep:.1f} mm (clamped end)",
                      f"measured on a coarse mesh: P(s <= {WINDOW_S:g} mm) changes by {meas['l2']:.2%} (L2), "
                      f"peak by {meas['peak']:.2%}", err, "measured")
    return Choice("truncation", "none",
                  f"truncation at s = {keep:.1f} mm changes P(s <= {WINDOW_S:g} mm) by {err:.2%}, more than "
                  f"the tolerance left ({max(budget, 0):.2%})", 0.0)
