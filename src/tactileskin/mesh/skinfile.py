"""A user's skin geometry from a file (skins.file): a gmsh .msh with named physical groups, or a
STEP solid meshed here with its bonded faces chosen by a rule. Also the OCC-solid mesher of the
built-in 3D skins that are CAD solids (skins.dome).

.msh: read by gmsh itself (any .msh version; scikit-fem's meshio import drops second-order
boundary tags, see mesh._gmsh), one cell type (triangles in 2D, tetrahedra in 3D, order 1 or
2; the scene's order is made by gmsh's `setOrder`), the boundaries by physical-group name:
the bonded surface(s) (`skin_bonded`, comma-separated names; default the first of
`BONDED_NAMES` present), the contact surface (`skin_outer`; default the first of
`OUTER_NAMES`, else every boundary facet not otherwise named), `symmetry` if present (then
the model is the half x >= 0), in 3D `symmetry_z` if present (then the model is the half
z >= 0: what `tactileskin mesh --dim 3` writes for a z-symmetric indenter), other groups kept
by name (free). A symmetry group must lie on its plane.

STEP: one closed solid (gmsh's OCC importer, target unit mm), meshed with P2 tetrahedra
curved onto the CAD (size `mesh_size`, `mesh_size / refinement` in a ball around the top
point where indenters start). Each CAD face is one group; a face is bonded when every
facet satisfies the rule `skin_bonded`: "normal:-y" (outward normal within 10 degrees of
-y; "normal:+x:5" for another axis and tolerance) or "plane:y=0" (every vertex on that plane
within 1e-6 of the part size); every other face is `outer_surface`. A STEP solid that is its own
mirror image about x = 0 (z = 0) (`step_symmetry`) is meshed as its half x >= 0 (z >= 0) where
the caller asks (`mesh_step(halve=...)`: skins.file, for an indenter symmetric the same way):
the cut faces are `symmetry` (`symmetry_z`, held as `end_back`), as in a .msh half; a cut
that leaves other than one volume (a hairline notch within the tolerances) meshes it whole.

Units: a part whose bounding box is smaller than 0.1 mm or larger than 1 m is refused (a
file in metres or micrometres).
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import hashlib
import logging
import re
import threading
import time
from pathlib import Path

import numpy as np

from tactileskin.errors import MeshError, ParameterError
from tactileskin.fileio import read_unchanged
from tactileskin.mesh import _gmsh
from tactileskin.mesh.skinmesh import SYMMETRY_Z, SkinMesh, check_quality, jacobian_ratio

logger = logging.getLogger(__name__)

MSH_SUFFIXES = (".msh",)
STEP_SUFFIXES = (".step", ".stp")
BONDED_NAMES = ("bone_interface", "bonded", "board", "bone", "base", "fixed")
OUTER_NAMES = ("outer_surface", "outer", "contact", "skin_surface", "top")
SIZE_RANGE = (0.1, 1000.0)  # mm: the largest bounding-box side of a plausible skin
DEFAULT_RULE = "normal:-y"
# a STEP solid is mirror-symmetric about x = 0 (z = 0) when the volume of its symmetric
# difference with its mirror image is below this fraction of its volume: an exact mirror image
# leaves none (0.0 measured on domed blocks), while a side face 1e-5 mm off its mirror place on
# a 20 mm pad leaves 1e-6 (2 x 1e-5 / 20): far below the cells (>= 0.05 mm) and print
# tolerances, far above OCC's 1e-7 mm modelling precision; a 12 mm domed block moved 0.001 mm
# along x (2.4e-4) already stays whole
SYMMETRY_TOL = 1e-6
# ... and each piece of that difference is thinner than this (mm; its mean thickness 2 V / S):
# the fraction of the volume alone hid a local asymmetry on a large skin (a 1 mm dimple 0.03 mm
# deep on one side of a 100 x 100 x 5 mm pad read 9.5e-7, and the quarter dropped it); a
# face's offset d leaves a slab 2 d thick, a nub or hole about a third of its size. 1e-4 mm: 5x
# below the finest cells (mesh_size 0.01 / refinement 20), 1000x above OCC's 1e-7 mm precision
SYMMETRY_LENGTH = 1e-4
# samples along each boundary curve of a CAD face for the polygon of its (u, v) domain
# (_face_domain): a point well inside it needs no isInside query
DOMAIN_SAMPLES = 16
# the faces and curves (gmsh's getType) whose (u, v) curves those samples follow (smooth, at
# most a period a turn): a B-spline edge can hide a wave or a notch between them (a wave of
# 16 periods read as a straight line), so a face bounded by one is asked of gmsh
DOMAIN_FACES = ("Plane", "Cylinder", "Cone", "Sphere", "Torus")
DOMAIN_CURVES = ("Line", "Circle", "Ellipse")
RULE_FORMS = "'normal:-y' (optionally ':TOL_DEG'), 'normal:+x', ... or 'plane:y=0' (x, y or z)"
_VALID_FILE = "a gmsh .msh with named physical groups or a STEP (.step/.stp) of the skin solid, in mm"


# a folder given for the file (the folder of a CAD export): named as such
_FOLDER = "it is a folder: give the skin's .msh or STEP file itself"


def file_digest(path) -> str:
    """SHA-256 of the file's bytes (ParameterError naming `skin_file` if it cannot be read)."""
    if Path(path).is_dir():
        raise ParameterError("skin_file", str(path), _VALID_FILE, _FOLDER)
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError as e:
        raise ParameterError("skin_file", str(path), _VALID_FILE, f"cannot read it: {e.strerror or e}") from None


