"""cylinder: a rigid solid cylinder of any radius, axis along z (uniform along the finger:
the 2D section is exact) or along x (across the finger: 3D only); and curved, the paper's
R = 12 mm cylinder along z (indenters.toml [curved]).

The lowest line of the cylinder starts at y0 and moves by -d; the axis is at y0 - d + R.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tactileskin import params
from tactileskin.errors import ParameterError
from tactileskin.geometry.indenters.base import RADIUS, Indenter, check_radius, hertz_halfwidth, stem_params
from tactileskin.geometry.indenters.registry import register

AXES = ("z", "x")


@register
@dataclass(frozen=True, eq=False)
class CylinderIndenter(Indenter):
    radius: float = 12.0
    axis: str = "z"             # "z": along the finger; "x": across it
    back_thickness: float = 4.0

    name = "cylinder"
    order = 10
    scene_params = ("indenter_radius", "indenter_axis")
    radius_range = RADIUS

    @classmethod
    def model_2d(cls, scene) -> str | None:
        return "exact" if (scene.indenter_axis or "z") == "z" else None

    @classmethod
    def check_scene(cls, scene) -> dict:
        radius = check_radius(scene.indenter_radius, cls.name, *cls.radius_range)
        axis = "z" if scene.indenter_axis is None else scene.indenter_axis
        if axis not in AXES:
            raise ParameterError("indenter_axis", axis, "'z' (along the finger) or 'x' (across it)")
        if scene.dim == 2 and axis != "z":
            raise ParameterError("dim", 2, "3 for a cylinder with indenter_axis = 'x'",
                                 "a cylinder across the finger is not uniform along it; use dim = 3, "
                                 "or indenter_axis = 'z' for the plane-strain section")
        return {"indenter_radius": radius, "indenter_axis": axis}

    @classmethod
    def label(cls, scene) -> str:
        return f"cylinder-R{scene.indenter_radius:g}" + ("-x" if scene.indenter_axis == "x" else "")

    @classmethod
    def from_params(cls, *, y0, dim, length, row=None, warn=True, indenter_radius=None,
                    indenter_axis=None, **_):
        R = check_radius(indenter_radius, cls.name, *cls.radius_range)
        axis = indenter_axis or "z"
        q = params.load("indenters")
        chord = min(float(q["curved"]["chord_width"]), 1.8 * R)
        width, length = (chord, length) if axis == "z" else (float(q["flat"]["width"]), min(length, 1.8 * R))
        sagitta = R - math.sqrt(R * R - 0.25 * chord * chord)
        back = min(float(q["curved"]["back_thickness"]), 0.5 * (R - sagitta))
        stem = stem_params()  # standard; a back narrower than it gets a mount block (solids._add_stem)
        return cls(kind=cls.name, y0=y0, dim=dim, width=width, length=length, radius=R, axis=axis,
                   back_thickness=back, **stem)

    @property
    def tip_radius(self) -> float:
        return float(self.radius)

    @property
    def chord(self) -> float:
        """Extent of the curved face across the axis."""
        return self.width if self.axis == "z" else self.length

    @property
    def sagitta(self) -> float:
        """Rise of the arc from its lowest point to the face edge (half the chord off the axis)."""
        R, c = self.radius, 0.5 * self.chord
        return R - math.sqrt(R * R - c * c)

    def working_travel(self, section, length: float) -> float:
        """The printed face is the strip of the cylinder one chord wide (solids.cylinder_indenter):
        its edges, and the back and the mount above them, start the sagitta above its lowest line,
        where the model's cylinder goes on round. The travel after which they first meet the
        undeformed skin: the sagitta plus how far below y0 the skin's top lies where the face ends
        (across the axis); inf where the skin ends within the face. A travel past it is flagged
        (fe.solve: indenter_cap), not refused: a soft skin sinks away from the edges (R 0.5 on a 1 mm
        pad at 0.4 mm: contact to x = 0.413 of the arc's 0.45), so it bounds the trouble from above."""
        c = 0.5 * self.chord
        if self.axis == "x":  # the chord runs along z, where the skin's top is straight
            return self.sagitta if 0.5 * length > c + 1e-9 else math.inf
        pts = section.outer_points(4000)
        x, y = np.abs(pts[:, 0]), pts[:, 1]
        beyond = x > c + 1e-9
        if not beyond.any():
            return math.inf
        top = float(y[beyond].max())
        if not beyond.all():  # the top at x = c itself, between the samples either side (a file's are unordered)
            i = np.flatnonzero(~beyond)[np.argmax(x[~beyond])]
            j = np.flatnonzero(beyond)[np.argmin(x[beyond])]
            top = max(top, float(np.interp(c, [x[i], x[j]], [y[i], y[j]])))
        return self.sagitta + max(self.y0 - top, 0.0)

    def _gap(self, p, d):
        R = self.radius
        across = 0 if self.axis == "z" else 2   # the coordinate across the axis besides y
        v = np.zeros_like(p)  # from the axis to the point, in the plane normal to the axis
        if across < p.shape[1]:
            v[:, across] = p[:, across]
        v[:, 1] = p[:, 1] - (self.y0 - d + R)
        dist = np.hypot(v[:, across] if across < p.shape[1] else 0.0, v[:, 1])
        n = np.zeros_like(p)
        on_axis = dist == 0.0
        safe = np.where(on_axis, 1.0, dist)
        if across < p.shape[1]:
            n[:, across] = v[:, across] / safe
        n[:, 1] = np.where(on_axis, -1.0, v[:, 1] / safe)  # on the axis: any direction; take -y
        return dist - R, n

    def _surface_y(self, x, z, d):
        R = self.radius
        c = x if self.axis == "z" else (np.zeros(np.shape(x)) if z is None else z)
        return self.y0 - d + R - np.sqrt(R * R - c * c)

    def face_halfwidths(self) -> tuple[float, float]:
        # the printed face is the arc of `chord` across the axis (solids.cylinder_indenter); the
        # model's gap is the whole circle
        return (0.5 * self.chord, float("inf")) if self.axis == "z" else (0.5 * self.width, 0.5 * self.chord)

    def contact_zrange(self, depth):
        if self.axis == "z":
            return None  # touches along the whole slab
        a = hertz_halfwidth(self.radius, depth)  # the skin is straight along z
        return -a, a

    def solid(self):
        from tactileskin.geometry import solids

        return solids.cylinder_indenter(self)

    def describe(self) -> str:
        return f"cylinder indenter, R = {self.radius:g} mm, axis along {self.axis}"

    def part_parameters(self) -> dict:
        return {"radius": self.radius, "axis": self.axis}


@register
@dataclass(frozen=True, eq=False)
class CurvedIndenter(CylinderIndenter):
    """The paper's convex indenter: the cylinder of indenters.toml [curved] along z."""

    name = "curved"
    order = 1
    scene_params = ()
    paper = True

    @classmethod
    def model_2d(cls, scene) -> str | None:
        return "exact"

    @classmethod
    def check_scene(cls, scene) -> dict:
        return {}

    @classmethod
    def label(cls, scene) -> str:
        return cls.name

    @classmethod
    def from_params(cls, *, y0, dim, length, row=None, warn=True, **_):
        q = params.load("indenters")["curved"]
        R, w = float(q["radius"]), float(q["chord_width"])
        if not 0.0 < w < 2.0 * R:
            raise ParameterError("curved.chord_width", w, f"(0, {2 * R:g}) mm (less than the diameter)")
        return cls(kind=cls.name, y0=y0, dim=dim, width=w, length=length, radius=R, axis="z",
                   back_thickness=float(q["back_thickness"]), **stem_params())

    def describe(self) -> str:
        return f"convex indenter, R = {self.radius:g} mm"

    def part_parameters(self) -> dict:
        return {"radius": self.radius}
