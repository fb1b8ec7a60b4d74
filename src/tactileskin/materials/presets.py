"""Named materials: a hyperfoam law plus its Prony series, with where the numbers came from.

Presets live in the package data file presets.toml (paper Table I). Users define their own
in a TOML file of the same shape (see `Material.from_toml`).
"""

from __future__ import annotations

import functools
import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from tactileskin import validate
from tactileskin.errors import ParameterError
from tactileskin.materials.hyperfoam import MAX_TERMS as HF_TERMS, Hyperfoam
from tactileskin.materials.prony import MAX_TERMS as PRONY_TERMS, Prony
from tactileskin.params import read_toml

__all__ = ["Material", "get_material", "list_materials"]


@dataclass(frozen=True)
class Material:
    name: str
    hyperfoam: Hyperfoam
    prony: Prony
    source: str = ""

    @classmethod
    def from_dict(cls, name: str, d: dict) -> "Material":
        """Build from {"name"?: str, "source"?: str, "hyperfoam": {mu, alpha, nu}, "prony"?: {g, tau}}.

        Every table is checked for unknown keys and value types here (a `[prnoy]` typo must
        not silently make the material elastic); Hyperfoam and Prony check the ranges."""
        what = f"material {name!r}"
        if not isinstance(d, dict) or "hyperfoam" not in d:
            raise ParameterError(what, d if not isinstance(d, dict) else sorted(d),
                                 "a table with a [hyperfoam] sub-table (mu, alpha, nu)")
        validate.known_keys(d, ("name", "source", "hyperfoam", "prony"), what)
        hf = validate.table(d["hyperfoam"], f"{what} hyperfoam")
        validate.known_keys(hf, ("mu", "alpha", "nu"), f"{what} hyperfoam")
        missing = [k for k in ("mu", "alpha", "nu") if k not in hf]
        if missing:
            raise ParameterError(f"{what} hyperfoam", sorted(hf), "keys mu, alpha, nu",
                                 "missing " + ", ".join(missing))
        mu = validate.number_list(hf["mu"], "mu", HF_TERMS, min_len=1)
        alpha = validate.number_list(hf["alpha"], "alpha", HF_TERMS, min_len=1)
        nu = validate.number(hf["nu"], "nu")
        pr = validate.table(d.get("prony", {"g": [], "tau": []}), f"{what} prony")
        validate.known_keys(pr, ("g", "tau"), f"{what} prony")
        if ("g" in pr) != ("tau" in pr):
            raise ParameterError(f"{what} prony", sorted(pr), "keys g and tau (both, or an empty table)")
        g = validate.number_list(pr.get("g", []), "g", PRONY_TERMS)
        tau = validate.number_list(pr.get("tau", []), "tau", PRONY_TERMS)
        return cls(
            name=validate.string(d.get("name", name), f"{what} name"),
            hyperfoam=Hyperfoam(mu, alpha, nu),
            prony=Prony(g, tau),
            source=validate.string(d.get("source", ""), f"{what} source"),
        )

    @classmethod
    def from_toml(cls, path) -> "Material":
        """Read a user-defined material.

        The file holds either one material at top level (keys name?, source?, tables
        [hyperfoam] and optional [prony]) or exactly one named table of that shape, like
        presets.toml. Without [prony] the material is purely elastic.
        """
        path = Path(path)
        data = read_toml(path, "material file")
        if "hyperfoam" in data:
            return cls.from_dict(str(data.get("name", path.stem)), data)
        tables = {k: v for k, v in data.items() if isinstance(v, dict)}
        if len(tables) != 1 or len(data) != 1:
            raise ParameterError("material file", str(path),
                                 "one material: top-level [hyperfoam] table, or exactly one named table")
        (name, d), = tables.items()
        return cls.from_dict(name, d)

    def to_dict(self) -> dict:
        return {"name": self.name, "source": self.source,
                "hyperfoam": self.hyperfoam.to_dict(), "prony": self.prony.to_dict()}


@functools.cache
def _presets() -> dict[str, Material]:
    text = resources.files("tactileskin.materials").joinpath("presets.toml").read_text(encoding="utf-8")
    data = tomllib.loads(text)
    return {name: Material.from_dict(name, d) for name, d in data.items()}


def list_materials() -> list[str]:
    """Names of the preset materials."""
    return sorted(_presets())


def get_material(name: str) -> Material:
    """A preset by name, or a user material from a path ending in .toml."""
    if isinstance(name, Material):
        return name
    if isinstance(name, (str, Path)) and str(name).endswith(".toml"):
        return Material.from_toml(name)
    try:
        return _presets()[name]
    except (KeyError, TypeError):
        raise ParameterError("material", name,
                             "one of " + ", ".join(list_materials()) + ", or a path to a .toml file") from None