def file_kind(path) -> str:
    if Path(str(path)).is_dir():
        raise ParameterError("skin_file", str(path), _VALID_FILE, _FOLDER)
    suffix = Path(str(path)).suffix.lower()
    if suffix in MSH_SUFFIXES:
        return "msh"
    if suffix in STEP_SUFFIXES:
        return "step"
    raise ParameterError("skin_file", str(path), _VALID_FILE, f"unknown suffix {suffix!r}")


def require_step(path) -> None:
    """ParameterError unless `path` names a STEP file: `build` makes parts and a mold of a skin's
    CAD solid, which a .msh does not hold."""
    if file_kind(path) != "step":
        raise ParameterError("skin_file", str(path), "a STEP (.step/.stp) skin solid for `build`",
                             "a .msh is a mesh, not CAD: export the skin's solid as STEP from its CAD")


def _names(value) -> tuple[str, ...]:
    if value is None:
        return ()
    return tuple(n.strip() for n in str(value).split(",") if n.strip())


def check_units(path, lo, hi) -> None:
    """Refuse a part whose largest bounding-box side is outside SIZE_RANGE (mm)."""
    ext = float(np.max(np.asarray(hi, float) - np.asarray(lo, float)))
    if not SIZE_RANGE[0] <= ext <= SIZE_RANGE[1]:
        hint = ("it looks like metres or inches-as-metres: scale it to mm" if ext < SIZE_RANGE[0]
                else "it looks like micrometres: scale it to mm")
        raise ParameterError("skin_file", f"{path} (largest side {ext:.4g} mm)",
                             f"a skin between {SIZE_RANGE[0]:g} mm and {SIZE_RANGE[1] / 1000:g} m in size (units mm)",
                             hint)


# --- .msh ---------------------------------------------------------------------------------------
def _physical_groups(gmsh, dim: int) -> dict[str, list[int]]:
    out = {}
    for d, tag in gmsh.model.getPhysicalGroups(dim):
        name = gmsh.model.getPhysicalName(d, tag) or f"#{tag}"
        out.setdefault(name, []).extend(int(e) for e in gmsh.model.getEntitiesForPhysicalGroup(d, tag))
    return out


def _cell_type(gmsh, path, dim: int) -> int:
    """The one gmsh cell type of dimension `dim` (MeshError for mixed or unsupported types)."""
    types = [int(t) for t in gmsh.model.mesh.getElementTypes(dim)]
    names = [gmsh.model.mesh.getElementProperties(t)[0] for t in types]
    ok = {2: (_gmsh.TRI3, _gmsh.TRI6), 3: (_gmsh.TET4, _gmsh.TET10)}[dim]
    if len(types) != 1:
        raise MeshError(f"skin_file {path}: mixed element types ({', '.join(names)}); "
                        f"one type of {'triangle' if dim == 2 else 'tetrahedron'} (order 1 or 2) is supported")
    if types[0] not in ok:
        raise MeshError(f"skin_file {path}: {names[0]} cells are not supported; "
                        f"{'triangles' if dim == 2 else 'tetrahedra'} of order 1 or 2 are")
    return types[0]


def _pick(groups: dict, given: tuple[str, ...], defaults: tuple[str, ...], field: str, path) -> list[str]:
    found = ", ".join(sorted(groups)) or "none"
    if given:
        missing = [n for n in given if n not in groups]
        if missing:
            raise ParameterError(field, ",".join(given), f"physical groups of {Path(str(path)).name} (found: {found})",
                                 f"no group named {missing[0]!r}")
        return list(given)
    return [n for n in defaults if n in groups][:1]


