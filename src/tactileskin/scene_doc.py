"""The reference of every Scene field (unit, range, default), which becomes `Scene.__doc__`,
so that `help(tactileskin.Scene)` answers "what can I set, in what unit, within what range".

A new Scene field needs an entry here (tests/test_api.py checks that every field has one).
"""

from __future__ import annotations

# field -> (unit, valid values, what it is)
FIELDS: dict[str, tuple[str, str, str]] = {
    "thickness": ("mm", "[fingertip thickness_min, largest the fingertip allows] (0.5-5.51 mm "
                  "for the default fingertip)", "skin thickness t over the rigid bone"),
    "material": ("-", "a preset name (tactileskin.materials.list_materials(): silicone, "
                 "polyurethane, ...) or a material .toml file", "skin material (its law + Prony)"),
    "indenter": ("-", "a registered kind: 'flat', 'curved', 'braille', 'cylinder', 'sphere' (3D), "
                 "'file' (3D)", "the rigid indenter (tactileskin.geometry.indenters)"),
    "braille_text": ("-", "up to 40 Braille cells of text; '' = one dot on the symmetry line",
                     "Braille indenter only"),
    "braille_standard": ("-", "a standard of data/geometry/braille.toml", "dot size and spacing"),
    "depth": ("mm", "(0, 0.6 t]; None = depth_fraction * t", "final indentation depth"),
    "depth_fraction": ("-", "(0, 0.6] (0.2: the paper's 20 % nominal strain)",
                       "depth as a fraction of t when depth and force are None"),
    "rate": ("mm/s", "[1e-6, 1e6], the first ramp taking at least 1e-6 s (rate <= depth / 1e-6 s)", "indentation rate (loading time = depth / rate)"),
    "dim": ("-", "2 (plane-strain half section) or 3 (extruded slab)", "model dimension"),
    "order": ("-", "1 or 2 (1 needs formulation='displacement')", "element order"),
    "mesh_size": ("mm", "[0.01, 5]; None = the `default` quality preset of dim and indenter",
                  "global element size"),
    "refinement": ("-", "[1, 20]; None = the `default` preset", "global / refined element size "
                   "ratio at the contact and the bone"),
    "formulation": ("-", "'mixed' (locking-free) or 'displacement'", "finite-element formulation"),
    "viscoelastic": ("-", "True or False", "include the Prony series (False: elastic hyperfoam)"),
    "fingertip": ("mm, deg", "a table of overrides of data/geometry/fingertip.toml: half_width, "
                  "height, max_fraction_of_min_radius, nail_angle_deg, sample_length, thickness_min",
                  "fingertip geometry"),
    "sensors": ("mm", "[[sensors]] layouts: kind points / line / grid (3D), s along the bone, depth "
                "below the surface or height above the bone, pitch, taxel (inside the skin); pad: s = x, "
                "depth along -y; file: s = x - x_top and z of the contact surface's point, depth along its "
                "inward normal there, height along that line from the bonded surface; dome: as file, s = x, "
                "z in [-dome_length, dome_tip]",
                "where stresses are read (sensors.csv); () = none"),
    "indenter_radius": ("mm", "(0.1, 1000] (sphere: (0.1, 100], its printed part); sphere and cylinder only", "indenter radius"),
    "indenter_axis": ("-", "'z' (along the finger, 2D-exact) or 'x' (3D); cylinder only", "cylinder axis"),
    "indenter_file": ("mm", "a closed STL/OBJ/PLY/OFF or STEP surface in mm; 'file' indenter only",
                      "the user's indenter surface"),
    "force": ("N (3D, the whole indenter), N/mm (2D, the half section)", "[0.0001, 10000]; instead of depth and depth_fraction",
              "force control: the target reaction"),
    "force_rate": ("N/s (N/mm/s in 2D)", "[1e-6, 1e6], the ramp taking at least 1e-6 s (<= force / 1e-6 s); with force, not with load_time", "force ramp rate"),
    "load_time": ("s", "[1e-6, 1e6]; with force, not with force_rate",
                  "time to reach the force (None: 0.2 t / rate, the default depth ramp's)"),
    "loading": ("mm, N, s", "[[loading]] segments after the first ramp: depth (mm) or force at a rate "
                "or in a time, hold (s)", "indent-hold-release history (history.csv)"),
    "skin": ("-", "a registered skin: 'fingertip' (the paper's), 'pad', 'dome' or 'file' (tactileskin.skins)",
             "the skin geometry"),
    "pad_width": ("mm", "[1, 500], [1, 100] under the flat plate; pad only (default 20)", "x extent of the whole pad"),
    "pad_length": ("mm", "[1, 500], [1, 100] under the flat plate in 3D; pad only (default 20)", "z extent of the pad (3D block)"),
    "skin_file": ("mm", "a gmsh .msh with named physical groups or a STEP solid, 0.1 mm to 1 m; file only",
                  "the user's skin geometry (fixes dim and thickness)"),
    "skin_bonded": ("-", ".msh: physical-group name(s), comma-separated; STEP: 'normal:-y[:TOL_DEG]' or "
                    "'plane:y=0'; file only", "the bonded (fixed) surface"),
    "skin_outer": ("-", ".msh: physical-group name(s); default outer_surface, else the free rest; file only",
                   "the contact surface"),
    "dome_length": ("mm", "[1, 200]; dome only (default 10)", "finger length before its dome (3D)"),
    "dome_tip": ("mm", "[2, 50], and the skin within 10 % of t everywhere (about 3.5-17 mm); dome only (default the section's half width)",
                 "semi-axis of the dome along the finger"),
}


def docstring(cls) -> str:
    """The class docstring: a table of every dataclass field with its unit, range and default."""
    import dataclasses

    lines = ["The single, validated, immutable description of one indentation (units mm, s, N, MPa).",
             "",
             "    Scene(thickness=1.0, material='polyurethane', indenter='braille', braille_text='a')",
             "",
             "Change a copy with .replace(**fields); save and load with .to_toml(path) / Scene.from_toml(path).",
             "An invalid value raises tactileskin.ParameterError naming the field and its valid range.",
             "",
             "Fields (unit; valid values; default):", ""]
    for f in dataclasses.fields(cls):
        unit, valid, what = FIELDS.get(f.name, ("?", "undocumented", ""))
        default = f.default if f.default is not dataclasses.MISSING else (
            f.default_factory() if f.default_factory is not dataclasses.MISSING else None)
        default = getattr(default, "value", default)
        lines.append(f"{f.name} ({unit}): {what}.")
        lines.append(f"    valid: {valid}; default: {default!r}")
    return "\n".join(lines) + "\n"
