"""Material laws (numpy; hyperfoam's plane-strain path compiled with numba): hyperfoam,
neo-Hookean, Mooney-Rivlin, Yeoh, Ogden (registry: materials.laws), Prony-series QLV,
named presets, fitting to uniaxial data (materials.fit)."""

from tactileskin.materials.hyperfoam import (
    EXP_CAP,
    LOG_C_CAP,
    Hyperfoam,
    cauchy_principal,
    energy,
    pk2,
    pk2_tangent,
)
from tactileskin.materials.laws import get_law, list_laws
from tactileskin.materials.presets import Material, get_material, list_materials
from tactileskin.materials.prony import Prony

__all__ = [
    "EXP_CAP", "LOG_C_CAP", "Hyperfoam", "Material", "Prony", "cauchy_principal", "energy",
    "get_law", "get_material", "list_laws", "list_materials", "pk2", "pk2_tangent",
]