def load_msh(path, *, bonded=None, outer=None, order: int | None = None):
    """(SkinMesh, group names) of a gmsh .msh file; see the module docstring."""
    path = Path(path)
    params = {"skin_file": str(path)}
    t0 = time.perf_counter()
    with _gmsh.session("skinfile", params) as gmsh:
        try:
            gmsh.merge(str(path))
        except Exception as e:
            raise ParameterError("skin_file", str(path), _VALID_FILE, f"gmsh cannot read it: {e}") from None
        dim = 3 if len(gmsh.model.mesh.getElementTypes(3)) else 2 if len(gmsh.model.mesh.getElementTypes(2)) else 0
        if dim == 0:
            raise MeshError(f"skin_file {path}: no triangles or tetrahedra (a surface or line mesh only?)")
        _, xyz, _ = gmsh.model.mesh.getNodes()
        xyz = xyz.reshape(-1, 3)
        check_units(path, xyz.min(axis=0), xyz.max(axis=0))
        if dim == 2 and np.ptp(xyz[:, 2]) > 1e-9 * np.ptp(xyz[:, :2]):
            raise MeshError(f"skin_file {path}: a 2D mesh must lie in the plane z = const (x-y section)")
        file_order = 2 if _cell_type(gmsh, path, dim) in (_gmsh.TRI6, _gmsh.TET10) else 1
        groups = _physical_groups(gmsh, dim - 1)
        found = ", ".join(sorted(groups)) or "none"
        bnames = _pick(groups, _names(bonded), BONDED_NAMES, "skin_bonded", path)
        if not bnames:
            raise ParameterError("skin_bonded", bonded, f"a physical group of {path.name} (found: {found})",
                                 "name the bonded surface(s): skin_bonded = 'NAME'")
        onames = _pick(groups, _names(outer), OUTER_NAMES, "skin_outer", path)
        order = file_order if order is None else order
        if order != file_order:
            gmsh.option.setNumber("Mesh.SecondOrderLinear", 1)
            gmsh.model.mesh.setOrder(order)
        rename = {**{n: "bone_interface" for n in bnames}, **{n: "outer_surface" for n in onames}}
        ents: dict[str, list[int]] = {}
        for name, tags in groups.items():
            ents.setdefault(rename.get(name, name), []).extend(tags)
        try:
            mesh, boundaries = _gmsh.to_skfem(gmsh, dim, order, ents)
        except _gmsh.InnerFacetError as e:
            # the message named the internal name ('bone_interface'), not the user's group or file
            group = next((n for n, tags in groups.items() if rename.get(n, n) == e.name and e.entity in tags),
                         e.name)
            field, value = (("skin_bonded", bonded or group) if group in bnames else
                            ("skin_outer", outer or group) if group in onames else ("skin_file", str(path)))
            raise ParameterError(field, value, f"a group on the boundary of {path.name}'s mesh",
                                 f"its group {group!r} lies inside the mesh, between cells, not on its "
                                 "outer boundary: name a surface of the skin") from None
    z_sym = dim == 3 and SYMMETRY_Z in boundaries
    if dim == 2:
        boundaries.pop(SYMMETRY_Z, None)
    for name, axis in (("symmetry", 0), (SYMMETRY_Z, 2)):
        if name in boundaries:
            _check_plane(mesh, boundaries[name], axis, name, path)
    if z_sym:  # the model's mid-plane support is on `end_back` (SkinMesh.z_symmetric)
        boundaries["end_back"] = boundaries.pop(SYMMETRY_Z)
    if "outer_surface" not in boundaries:  # no contact group named: the rest of the boundary
        named = np.concatenate([boundaries[n] for n in ("bone_interface", "symmetry", "end_back")
                                if n in boundaries and (n != "end_back" or z_sym)])
        rest = np.setdiff1d(mesh.boundary_facets(), named)
        if not rest.size:
            raise MeshError(f"skin_file {path}: no free boundary left for the contact surface")
        boundaries["outer_surface"] = rest
    mesh = dataclasses.replace(mesh, _boundaries=boundaries) if dim == 3 else mesh.with_boundaries(boundaries)
    quality = {"elements": int(mesh.nelements), "nodes": int(mesh.doflocs.shape[1]),
               "vertices": int(mesh.nvertices), "min_scaled_jacobian": jacobian_ratio(mesh),
               "wall_s": time.perf_counter() - t0}
    check_quality(quality, {})
    return (SkinMesh(mesh=mesh, boundaries=boundaries, dim=dim, quality=quality, z_symmetric=z_sym),
            sorted(groups))


def _check_plane(mesh, facets, axis: int, name: str, path) -> None:
    """ParameterError unless the group's facets lie on the plane x = 0 (axis 0) or z = 0 (2)."""
    if not len(facets):
        return
    X = mesh.p[:, np.unique(mesh.facets[:, facets])]
    off = float(np.max(np.abs(X[axis])))
    if off > 1e-6 * float(np.max(np.ptp(mesh.p, axis=1))):
        raise ParameterError("skin_file", str(path), f"a {name!r} group on the plane {'xyz'[axis]} = 0",
                             f"its facets reach {'xyz'[axis]} = {off:.4g} mm: a symmetry group must lie on "
                             "its plane; rename the group if it is a free face")


# --- OCC solids (STEP files, built-in CAD skins) ------------------------------------------------
def parse_rule(rule):
    """('normal', axis vector, tol_deg) or ('plane', axis index, value) of a bonded-face rule."""
    text = DEFAULT_RULE if rule is None else str(rule).strip().lower()
    m = re.fullmatch(r"normal:([+-]?)([xyz])(?::([0-9.]+))?", text)
    if m:
        v = np.zeros(3)
        v["xyz".index(m.group(2))] = -1.0 if m.group(1) == "-" else 1.0
        try:
            tol = float(m.group(3)) if m.group(3) else 10.0
        except ValueError:  # '.', '1.2.3' (digits and dots): refused below as out of range, no traceback
            tol = float("nan")
        if not 0.0 < tol < 90.0:
            raise ParameterError("skin_bonded", rule, "a tolerance in (0, 90) degrees")
        return "normal", v, tol
    m = re.fullmatch(r"plane:([xyz])=([-+0-9.e]+)", text)
    if m:
        try:
            return "plane", "xyz".index(m.group(1)), float(m.group(2))
        except ValueError:
            pass
    raise ParameterError("skin_bonded", rule, f"a rule for the STEP's bonded faces: {RULE_FORMS}")


