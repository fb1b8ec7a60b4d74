"""Pressure profiles along the bone path and their metrics (peak, span, AUC).

The same definitions serve the simulation and the pressure-film measurements, so that the
two compare like for like. Pure numpy.
"""

from __future__ import annotations

import csv
import io
import json
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tactileskin import fileio, outdir, quality, staging, validate
from tactileskin.errors import ConvergenceError, ParameterError


def _check(s, p):
    s = np.asarray(s, float)
    p = np.asarray(p, float)
    if s.ndim != 1 or s.shape != p.shape or s.size < 2:
        raise ParameterError("profile", f"s {s.shape}, p {p.shape}", "1-D arrays of equal length >= 2")
    if not (np.all(np.isfinite(s)) and np.all(np.isfinite(p))):
        raise ParameterError("profile", "non-finite values", "finite s and P")
    if np.any(np.diff(s) <= 0):
        raise ParameterError("profile s", "not increasing", "strictly increasing positions")
    return s, p


def peak(s, p) -> float:
    """Largest pressure of the profile."""
    s, p = _check(s, p)
    return float(np.max(p))


def edge_peak(s, p, margin: float):
    """(peak, its s, interior peak, its s) if the profile's largest value lies within `margin`
    (mm) of an end that is an edge of the bonded skin and is larger than the largest value
    farther in, else None. A profile starting at s = 0 starts at a symmetry line, not at an edge
    (as BoneMap.interior_peak). Where the bonded skin ends under load (a pad pressed by a plate
    wider than itself) the bone pressure has a corner singularity: t = 2 pad, plate, depth 0.1:
    0.193 / 0.176 / 0.307 MPa at the edge on 0.177 / 3, 0.177 / 6, 0.1 / 6 against 0.1696-0.1698
    at s = 0."""
    s, p = _check(s, p)
    if not margin > 0:
        return None
    inner = s <= s[-1] - margin
    if abs(s[0]) > 1e-9:
        inner &= s >= s[0] + margin
    if not inner.any() or inner.all():
        return None
    i, j = int(np.argmax(p)), int(np.argmax(np.where(inner, p, -np.inf)))
    if inner[i] or not p[i] > p[j]:
        return None
    return float(p[i]), float(s[i]), float(p[j]), float(s[j])


def span(s, p, fraction: float = 0.1) -> float:
    """Extent of s where P >= fraction * peak (mm).

    From the first to the last sample at or above the threshold, each end moved to the
    linearly interpolated crossing with its outer neighbour (so the value does not jump
    with the sampling); an end that never drops below the threshold stays at the profile's
    end. Zero if the peak is not positive.
    """
    s, p = _check(s, p)
    if not 0 < fraction <= 1:
        raise ParameterError("fraction", fraction, "(0, 1]")
    top = float(np.max(p))
    if top <= 0:
        return 0.0
    thr = fraction * top
    idx = np.flatnonzero(p >= thr)
    a, b = idx[0], idx[-1]
    sa = s[a] if a == 0 else float(np.interp(thr, [p[a - 1], p[a]], [s[a - 1], s[a]]))
    sb = s[b] if b == s.size - 1 else float(np.interp(thr, [p[b + 1], p[b]], [s[b + 1], s[b]]))
    return float(sb - sa)


def auc(s, p) -> float:
    """Area under P(s), trapezoid rule (MPa mm for a pressure profile)."""
    s, p = _check(s, p)
    return float(np.trapezoid(p, s))


def fold_profile(s, p):
    """Fold a two-sided profile about s = 0 onto s >= 0 (to compare with the half model).

    On the grid s_k = k*ds (ds the profile's median spacing) up to max |s|, the folded value
    is the mean of P(+s_k) and P(-s_k) (linear interpolation) where both sides are measured,
    else the one that is. Returns (s_half, p_half, asymmetry) with asymmetry =
    max |P(+s) - P(-s)| / max P over the overlap (0 for a symmetric profile).
    """
    s = np.asarray(s, float)
    p = np.asarray(p, float)
    ds = float(np.median(np.diff(s)))
    smax = max(abs(s[0]), abs(s[-1]))
    sh = np.arange(int(np.floor(smax / ds + 1e-9)) + 1) * ds
    tol = 1e-9 * ds
    right = np.where(sh <= s[-1] + tol, np.interp(sh, s, p), np.nan)
    left = np.where(-sh >= s[0] - tol, np.interp(-sh, s, p), np.nan)
    both = np.isfinite(right) & np.isfinite(left)
    ph = np.where(both, 0.5 * (right + left), np.where(np.isfinite(right), right, left))
    top = float(np.max(p)) if p.size else 0.0
    asym = float(np.max(np.abs(right[both] - left[both])) / top) if both.any() and top > 0 else 0.0
    return sh, ph, asym



