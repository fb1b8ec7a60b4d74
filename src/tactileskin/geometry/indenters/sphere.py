"""sphere: a rigid ball of radius R whose lowest point starts at (0, y0, 0).

Not uniform along the finger, so 3D only: its plane-strain section would be a cylinder
(use the cylinder kind with axis z for that model, and say so)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tactileskin.errors import ParameterError
from tactileskin.geometry.indenters.base import RADIUS, Indenter, check_radius, hertz_halfwidth, stem_params
from tactileskin.geometry.indenters.registry import register


# the printed ball's working face: a cap this fraction of R high (solids.sphere_indenter fuses
# it into a plate there); deeper presses are refused
CAP = 0.95
# The largest ball (mm): its printed part (solids.sphere_indenter, a 2.4 R plate under the
# ball) is then 240 mm across, a desktop printer's bed. The ball cannot be cut to the part
# that touches the skin as the cylinder's strip is: its contact grows as sqrt(2 R d) along the
# finger as well as across it, so a cut face would end inside the contact the model has. Past
# it the build grows with R (R 100: 8 s, a 5 MB STL; R 1000: 176 s, 46 MB, for a part
# 2.4 m across); a larger ball on a fingertip-sized skin approaches the flat plate.
MAX_RADIUS = 100.0
RADIUS_HINT = (f"the printed ball is 2.4 R across (a desktop printer's bed at R {MAX_RADIUS:g}); "
               "a larger one on a fingertip-sized skin approaches the flat indenter")


@register
@dataclass(frozen=True, eq=False)
class SphereIndenter(Indenter):
    radius: float = 2.5

    name = "sphere"
    order = 11
    scene_params = ("indenter_radius",)
    section_2d = None
    local_3d = True
    radius_range = (RADIUS[0], MAX_RADIUS)

    @classmethod
    def check_scene(cls, scene) -> dict:
        radius = check_radius(scene.indenter_radius, cls.name, *cls.radius_range, hint=RADIUS_HINT)
        if scene.dim == 2:
            raise ParameterError("dim", 2, "3 for the sphere indenter",
                                 "a sphere is not uniform along the finger; its plane-strain section "
                                 "is a cylinder: use indenter = 'cylinder' (indenter_axis = 'z') for "
                                 "that 2D model")
        if scene.force is None and not scene.loading:
            # past its cap the ball would sink to its mount (and in the model, wrap the skin
            # round its equator): the printed part presses with its plate there
            depth = scene.depth if scene.depth is not None else scene.depth_fraction * scene.thickness
            if depth > CAP * radius:
                raise ParameterError("depth", depth, f"<= {CAP:g} x indenter_radius = {CAP * radius:.3g} mm "
                                     "for the sphere indenter",
                                     f"the ball's working face is a cap {CAP:g} R high; its mount plate starts "
                                     "there: use a larger indenter_radius or a smaller depth")
        return {"indenter_radius": radius}

    @classmethod
    def label(cls, scene) -> str:
        return f"sphere-R{scene.indenter_radius:g}"

    @classmethod
    def from_params(cls, *, y0, dim, length, row=None, warn=True, indenter_radius=None, **_):
        R = check_radius(indenter_radius, cls.name, *cls.radius_range, hint=RADIUS_HINT)
        # the standard stem: a ball narrower than it gets a mount block (solids._add_stem)
        return cls(kind=cls.name, y0=y0, dim=dim, width=2.0 * R, length=2.0 * R, radius=R, **stem_params())

    @property
    def tip_radius(self) -> float:
        return float(self.radius)

    @property
    def working_depth(self) -> float:
        return CAP * float(self.radius)

    def centre(self, d: float = 0.0) -> np.ndarray:
        return np.array([0.0, self.y0 + self.radius - d, 0.0])

    def _gap(self, p, d):
        c = self.centre(d)[: p.shape[1]]  # 2D points: the section z = 0 through the centre
        v = p - c
        dist = np.sqrt(np.einsum("ij,ij->i", v, v))
        at_centre = dist == 0.0
        n = v / np.where(at_centre, 1.0, dist)[:, None]
        n[at_centre] = 0.0
        n[at_centre, 1] = -1.0  # at the centre any direction is a normal; take -y
        return dist - self.radius, n

    def _surface_y(self, x, z, d):
        rho2 = x * x + (0.0 if z is None else z * z)
        return self.centre(d)[1] - np.sqrt(np.maximum(self.radius ** 2 - rho2, 0.0))

    def contact_zrange(self, depth):
        a = hertz_halfwidth(self.radius, depth)  # the skin is straight along z
        return -a, a

    def contact_patches(self, depth):
        """One spot at the pole, of the ball's chord radius at the depth on a flat top (the
        curved fingertip and the skin's own give make the contact no wider)."""
        d = min(max(float(depth), 0.0), self.radius)
        return ((0.0, 0.0, math.sqrt(2.0 * self.radius * d - d * d)),)

    def solid(self):
        from tactileskin.geometry import solids

        return solids.sphere_indenter(self)

    def describe(self) -> str:
        return f"sphere indenter, R = {self.radius:g} mm"

    def part_parameters(self) -> dict:
        return {"radius": self.radius}