def outward_normals(mesh, facets) -> np.ndarray:
    """(n, 3) outward unit normals of boundary facets of a tetrahedral mesh (straight facets)."""
    p, t = mesh.p, mesh.t
    v = p[:, mesh.facets[:, facets]]                      # (3, 3 vertices, n)
    n = np.cross((v[:, 1] - v[:, 0]).T, (v[:, 2] - v[:, 0]).T)
    inside = p[:, t[:, mesh.f2t[0, facets]]].mean(axis=1).T - v[:, 0].T
    n *= np.where(np.sum(n * inside, axis=1) > 0, -1.0, 1.0)[:, None]
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def classify_by_rule(mesh, faces: dict[int, np.ndarray], rule, size: float) -> list[int]:
    """The CAD faces (tag -> facet indices) that satisfy the bonded-face rule."""
    kind, a, b = parse_rule(rule)
    hits = []
    for tag, f in faces.items():
        if kind == "normal":
            ok = np.all(outward_normals(mesh, f) @ a >= np.cos(np.radians(b)))
        else:
            ok = np.all(np.abs(mesh.p[a, mesh.facets[:, f]] - b) <= 1e-6 * size)
        if ok:
            hits.append(tag)
    return hits


def mesh_occ(gmsh, path_label, *, mesh_size: float, fine: float, centre, radius: float, order: int,
             classify) -> tuple[object, dict, dict]:
    """Mesh the single OCC volume of the current gmsh model with P`order` tetrahedra (curved
    onto the CAD), fine (size `fine`) in a ball of `radius` around `centre`; `classify(mesh,
    faces)` maps {CAD face tag: facet indices} to {boundary name: [face tags]}. Returns
    (skfem mesh, boundaries, quality)."""
    vols = gmsh.model.getEntities(3)
    faces = [t for _, t in gmsh.model.getBoundary(vols, oriented=False)]
    gmsh.option.setNumber("Mesh.MeshSizeMax", mesh_size)
    gmsh.option.setNumber("Mesh.MeshSizeMin", min(fine, mesh_size))
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 12)  # curved faces: <= 30 degrees per cell
    ball = gmsh.model.mesh.field.add("Ball")
    for k, v in zip(("XCenter", "YCenter", "ZCenter"), centre):
        gmsh.model.mesh.field.setNumber(ball, k, float(v))
    gmsh.model.mesh.field.setNumber(ball, "Radius", radius)
    gmsh.model.mesh.field.setNumber(ball, "Thickness", radius)
    gmsh.model.mesh.field.setNumber(ball, "VIn", fine)
    gmsh.model.mesh.field.setNumber(ball, "VOut", mesh_size)
    gmsh.model.mesh.field.setAsBackgroundMesh(ball)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.Algorithm", 6)
    gmsh.option.setNumber("Mesh.Algorithm3D", 10)
    gmsh.model.mesh.generate(3)
    quality = _gmsh.shape_quality(gmsh, 3)
    if order == 2:
        gmsh.option.setNumber("Mesh.SecondOrderLinear", 0)  # mid-nodes on the CAD surfaces
        gmsh.model.mesh.setOrder(2)
    mesh, per_face = _gmsh.to_skfem(gmsh, 3, order, {f"face{f}": [f] for f in faces})
    by_tag = {f: per_face[f"face{f}"] for f in faces}
    names = classify(mesh, by_tag)
    boundaries = {n: np.unique(np.concatenate([by_tag[f] for f in tags])) for n, tags in names.items() if tags}
    mesh = dataclasses.replace(mesh, _boundaries=boundaries)
    quality.update(elements=int(mesh.nelements), nodes=int(mesh.doflocs.shape[1]),
                   vertices=int(mesh.nvertices), min_scaled_jacobian=jacobian_ratio(mesh))
    logger.info("%s: %d cells, %d nodes, min SICN %.3f", path_label, quality["elements"], quality["nodes"],
                quality["min_sicn"])
    return mesh, boundaries, quality


def _import_step(gmsh, path: Path) -> None:
    gmsh.option.setString("Geometry.OCCTargetUnit", "MM")
    gmsh.option.setNumber("Geometry.OCCBoundsUseStl", 1)
    try:
        gmsh.model.occ.importShapes(str(path))
    except Exception as e:
        raise ParameterError("skin_file", str(path), _VALID_FILE, f"gmsh cannot import it: {e}") from None
    gmsh.model.occ.synchronize()
    nvol, nface = len(gmsh.model.getEntities(3)), len(gmsh.model.getEntities(2))
    if nvol != 1:
        raise ParameterError("skin_file", str(path), "a STEP of one closed solid",
                             f"it holds {nvol} solids and {nface} faces"
                             + (" (an open shell: the solid is not closed)" if nvol == 0 else ""))
    check_units(path, *np.split(np.array(gmsh.model.getBoundingBox(-1, -1)), 2))


def step_symmetry(path, bonded=None) -> tuple[bool, bool]:
    """(about x = 0, about z = 0): a STEP skin solid is its own mirror image about the plane
    (symmetric difference below SYMMETRY_TOL of its volume, each piece of it thinner than
    SYMMETRY_LENGTH) and so are its bonded faces (the
    rule `bonded` picks mirror images of bonded faces unless it names that axis: 'normal:+x',
    'plane:x=1' bond one side only). Cached by the file's bytes."""
    kind, a, _ = parse_rule(bonded)
    axis = int(np.argmax(np.abs(a))) if kind == "normal" else a
    solid = _solid_symmetry(str(Path(path).resolve()), file_digest(path))
    return solid[0] and axis != 0, solid[1] and axis != 2