# --- solver results ------------------------------------------------------------------------

@dataclass
class BoneMap:
    """Bone pressure P(s, z) of a 3D result on a tensor grid: pressure[j, i] at (s[i], z[j]).

    s: the section profile's samples (so the row z = section_z is the profile); z: rows over
    the slab (fe.output.map_planes). Values are the nodal pressure field of result.vtu,
    interpolated with each bone facet's own shape functions (fe.output.surface_grid).
    """

    s: np.ndarray
    z: np.ndarray
    pressure: np.ndarray
    section_z: float = 0.0

    def __post_init__(self):
        self.s = np.asarray(self.s, float)
        self.z = np.asarray(self.z, float)
        self.pressure = np.asarray(self.pressure, float)
        for name in ("s", "z"):
            v = getattr(self, name)
            if v.ndim != 1 or v.size < 1 or np.any(np.diff(v) <= 0):
                raise ParameterError(f"bone map {name}", f"shape {v.shape}", "a strictly increasing 1-D grid")
        if self.pressure.shape != (self.z.size, self.s.size):
            raise ParameterError("bone map pressure", f"shape {self.pressure.shape}",
                                 f"(len(z), len(s)) = ({self.z.size}, {self.s.size})")
        if not np.all(np.isfinite(self.pressure)):
            raise ConvergenceError("non-finite values in the bone map", {"field": "bone_map"})

    def max_over_z(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(s, P_max(s) = max over z of P(s, z), the z where it occurs)."""
        j = np.argmax(self.pressure, axis=0)
        return self.s, self.pressure[j, np.arange(self.s.size)], self.z[j]

    def peak(self) -> tuple[float, float, float]:
        """(largest P over the map, its s, its z)."""
        j, i = np.unravel_index(int(np.argmax(self.pressure)), self.pressure.shape)
        return float(self.pressure[j, i]), float(self.s[i]), float(self.z[j])

    def interior_peak(self, margin: float, z_end_free: bool = True,
                      s_end_free: bool = True) -> tuple[float, float, float]:
        """peak() over the points farther than `margin` (mm) from the map's edges, or over the
        whole map if none is. A grid starting at 0 starts at a symmetry plane of the reduced
        model, not at an edge. Why: where the bonded skin ends (a slab's free end, a pad's
        side) the bone pressure has a corner singularity (t = 5 mm dot, plate on the whole
        slab: 0.044, 0.056, 0.065 MPa at the end on meshes 1.6, 1.2, 0.8 / 8, against
        0.0348, 0.0352, 0.0353 under the dot; benchmarks/results/convergence3d.md)."""
        keep = []
        for v, end_free in ((self.z, z_end_free), (self.s, s_end_free)):
            ok = v <= v[-1] - margin if end_free else np.ones(v.shape, bool)
            if abs(v[0]) > 1e-9:
                ok &= v >= v[0] + margin
            keep.append(ok)
        if margin <= 0 or not (keep[0].any() and keep[1].any()):
            return self.peak()
        P = np.where(keep[0][:, None] & keep[1][None, :], self.pressure, -np.inf)
        j, i = np.unravel_index(int(np.argmax(P)), P.shape)
        return float(self.pressure[j, i]), float(self.s[i]), float(self.z[j])

    def row(self, z: float) -> np.ndarray:
        """P(s) on the map's row nearest z."""
        return self.pressure[int(np.argmin(np.abs(self.z - z)))]

    def to_csv(self) -> str:
        """Long (tidy) table s_mm, z_mm, pressure_mpa, one row per grid point, z-major."""
        S, Z = np.meshgrid(self.s, self.z)
        return _csv(["s_mm", "z_mm", "pressure_mpa"], S.ravel(), Z.ravel(), self.pressure.ravel())


def read_bone_map(path, section_z: float = 0.0) -> BoneMap:
    """The BoneMap of a bone_map.csv (as Result.write writes it). A file that is not a complete
    (s, z) grid of finite numbers raises ParameterError naming it."""
    path = Path(path)
    valid = "a bone_map.csv written by tactileskin solve (s_mm, z_mm, pressure_mpa on a full grid[, status])"
    try:
        with open(path, encoding="utf-8") as fh:
            header = fh.readline().strip().split(",")
            if without_status(header) != ["s_mm", "z_mm", "pressure_mpa"]:
                raise ParameterError("bone map file", str(path), valid)
            # the numbers only: the status (last, quoted where it holds a comma) is the summary's
            data = np.loadtxt(fh, delimiter=",", ndmin=2, usecols=(0, 1, 2), quotechar='"')
    except (OSError, ValueError) as e:
        raise ParameterError("bone map file", str(path), valid, hint=str(e)) from None
    if data.shape[1] != 3 or not np.all(np.isfinite(data)):
        raise ParameterError("bone map file", str(path), valid)
    s, z = np.unique(data[:, 0]), np.unique(data[:, 1])
    if data.shape[0] != s.size * z.size:
        raise ParameterError("bone map file", str(path), valid, hint=f"{data.shape[0]} rows for "
                             f"{s.size} s x {z.size} z values")
    P = np.full((z.size, s.size), np.nan)
    P[np.searchsorted(z, data[:, 1]), np.searchsorted(s, data[:, 0])] = data[:, 2]
    if not np.all(np.isfinite(P)):
        raise ParameterError("bone map file", str(path), valid, hint="repeated (s, z) points")
    return BoneMap(s, z, P, section_z)


@dataclass
class Result:
    """Output of one solve (units mm, MPa, N; plane-strain forces per mm of depth).

    s, pressure: mean pressure P = -(sx+sy+sz)/3 (positive in compression) at the nodes of
      the bone interface, L2-projected from the quadrature points, sorted by curvilinear
      distance s from the symmetry line. 3D: on the section plane z = stats["profile_plane_z"],
      sampled along the cut of each bone-interface facet (fe.output.plane_profile).
    bone_map: 3D only, P(s, z) over the whole bone surface (BoneMap); its row z =
      profile_plane_z is the profile.
    sensors: the readings of the scene's sensor layouts (sensors.SensorReadings), or None;
      written as sensors.csv.
    contact_x, contact_pressure: contact pressure (per current area) at the contact points
      of the outer surface, sorted by the current x.
    reaction: the indenter's vertical force: on the whole indenter in 3D (the fixed
      boundaries' reaction on the modelled part times its mirror copies), per mm of the half
      section in 2D (half the whole section's on a model without the x = 0 line).
    stats: dofs, increments, newton_iterations, wall_s (and more).
    fields: optional nodal data for the .vtu (points, cells, cell_type, point_data).
    history: per-increment records when requested.
    """

    s: np.ndarray
    pressure: np.ndarray
    contact_x: np.ndarray
    contact_pressure: np.ndarray
    reaction: float
    stats: dict
    fields: dict | None = None
    history: list = field(default_factory=list)
    scene: dict | None = None
    bone_map: BoneMap | None = None
    sensors: object | None = None  # sensors.SensorReadings of the scene's sensor layouts
    # force control / a loading history (fe.solve): control, target and reached force, the
    # profile's state (peak load: time, travel, reaction) and the final state; None: a plain ramp
    loading: dict | None = None
    # the contact points' current positions (n, dim), in contact_x's order; None: x only
    contact_points: np.ndarray | None = None

    def __post_init__(self):
        for name in ("s", "pressure", "contact_x", "contact_pressure"):
            v = np.asarray(getattr(self, name), float)
            if not np.all(np.isfinite(v)):
                raise ConvergenceError(f"non-finite values in result field {name!r}", {"field": name})
            setattr(self, name, v)
        if not np.isfinite(self.reaction):
            raise ConvergenceError("non-finite reaction force", {"field": "reaction"})

    def __repr__(self) -> str:
        """One line: the scene, the metrics, the status and the sizes (not the arrays)."""
        sc = self.scene or {}
        name = (f"t{sc['thickness']:g}-{sc.get('material', '?')}-{sc.get('indenter', '?')}-{sc.get('dim', 2)}d"
                if "thickness" in sc else "scene ?")
        try:  # the scene's own label (Braille text, skin), as the CLI and summary.json name it
            from tactileskin.scene import Scene

            name = Scene.from_dict(dict(sc)).label()
        except Exception:  # noqa: BLE001 - a scene this version cannot rebuild keeps the short name
            pass
        try:
            metrics = f"peak={self.peak:.4g} MPa, span={self.span:.3g} mm, auc={self.auc:.4g} MPa*mm"
        except ParameterError:  # a profile too short for the metrics
            metrics = "no profile"
        extra = ", bone_map" if self.bone_map is not None else ""
        from tactileskin.loading import force_unit

        unit = force_unit(self.dim)
        return (f"<Result {name}: {metrics}, reaction={self.reaction:.4g} {unit}, status={self.status!r}; "
                f"{self.s.size} profile points, {self.contact_x.size} contact points, "
                f"{int(self.stats.get('dofs', 0))} dofs{extra}>")

    @property
    def dim(self) -> int:
        """2 or 3: the scene's, else 3 when the result has a bone map."""
        d = (self.scene or {}).get("dim")
        return int(d) if d in (2, 3) else (3 if self.bone_map is not None else 2)

    @property
    def peak(self) -> float:
        """Largest mean pressure of the bone profile (MPa)."""
        return peak(*self._profile())

    @property
    def sides(self) -> int:
        """1: the profile starts at the symmetry line (a halved model); 2: it runs across the
        centre (a model without the x = 0 plane: a user's full skin, a full-width pad)."""
        return 2 if int(self.stats.get("profile_sides", 1)) == 2 else 1

    @property
    def span(self) -> float:
        """Span (mm); of a two-sided profile half its extent, as the halved model reads it."""
        return span(*self._profile()) / self.sides

    @property
    def auc(self) -> float:
        """Area under P(s) (MPa mm); of a two-sided profile half of it (the half section's)."""
        return auc(*self._profile()) / self.sides

    def _profile(self):
        # nodes at (numerically) the same s: keep their mean so that s is strictly increasing
        s, inv = np.unique(np.round(self.s, 9), return_inverse=True)
        p = np.bincount(inv, weights=self.pressure) / np.bincount(inv)
        return s, p

    def _contact_csv(self) -> str:
        """contact.csv: the contact points' current position (x, y[, z] mm) and their contact
        pressure per current area (MPa); x alone for a result without positions."""
        pts = self.contact_points
        if pts is None or len(pts) != len(self.contact_x):
            return _csv(["x_mm", "contact_pressure_mpa"], self.contact_x, self.contact_pressure)
        pts = np.asarray(pts, float)
        pts = pts.reshape(len(self.contact_x), pts.shape[-1] if pts.ndim == 2 else -1)
        names = ["x_mm", "y_mm", "z_mm"][: pts.shape[1]]
        return _csv(names + ["contact_pressure_mpa"], *pts.T, self.contact_pressure)

    def summary(self) -> dict:
        """The result's numbers, with its status ("ok" or "suspect: reasons") and flags
        (tactileskin.quality: no contact, material law outside its range, locking, coarse
        mesh, a peak at the bonded edge, ...)."""
        out = {
            "peak_mpa": self.peak,
            "span_mm": self.span,
            "auc_mpa_mm": self.auc,
            # the most tensile value of P(s): quality judges whether the bone is pressed at all
            **({"profile_min_mpa": float(np.min(self.pressure))} if len(self.pressure) else {}),
            reaction_key(self.dim): float(self.reaction),
            # the depth a depth ramp pressed to (mm from first touch); force control and histories: `loading`
            **({"depth_mm": float(self.stats["depth_mm"])} if "depth_mm" in self.stats else {}),
            "contact_points": int(len(self.contact_x)),
            # extremes of the material law's state (fe.output.law_state)
            **{k: float(self.stats[k]) for k in ("min_J", "max_abs_stress_mpa", "max_pressure_mpa", "material_nu0",
                                                       "material_mu0_mpa")
               if k in self.stats},
            **({"element_order": int(self.stats["order"])} if "order" in self.stats else {}),
            **({"mesh_sizes_mm": dict(self.stats["mesh_sizes_mm"])} if "mesh_sizes_mm" in self.stats else {}),
            "dofs": int(self.stats.get("dofs", 0)),
            "newton_iterations": int(self.stats.get("newton_iterations", 0)),
            "increments": int(self.stats.get("increments", 0)),
            "wall_s": float(self.stats.get("wall_s", 0.0)),
            # 3D: the profile is that of the section plane z = profile_plane_z (fe.output.plane_profile)
            **({"profile_plane_z": float(self.stats["profile_plane_z"])} if "profile_plane_z" in self.stats else {}),
            # ... chosen from the map's interior peak (a file indenter): quality judges its edges
            **({"profile_plane_from_map": True} if self.stats.get("profile_plane_from_map") else {}),
            **{k: True for k in ("bone_map_missing", "profile_plane_unknown") if self.stats.get(k)},
            # a profile across the centre (no x = 0 plane): span and AUC are half of it
            **({"profile_sides": 2} if self.sides == 2 else {}),
            # a half model (x >= 0) of an indenter that is not symmetric about x = 0 (quality flag)
            **({"indenter_cap": dict(self.stats["indenter_cap"])} if self.stats.get("indenter_cap") else {}),
            # pressed past a slender pad's buckling strain (the model cannot buckle: quality flag)
            **({"buckling": dict(self.stats["buckling"])} if self.stats.get("buckling") else {}),
            **({"mirrored_x": True} if self.stats.get("mirrored_x") else {}),
            **({"mirrored_z": True} if self.stats.get("mirrored_z") else {}),
            **self._edge_summary(),
            **self._map_summary(),
            **({"loading": self.loading} if self.loading is not None else {}),
            **(self.sensors.summary() if self.sensors is not None else {}),
            **({"scene": self.scene} if self.scene else {}),
        }
        found = quality.flags(out)
        out["status"] = quality.status_of(found)
        out["flags"] = [f.to_dict() for f in found]
        return out

    def _edge_summary(self) -> dict:
        """The profile's peak at an edge of the bonded skin (`edge_peak`), with the interior one
        (quality flags it: the peak is a corner singularity)."""
        scene = self.scene or {}
        if not skin_says(scene, "profile_ends_free"):
            return {}
        found = edge_peak(*self._profile(), float(scene.get("thickness") or 0.0))
        if found is None:
            return {}
        _, se, pi, si = found
        return {"peak_edge_s_mm": se, "peak_interior_mpa": pi, "peak_interior_s_mm": si}

    def _map_summary(self) -> dict:
        """The map's peak one skin thickness or more from the edges of the bonded surface, and
        the edge band's larger value apart (a corner singularity: it grows with refinement)."""
        if self.bone_map is None:
            return {}
        margin = float((self.scene or {}).get("thickness") or 0.0)
        p, s, z = self.bone_map.interior_peak(margin, skin_says(self.scene or {}, "map_z_end_free"),
                                              skin_says(self.scene or {}, "profile_ends_free"))
        out = {"peak_map_mpa": p, "peak_map_s_mm": s, "peak_map_z_mm": z}
        pe, se, ze = self.bone_map.peak()
        if pe > p:
            out.update({"peak_map_edge_mpa": pe, "peak_map_edge_s_mm": se, "peak_map_edge_z_mm": ze})
        return out

    @property
    def status(self) -> str:
        """'ok' or 'suspect: <reasons>' (tactileskin.quality)."""
        return self.summary()["status"]

    def plot(self, path=None, *, ax=None):
        """A matplotlib figure of the result: the bone profile P(s) (3D: on the section plane,
        with the maximum over z, beside the map P(s, z)). Returns (figure, axes); `ax`: draw
        the profile into these axes (2D); `path`: also save it (.png, .svg or .pdf by suffix).
        Writes no file unless `path` is given."""
        if path is not None:
            validate.path(path, "path", "a file path (.png, .svg or .pdf) or None")
        if ax is not None:
            from matplotlib.axes import Axes

            if not isinstance(ax, Axes):
                raise ParameterError("ax", repr(ax), "matplotlib Axes or None")
        from tactileskin.report.result_plot import plot_result

        return plot_result(self, path, ax=ax)

    def to_pyvista(self):
        """The result as a pyvista.UnstructuredGrid, the content of result.vtu: the reference
        mesh with the nodal fields named with their unit (`displacement_mm` is the active
        vectors: grid.warp_by_vector() gives the deformed skin), the named boundaries as
        facet cells with cell data `boundary_id` (0: the skin), their names in field data,
        cell data `suspect` (1 on every cell of a suspect result, else 0).
        Needs pyvista (pip install 'tactileskin[render]'); raises MissingDependency without."""
        from tactileskin.errors import MissingDependency, require_pyvista

        if self.fields is None:
            raise ParameterError("result fields", None, "a result with its mesh fields (Result.fields)",
                                 hint="a result read back from a summary has no mesh")
        pv = require_pyvista("Result.to_pyvista()")
        mesh = _meshio_mesh(self.fields, status=self.status)
        try:
            grid = pv.from_meshio(mesh)
        except ImportError as e:  # pragma: no cover - a broken VTK install
            raise MissingDependency("vtk", "Result.to_pyvista()") from e
        for name, v in mesh.field_data.items():
            grid.field_data[name] = v
        if "displacement_mm" in grid.point_data:
            grid.point_data.active_vectors_name = "displacement_mm"
        return grid

    def write(self, directory) -> Path:
        """Write the result into `directory`: a new or empty folder, or one tactileskin marked
        as a solve's (outdir.claim_dir; a folder of other files is refused, OutputError, and
        left as it is, and so is one another run is writing into). See write_owned for the files; the earlier result there goes whole, a
        CLI solve's figures, 2D section and comparison included (SOLVE_FILES)."""
        validate.path(directory, "directory", "a folder path (str or os.PathLike)")
        directory = outdir.claim_dir(directory, "solve", what="directory")
        with outdir.run_lock(directory, "directory"), \
                staging.staged_files(directory, SOLVE_FILES, last="summary.json") as tmp:
            self._write_files(tmp)
        return directory

    def write_owned(self, directory) -> Path:
        """Write OWN_FILES (profile.csv, contact.csv, summary.json, result.vtu (reference mesh,
        displacement_mm and the other fields named with their unit, boundaries by name, the status
        as the cell array `suspect` and a comment, vtu_status);
        with a history, result.pvd over result_steps/; with sensors, sensors.csv; 3D: also
        bone_map.csv, the map P(s, z), and profile_max_z.csv, P_max(s) = max over z with the z
        where it occurs) into `directory`, creating it. All of them are staged and moved in
        together (staging.staged_files): a failed write leaves the folder as it was, and files of
        an earlier result that this one has not (a map, a field file) are removed; other files
        are not touched. For folders the caller owns (a cache entry, a staging folder): `write`
        claims a user's folder first."""
        directory = fileio.make_dirs(directory)
        with staging.staged_files(directory, OWN_FILES, last="summary.json") as tmp:
            self._write_files(tmp)
        return directory

    def _write_files(self, directory: Path) -> None:
        summary = self.summary()
        # every table carries the status on every row: a suspect result's rows read like an
        # ok one's once a file is taken out of its folder (the sweep's sensors.csv does the same)
        status = summary["status"]

        def table(name: str, text: str) -> None:
            fileio.atomic_write_text(directory / name, with_status(text, status))

        s, p = self._profile()
        table("profile.csv", _csv(["s_mm", "pressure_mpa"], s, p))
        table("contact.csv", self._contact_csv())
        if self.fields is not None:
            _write_vtu(directory / "result.vtu", self.fields, status=status)
        _write_steps(directory, self.fields, status)
        if self.bone_map is not None:
            table("bone_map.csv", self.bone_map.to_csv())
            table("profile_max_z.csv", _csv(["s_mm", "pressure_mpa", "z_mm"], *self.bone_map.max_over_z()))
        if self.sensors is not None:
            table("sensors.csv", self.sensors.to_csv())
        if self.loading is not None and self.history:
            cols = ["t", "d", "reaction", "peak_mpa", "segment"]
            table("history.csv", _csv(
                ["t_s", "travel_mm", reaction_key(self.dim), "peak_bone_pressure_mpa", "segment"],
                *[np.array([h.get(c, np.nan) for h in self.history], float) for c in cols]))
        fileio.atomic_write_json(directory / "summary.json", summary)


def reaction_key(dim: int) -> str:
    """The summary key of the indenter's reaction, named with its unit: per mm of depth in 2D
    (plane strain, the half section x >= 0), the force on the whole indenter in 3D (the
    modelled part's times its mirror copies)."""
    return "reaction_n" if int(dim) == 3 else "reaction_n_per_mm"


# the files of one result (write_owned; fnmatch patterns, relative paths)
OWN_FILES = ("profile.csv", "contact.csv", "summary.json", "result.vtu", "bone_map.csv", "profile_max_z.csv",
             "sensors.csv", "history.csv", "result.pvd", "result_steps/step_*.vtu")
# every file of a solve folder, whoever writes it (`tactileskin solve`, Result.write): one list,
# so that either replaces all of the other's earlier result (a stale map figure or 2D section
# would look current); --compare-2d's section is a result folder of its own
SOLVE_FILES = (*OWN_FILES, "bone_map.png", "sensors.png", "compare_2d.json",
               *(f"section_2d/{n}" for n in OWN_FILES))


def skin_says(scene: dict, what: str) -> bool:
    """A skin kind's boolean class attribute (skins.base.Skin) for a scene dict; True for an
    unknown skin name (its profile and map are judged as they are)."""
    from tactileskin.skins import registry

    try:
        return bool(getattr(registry.get(scene.get("skin", "fingertip")), what))
    except ParameterError:
        return True


def read_vtu(path):
    """meshio.read of a .vtu, with a damaged file raised as ValueError: meshio's VTU reader
    ends the process (sys.exit) on an XML it cannot parse, which no caller catches as an error
    (a truncated cached result.vtu aborted every later sweep)."""
    import contextlib

    import meshio

    said = io.StringIO()
    try:
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said):  # it prints, then exits
            return meshio.read(path)
    except SystemExit:
        raise ValueError(f"cannot read {path} as VTU (truncated or damaged?)") from None


