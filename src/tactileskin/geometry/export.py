"""Write parts as binary STL + STEP, check every STL is a valid volume, write manifest.json.

All output goes into a staging folder inside the target (staging.staged_files) and is moved
into place only once every file is written and checked: a failed build leaves nothing behind
(an existing previous build in the target stays untouched until the new one is complete).
The target is a new or empty folder or a previous build's; the folder itself (its mode,
group, ACLs; a mount point) is kept, and only the files the previous build recorded writing
are replaced: a user's files stay, one of ours the user edited is refused.
"""

from __future__ import annotations

import io
import json
import logging
import math
import time
from pathlib import Path

import numpy as np
import trimesh

from tactileskin import fileio, outdir, staging
from tactileskin.errors import CadError, ParameterError
from tactileskin.geometry.occ import bd
from tactileskin.geometry.parts import Part
from tactileskin.geometry.solids import format_params, occ_guard

log = logging.getLogger(__name__)

MANIFEST = "manifest.json"
MANIFEST_KIND = "tactileskin.parts"  # marks a folder this module wrote (and may replace)
FOLDER_KIND = "build"  # the folder's marker (outdir.claim_dir)
BUILD_FILES = (MANIFEST, "*.stl", "*.step")  # staged_files patterns: what a build may replace

# Tessellation (absolute, unlike build123d.export_stl whose deflection is relative to each
# edge's size): chordal deviation 5 um, angular deflection 0.1 rad. Mesh vertices lie on the
# exact surfaces and no facet sags more than 0.005 mm from them: half the 0.01 mm
# surface-accuracy and a quarter of the 0.02 mm Braille-dimension checks. The volume the
# chords cut off is at most that times the part's area (manifest: volume_mm3 vs
# cad_volume_mm3, OCC's integral to 1e-9): up to 0.1 % (the t = 5 rigid base), well inside
# the 0.5 % mold-cavity check. 0.1 rad keeps >= 60 facets around a Braille dot.
# 0.001 mm would triple the export time for no gain these checks can see.
STL_TOLERANCE = 0.005
STL_ANGULAR_TOLERANCE = 0.1


def write_stl(shape, path: Path, tolerance: float = STL_TOLERANCE,
              angular_tolerance: float = STL_ANGULAR_TOLERANCE) -> bool:
    """Binary STL with an absolute chordal deviation `tolerance` (mm); False if the shape could
    not be meshed, None if the mesh could not be written (OCC gives no reason)."""
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.BRepTools import BRepTools
    from OCP.StlAPI import StlAPI_Writer

    BRepTools.Clean_s(shape.wrapped)  # drop any coarser cached triangulation: same file every time
    mesher = BRepMesh_IncrementalMesh(shape.wrapped, tolerance, False, angular_tolerance, True)
    mesher.Perform()
    if not mesher.IsDone():
        return False
    writer = StlAPI_Writer()
    writer.ASCIIMode = False
    if not writer.Write(shape.wrapped, str(path)):
        return None
    drop_pole_facets(Path(path))
    return True


def drop_pole_facets(path: Path) -> int:
    """Rewrite the STL without facets that have two coincident corners; return their number.

    OCC meshes a surface pole (a scaled sphere's tip, e.g. the dome's cap) through its
    degenerate edge and leaves a zero-area triangle there whose collapsed edge is unmatched,
    so the STL is not watertight although the surface is closed. Such a facet carries no
    area and its two other edges are each other's twin, so dropping it changes no surface
    and no volume. A file without one is left untouched (byte for byte)."""
    mesh = trimesh.load(str(path), force="mesh")  # merges exactly coincident vertices
    f = mesh.faces
    keep = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])
    n = int(np.count_nonzero(~keep))
    if n:
        mesh.update_faces(keep)
        mesh.remove_unreferenced_vertices()
        fileio.atomic_write_bytes(path, mesh.export(file_type="stl"))
        log.info("%s: dropped %d zero-area pole facet(s)", path.name, n)
    return n


def check_stl(path: Path, what: str = "", parameters: dict | None = None) -> trimesh.Trimesh:
    """Load an STL and require a valid volume (watertight, consistent winding, volume > 0)."""
    mesh = trimesh.load(str(path), force="mesh")
    if not mesh.is_volume:
        raise CadError(f"{what or path.name}: exported STL is not a valid volume (watertight="
                       f"{mesh.is_watertight}, winding_consistent={mesh.is_winding_consistent}, "
                       f"volume={mesh.volume:g} mm^3) for {format_params(parameters or {})}")
    return mesh


def _json_safe(v):
    if isinstance(v, (np.floating, np.integer)):
        return v.item()
    if isinstance(v, float) and not math.isfinite(v):
        raise CadError(f"non-finite value {v!r} in the manifest")
    return v


