"""Material laws (pure numpy): Storakers hyperfoam, Prony-series QLV, named presets."""

from tactileskin.materials.hyperfoam import (
    EXP_CAP,
    LOG_C_CAP,
    Hyperfoam,
    cauchy_principal,
    energy,
    pk2,
    pk2_tangent,
)
from tactileskin.materials.presets import Material, get_material, list_materials
from tactileskin.materials.prony import Prony

__all__ = [
    "EXP_CAP", "LOG_C_CAP", "Hyperfoam", "Material", "Prony", "cauchy_principal", "energy",
    "get_material", "list_materials", "pk2", "pk2_tangent",
]
