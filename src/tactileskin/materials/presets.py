"""Named materials: a law (materials.laws) plus its Prony series, with where the numbers came from.

Presets live in the package data file presets.toml (paper Table I and published fits of
skin elastomers, each with its source). Users define their own in a TOML file of the same
shape (see `Material.from_toml`).
"""

from __future__ import annotations

import functools
import json
import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from tactileskin import validate
from tactileskin.errors import ParameterError
from tactileskin.materials.hyperfoam import Hyperfoam
from tactileskin.materials.laws import get_law, law_from_dict, list_laws
from tactileskin.materials.prony import MAX_TERMS as PRONY_TERMS, Prony
from tactileskin.params import read_toml

__all__ = ["Material", "get_material", "list_materials"]


@dataclass(frozen=True)
class Material:
    """A named material: its law (any registered in `materials.laws`), its Prony series
    (the viscoelastic part, wrapping whatever law; `Prony.elastic()` for none) and where
    the numbers came from."""

    name: str
    law: object
    prony: Prony
    source: str = ""

    @property
    def law_name(self) -> str:
        return self.law.law

    @property
    def hyperfoam(self) -> Hyperfoam:
        """The law, for the paper's hyperfoam materials (ParameterError for another law)."""
        if not isinstance(self.law, Hyperfoam):
            raise ParameterError(f"material {self.name!r} law", self.law_name, "hyperfoam",
                                 "use Material.law")
        return self.law

    @classmethod
    def from_dict(cls, name: str, d: dict) -> "Material":
        """Build from {"name"?, "source"?, "law"?, <law>: {its parameters}, "prony"?: {g, tau}}.

        `law` names the law (`materials.laws.list_laws()`) and the table of the same name
        holds its parameters; without `law` the one law table present names it
        (`[hyperfoam]` alone: the paper's format). Every table is checked for unknown keys
        and value types (a `[prnoy]` typo must not silently make the material elastic); the
        law and Prony classes check the ranges."""
        what = f"material {name!r}"
        laws = list_laws()
        if not isinstance(d, dict):
            raise ParameterError(what, d, "a table with a law table (" + ", ".join(laws) + ")")
        present = [k for k in d if k in laws]
        if "law" in d:
            law = validate.string(d["law"], f"{what} law", "one of " + ", ".join(laws))
            get_law(law)  # unknown name: ParameterError listing the laws
            if law not in d:
                raise ParameterError(f"{what} [{law}]", "missing", f"a [{law}] table with the law's parameters")
            if len(present) > 1:
                raise ParameterError(what, present, f"only the [{law}] law table")
        elif len(present) == 1:
            law = present[0]
        else:
            raise ParameterError(what, sorted(d), "one law table: " + ", ".join(laws),
                                 "or law = \"<name>\" and its table")
        validate.known_keys(d, ("name", "source", "law", law, "prony"), what)
        pr = validate.table(d.get("prony", {"g": [], "tau": []}), f"{what} prony")
        validate.known_keys(pr, ("g", "tau"), f"{what} prony")
        if ("g" in pr) != ("tau" in pr):
            raise ParameterError(f"{what} prony", sorted(pr), "keys g and tau (both, or an empty table)")
        g = validate.number_list(pr.get("g", []), "g", PRONY_TERMS)
        tau = validate.number_list(pr.get("tau", []), "tau", PRONY_TERMS)
        return cls(
            name=validate.string(d.get("name", name), f"{what} name"),
            law=law_from_dict(law, d[law], what),
            prony=Prony(g, tau),
            source=validate.string(d.get("source", ""), f"{what} source"),
        )

    @classmethod
    def from_toml(cls, path) -> "Material":
        """Read a user-defined material.

        The file holds either one material at top level (keys name?, source?, law?, its law
        table, optional [prony]) or exactly one named table of that shape, like presets.toml.
        Without [prony] the material is purely elastic.
        """
        path = Path(path)
        data = read_toml(path, "material file")
        if "law" in data or any(k in data for k in list_laws()):
            mat = cls.from_dict(str(data.get("name", path.stem)), data)
        else:
            tables = {k: v for k, v in data.items() if isinstance(v, dict)}
            if len(tables) != 1 or len(data) != 1:
                raise ParameterError("material file", str(path),
                                     "one material: a top-level law table (e.g. [hyperfoam]), or exactly one named table")
            (name, d), = tables.items()
            mat = cls.from_dict(name, d)
        _check_stable(mat, path)
        return mat

    def to_dict(self) -> dict:
        """The TOML shape read by `from_dict` (hyperfoam materials keep the paper's format)."""
        d = {"name": self.name, "source": self.source}
        if self.law_name != "hyperfoam":
            d["law"] = self.law_name
        d[self.law_name] = self.law.to_dict()
        d["prony"] = self.prony.to_dict()
        return d

    def to_toml(self) -> str:
        """TOML text of `to_dict()` (read back by `from_toml`)."""
        return _toml(self.to_dict())


def _check_stable(mat: Material, path: Path) -> None:
    """A hand-written law whose uniaxial stress falls with stretch is refused (as `material fit`
    refuses such a fit): an Ogden of mu [0.5, -0.41], alpha [20, -10] turns tensile under 4 %
    compression; it stalled after 0.004 mm in 3D with a message blaming the mesh, and read "ok"
    in 2D (9.7 MPa)."""
    from tactileskin.materials.fit import STABLE_RANGE, unstable_stretch
    from tactileskin.materials.laws import bulk_error, bulk_range, nu0

    at = unstable_stretch(mat.law, nu0(mat.law))
    if at is not None:
        lo, _ = bulk_range(mat.law)
        if lo is not None:  # a larger bulk modulus makes it stable: name that parameter
            raise bulk_error(mat.law, f"material {mat.name!r} {mat.law_name}",
                             f"below it the law's uniaxial stress does not rise with stretch at {at:.3g} ({path})")
        lo, hi = STABLE_RANGE
        raise ParameterError("material file", str(path), f"a stable law: its uniaxial stress rising with stretch "
                             f"over {lo:g}-{hi:g}", f"the {mat.law_name} law of {mat.name!r} does not at stretch {at:.3g}")


def _toml_value(v) -> str:
    if isinstance(v, str):
        return json.dumps(v)  # a JSON string is a valid TOML basic string
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return repr(float(v))


def _toml(d: dict) -> str:
    top = [f"{k} = {_toml_value(v)}" for k, v in d.items() if not isinstance(v, dict)]
    tables = [f"\n[{k}]\n" + "\n".join(f"{kk} = {_toml_value(vv)}" for kk, vv in v.items())
              for k, v in d.items() if isinstance(v, dict)]
    return "\n".join(top) + "\n" + "\n".join(tables) + "\n"


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
