"""The indenter contract: what every kind answers for itself (pure numpy).

Conventions (mm): x lateral, y towards the pulp, z along the finger. The indenter sits above
the skin; its lowest point starts at y0 (the skin top on x = 0) and moves by -d (d >= 0 the
travel). `gap(points, d)` returns the signed distance g from each point to the indenter
surface (g > 0 separated, g < 0 inside the indenter) and the unit normal n of the indenter
surface at the closest point, pointing out of the indenter towards the skin (the gradient
of g). Points may be (..., 2) (the plane section z = section_z) or (..., 3).

A kind is a subclass registered with `registry.register`; it declares the Scene fields it
reads (`scene_params`), validates them (`check_scene`), builds itself from a scene
(`from_params`), and answers its symmetry, its 2D model (`section_2d`), its contact extent
for mesh sizing, the planes where it first touches, its label and its printable solid.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from tactileskin.errors import ParameterError, check_range

# Scene fields that only some kinds take (None = not given). A kind lists the ones it reads
# in `scene_params`; the Scene refuses a value for a kind that does not read it.
KIND_FIELDS = ("indenter_radius", "indenter_axis", "indenter_file")


def as_points(points) -> tuple[np.ndarray, tuple[int, ...]]:
    p = np.asarray(points, dtype=float)
    if p.ndim < 1 or p.shape[-1] not in (2, 3):
        raise ParameterError("points", f"array of shape {p.shape}", "shape (..., 2) or (..., 3)")
    if not np.isfinite(p).all():
        raise ParameterError("points", "non-finite coordinates", "finite coordinates (mm)")
    return p.reshape(-1, p.shape[-1]), p.shape[:-1]


def check_d(d) -> float:
    return check_range("d", d, 0.0, None, unit="mm")


def hertz_halfwidth(r_top: float, depth: float) -> float:
    """Contact half-width estimate sqrt(2 R d) against a skin of top radius R, times 1.5 for
    the skin's own deformation; it bounds a convex indenter on that skin from above."""
    return 1.5 * math.sqrt(2.0 * r_top * max(depth, 0.0))