STATUS_COLUMN = "status"  # the last column of a solve's tables, the first after `case` in a sweep's


def with_status(text: str, status: str) -> str:
    """A CSV table (header line, then rows, each ending with a line feed; no field holding one)
    with the column STATUS_COLUMN appended: `status` (summary.json's "ok" or "suspect: reasons")
    on every row, quoted where it holds a comma or a quote. Last, so the other columns keep
    their positions. Rows are split at line feeds only, as a CSV reader does: str.splitlines
    also breaks at U+2028, NEL, form feed, ..., which a sensor layout's name may hold.
    A table without rows of a result that is not ok (contact.csv of one without contact) gets
    one, its other fields empty (read as NaN: no point is invented), so that the status saying
    why is read; its header alone showed no status."""
    buf = io.StringIO()
    csv.writer(buf, lineterminator="").writerow([status])
    cell = buf.getvalue()
    lines = text.split("\n")
    if lines[-1] == "":
        lines.pop()
    if len(lines) == 1 and quality.kind(status) != "ok":
        lines.append("," * lines[0].count(","))
    return "".join([lines[0] + "," + STATUS_COLUMN + "\n", *(line + "," + cell + "\n" for line in lines[1:])])


def without_status(header: list[str]) -> list[str]:
    """`header` without a trailing STATUS_COLUMN (a table written before it has none)."""
    return header[:-1] if header[-1:] == [STATUS_COLUMN] else header


