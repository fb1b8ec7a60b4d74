"""Element-size plan: global and refined sizes, the contact zone, the count estimate.

Pure numpy (no gmsh): the plan is checked before gmsh is called, so an absurd request is a
ParameterError, not a hang. `apply_fields` turns a plan into gmsh size fields.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from tactileskin.errors import ParameterError, check_range

logger = logging.getLogger(__name__)

ROI_S = 6.0  # mm: the paper reports bone pressure within 6 mm of s = 0; refine the interface there
MAX_ELEMENTS = {2: 2_000_000, 3: 5_000_000}
# cells per (size^dim) of area/volume for gmsh's Delaunay/Frontal meshes, measured on the
# fingertip section (benchmarks/mesh.py); with the zone areas below the estimate is 1-1.5x
# the actual count (an upper-side guess).
_CELLS_PER_UNIT = {2: 2.0, 3: 3.0}


@dataclass(frozen=True)
class SizePlan:
    coarse: float                      # global element size (mm)
    fine: float                        # refined size under the contact zone and along the ROI
    contact_x: float                   # contact zone: x <= contact_x (mm) ...
    contact_z: tuple[float, float]     # ... and z in this range (3D)
    contact_ymin: float                # ... and y >= contact_ymin (through the skin below it)
    roi_s: float                       # interface refined for s <= roi_s (mm)
    transition: float                  # width over which the size grows from fine to coarse
    estimate: int                      # estimated cell count

    def as_dict(self) -> dict:
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


def contact_halfwidth(scene, section) -> float:
    """Half-width (x, mm) of the skin that may touch the indenter at full depth, with margin.

    Hertz-like estimate sqrt(2 R d) with R the contour's radius at the top (a^2/b) and a
    factor 1.5 for the skin's own deformation; it bounds the convex (curved) indenter from
    above too. Braille: the dot row's extent plus a dot radius, and the flat estimate for
    the base plate if the depth exceeds the dot height.
    """
    ft = section.fingertip
    d = scene.indentation
    r_top = ft.half_width ** 2 / ft.height

    def flat(depth):
        return 1.5 * math.sqrt(2.0 * r_top * max(depth, 0.0))

    kind = scene.indenter.value
    if kind in ("flat", "curved"):
        w = flat(d)
    else:
        from tactileskin.geometry import braille

        std = braille.get_standard(scene.braille_standard)
        xz = braille.dot_centres(scene.braille_text, std)
        row = xz[np.argmin(np.abs(xz[:, 1])), 1]
        xs = xz[np.abs(xz[:, 1] - row) < 1e-9, 0]
        w = float(np.max(np.abs(xs))) + 2.0 * std.base_radius
        w = max(w, flat(d - std.height))
    return min(w, ft.half_width)


def contact_zrange(scene, length: float, z_symmetric: bool) -> tuple[float, float]:
    """z range of the contact zone in the 3D slab."""
    z0, z1 = (0.0, 0.5 * length) if z_symmetric else (-0.5 * length, 0.5 * length)
    if scene.indenter.value != "braille":
        return z0, z1  # plate and cylinder touch along the whole slab
    from tactileskin.geometry import braille

    std = braille.get_standard(scene.braille_standard)
    _, _, zmin, zmax = braille.footprint(scene.braille_text, std)
    m = std.base_radius
    return max(z0, zmin - m), min(z1, zmax + m)


def plan(scene, section, *, mesh_size: float | None = None, refinement: float | None = None,
         dim: int = 2, length: float | None = None, z_symmetric: bool = False) -> SizePlan:
    """Sizes for `section`; raises ParameterError if a size is not positive or the estimate
    exceeds MAX_ELEMENTS[dim]."""
    coarse = scene.mesh_size if mesh_size is None else mesh_size
    ratio = scene.refinement if refinement is None else refinement
    coarse = check_range("mesh_size", coarse, 0.0, None, lo_open=True, unit="mm")
    ratio = check_range("refinement", ratio, 1.0, None)
    fine = coarse / ratio
    t = section.thickness
    ft = section.fingertip
    w = contact_halfwidth(scene, section)
    y_w = float(ft.outer(np.arcsin(min(w / ft.half_width, 1.0)))[1])
    ymin = y_w - t
    zr = (0.0, 0.0)
    roi = min(ROI_S, section.interface_length)
    trans = 4.0 * coarse

    # estimate: coarse everywhere plus the two refined zones (with half the transition)
    area = section.area()
    a_contact = min(area, (w + 0.5 * trans) * (t + 0.5 * trans))
    a_band = roi * min(t, fine + 0.5 * trans)
    if dim == 2:
        n = _CELLS_PER_UNIT[2] * (area / coarse ** 2 + (a_contact + a_band) / fine ** 2)
    else:
        if length is None:
            raise ParameterError("length", length, "> 0 mm (slab length along z)")
        lz = 0.5 * length if z_symmetric else length
        zr = contact_zrange(scene, length, z_symmetric)
        lc = min(lz, zr[1] - zr[0] + trans)
        n = _CELLS_PER_UNIT[3] * (area * lz / coarse ** 3 + (a_contact * lc + a_band * lz) / fine ** 3)
    n = int(n)
    cap = MAX_ELEMENTS[dim]
    if n > cap:
        hf = fine * (n / cap) ** (1.0 / dim)
        raise ParameterError(
            "mesh_size", coarse,
            f"a size giving at most {cap:.0e} cells in {dim}D; the request (mesh_size={coarse:g} mm, "
            f"refinement={ratio:g}, refined size {fine:.3g} mm) needs about {n:.2e}",
            hint=f"keep the refined size mesh_size/refinement above about {hf:.3g} mm")
    return SizePlan(coarse, fine, w, zr, ymin, roi, trans, n)


def apply_fields(gmsh, p: SizePlan, interface_roi: list[int], dim: int) -> None:
    """Install the size fields: Min(box under the contact, threshold on distance to the ROI)."""
    f = gmsh.model.mesh.field
    box = f.add("Box")
    f.setNumber(box, "VIn", p.fine)
    f.setNumber(box, "VOut", p.coarse)
    f.setNumber(box, "XMin", -1.0)
    f.setNumber(box, "XMax", p.contact_x)
    f.setNumber(box, "YMin", p.contact_ymin)
    f.setNumber(box, "YMax", 1e3)
    zmin, zmax = p.contact_z if dim == 3 else (-1.0, 1.0)
    f.setNumber(box, "ZMin", zmin - (1.0 if dim == 3 and zmin == 0.0 else 0.0))
    f.setNumber(box, "ZMax", zmax)
    f.setNumber(box, "Thickness", p.transition)

    dist = f.add("Distance")
    f.setNumbers(dist, "CurvesList" if dim == 2 else "SurfacesList", interface_roi)
    f.setNumber(dist, "Sampling", 400 if dim == 2 else 60)
    thr = f.add("Threshold")
    f.setNumber(thr, "InField", dist)
    f.setNumber(thr, "SizeMin", p.fine)
    f.setNumber(thr, "SizeMax", p.coarse)
    f.setNumber(thr, "DistMin", p.fine)
    f.setNumber(thr, "DistMax", p.fine + p.transition)

    mn = f.add("Min")
    f.setNumbers(mn, "FieldsList", [box, thr])
    f.setAsBackgroundMesh(mn)
    # the fields alone decide the size
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.MeshSizeMax", p.coarse)
    gmsh.option.setNumber("Mesh.MeshSizeMin", p.fine)