@functools.lru_cache(maxsize=16)
def _solid_symmetry(path: str, digest: str) -> tuple[bool, bool]:
    """The solid's symmetry, memoised by its bytes' digest (fileio.read_unchanged)."""
    return read_unchanged(_symmetry_of, path, digest, file_digest, "skin_file", _VALID_FILE)


def _symmetry_of(path: str) -> tuple[bool, bool]:
    out = []
    with _gmsh.session("skinstep-symmetry", {"skin_file": path}) as gmsh:
        _import_step(gmsh, Path(path))
        occ = gmsh.model.occ
        vol = gmsh.model.getEntities(3)
        v = occ.getMass(*vol[0])
        for plane in ((1, 0, 0, 0), (0, 0, 1, 0)):
            image = occ.copy(vol)
            occ.mirror(image, *plane)
            try:  # |A - B| = |B - A| (equal volumes): the symmetric difference is twice it
                rest, _ = occ.cut(vol, image, removeObject=False, removeTool=True)
            except Exception as e:  # OCC failed on the boolean: model it whole, as it is
                logger.warning("STEP skin %s: no symmetry test about the plane %s (OCC: %s): meshed whole",
                               Path(path).name, "xz"[plane[2]], e)
                out.append(False)
                continue
            pieces = [e for e in rest if e[0] == 3]
            diff = 2.0 * sum(occ.getMass(*e) for e in pieces)
            thick = max((_thickness(occ, e[1]) for e in pieces), default=0.0)
            occ.remove(rest, recursive=True)
            out.append(diff <= SYMMETRY_TOL * v and thick <= SYMMETRY_LENGTH)
            logger.info("STEP skin %s: symmetric difference with its mirror image about %s = 0: %.3g of its "
                        "volume, its thickest piece %.3g mm (symmetric below %g and %g mm)", Path(path).name,
                        "xz"[plane[2]], diff / v, thick, SYMMETRY_TOL, SYMMETRY_LENGTH)
    return out[0], out[1]


def _thickness(occ, tag: int) -> float:
    """Mean thickness 2 V / S (mm) of an OCC volume: d for a slab d thick, a / 3 for a cube of
    side a."""
    area = sum(occ.getMass(2, f) for loop in occ.getSurfaceLoops(tag)[1] for f in loop)
    return 2.0 * occ.getMass(3, tag) / area if area > 0.0 else 0.0


def _keep_half(gmsh, halve, lo, hi, path: Path) -> bool:
    """Cut the model's one volume to x >= 0 (halve[0]) and z >= 0 (halve[1]); False (logged) if
    that left other than one volume: the model is then spent, the caller re-imports it whole."""
    occ = gmsh.model.occ
    pad = 1.0 + float(np.max(hi - lo))
    a = [0.0 if halve[0] else lo[0] - pad, lo[1] - pad, 0.0 if halve[1] else lo[2] - pad]
    box = occ.addBox(*a, *(hi + pad - np.array(a)))
    out, _ = occ.intersect(gmsh.model.getEntities(3), [(3, box)])
    occ.synchronize()
    nvol = len([e for e in out if e[0] == 3])
    if nvol != 1:
        # a mirror image within SYMMETRY_TOL / SYMMETRY_LENGTH, not an exact one: a hairline
        # notch on one side splits the part kept (the exact mirror image of one solid cannot)
        logger.warning("STEP skin %s: cutting it at %s left %d volumes, not one: meshed whole", path.name,
                       " and ".join(n for n, h in zip(("x = 0", "z = 0"), halve) if h), nvol)
    return nvol == 1


def mesh_step(path, *, bonded=None, mesh_size: float | None, refinement: float = 1.0, order: int = 2,
              centre=None, radius: float | None = None, halve=(False, False)) -> SkinMesh:
    """Mesh a STEP skin solid (module docstring); `centre`, `radius`: the fine ball (default
    around the top of the bounding box on x = z = 0, a fifth of the part's size); mesh_size
    None: an eighth of the part's size. halve: (x, z) mesh the part x >= 0 (z >= 0) only, its
    cut faces `symmetry` (`end_back`, z_symmetric): for a solid that `step_symmetry` finds
    symmetric (the caller's check); sizes default from the whole solid. A cut that leaves other
    than one volume falls back to the whole solid (a warning; not halved)."""
    path = Path(path)
    parse_rule(bonded)  # a bad rule fails before any CAD work
    halve = (bool(halve[0]), bool(halve[1]))
    params = {"skin_file": str(path), "mesh_size": mesh_size, "refinement": refinement, "order": order,
              "halve": halve}
    t0 = time.perf_counter()
    with _gmsh.session("skinstep", params) as gmsh:
        _import_step(gmsh, path)
        lo, hi = np.split(np.array(gmsh.model.getBoundingBox(-1, -1)), 2)
        size = float(np.max(hi - lo))
        if any(halve) and not _keep_half(gmsh, halve, lo, hi, path):
            gmsh.model.remove()  # the cut consumed the solid: a fresh model of the whole one
            gmsh.model.add("skinstep")
            _import_step(gmsh, path)
            halve = (False, False)
        mesh_size = size / 8.0 if mesh_size is None else mesh_size
        centre = (0.0, hi[1], 0.0) if centre is None else centre
        radius = 0.2 * size if radius is None else radius

        bonded_tags = []
        face_facets = {}

        def classify(mesh, faces):
            face_facets.update(faces)
            # the cut faces (every vertex on the plane) first: the rule picks among the skin's own
            cut = {name: [f for f in faces if np.all(np.abs(mesh.p[k, mesh.facets[:, faces[f]]]) <= 1e-9 * size)]
                   for name, k, h in (("symmetry", 0, halve[0]), ("end_back", 2, halve[1])) if h}
            own = {f: v for f, v in faces.items() if not any(f in c for c in cut.values())}
            hits = classify_by_rule(mesh, own, bonded, size)
            bonded_tags.extend(hits)
            if not hits:
                kind = parse_rule(bonded)[0]
                raise ParameterError("skin_bonded", bonded or DEFAULT_RULE,
                                     f"a rule that some of the {len(faces)} faces of {path.name} satisfy ({RULE_FORMS})",
                                     f"no face matches the {kind} rule")
            return {"bone_interface": hits, "outer_surface": [f for f in own if f not in hits], **cut}

        mesh, boundaries, quality = mesh_occ(gmsh, f"STEP skin {path.name}", mesh_size=mesh_size,
                                             fine=mesh_size / refinement, centre=centre, radius=radius,
                                             order=order, classify=classify)
    if "outer_surface" not in boundaries:
        raise ParameterError("skin_bonded", bonded, "a rule that leaves a free outer surface",
                             "every face of the solid matched it")
    quality["wall_s"] = time.perf_counter() - t0
    check_quality(quality, {"coarse": mesh_size})
    for name, h in (("symmetry", halve[0]), ("end_back", halve[1])):
        if h and name not in boundaries:
            raise MeshError(f"cutting the STEP skin {path.name} left no face on its symmetry plane ({name})")
    sm = SkinMesh(mesh=mesh, boundaries=boundaries, dim=3, quality=quality, z_symmetric=halve[1])
    # CAD face tags (the same on a re-import of the whole solid, not of a cut one): distance_to_faces
    sm.bonded_faces = None if any(halve) else tuple(bonded_tags)
    sm.face_facets = None if any(halve) else face_facets  # CAD face tag -> its facets: line_heights
    return sm