def _csv(header: list[str], *cols) -> str:
    if not cols or len(np.atleast_1d(cols[0])) == 0:
        return ",".join(header) + "\n"
    buf = io.StringIO()
    np.savetxt(buf, np.column_stack(cols), delimiter=",", header=",".join(header), comments="", fmt="%.10g")
    return buf.getvalue()


def _pad3(v) -> np.ndarray:
    v = np.asarray(v, float)
    if v.ndim == 2 and v.shape[1] == 2:
        v = np.column_stack([v, np.zeros(len(v))])
    return v


def _meshio_mesh(fields: dict, point_data: dict | None = None, status: str | None = None):
    """The meshio.Mesh of `fields` (fe.output.vtk_fields): the cells with cell data
    `boundary_id` 0, then each named boundary's facets with its id; its field data
    {name: [id, dim]} names the ids (as gmsh and meshio keep them). The facet fields of
    fields["facet_data"] ({field: {boundary: (F,) values}}, e.g. contact_pressure_MPa on
    outer_surface) are cell data, zero on the other cells; not with a `point_data` override
    (the increments of result.pvd, which hold the displacement only). With the result's
    `status`, cell data SUSPECT_ARRAY: 1 on every cell if it is not "ok", else 0."""
    import meshio  # only when writing files (keeps the solver import light)

    pts = _pad3(fields["points"])
    pdata = {k: _pad3(v) for k, v in (fields["point_data"] if point_data is None else point_data).items()}
    blocks = [(fields["cell_type"], np.asarray(fields["cells"]))]
    ids = [np.zeros(len(blocks[0][1]), np.int32)]
    field_data = {}
    for k, (name, (ctype, conn)) in enumerate(sorted(fields.get("boundaries", {}).items()), start=1):
        blocks.append((ctype, np.asarray(conn)))
        ids.append(np.full(len(conn), k, np.int32))
        field_data[name] = np.array([k, pts.shape[1] - 1 if ctype == "triangle" else 1], np.int32)
    cell_data = {"boundary_id": ids} if len(blocks) > 1 else {}
    names = [None] + sorted(fields.get("boundaries", {}))
    for fname, per_boundary in (fields.get("facet_data") or {}).items() if point_data is None else ():
        cell_data[fname] = [np.asarray(per_boundary[n], float) if n in per_boundary else np.zeros(len(b[1]))
                            for n, b in zip(names, blocks)]
    if status is not None:
        flag = int(quality.kind(status) != "ok")
        cell_data[SUSPECT_ARRAY] = [np.full(len(b[1]), flag, np.int8) for b in blocks]
    return meshio.Mesh(pts, blocks, point_data=pdata, cell_data=cell_data, field_data=field_data)


