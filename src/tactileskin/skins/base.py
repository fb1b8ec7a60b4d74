"""The skin contract: what a skin geometry answers for the Scene, the meshers and the solver.

A skin is a class (no instances: every answer is a function of the Scene) with
- `name`, `order` (listing order), `scene_params` (the Scene fields it reads besides
  `thickness`; a Scene refuses them with another skin) and `check_scene(scene) -> dict`
  (ParameterError naming the field and its valid range; returns normalised values);
- `section(scene)`: its 2D section as curves and coordinates (the `Section` duck type of
  geometry.fingertip: `thickness`, `top` (y of the outer surface on x = 0, where indenters
  start), `interface_length` (bonded surface from x = 0), `s_of_point(points)`,
  `point_at_s(s)`, `outer_points(n)`, `area()`, and for mesh sizing `half_width` (x extent
  of the outer surface), `contact_radius(indenter)`, `outer_length_to_x(x)`,
  `min_radius_of_curvature`);
- `sample_length(scene)`: the z extent of the 3D model (and the indenter plates);
- `coordinates(scene)`: the sensor coordinates (`frame(s, depth)`, `thickness`, `s_max`; a
  `local` one, skins.file's, also `depths(...)` and `frame(s, depth, z)`: see sensors.resolve);
  `mesh_coordinates(scene, skinmesh)`: those on the mesh solved (where the sensors are read);
- `fixed_boundaries`: the boundary names held fixed (bonded to rigid parts). Every skin mesh
  names `bone_interface` (the bonded surface: the pressure path), `outer_surface` (contact),
  `symmetry` (x = 0) and, in 3D, `end_front` / `end_back` (z = +-L/2; `end_back` is z = 0
  when the indenter is z-symmetric); other names are free surfaces unless listed here;
- `build_mesh(scene, **overrides) -> SkinMesh` (gmsh, imported inside);
- `top_extent(scene)`: (x, z) half extents of the top an indenter presses (mm), or None where
  the skin does not know it before meshing (a Braille text is refused past it);
- `buckling_strain(scene)`: the nominal strain at which the skin, pressed as the scene presses
  it, would buckle, where the model (no imperfection, often a symmetric half) cannot show it;
  None where that does not apply;
- `size_plan(scene)`: the mesh's sizing plan without meshing (ParameterError above the dofs
  cap: a request is refused before any other solve runs), or None where only meshing tells;
- `build_parts(thickness, molds=True, **params) -> list[Part]` (build123d, imported inside);
- `label(scene)`: the prefix of case labels ("" for the paper's fingertip);
- `s_path` / `s_axis`: what the profile's path is and what s measures on it (figure labels);
- `cache_content(scene)`: digests of files it reads, for cache.cache_key (a user's skin file).
"""

from __future__ import annotations

from typing import ClassVar


class Skin:
    name: ClassVar[str] = ""
    order: ClassVar[int] = 9
    scene_params: ClassVar[tuple[str, ...]] = ()
    fixed_boundaries: ClassVar[tuple[str, ...]] = ("bone_interface",)
    # the geometry fixes the thickness (a user's file): a sweep does not vary it by default
    fixes_thickness: ClassVar[bool] = False
    # 3D spot contacts (an indenter kind's `local_3d`) are meshed by mesh.sizing.local_plan,
    # whose `_dot_frame` knows this skin's outer surface; False: the strip plan
    local_plan: ClassVar[bool] = False
    # modelled as its half x >= 0 whatever the indenter (the pad takes its full width for an
    # x-asymmetric indenter; a user's file skin is meshed as given)
    halves_x: ClassVar[bool] = False
    # its section's outer_points are the half x >= 0 of a skin it meshes in full width for an
    # x-asymmetric indenter (the pad): the first-contact check mirrors them there
    full_width_if_asymmetric: ClassVar[bool] = False
    # the bonded surface ends free where the bone profile ends (a pad's side): a corner
    # singularity there is flagged (quality "edge_peak"); False where it continues into another
    # bonded part (the fingertip's bone into the nail)
    profile_ends_free: ClassVar[bool] = True
    # likewise the 3D bone map's largest z: False where the bone runs on past it (the dome's
    # tip, bonded beyond z = 0), so that a load there is not taken for a corner of the map
    map_z_end_free: ClassVar[bool] = True
    boundaries_2d: ClassVar[tuple[str, ...]] = ("bone_interface", "outer_surface", "symmetry")
    # the top falls away from x = 0 (the fingertip's ellipse), the same in every z plane (or
    # lower, the dome's tip): a Braille dot on it presses only if its section contour comes
    # within the travel of the dot (geometry.indenters.braille), not wherever it lies inside
    # `top_extent`
    top_curved: ClassVar[bool] = False
    # the path of the pressure profile and what s is on it (the sweep's Fig. 10 labels): a pad
    # has no bone, its s is x on the board
    s_path: ClassVar[str] = "the bonded surface"
    s_axis: ClassVar[str] = "distance along the bonded surface s"

    @classmethod
    def boundaries_3d(cls) -> tuple[str, ...]:
        return cls.boundaries_2d + ("end_front", "end_back")

    @classmethod
    def check_scene(cls, scene) -> dict:
        raise NotImplementedError

    @classmethod
    def section(cls, scene):
        raise NotImplementedError

    @classmethod
    def sample_length(cls, scene) -> float:
        raise NotImplementedError

    @classmethod
    def coordinates(cls, scene):
        raise NotImplementedError

    @classmethod
    def mesh_coordinates(cls, scene, skinmesh):
        """The sensor coordinates on the mesh solved (the built-in skins' are analytic: the
        scene's)."""
        return cls.coordinates(scene)

    @classmethod
    def build_mesh(cls, scene, *, cell: str = "tri", **overrides):
        raise NotImplementedError

    @classmethod
    def size_plan(cls, scene):
        return None

    @classmethod
    def convergence_hint(cls, scene) -> str | None:
        """What to change when a depth ramp of this skin fails to converge, where the skin knows
        (a confined pad under the flat plate), else None."""
        return None

    @classmethod
    def top_extent(cls, scene) -> tuple[float, float] | None:
        return None

    @classmethod
    def buckling_strain(cls, scene) -> float | None:
        return None

    @classmethod
    def build_parts(cls, thickness: float, *, molds: bool = True, **params) -> list:
        raise NotImplementedError

    @classmethod
    def cache_content(cls, scene) -> dict:
        """{scene field: digest} of files the skin reads (their bytes enter cache.cache_key, their
        paths do not)."""
        return {}

    @classmethod
    def label(cls, scene) -> str:
        return cls.name + "-"
