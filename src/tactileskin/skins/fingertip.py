"""fingertip: the paper's skin, an elliptical half section over bone and nail (geometry.fingertip),
as a plane-strain section (2D) or its extrusion along the finger (3D slab)."""

from __future__ import annotations

from tactileskin.skins.base import Skin
from tactileskin.skins.registry import register


@register
class FingertipSkin(Skin):
    name = "fingertip"
    halves_x = True
    local_plan = True
    order = 0
    scene_params = ("fingertip",)
    fixed_boundaries = ("bone_interface", "nail_edge")
    profile_ends_free = False  # the bone runs on into the bonded nail
    boundaries_2d = ("bone_interface", "outer_surface", "symmetry", "nail_edge")
    top_curved = True
    s_path = "the bone"
    s_axis = "distance along bone s"  # arc length from x = 0, the paper's

    @classmethod
    def model(cls, scene):
        from tactileskin.geometry.fingertip import Fingertip

        return Fingertip.from_params(**dict(scene.fingertip))

    @classmethod
    def check_scene(cls, scene) -> dict:
        return {"thickness": cls.model(scene).check_thickness(scene.thickness)}

    @classmethod
    def section(cls, scene):
        return cls.model(scene).section(scene.thickness)

    @classmethod
    def sample_length(cls, scene) -> float:
        return cls.model(scene).sample_length

    @classmethod
    def coordinates(cls, scene):
        from tactileskin.sensors import SectionCoordinates

        return SectionCoordinates(cls.section(scene))

    @classmethod
    def build_mesh(cls, scene, *, cell: str = "tri", **overrides):
        from tactileskin.errors import ParameterError

        if scene.dim == 2:
            from tactileskin.mesh.section2d import build_section_mesh

            return build_section_mesh(scene, cell=cell, **overrides)
        if cell != "tri":
            raise ParameterError("cell", cell, "'tri' in 3D (tetrahedra); 'quad' is 2D only")
        from tactileskin.mesh.slab3d import build_slab_mesh

        return build_slab_mesh(scene, **overrides)

    @classmethod
    def top_extent(cls, scene) -> tuple[float, float]:
        return float(cls.section(scene).half_width), 0.5 * cls.sample_length(scene)

    @classmethod
    def size_plan(cls, scene):
        if scene.dim == 2:
            from tactileskin.mesh import sizing

            return sizing.plan(scene, scene.section(), dim=2)
        from tactileskin.mesh.slab3d import slab_plan

        return slab_plan(scene)[0]

    @classmethod
    def build_parts(cls, thickness, *, molds=True, **params):
        from tactileskin.geometry.parts import build_parts

        return build_parts(thickness, molds=molds, **params)

    @classmethod
    def label(cls, scene) -> str:
        return ""  # the paper's case labels stay as they were