def cad_volume(shape, precision: float = 1e-9) -> float:
    """OCC's volume integral of a shape to `precision` (mm^3); build123d's `.volume` uses
    OCC's default precision, off by up to ~1e-3 on curved faces (the dome: 0.11 %)."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape.wrapped, props, precision, False, False)
    return float(props.Mass())


def _write_part(part: Part, folder: Path, tolerance: float, angular_tolerance: float) -> dict:
    stl, step = folder / f"{part.name}.stl", folder / f"{part.name}.step"
    step_bytes = io.BytesIO()  # written by Python below: a full disk is an OSError naming its cause
    with occ_guard(f"exporting {part.name}", **{k: v for k, v in part.parameters.items() if not isinstance(v, dict)}):
        ok_stl = write_stl(part.shape, stl, tolerance, angular_tolerance)
        ok_step = bd.export_step(part.shape, step_bytes)
    if ok_step:
        fileio.atomic_write_bytes(step, step_bytes.getvalue())
    if ok_stl is None:  # meshed, but OCC's writer could not write the file, and says no more
        raise fileio.OutputError(stl, "the CAD kernel could not write it (no space left on the device, "
                                      "a file size limit or a read-only folder?)")
    if not (ok_stl and ok_step and stl.is_file() and step.is_file()):
        raise CadError(f"exporting {part.name} failed (stl={ok_stl}, step={ok_step}) for {format_params(part.parameters)}")
    mesh = check_stl(stl, part.name, part.parameters)
    lo, hi = mesh.bounds
    return {
        "name": part.name,
        "description": part.description,
        "stl": stl.name,
        "step": step.name,
        "volume_mm3": float(mesh.volume),
        "cad_volume_mm3": cad_volume(part.shape),
        "bbox_min": [float(v) for v in lo],
        "bbox_max": [float(v) for v in hi],
        "watertight": bool(mesh.is_watertight),
        "is_volume": bool(mesh.is_volume),
        "triangles": int(len(mesh.faces)),
        "parameters": {k: _json_safe(v) for k, v in part.parameters.items()},
    }


def _previous_build_files(out: Path) -> set[str] | None:
    """The names a previous parts build in `out` wrote (its manifest and the STL / STEP files
    the manifest lists), or None if `out` holds no manifest of ours."""
    try:
        manifest = json.loads((out / MANIFEST).read_text())
        if manifest.get("kind") != MANIFEST_KIND:
            return None
        return {MANIFEST} | {str(e[k]) for e in manifest.get("parts", ()) for k in ("stl", "step") if k in e}
    except (OSError, ValueError, AttributeError, TypeError):
        return None


def check_target(out: Path) -> None:
    """Only a new or empty folder, or a previous parts build (our marker, or the manifest of a
    build from before the marker with nothing added), may be written into."""
    if out.is_symlink():
        raise ParameterError("out", str(out), "a folder path, not a symbolic link",
                             "write to the folder it points to, or to a new folder")
    if out.exists() and not out.is_dir():
        raise ParameterError("out", str(out), "a folder path (it exists and is not a folder)")
    kind = outdir.marker_kind(out)
    if not out.is_dir() or kind == FOLDER_KIND:
        return
    with fileio.os_errors(out):
        entries = [p.name for p in out.iterdir()
                   if not fileio.is_temporary(p.name) and p.name not in outdir.BOOKKEEPING]
    valid = "a new or empty folder, or the folder of a previous `tactileskin build`"
    if kind is not None:
        raise ParameterError("out", str(out), valid,
                             hint=f"the folder was written by another tactileskin command ({outdir.written_by(kind)})")
    ours = _previous_build_files(out)
    others = sorted(n for n in entries if ours is None or n not in ours)
    if others:
        shown = ", ".join(others[:3]) + (", ..." if len(others) > 3 else "")
        raise ParameterError("out", str(out), valid, hint=f"the folder holds files the build did not write ({shown})")


def export_parts(parts: list[Part], out_dir, *, tolerance: float = STL_TOLERANCE,
                 angular_tolerance: float = STL_ANGULAR_TOLERANCE, meta: dict | None = None) -> dict:
    """Write every part to out_dir (STL + STEP + manifest.json) atomically; return the manifest."""
    out = Path(out_dir).absolute()
    check_target(out)
    names = [p.name for p in parts]
    if len(set(names)) != len(names):
        raise ParameterError("parts", names, "unique part names")
    legacy = None if (out / outdir.MARKER).is_file() else _previous_build_files(out)
    if legacy is not None:  # a build from before the marker: its listed files become recorded ones
        outdir.adopt_dir(out, FOLDER_KIND, legacy)
    with outdir.claimed(out, FOLDER_KIND), staging.staged_files(out, BUILD_FILES, last=MANIFEST) as tmp:
        t0 = time.perf_counter()
        entries = []
        for part in parts:
            t1 = time.perf_counter()
            with fileio.os_errors(out):  # OCP writes the files itself
                entries.append(_write_part(part, tmp, tolerance, angular_tolerance))
            log.info("exported %s in %.2f s", part.name, time.perf_counter() - t1)
        manifest = {
            "kind": MANIFEST_KIND,
            "units": "mm",
            "stl_tolerance_mm": tolerance,
            "stl_angular_tolerance_rad": angular_tolerance,
            "parameters": {k: _json_safe(v) for k, v in (meta or {}).items()},
            "parts": entries,
        }
        fileio.atomic_write_json(tmp / MANIFEST, manifest)
        fileio.fix_tree_modes(tmp)  # OCP and trimesh write with their own modes
        log.info("exported %d parts in %.2f s", len(parts), time.perf_counter() - t0)
    return manifest