def _write_vtu(path: Path, fields: dict, point_data: dict | None = None, status: str | None = None) -> None:
    """One .vtu of `fields` (see `_meshio_mesh`), the boundary names kept as VTK field data;
    with the result's `status` (summary.json's) the SUSPECT_ARRAY flag and the text in a comment."""
    mesh = _meshio_mesh(fields, point_data, status)
    field_data = mesh.field_data
    with fileio.atomic_path(path) as tmp, fileio.os_errors(path):
        mesh.write(tmp, file_format="vtu")
        if field_data or status is not None:  # one rewrite of the file for both
            data = Path(tmp).read_bytes()
            if field_data:  # meshio's VTU writer drops field data: add it as VTK reads it
                data = _with_field_data(data, field_data)
            if status is not None:
                data = _with_status(data, status)
            Path(tmp).write_bytes(data)


# A cell array of result.vtu: 1 on every cell of a suspect result, 0 of an ok one. Numeric, as
# ParaView lists and colours it and meshio (the package's reader) refuses string arrays; not
# field data, which holds the boundary names.
SUSPECT_ARRAY = "suspect"
# ... and the status text itself, in an XML comment before the grid (VTK and meshio skip it)
_STATUS_COMMENT = "<!-- tactileskin status: "


# what an XML 1.0 comment may not hold as text: control characters but tab and newline (CR
# too: a parser turns CR LF into LF), surrogates (no UTF-8 form) and the non-characters U+FFFE/F
_NOT_XML = re.compile("[\x00-\x08\x0b-\x1f\ud800-\udfff\ufffe\uffff]")