def bonded_plane(path, bonded=None) -> float:
    """y (mm) of the one plane y = const, facing -y, that holds a STEP skin's bonded faces (the
    rule `bonded` picks them, as the solver does): the open top of a mold that casts the skin
    face down (geometry.file_parts). ParameterError naming `skin_bonded` when they are curved
    or at several heights (a fingertip's bone), or face another way."""
    path = Path(path)
    sm = mesh_step(path, bonded=bonded, mesh_size=None, order=1)  # coarse: its vertices lie on the CAD
    m, f = sm.mesh, sm.boundaries["bone_interface"]
    size = float(np.max(np.ptp(m.p, axis=1)))
    y = m.p[1, np.unique(m.facets[:, f])]
    off = float(np.degrees(np.arccos(np.clip(-outward_normals(m, f)[:, 1], -1.0, 1.0))).max())
    if np.ptp(y) > 1e-6 * size or off > 1e-3:
        lo, hi = (round(float(v), 9) + 0.0 for v in (y.min(), y.max()))  # no "-1.959e-15" for 0
        raise ParameterError("skin_bonded", bonded or DEFAULT_RULE,
                             "bonded faces in one plane y = const facing -y for a mold (the skin cast face down on "
                             "a flat board)",
                             f"{path.name}'s bonded faces span y in [{lo:.4g}, {hi:.4g}] mm"
                             + (f", normals up to {off:.3g} degrees off -y" if off > 1e-3 else "")
                             + ": a curved or stepped bonded surface (a fingertip's bone) "
                             "needs a core in the mold, which `build` makes for the built-in fingertip and dome only")
    return float(np.mean(y))


def distance_to_faces(path, point, faces) -> float | None:
    """Distance (mm) from `point` to the CAD faces `faces` of a STEP solid (their interiors,
    edges and corners), or None if no projection lands on them. The meshed facets are chords:
    on a curved bonded face (a fingertip's bone, R 6 mm) their distance read the thickness
    2.06 mm for a 2.00 mm skin."""
    p = np.asarray(point, float)
    best = None
    with _gmsh.session("skinstep-distance", {"skin_file": str(path)}) as gmsh:
        _import_step(gmsh, Path(path))
        curves = set()
        for f in faces:
            xyz, uv = gmsh.model.getClosestPoint(2, f, p)
            if gmsh.model.isInside(2, f, uv, parametric=True) > 0:
                d = float(np.linalg.norm(np.asarray(xyz) - p))
                best = d if best is None else min(best, d)
            curves.update(abs(c) for _, c in gmsh.model.getBoundary([(2, f)], oriented=False))
        for c in curves:  # a nearest point on a face's edge (its projection falls off the trim)
            xyz, u = gmsh.model.getClosestPoint(1, c, p)
            lo, hi = gmsh.model.getParametrizationBounds(1, c)
            if lo[0] <= u[0] <= hi[0]:
                d = float(np.linalg.norm(np.asarray(xyz) - p))
                best = d if best is None else min(best, d)
            for _, v in gmsh.model.getBoundary([(1, c)], oriented=False):
                d = float(np.linalg.norm(np.asarray(gmsh.model.getValue(0, v, [])) - p))
                best = d if best is None else min(best, d)
    return best


