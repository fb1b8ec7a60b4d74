"""Printable parts of a user's STEP skin (skins.file): the skin as read and its two-part casting
mold, made as the pad's (pad_parts.py) for a skin bonded on one flat face.

Frame the file's (the solver's): contact face up (+y), its bonded faces (the rule `skin_bonded`
picks, mesh.skinfile.bonded_plane) all in one plane y = y_b, facing -y. The mold casts the skin
face down:
- lower part: a block around the skin, `wall` beyond it, minus the skin: a pocket open at the
  split plane y = y_b (its floor is the skin's contact face); four alignment pins on the split
  face at the corners of the skin's footprint, as the pad's;
- upper part (lid): a plate over y < y_b with the pin holes, an air vent `vent_inset` from each
  end of the bonded face along the line x = 0 (as the pad's) and the sprue beside the z < 0
  vent with 1 mm of mold between them: off the middle, where the indenters press (the pad's
  sprue is at its centre). The sensor board, if it is to be bonded while curing, replaces the
  lid. Every hole must open wholly onto the bonded plane. Sizes from data/geometry/molds.toml.
Undercuts: the cast comes out of the pocket along -y, through its opening. Where the skin is
wider above than at some section between there and the bonded face (an overhang, a dovetail
groove, a ball on a neck), the pocket holds it; those are also ceilings under which air may
stay while pouring (the lid's vents reach only the bonded plane). Elsewhere the vents on x = 0
are at the cavity's top: poured lid up, the bonded plane is its highest level (the skin lies
wholly at y >= y_b, checked), and a ridge or a high side off x = 0 is the pocket's floor,
which fills first. `undercut` measures how far (mm) the cast must squeeze sideways
there; a silicone skin stretches out of a shallow one: up to UNDERCUT_SILENT nothing is said
(below a printed layer's step), up to UNDERCUT_REFUSE the mold is written with a warning (log,
the lower part's description and the mold parts' `undercut_mm`), deeper it is refused.
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from tactileskin.errors import CadError, ParameterError
from tactileskin.geometry.molds import MoldParams
from tactileskin.geometry.occ import bd
from tactileskin.geometry.pad_parts import face_down_mold
from tactileskin.geometry.parts import Part
from tactileskin.geometry.solids import check_solid, occ_guard

log = logging.getLogger(__name__)

NO_MOLDS = "or build without molds (--no-molds)"
# undercut depths (mm): below SILENT, a printed layer's own step; above REFUSE, more than the
# thinnest skin (1 mm) would have to squeeze or fold to pass: it tears or stays held
UNDERCUT_SILENT = 0.05
UNDERCUT_REFUSE = 1.0


def read_skin(path) -> bd.Solid:
    """The one solid of a STEP skin file (CadError if it is not one valid solid)."""
    p = dict(skin_file=str(path))
    with occ_guard("reading the skin's STEP", **p):
        shape = bd.import_step(str(path))
    return check_solid(shape, f"the skin in {Path(str(path)).name}", **p)


def _bonded_faces(skin: bd.Solid, y_b: float, tol: float) -> list[bd.Face]:
    """The skin's faces in the plane y = y_b (the pocket's opening, which the lid closes)."""
    out = []
    for f in skin.faces():
        bb = f.bounding_box()
        if f.geom_type == bd.GeomType.PLANE and abs(bb.min.Y - y_b) <= tol and abs(bb.max.Y - y_b) <= tol:
            out.append(f)
    return out


def _overhang(faces: list[bd.Face], x: float, z: float, y_b: float, diameter: float) -> float:
    """Area (mm^2) of the hole's disc at (x, z) that lies off the bonded faces."""
    disc = bd.Face(bd.Wire([bd.Edge.make_circle(0.5 * diameter, plane=bd.Plane((x, y_b, z), x_dir=(1, 0, 0),
                                                                                 z_dir=(0, -1, 0)))]))
    on = 0.0
    for f in faces:  # a bonded face split in several (as CAD exports often are) the disc may miss
        common = disc.intersect(f)
        on += sum(g.area for g in common.faces()) if common is not None else 0.0
    return max(0.0, disc.area - on)


