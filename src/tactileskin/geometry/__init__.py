"""Geometry: the fingertip section (pure numpy) and, at the edges, build123d solids."""

from tactileskin.geometry.fingertip import Fingertip, Section  # noqa: F401