def _with_status(data: bytes, status: str) -> bytes:
    """A .vtu's bytes with `status` in a comment after the XML declaration. A comment cannot
    hold "--" (a reason says "use --quality"): a "-" after a "-" is written "\\-", a backslash
    "\\\\", a character XML does not allow (_NOT_XML) "\\uXXXX;" (vtu_status reads them back),
    so "--quality" reads "-\\-quality"."""
    text = _NOT_XML.sub(lambda m: f"\\u{ord(m.group()):04x};", status.replace("\\", "\\\\"))
    text = re.sub(r"(?<=-)-", r"\\-", text)
    i = data.index(b"?>") + 2 if data.startswith(b"<?xml") else 0
    return data[:i] + ("\n" + _STATUS_COMMENT + text + " -->").encode("utf-8") + data[i:]


def vtu_status(path) -> str | None:
    """The status text a result.vtu was written with (summary.json's "ok" or "suspect: ..."),
    None for a file without one (written before, or not a result)."""
    # the comment starts after the XML declaration (_with_status), whatever the mesh's size;
    # a long status runs past the first chunk, so read on to its end
    with open(path, "rb") as fh:
        # a bytearray grows in place: a damaged file without the comment's end is read in
        # linear time (appending to bytes copied all read so far: 64 MiB took 34 s)
        data = bytearray(fh.read(1 << 16))
        i = data.find(_STATUS_COMMENT.encode())
        if i < 0:
            return None
        j = data.find(b" -->", i)
        while j < 0:
            more = fh.read(1 << 16)
            if not more:
                return None
            start = max(len(data) - 3, i)  # " -->" may straddle the chunks
            data += more
            j = data.find(b" -->", start)
    head = bytes(data[:j]).decode("utf-8", "replace")
    i, j = head.find(_STATUS_COMMENT), len(head)
    return re.sub(r"\\(?:u([0-9a-f]{4});|(.))", lambda m: chr(int(m.group(1), 16)) if m.group(1) else m.group(2),
                  head[i + len(_STATUS_COMMENT):j], flags=re.S)