def hole_positions(faces: list[bd.Face], y_b: float, lo_z: float, hi_z: float, mp: MoldParams, path):
    """((x, z) of the sprue, [(x, z) of the two vents]) on the line x = 0 of the bonded faces:
    the vents `vent_inset` from its ends, the sprue 1 mm of mold beyond the z < 0 vent."""
    line = bd.Edge.make_line((0.0, y_b, lo_z - 1.0), (0.0, y_b, hi_z + 1.0))
    zs = []
    for f in faces:
        for e in f.intersect(line) or ():
            zs += [e.bounding_box().min.Z, e.bounding_box().max.Z]
    rs, rv = 0.5 * mp.pour_diameter, 0.5 * mp.vent_diameter
    need = 2.0 * (mp.vent_inset + rv + 1.0 + rs)  # as the pad's: 11.5 mm with molds.toml's sizes
    name = Path(str(path)).name
    if not zs or max(zs) - min(zs) < need:
        got = f"{max(zs) - min(zs):.4g} mm long there" if zs else "not crossed by it"
        raise ParameterError("skin_file", str(path), f"a skin whose bonded face runs >= {need:g} mm along z on "
                             "x = 0 for the mold's sprue and two vents (molds.toml [pour])",
                             f"{name}'s is {got}; {NO_MOLDS}")
    z0, z1 = min(zs), max(zs)
    vents = [(0.0, z0 + mp.vent_inset), (0.0, z1 - mp.vent_inset)]
    sprue = (0.0, vents[0][1] + rv + 1.0 + rs)
    for what, (x, z), d in [("sprue", sprue, mp.pour_diameter)] + [("vent", v, mp.vent_diameter) for v in vents]:
        off = _overhang(faces, x, z, y_b, d)
        if off > 1e-6 * d * d:
            raise ParameterError("skin_file", str(path), "a bonded face under the whole of the mold's sprue and vents "
                                 "(on x = 0)", f"{name}'s leaves {off:.3g} mm^2 of the {d:g} mm {what} at "
                                 f"z = {z:.4g} mm off it, over the mold's wall; {NO_MOLDS}")
    return sprue, vents


def _outline(loops: list[np.ndarray], step: float) -> np.ndarray:
    """Points every `step` (mm) or closer along the closed polygons `loops` ((n, 2) each)."""
    q = np.concatenate(loops)
    e = np.concatenate([np.roll(c, -1, axis=0) - c for c in loops])
    n = np.maximum(1, np.ceil(np.linalg.norm(e, axis=1) / step)).astype(int)
    i = np.repeat(np.arange(len(q)), n)
    k = np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)
    return q[i] + (k / n[i])[:, None] * e[i]


def undercut(skin: bd.Solid, y_b: float, tol: float = 0.01, step: float = 0.02):
    """(depth (mm), (x, y, z) where deepest) of the skin's undercut along the pull, -y out through
    its bonded plane y = y_b: the largest distance of a point of a section y = const of the skin
    from the part of that section that every section between it and y = y_b also covers (the
    throat it must pass), i.e. how far it must squeeze sideways; (0, None) for none. Measured
    on a `tol` mm tessellation, to within `step` / 2, on sections just above and below every
    height of its vertices (between them the facets' sections change linearly)."""
    import manifold3d
    import trimesh
    from scipy.spatial import cKDTree

    v, f = skin.tessellate(tol, 0.2)
    mesh = trimesh.Trimesh(np.array([tuple(p) for p in v]), np.array(f), process=True)  # merge the faces' seams
    xzy = np.ascontiguousarray(np.asarray(mesh.vertices)[:, [0, 2, 1]], np.float64)  # slices are z = const
    solid = manifold3d.Manifold(manifold3d.Mesh64(vert_properties=xzy, tri_verts=np.ascontiguousarray(
        np.asarray(mesh.faces)[:, ::-1], np.uint64)))  # swapping y and z mirrors: reverse the winding
    if solid.status() != manifold3d.Error.NoError:
        # the mold is what needs the measure: the skin alone is built without it
        raise CadError(f"measuring the skin's undercut: its {tol:g} mm tessellation is no closed volume "
                       f"({solid.status()}); {NO_MOLDS}")
    heights = np.unique(np.round(xzy[:, 2] / tol) * tol)
    heights = np.concatenate([[y_b], heights[heights > y_b + tol]])
    depth, where, throat = 0.0, None, None
    for lo, hi in zip(heights[:-1], heights[1:]):
        d = min(1e-4, 0.25 * (hi - lo))
        for y in (lo + d, hi - d):
            section = solid.slice(y)
            if throat is None:
                throat = None if section.is_empty() else section
                continue
            out = section - throat
            if out.area() > tol * tol:
                # the farthest point lies on its outline; the throat's sampled as finely: the
                # distance to a sample is at most step / 2 more than to the outline
                pts = _outline(out.to_polygons(), step)
                far, i = cKDTree(_outline(throat.to_polygons(), step)).query(pts)
                if far.max() > depth:
                    i = int(far.argmax())
                    depth, where = float(far[i]), (float(pts[i, 0]), float(y), float(pts[i, 1]))
            common = throat ^ section
            if not common.is_empty():  # else (a leaning part) what follows is measured from the last one
                throat = common
    return depth, where


