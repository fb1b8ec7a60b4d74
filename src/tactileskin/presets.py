"""Mesh quality presets (`preview` / `default` / `fine`) per dimension, read from
tactileskin/data/presets.json (importlib.resources): the one place the preset sizes and
their measured errors live (scene.default_mesh and planner.QUALITY read it).

File layout: "2" and "3" map each preset to its mesh ([mesh_size, refinement]) and its
"braille_mesh" (2D: finer at the dot; 3D: the local plan's sizes, mesh.sizing.local_plan:
coarse size and coarse / fine ratio at the dots), optionally overridden for thick skins by
"braille_mesh_by_thickness" ([[from thickness mm, [mesh_size, refinement]], ...]: the 3D
`default` is 0.8 / 8 below t = 3 mm, where the t = 1 full cells need it (1.2 / 8 read them 5 %
low), and 1.6 / 8 from t = 3 mm, where the convergence study measured it within the accuracy
target; `fine` one level finer on both sides); 2D also has the "peak_error" measured by
benchmarks/preset_accuracy.py. "cases3d"
holds the 3D convergence study (benchmarks/convergence3d.py writes it): per case (thickness,
material, dot pattern) each level's dofs, relative peak error against the reference, map L2
against the finest level and CPU time. A 3D preset's errors are the worst over the cases
that measured its level (`preset_errors`); cases that did not are listed as not measured.
"""

from __future__ import annotations

import json
import math
from functools import lru_cache
from importlib import resources

from tactileskin.errors import ParameterError

QUALITIES = ("preview", "default", "fine")
DATA = ("data", "presets.json")


@lru_cache(maxsize=1)
def load() -> dict:
    """The parsed preset file (cached; do not mutate)."""
    text = resources.files("tactileskin").joinpath(*DATA).read_text(encoding="utf-8")
    data = json.loads(text)
    for dim in ("2", "3"):
        for q in QUALITIES:
            mesh = data.get(dim, {}).get(q, {}).get("mesh")
            if not (isinstance(mesh, list) and len(mesh) == 2 and all(float(v) > 0 for v in mesh)):
                raise ParameterError(f"presets.json {dim}D {q} mesh", mesh, "[mesh_size, refinement] > 0")
            for row in data.get(dim, {}).get(q, {}).get("braille_mesh_by_thickness", ()):
                if not (isinstance(row, list) and len(row) == 2 and float(row[0]) > 0 and isinstance(row[1], list)
                        and len(row[1]) == 2 and all(float(v) > 0 for v in row[1])):
                    raise ParameterError(f"presets.json {dim}D {q} braille_mesh_by_thickness", row,
                                         "[thickness > 0, [mesh_size, refinement] > 0]")
    return data


def check_quality(quality: str) -> str:
    if quality not in QUALITIES:
        raise ParameterError("quality", quality, "one of " + ", ".join(QUALITIES))
    return quality


def mesh(dim: int, quality: str, braille: bool = False, thickness: float | None = None) -> tuple[float, float]:
    """(mesh_size, refinement) of a preset; Braille has its own (2D: finer at the dot; 3D: the
    local plan's coarse size and ratio), and with the skin's `thickness` its thick-skin
    override ("braille_mesh_by_thickness": the row of the largest thickness it reaches, in any
    order)."""
    q = load()[str(int(dim))][check_quality(quality)]
    m = q["braille_mesh"] if braille and "braille_mesh" in q else q["mesh"]
    if braille and thickness is not None:
        reached = [row for row in q.get("braille_mesh_by_thickness", ()) if float(thickness) >= float(row[0]) - 1e-9]
        if reached:
            m = max(reached, key=lambda row: float(row[0]))[1]
    return float(m[0]), float(m[1])


def _same(a: float, b: float) -> bool:
    return math.isclose(float(a), float(b), rel_tol=1e-9)


def case_thickness(key: str) -> float | None:
    """The skin thickness (mm) of a convergence-study case key ("t5-silicone-..."), or None."""
    import re

    found = re.match(r"t([0-9.]+)-", key)
    return float(found.group(1)) if found else None


