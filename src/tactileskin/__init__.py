"""tactileskin: design soft artificial skins over embedded tactile sensors.

Units throughout: millimetres, seconds, newtons, megapascals (N/mm^2).
Pressures per unit depth in plane strain are N/mm per mm of depth = MPa.

    import tactileskin as ts
    scene = ts.Scene(thickness=1, material="polyurethane", indenter="braille")  # help(ts.Scene)
    r = ts.solve(scene, quality="preview")          # r.peak, r.span, r.auc, r.write("out")
    df = ts.sweep({"thickness": [1, 2, 3]}, quality="preview")   # a pandas DataFrame

The names below are imported on first use, so `import tactileskin` stays light.
"""

__version__ = "0.1.0"


def _source_hashes() -> dict:
    """{path in the package (posix): SHA-256 of its bytes, None if unreadable} of its .py files."""
    import hashlib
    import os

    root, out = os.path.dirname(os.path.realpath(__file__)), {}
    for folder, dirs, files in os.walk(root):
        dirs[:] = [d for d in dirs if d != "__pycache__"]
        for name in files:
            path = os.path.join(folder, name)
            # a regular file, as code_digest's were: not an editor's dangling lock link (Emacs' .#name.py)
            if name.endswith(".py") and os.path.isfile(path):
                try:
                    with open(path, "rb") as fh:
                        digest = hashlib.sha256(fh.read()).hexdigest()
                except OSError:
                    digest = None
                out[path[len(root) + 1:].replace(os.sep, "/")] = digest
    return out


# the sources as this process imports them (3-8 ms), before any other module of the package: a
# `git pull` in a running kernel leaves the old code running, and cache.code_changes() sees it.
# Kept by importlib.reload(tactileskin): it re-runs this file alone, the loaded modules keep
# running, so a new snapshot would take the pulled files for the code that runs
if "_IMPORTED_SOURCES" not in globals():
    _IMPORTED_SOURCES = _source_hashes()

from tactileskin.errors import (  # noqa: F401  (re-exported API)
    CadError,
    ConvergenceError,
    MeshError,
    ParameterError,
    TactileSkinError,
)

# top-level name -> (module, attribute), imported on first access (PEP 562)
_LAZY = {
    "Scene": ("tactileskin.scene", "Scene"),
    "Result": ("tactileskin.results", "Result"),
    "solve": ("tactileskin.api", "solve"),
    "scenes": ("tactileskin.api", "scenes"),
    "default_cache_dir": ("tactileskin.api", "default_cache_dir"),
    "list_materials": ("tactileskin.materials", "list_materials"),
}

__all__ = ["__version__", "CadError", "ConvergenceError", "MeshError", "ParameterError",
           "TactileSkinError", "sweep", *_LAZY]


def __getattr__(name):
    if name == "sweep":  # the module tactileskin.sweep, which is callable: api.sweep (see there)
        import importlib

        return importlib.import_module("tactileskin.sweep")
    if name in _LAZY:
        import importlib

        mod, attr = _LAZY[name]
        value = getattr(importlib.import_module(mod), attr)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'tactileskin' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_LAZY) | {"sweep"})