def check_undercut(skin: bd.Solid, y_b: float, path) -> float:
    """The skin's undercut depth (mm, `undercut`): ParameterError above UNDERCUT_REFUSE, a
    warning above UNDERCUT_SILENT."""
    depth, at = undercut(skin, y_b)
    if depth <= UNDERCUT_SILENT:
        return depth
    name = Path(str(path)).name
    where = f"{depth:.3g} mm deep at (x, y, z) = ({at[0]:.3g}, {at[1]:.3g}, {at[2]:.3g}) mm"
    if depth > UNDERCUT_REFUSE:
        raise ParameterError("skin_file", str(path), f"a skin the mold releases along -y (out through its bonded face "
                             f"y = {y_b:.4g} mm) with an undercut <= {UNDERCUT_REFUSE:g} mm",
                             f"{name}'s pocket holds it by an undercut {where}; {NO_MOLDS}")
    log.warning("%s: the mold's pocket holds the cast by an undercut %s (it must squeeze that far sideways to come "
                "out along -y; a soft silicone stretches out of up to %g mm, a stiff one may tear), and air may stay "
                "under it while pouring", name, where, UNDERCUT_REFUSE)
    return depth


def file_mold(skin: bd.Solid, y_b: float, path, mp: MoldParams | None = None):
    """(lower part with the pocket and pins, lid with sprue and vents, undercut depth (mm)) of the
    skin `skin`, bonded on the plane y = y_b."""
    mp = mp or MoldParams.from_params()
    bb = skin.bounding_box()
    size = max(bb.size.X, bb.size.Y, bb.size.Z)
    tol = 1e-6 * size
    name = Path(str(path)).name
    if bb.min.Y < y_b - tol:
        raise ParameterError("skin_file", str(path), "a skin above its bonded plane (the mold's split plane)",
                             f"{name} reaches y = {bb.min.Y:.4g} mm, below its bonded faces at y = {y_b:.4g} mm")
    p = dict(skin_file=name, bonded_y=y_b, wall=mp.wall)

    def one_pocket(lower):
        pieces = len(lower.solids())
        if pieces != 1:
            # the skin closes a room under it onto the bonded plane (a hollow over a core): the
            # block there is a loose core, which this two-part mold cannot hold
            raise ParameterError("skin_file", str(path), "a skin whose mold pocket is one piece (open only at the "
                                 "bonded plane)", f"{name} encloses {pieces - 1} room(s) under it down to its "
                                 f"bonded plane y = {y_b:.4g} mm, which would be loose core(s) of the mold")
        depth.append(check_undercut(skin, y_b, path))  # a loose core is also an undercut: named first

    depth = []
    lower, upper = face_down_mold(skin, (bb.min.X, bb.max.X, bb.max.Y, bb.min.Z, bb.max.Z), y_b, mp, "skin mold", p,
                                  check=one_pocket,
                                  holes=lambda: hole_positions(_bonded_faces(skin, y_b, tol), y_b, bb.min.Z,
                                                               bb.max.Z, mp, path))
    return lower, upper, depth[0]


def build_file_parts(path, bonded=None, *, molds: bool = True) -> list[Part]:
    """The skin of a STEP file and (molds=True) its mold parts. ParameterError for a .msh (no
    CAD) and for bonded faces not in one plane facing -y (mesh.skinfile.bonded_plane)."""
    from tactileskin.mesh import skinfile

    skinfile.require_step(path)
    skinfile.parse_rule(bonded)  # a bad rule fails before any CAD work
    rule = bonded or skinfile.DEFAULT_RULE
    fp = dict(skin="file", skin_file=str(path), skin_sha256=skinfile.file_digest(path), skin_bonded=rule)
    y_b = skinfile.bonded_plane(path, bonded) if molds else None
    skin = read_skin(path)
    parts = [Part("skin", f"your skin ({Path(str(path)).name}; cast in the mold)", skin, fp)]
    if molds:
        lower, upper, depth = file_mold(skin, y_b, path)
        fp = dict(fp, bonded_y=y_b, undercut_mm=round(depth, 3))
        held = f"; UNDERCUT {depth:.2g} mm: stretch the cast out" if depth > UNDERCUT_SILENT else ""
        parts.append(Part("mold_lower", f"skin mold, lower part (pocket = the skin, cast face down; pins{held})", lower,
                          fp))
        parts.append(Part("mold_upper", "skin mold, lid over the bonded face (sprue, vents; or the sensor board)",
                          upper, fp))
    return parts