@dataclass(frozen=True, eq=False)
class Indenter:
    """Common data of the indenters. Use `make_indenter` / `indenter_for_scene`."""

    kind: str
    y0: float                # lowest point at d = 0 (mm)
    dim: int                 # model dimension the indenter was made for (2 or 3)
    width: float             # x extent of the working face (mm)
    length: float            # z extent of the working face / base plate (mm)
    stem_diameter: float
    stem_length: float

    # -- what the kind declares (class level) ----------------------------------------------
    name: ClassVar[str] = ""                 # the kind's name in Scene.indenter and TOML
    order: ClassVar[int] = 100               # listing order (the paper's kinds first)
    scene_params: ClassVar[tuple[str, ...]] = ()  # Scene fields the kind reads
    # "exact": uniform along the finger, the 2D plane-strain section is exact; "ridge": a 2D
    # model exists but approximates (Braille: the dot row as a ridge); None: 3D only.
    section_2d: ClassVar[str | None] = "exact"
    fine_2d_mesh: ClassVar[bool] = False     # 2D uses the finer preset mesh (small features)
    paper: ClassVar[bool] = False            # one of the paper's indenters (build "all")
    # 3D: touches in compact spots (`contact_patches`), meshed on the local plan at the local
    # presets' sizes (data/presets.json "braille_mesh"); False: the strip plan ("mesh")
    local_3d: ClassVar[bool] = False
    # (lo, hi] mm of indenter_radius for a kind that reads it: what its check takes and --help quotes
    radius_range: ClassVar[tuple[float, float] | None] = None

    @classmethod
    def model_2d(cls, scene) -> str | None:
        """The 2D model of the scene's indenter: "exact", "ridge" or None (see section_2d)."""
        return cls.section_2d

    @classmethod
    def check_scene(cls, scene) -> dict:
        """Validate the kind's parameters of `scene` (ParameterError naming the field and its
        valid range); return normalised values of Scene fields to store."""
        if scene.dim == 2 and cls.model_2d(scene) is None:
            raise ParameterError("dim", 2, f"3 for the {cls.name} indenter",
                                 f"the {cls.name} indenter is not uniform along the finger, so a "
                                 "plane-strain section does not model it")
        return {}

    @classmethod
    def label(cls, scene) -> str:
        """Short name of the scene's indenter for case ids, tables and figures."""
        return cls.name

    @classmethod
    def cache_content(cls, scene) -> dict:
        """Content of files the kind reads, for the cache key: {scene field: digest}."""
        return {}

    @classmethod
    def from_params(cls, *, y0: float, dim: int, length: float, row: int | None, warn: bool,
                    **params) -> "Indenter":  # pragma: no cover - abstract
        raise NotImplementedError

    # -- interface -------------------------------------------------------------------------
    def gap(self, points, d: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Signed distance g (...,) and unit outward normal n (..., D) of points (..., D), D = 2 or 3."""
        p, shape = as_points(points)
        g, n = self._gap(p, check_d(d))
        return g.reshape(shape), n.reshape(shape + (p.shape[-1],))

    def surface_y(self, x, z=None, d: float = 0.0) -> np.ndarray:
        """y of the working face at (x[, z]) (the lowest point of the solid on that vertical line).

        Without z: the 2D section. Valid on the face, |x| <= width/2 (and |z| <= length/2);
        points outside raise ParameterError.
        """
        x = np.asarray(x, dtype=float)
        if np.any(np.abs(x) > 0.5 * self.width + 1e-9):
            raise ParameterError("x", f"max |x| = {np.abs(x).max():g}", f"|x| <= {0.5 * self.width:g} mm (face half-width)")
        if z is not None:
            z = np.asarray(z, dtype=float)
            if np.any(np.abs(z) > 0.5 * self.length + 1e-9):
                raise ParameterError("z", f"max |z| = {np.abs(z).max():g}", f"|z| <= {0.5 * self.length:g} mm (face half-length)")
            x, z = np.broadcast_arrays(x, z)
        return self._surface_y(x, z, check_d(d))

    @property
    def lowest_point(self) -> float:
        return self.y0

    @property
    def tip_radius(self) -> float:
        """Smallest radius of curvature (mm) of the working face where it first touches: the
        strain a travel d makes there scales as sqrt(d / R) (inf: flat or unknown)."""
        return float("inf")

    @property
    def section_z(self) -> float:
        """z of the plane whose section a 2D model (and the 3D profile) uses."""
        return 0.0

    def face_box(self) -> tuple[float, float, float, float]:
        """(xmin, xmax, zmin, zmax) of the working face, centred on x = 0, z = 0."""
        return (-0.5 * self.width, 0.5 * self.width, -0.5 * self.length, 0.5 * self.length)

    def symmetry(self, depth: float | None = None) -> tuple[bool, bool]:
        """(about x = 0, about z = 0): mirror symmetry of the indenter (of the part that can
        touch the skin within `depth` of travel, where the kind can tell)."""
        return True, True

    def contact_halfwidth(self, depth: float, r_top: float) -> float:
        """Half-width (x, mm) of the skin that may touch the indenter at full depth, with
        margin, on a skin whose top has radius r_top (clipped to the skin by the caller)."""
        return hertz_halfwidth(r_top, depth)

    def contact_zrange(self, depth: float) -> tuple[float, float] | None:
        """z range (mm) of the contact zone in 3D; None: the whole slab."""
        return None

    def contact_patches(self, depth: float) -> tuple[tuple[float, float, float], ...] | None:
        """(x, z, a) of each compact spot of the face that can touch the skin within `depth` of
        travel: its centre (x, z) and a bound a on its radius (mm), for the 3D local mesh plan
        (mesh.sizing.local_plan). None: the contact is a strip along the slab (the strip plan)."""
        return None

    def plate_depth(self, depth: float) -> float:
        """How far (mm) a flat part of the face that spans the slab presses at `depth` (the
        Braille base plate past the dot height); 0: none does."""
        return 0.0

    @property
    def working_depth(self) -> float:
        """Travel (mm) beyond which the printed part would press with more than the modelled
        face (its mount); inf where the model is the whole part."""
        return float("inf")

    def face_halfwidths(self) -> tuple[float, float]:
        """Half extents (x, z; mm) of the printed working face about x = 0, z = 0: past them the
        printed part has its sides, back or mount where the model has more of the face; inf
        where the model's face is the whole part's."""
        return float("inf"), float("inf")

    def working_travel(self, section, length: float) -> float:
        """`working_depth` on a given skin (its `section`, `length` long along z), where the kind
        can tell that the skin meets the printed part's other faces later or never."""
        return self.working_depth

    def contact_planes(self) -> np.ndarray:
        """z planes on which the first touch is sought in 3D (the slab is uniform along z)."""
        return np.zeros(1)

    def describe(self) -> str:
        """One line for the part list."""
        return f"{self.name} indenter"

    def part_parameters(self) -> dict:
        """What the printable part is made from (manifest)."""
        return {}

    def solid(self):
        """The printable indenter (build123d) in its scene position, with its mounting stem;
        a kind calls its builder in geometry/solids.py (build123d stays at that edge)."""
        from tactileskin.errors import CadError

        raise CadError(f"no printable solid for the {self.kind} indenter")

    # implemented by the kinds
    def _gap(self, p: np.ndarray, d: float):  # pragma: no cover - abstract
        raise NotImplementedError

    def _surface_y(self, x, z, d):  # pragma: no cover - abstract
        raise NotImplementedError


RADIUS = (0.1, 1000.0)  # mm: indenter_radius of a sphere or cylinder, (lo, hi] (a kind may take less)


def radius_ranges() -> dict[str, tuple[float, float]]:
    """{kind: its radius_range} of the registered kinds that read indenter_radius."""
    from tactileskin.geometry.indenters.registry import get, names

    return {n: get(n).radius_range for n in names() if "indenter_radius" in get(n).scene_params}


def check_radius(value, kind: str, lo: float = RADIUS[0], hi: float = RADIUS[1], hint: str = "") -> float:
    if value is None:
        raise ParameterError("indenter_radius", None, f"({lo:g}, {hi:g}] mm for the {kind} indenter",
                             "the radius is required (no default)")
    try:
        return check_range("indenter_radius", value, lo, hi, lo_open=True, unit="mm")
    except ParameterError as e:
        if not hint:
            raise
        raise ParameterError("indenter_radius", value, f"{e.valid} for the {kind} indenter", hint) from None


def stem_params() -> dict:
    """The mounting stem every printable indenter carries (indenters.toml [stem])."""
    from tactileskin import params

    p = params.load("indenters")["stem"]
    return dict(stem_diameter=float(p["diameter"]), stem_length=float(p["length"]))