def refine_top(path, top) -> tuple[np.ndarray, np.ndarray | None]:
    """(highest, on_axis) of a STEP solid: `highest`, its top from a mesh node near it (the
    closest CAD point to a point above it: the surface is horizontal at its highest point);
    `on_axis`, the highest point where the axis x = z = 0 crosses its faces (None if it
    misses them). A coarse node left `highest` off the axis (0.34 mm on a sphere cap of
    radius 6, 3.2 mm along a crown's top line), and with it s = x - x_top and the thickness;
    the indenters are centred on the axis, so the skin's top is read there."""
    with _gmsh.session("skinstep-top", {"skin_file": str(path)}) as gmsh:
        _import_step(gmsh, Path(path))
        lo, hi = np.split(np.array(gmsh.model.getBoundingBox(-1, -1)), 2)
        size = float(np.max(hi - lo))
        best = np.asarray(top, float)
        probe = best + np.array([0.0, 1.0, 0.0])
        on_axis = None
        for _, f in gmsh.model.getEntities(2):
            p = np.asarray(gmsh.model.getClosestPoint(2, f, probe)[0])
            if np.linalg.norm(p - best) < 1e-2 * max(1.0, abs(best).max()) and p[1] > best[1]:
                best = p
            q = _line_crossings(gmsh, f, [0.0, hi[1] + size, 0.0], [0.0, 0.0], 1e-9 * size)[0]
            q = None if np.isnan(q[0]) else q
            if q is not None and (on_axis is None or q[1] > on_axis[1]):
                on_axis = q
    return best, on_axis


def line_heights(path, faces, points) -> np.ndarray:
    """y (mm) where the vertical line through each point (x, y, z) of `points` (n, 3) crosses
    the CAD face `faces[i]` of a STEP solid, from the crossing nearest the point (a mesh facet's
    answer: its chord); NaN where the line misses the (trimmed) face. The coarse analysis mesh's
    chords lay 0.03 mm under a sphere cap of R 6 (1 mm facets), the scene refused a sensor the
    CAD and the solved mesh hold."""
    pts = np.asarray(points, float).reshape(-1, 3)
    faces = np.asarray(faces, int)
    out = np.full(len(pts), np.nan)
    if not len(pts):
        return out
    with step_open(path):
        gmsh, tol, domains = _OPEN.gmsh, _OPEN.tol, _OPEN.domains
        for f in np.unique(faces):
            on = faces == f
            if f not in domains:
                domains[f] = _face_domain(gmsh, int(f))
            out[on] = _line_crossings(gmsh, int(f), pts[on], pts[on][:, [0, 2]], tol, domain=domains[f])[:, 1]
    return out


_OPEN = threading.local()  # the STEP imported for line_heights in this thread (step_open)


@contextlib.contextmanager
def step_open(path):
    """Import the STEP `path` once for every line_heights of it in the block (this thread):
    each call imported it again (~10-20 ms; 44 imports, a third of placing the half tube's
    273 taxels at a height, its exits' regula falsi reading columns ~30 times). A block inside
    one for the same file reuses it; gmsh's session lock is held throughout, so no other
    gmsh session may open inside (another file's is refused: it would wait on itself)."""
    path = str(path)
    if getattr(_OPEN, "path", None) is not None:
        if _OPEN.path != path:
            raise MeshError(f"line_heights of {path} inside an open import of {_OPEN.path}")
        yield
        return
    caught = None
    with _gmsh.session("skinstep-columns", {"skin_file": path}) as gmsh:
        _import_step(gmsh, Path(path))
        lo, hi = np.split(np.array(gmsh.model.getBoundingBox(-1, -1)), 2)
        _OPEN.gmsh, _OPEN.tol, _OPEN.domains = gmsh, 1e-9 * float(np.max(hi - lo)), {}
        _OPEN.path = path
        try:
            yield
        except Exception as e:
            if type(e) is Exception:  # gmsh's API raises plain Exception: the session's MeshError
                raise
            caught = e  # the block's own error (a bug, MemoryError): not gmsh's, raised as it is
        finally:
            _OPEN.path = None
    if caught is not None:
        raise caught


def _face_domain(gmsh, face: int):
    """(segments (m, 2, 2), margin): the polygon of a CAD face's boundary curves in its (u, v)
    (DOMAIN_SAMPLES chords a curve, one where it is straight in (u, v)) and how far inside it a
    point is surely inside the trimmed face (4 x the chords' largest sagitta, measured at their
    midpoints, + 1e-6 of the domain's size); None where the curves do not close (a periodic
    face's seam is not among them) or a face or curve not of DOMAIN_FACES / DOMAIN_CURVES:
    every point is then asked of gmsh."""
    try:
        segs, ends, dev = [], [], 0.0
        if gmsh.model.getType(2, face) not in DOMAIN_FACES:
            return None
        for _, c in gmsh.model.getBoundary([(2, face)], oriented=False):
            if gmsh.model.getType(1, abs(c)) not in DOMAIN_CURVES:
                return None
            lo, hi = gmsh.model.getParametrizationBounds(1, abs(c))
            t = np.linspace(lo[0], hi[0], 2 * DOMAIN_SAMPLES + 1)
            uv = np.asarray(gmsh.model.reparametrizeOnSurface(1, abs(c), t, face), float).reshape(-1, 2)
            line = _off_chords(uv[[0, -1]], uv)
            pts, off = (uv[[0, -1]], line) if line <= 1e-12 * np.ptp(uv, axis=0).max() else \
                (uv[::2], _off_chords(uv[::2], uv[1::2], paired=True))
            segs.append(np.stack([pts[:-1], pts[1:]], axis=1))
            ends += [pts[0], pts[-1]]
            dev = max(dev, off)
    except Exception:  # a curve gmsh cannot put on the face (a degenerate edge): ask gmsh
        return None
    if not segs:
        return None
    segs, ends = np.concatenate(segs), np.array(ends)
    span = float(np.ptp(segs.reshape(-1, 2), axis=0).max())
    gap = np.linalg.norm(ends[:, None] - ends[None], axis=2)
    np.fill_diagonal(gap, np.inf)  # each curve's end meets another's
    if not np.all(gap.min(axis=1) <= 1e-9 * span):  # an open chain: not the face's whole boundary
        return None
    return segs, 4.0 * dev + 1e-6 * span


