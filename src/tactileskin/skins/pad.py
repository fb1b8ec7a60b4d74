"""pad: a flat pad of width x length x thickness bonded to a rigid board (the most common
tactile-skin build).

Frame: the board is the plane y = 0 (the bonded surface, `bone_interface`), the free top is
y = t (`outer_surface`, where indenters start), x across the pad (the models keep x >= 0, with
`symmetry` on x = 0, unless the indenter is not mirror-symmetric about x = 0: then the full
width, see mesh.pad), z along it (z in [-L/2, L/2]). The free side x = W/2 is `side` (and in
3D the free ends z = +-L/2 are `end_front` / `end_back`). s along the bonded surface is x (signed on a full-width model), so
a 2D section is exact for an indenter uniform along z (plane strain) and the sensor frames are
flat (`sensors.FlatCoordinates`: depth along -y).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tactileskin.errors import ParameterError, check_range
from tactileskin.skins.base import Skin
from tactileskin.skins.registry import register

DEFAULT_WIDTH = 20.0    # mm, x extent of the whole pad
DEFAULT_LENGTH = 20.0   # mm, z extent
THICKNESS = (0.1, 50.0)  # mm
SIZE = (1.0, 500.0)      # mm, width and length
# mm: the largest width (and 3D length) under the flat plate, a plane pressing the whole top. A
# wider bonded pad is confined and locks up early (t = 3 silicone at 20 %: 28 mm failed at 0.55 mm,
# 100 mm at 0.22 mm in 43 s CPU, 500 mm at ~0.08 mm, still cutting back after 300 s); real
# fingertip and robot pads are up to ~100 mm, and a local press on a wider pad solves
PLATE_SIZE = 100.0
# ... and within it the width (over t) up to which a silicone pad solved at the default 20 %
# depth: t = 1 mm: 5, 7, 8 t solved (8 t: |stress| 186 MPa, flagged), 10 t failed at 17 %,
# 15 t at 13 %, 60 t at 4.1 %; t = 3 mm: 6.7 and 8 t solved, 9.3 t failed at 18 %. A hint
# when such a pad fails (a smaller depth or a more compressible law may solve: not refused)
CONFINED_WIDTH_OVER_T = 8.0
FLAT_RADIUS = 1e6        # mm: "radius" of the flat top for contact-size estimates


@dataclass(frozen=True)
class PadSection:
    """The pad's half section x in [0, W/2], y in [0, t] (the `Section` duck type of
    geometry.fingertip, see skins.base)."""

    width: float
    thickness: float
    length: float = DEFAULT_LENGTH

    @property
    def half_width(self) -> float:
        return 0.5 * self.width

    @property
    def top(self) -> float:
        return self.thickness

    @property
    def interface_length(self) -> float:
        return self.half_width

    @property
    def min_radius_of_curvature(self) -> float:
        return math.inf

    def contact_radius(self, indenter) -> float:
        """Radius for the indenter kind's contact-size estimate: on a flat top the indenter's
        own curvature (cylinder, sphere) sets it; plates touch the whole width."""
        r = getattr(indenter, "radius", None)
        return float(r) if r else FLAT_RADIUS

    def outer_length_to_x(self, x: float) -> float:
        return float(min(max(x, 0.0), self.half_width))

    def s_of_point(self, points) -> np.ndarray:
        """s = x, signed (a full-width model has x < 0; a half model only x >= 0)."""
        pts = np.atleast_2d(np.asarray(points, float))
        return np.clip(pts[:, 0], -self.half_width, self.half_width)

    def point_at_s(self, s) -> np.ndarray:
        s = np.asarray(s, float)
        if np.any(np.abs(s) > self.half_width + 1e-9):
            raise ParameterError("s", f"{np.min(s):g}..{np.max(s):g}",
                                 f"[-{self.half_width:g}, {self.half_width:g}] mm along the bonded surface")
        return np.stack([s, np.zeros_like(s)], axis=-1)

    def outer_points(self, n: int = 200) -> np.ndarray:
        x = np.linspace(0.0, self.half_width, n)
        return np.column_stack([x, np.full(n, self.thickness)])

    def interface_points(self, n: int = 200) -> np.ndarray:
        x = np.linspace(0.0, self.half_width, n)
        return np.column_stack([x, np.zeros(n)])

    def area(self) -> float:
        return self.half_width * self.thickness


@register
class PadSkin(Skin):
    name = "pad"
    local_plan = True
    full_width_if_asymmetric = True  # mesh.pad: x in [-W/2, W/2] for an x-asymmetric indenter
    order = 1
    scene_params = ("pad_width", "pad_length")
    fixed_boundaries = ("bone_interface",)
    s_path = "the board"
    s_axis = "distance across the pad s = x"  # on the board, from the centre line
    boundaries_2d = ("bone_interface", "outer_surface", "symmetry", "side")

    @classmethod
    def check_scene(cls, scene) -> dict:
        w = DEFAULT_WIDTH if scene.pad_width is None else scene.pad_width
        length = DEFAULT_LENGTH if scene.pad_length is None else scene.pad_length
        out = {"thickness": check_range("thickness", scene.thickness, *THICKNESS, unit="mm"),
               "pad_width": check_range("pad_width", w, *SIZE, unit="mm"),
               "pad_length": check_range("pad_length", length, *SIZE, unit="mm")}
        if scene.indenter_kind.name == "flat":
            for name in ("pad_width", "pad_length") if scene.dim == 3 else ("pad_width",):
                if out[name] > PLATE_SIZE:
                    raise ParameterError(name, out[name], f"[{SIZE[0]:g}, {PLATE_SIZE:g}] mm under the flat plate "
                                         f"(up to {SIZE[1]:g} mm under the other indenters)",
                                         "the plate presses the whole top: a wider bonded pad is confined and "
                                         "locks up; for a local press use a cylinder or sphere indenter")
        return out

    @classmethod
    def convergence_hint(cls, scene) -> str | None:
        if scene.indenter_kind.name != "flat":
            return None
        t = float(scene.thickness)
        sides = [("pad_width", float(scene.pad_width))]
        if scene.dim == 3:
            sides.append(("pad_length", float(scene.pad_length)))
        # in 3D the pad bulges out at its free ends too: its shorter side sets the confinement (a
        # 5 x 60 x 1 mm strip is no more confined than the 2D 5 t section, which solved)
        if min(v for _, v in sides) <= CONFINED_WIDTH_OVER_T * t:
            return None
        wide = " and ".join(f"{name} = {v:g} mm = {v / t:.3g} t" for name, v in sides)
        load = "force" if any(seg.kind == "force" for seg in scene.program()) else "depth"
        return (f"the bonded pad ({wide}) under the flat plate is confined and locks up: silicone pads "
                f"up to {CONFINED_WIDTH_OVER_T:g} t wide ({CONFINED_WIDTH_OVER_T * t:g} mm here) solved at 20 % depth "
                f"(10 t failed at 17 %, 60 t at 4 %), so use a narrower pad, a smaller {load}, or a local indenter "
                "(cylinder, sphere)")

    @classmethod
    def section(cls, scene) -> PadSection:
        return PadSection(float(scene.pad_width), float(scene.thickness), float(scene.pad_length))

    @classmethod
    def sample_length(cls, scene) -> float:
        return float(scene.pad_length)

    @classmethod
    def coordinates(cls, scene):
        from tactileskin.sensors import FlatCoordinates

        return FlatCoordinates(top=scene.thickness, thickness=scene.thickness, half_width=0.5 * scene.pad_width)

    @classmethod
    def build_mesh(cls, scene, *, cell: str = "tri", **overrides):
        from tactileskin.mesh.pad import build_pad_mesh

        return build_pad_mesh(scene, cell=cell, **overrides)

    @classmethod
    def buckling_strain(cls, scene) -> float | None:
        """Under the flat plate (wider than the pad) the pad is a column clamped to the board
        and guided by the frictionless plate over its whole top (effective length t): Euler's
        strain pi^2 / 12 (a / t)^2, a its smaller side. The model has no imperfection (and
        halves the pad by symmetry), so past it the solve follows the unbuckled branch: t = 10,
        width 2 at 20 % read 'ok' (Euler strain 3.3 %)."""
        from tactileskin import params

        if scene.indenter_kind.name != "flat" or scene.pad_width > float(params.load("indenters")["flat"]["width"]):
            return None
        a = scene.pad_width if scene.dim == 2 else min(scene.pad_width, scene.pad_length)
        return math.pi ** 2 / 12.0 * (a / scene.thickness) ** 2

    @classmethod
    def top_extent(cls, scene) -> tuple[float, float]:
        return 0.5 * float(scene.pad_width), 0.5 * float(scene.pad_length)

    @classmethod
    def size_plan(cls, scene):
        from tactileskin.mesh.pad import pad_plan

        return pad_plan(scene)[0]

    @classmethod
    def build_parts(cls, thickness, *, molds=True, pad_width=DEFAULT_WIDTH, pad_length=DEFAULT_LENGTH, **_):
        from tactileskin.geometry.pad_parts import build_pad_parts

        return build_pad_parts(thickness, pad_width, pad_length, molds=molds)

    @classmethod
    def cache_content(cls, scene) -> dict:
        """An x-asymmetric indenter is solved on the full width (mesh.pad): its key changes
        from the half model's it once had; a 3D Braille scene is meshed by the local plan
        (mesh.sizing.local_plan: fine at the dots only), not the strip plan it once had, and so
        is any 3D scene of a kind that touches in spots (`local_3d`); the other scenes keep
        their keys."""
        from tactileskin.geometry.indenters import indenter_symmetry

        out = {} if indenter_symmetry(scene)[0] else {"model": "full_width"}
        if scene.dim == 3 and scene.indenter_kind.local_3d:
            out["mesh_plan"] = "local"
        return out

    @classmethod
    def label(cls, scene) -> str:
        return f"pad{scene.pad_width:g}x{scene.pad_length:g}-"
