"""Figures (matplotlib), renders (pyvista, off-screen) and the Markdown report of a sweep."""