def preset_level(key: str, case: dict, quality: str) -> dict | None:
    """The level of convergence-study case `key` (presets.json "cases3d") meshed as the 3D
    Braille preset `quality` at the case's thickness, or None if the study did not solve it.
    A level counts only if the local plan gives the patch scales it was meshed with now
    (study_scales; "bone_scale" and "spot_scale" where recorded, "spot_factor" 1 where not):
    the same sizes with another layout are another mesh."""
    t = case_thickness(key)
    h, r = mesh(3, quality, braille=True, thickness=t)  # the local plan's sizes (dots, spheres)
    now = study_scales(key, h, r)

    def same(v, k):
        got = v.get(k, SCALE_BEFORE_RECORDS.get(k))
        return got is None or _same(got, now[k])

    return next((v for v in case["levels"] if _same(v["mesh_size"], h) and _same(v["refinement"], r)
                 and all(same(v, k) for k in now)), None)


# a level that does not record a scale was meshed with this value of it (levels solved before
# mesh.sizing.spot_factor had every spot at its fine size); other scales are not compared there
SCALE_BEFORE_RECORDS = {"spot_factor": 1.0}


def study_scales(key: str, mesh_size: float, refinement: float) -> dict:
    """The local plan's scales for a convergence-study case key meshed at (mesh_size,
    refinement): {"bone_scale", "spot_factor"} (mesh.sizing.bone_scale, spot_factor) of the
    standard American dots, and for a sphere case ("t1-silicone-sphere-R2.5", the scene's
    default depth) also its "spot_scale" (mesh.sizing.patch_scale of the ball's spot)."""
    import re

    from tactileskin.mesh.sizing import bone_scale, patch_scale, spot_factor, spot_fine

    t = case_thickness(key)
    fine = float(mesh_size) / float(refinement)
    ball = re.search(r"-sphere-R([0-9.]+)$", key)
    if ball is None:
        from tactileskin.geometry import braille

        a = braille.get_standard("standard_american").base_radius
        return {"bone_scale": study_bone_scale(t), "spot_factor": round(spot_factor(t, a, fine), 4)}
    from tactileskin.errors import ParameterError
    from tactileskin.geometry.indenters import indenter_for_scene
    from tactileskin.scene import Scene

    try:
        sc = Scene(thickness=t, dim=3, indenter="sphere", indenter_radius=float(ball.group(1)))
    except ParameterError:
        # a user's geometry (TACTILESKIN_GEOMETRY) that does not take the study's thickness:
        # the study's level is not this geometry's mesh (and every command used to fail here)
        return {"bone_scale": math.nan, "spot_scale": math.nan, "spot_factor": math.nan}
    (_, _, a), = indenter_for_scene(sc, warn=False).contact_patches(sc.indentation)
    h = spot_fine(float(mesh_size), fine, a)
    return {"bone_scale": round(bone_scale(t, a), 4), "spot_scale": round(patch_scale(a), 4),
            "spot_factor": round(spot_factor(t, a, h), 4)}


def study_bone_scale(thickness: float) -> float:
    """mesh.sizing.bone_scale of the convergence study's dots (the standard American cell) at a
    skin thickness: what a level records and preset_level matches."""
    from tactileskin.geometry import braille
    from tactileskin.mesh.sizing import bone_scale

    return round(bone_scale(thickness, braille.get_standard("standard_american").base_radius), 4)


def preset_errors(quality: str) -> dict:
    """Measured errors of a 3D preset over the convergence study's cases, each at the preset's
    mesh for its thickness: {"peak_error": worst
    |relative peak error|, "map_l2": worst map L2, "cases": measured case keys, "not_measured":
    case keys whose levels do not include this preset's mesh, "reference_in": cases where this
    level is the finest, i.e. the reference (error 0 by construction, not a measurement)}.
    Errors are None when no case measured the level."""
    peak, l2, seen, missing, ref = [], [], [], [], []
    for key, case in load().get("cases3d", {}).items():
        lv = preset_level(key, case, quality)
        if lv is None:
            missing.append(key)
            continue
        seen.append(key)
        if lv is case["levels"][-1]:
            ref.append(key)  # the case's finest level: its errors are 0 by construction
        peak.append(abs(float(lv["peak_error"])))
        l2.append(float(lv["map_l2"]))
    return {"peak_error": max(peak) if peak else None, "map_l2": max(l2) if l2 else None,
            "cases": seen, "not_measured": missing, "reference_in": ref}
