"""tactileskin: design soft artificial skins over embedded tactile sensors.

Units throughout: millimetres, seconds, newtons, megapascals (N/mm^2).
Pressures per unit depth in plane strain are N/mm per mm of depth = MPa.
"""

__version__ = "0.1.0"

from tactileskin.errors import (  # noqa: F401  (re-exported API)
    CadError,
    ConvergenceError,
    MeshError,
    ParameterError,
    TactileSkinError,
)