def _off_chords(pts, q, paired: bool = False) -> float:
    """The largest distance of the points q from the chords between consecutive pts (paired:
    q[i] from the chord i only)."""
    a, b = pts[:-1], pts[1:]
    if not paired:
        a, b = np.broadcast_to(a[0], q.shape), np.broadcast_to(b[0], q.shape)
    ab = b - a
    u = np.clip(np.sum((q - a) * ab, axis=1) / np.maximum(np.sum(ab * ab, axis=1), 1e-300), 0.0, 1.0)
    return float(np.max(np.linalg.norm(a + u[:, None] * ab - q, axis=1), initial=0.0))


def _surely_inside(domain, uv) -> np.ndarray:
    """Whether each (u, v) lies inside the polygon `domain` (_face_domain) by more than its
    margin: inside the trimmed face, gmsh's isInside's answer without asking it (~30 us a point)."""
    out = np.zeros(len(uv), bool)
    if domain is None or not len(uv):
        return out
    segs, margin = domain
    a, b = segs[:, 0], segs[:, 1]
    ab = b - a
    ab2 = np.maximum(np.sum(ab * ab, axis=1), 1e-300)
    step = max(1, 2 ** 20 // len(segs))  # bounded memory: points x segments
    for c in range(0, len(uv), step):
        p = uv[c:c + step, None, :]
        with np.errstate(divide="ignore", invalid="ignore"):  # a horizontal chord crosses no ray
            x = a[:, 0] + (p[..., 1] - a[:, 1]) * ab[:, 0] / ab[:, 1]
        ray = ((a[:, 1] > p[..., 1]) != (b[:, 1] > p[..., 1])) & (p[..., 0] < x)  # even-odd, along +u
        u = np.clip(np.sum((p - a) * ab, axis=2) / ab2, 0.0, 1.0)
        d = np.linalg.norm(a + u[..., None] * ab - p, axis=2).min(axis=1)
        out[c:c + step] = (ray.sum(axis=1) % 2 == 1) & (d > margin)
    return out


def _line_crossings(gmsh, face: int, probes, at, tol: float, domain=None) -> np.ndarray:
    """(n, 3): the points of CAD face `face` on the vertical lines x, z = `at` (n, 2) (Newton on
    its parameters from the points nearest `probes` (n, 3)), NaN rows where a line misses the
    (trimmed) face. Every point in one call of gmsh each (isInside, 0.1 ms a call, counts the
    points inside: each point's own call only when some are out), but those surely inside the
    face's `domain` (_face_domain): gmsh's answer there is yes."""
    at = np.asarray(at, float).reshape(-1, 2)
    n = len(at)
    uv = np.asarray(gmsh.model.getClosestPoint(2, face, np.ravel(probes))[1], float).reshape(n, 2)
    xyz = np.full((n, 3), np.nan)
    live = np.ones(n, bool)
    for _ in range(30):
        if not live.any():
            break
        val = np.asarray(gmsh.model.getValue(2, face, uv[live].ravel()), float).reshape(-1, 3)
        r = val[:, [0, 2]] - at[live]
        done = np.all(np.abs(r) <= tol, axis=1)
        idx = np.flatnonzero(live)
        xyz[idx[done]] = val[done]
        live[idx[done]] = False
        idx, r = idx[~done], r[~done]
        if not idx.size:
            break
        d = np.asarray(gmsh.model.getDerivative(2, face, uv[idx].ravel()), float).reshape(-1, 2, 3)  # d/du, d/dv
        jac = np.transpose(d[:, :, [0, 2]], (0, 2, 1))
        flat = np.abs(np.linalg.det(jac)) < 1e-14  # a face along the line (or a degenerate point)
        live[idx[flat]] = False
        idx, jac, r = idx[~flat], jac[~flat], r[~flat]
        if idx.size:
            uv[idx] = uv[idx] - np.linalg.solve(jac, r[:, :, None])[:, :, 0]
    found = np.flatnonzero(~np.isnan(xyz[:, 0]))
    # gmsh's isInside classifies each point on the trimmed face (OCC's BRepClass_FaceClassifier,
    # ~30 us a point: 74 % of placing the half tube's taxel layout); a point well inside the
    # polygon of the face's boundary in (u, v) is inside, so only the rest is asked
    found = found[~_surely_inside(domain, uv[found])]
    if found.size and gmsh.model.isInside(2, face, uv[found].ravel(), parametric=True) < found.size:
        out = [i for i in found if gmsh.model.isInside(2, face, uv[i], parametric=True) <= 0]
        xyz[out] = np.nan
    return xyz