def vtu_reasons(path, status: str | None) -> list[str] | None:
    """The reasons of a .vtu's `status` as the summary.json of its result lists them (its
    flags; result_steps/ files: the folder above), None where that summary has another
    status or none. A status written before quality.Flag kept '; ' out of a reason splits
    into one reason too many; the flags do not."""
    path = Path(path)
    folder = path.parent.parent if path.parent.name == STEPS_DIR else path.parent
    try:
        doc = json.loads((folder / "summary.json").read_text(encoding="utf-8"))
        flags = [str(f["reason"]) for f in doc["flags"]]
    except (OSError, ValueError, KeyError, TypeError):
        return None
    return flags if flags and doc.get("status") == status else None


def add_vtu_field_data(path: Path, field_data: dict) -> None:
    """Add {name: [id, dim]} to a .vtu as VTK field data (meshio's VTU writer drops it)."""
    path.write_bytes(_with_field_data(path.read_bytes(), field_data))


def _with_field_data(data: bytes, field_data: dict) -> bytes:
    arrays = "".join(f'<DataArray type="Int32" Name="{name}" NumberOfTuples="1" NumberOfComponents="2" '
                     f'format="ascii">{v[0]} {v[1]}</DataArray>\n' for name, v in field_data.items())
    tag = b"<UnstructuredGrid>"
    i = data.index(tag) + len(tag)
    return data[:i] + b"\n<FieldData>\n" + arrays.encode() + b"</FieldData>" + data[i:]


STEPS_DIR = "result_steps"  # the .vtu of each increment, listed by result.pvd


def _write_steps(directory: Path, fields: dict, status: str | None = None) -> None:
    """result.pvd, a ParaView time series over result_steps/step_NNNN.vtu (the displacement
    of each converged increment on the reference mesh; the final state's stresses and
    pressure are in result.vtu), when the fields have steps; each step with the result's status."""
    steps = fields.get("steps") if fields else None
    if not steps:
        return
    sd = fileio.make_dirs(directory / STEPS_DIR)
    entries = []
    for i, (t, u) in enumerate(steps):
        name = f"step_{i:04d}.vtu"
        _write_vtu(sd / name, fields, {"displacement_mm": u}, status)
        entries.append(f'    <DataSet timestep="{t:.9g}" group="" part="0" file="{STEPS_DIR}/{name}"/>')
    fileio.atomic_write_text(directory / "result.pvd",
                             '<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
                             "  <Collection>\n" + "\n".join(entries) + "\n  </Collection>\n</VTKFile>\n")
