"""The cache key follows the material's law name and every one of its parameters."""

from __future__ import annotations

import pytest

from tactileskin.cache import _floats, cache_key, material_content
from tactileskin.materials import get_material
from tactileskin.scene import Scene

TABLES = {
    "neo_hookean": {"mu": 0.03, "kappa": 1.5},
    "mooney_rivlin": {"c10": 0.01, "c01": 0.005, "kappa": 1.5},
    "yeoh": {"c": [0.015, -0.001, 0.0002], "kappa": 1.5},
    "ogden": {"mu": [0.02, 0.01], "alpha": [2.0, -2.0], "kappa": 1.5},
}


def _toml(law, table, prony="[prony]\ng = [0.1]\ntau = [0.5]\n"):
    def v(x):
        return "[" + ", ".join(repr(float(a)) for a in x) + "]" if isinstance(x, list) else repr(float(x))
    return f'law = "{law}"\n[{law}]\n' + "".join(f"{k} = {v(x)}\n" for k, x in table.items()) + prony


def test_paper_materials_keep_their_key_content():
    """Hyperfoam materials hash the same {hyperfoam, prony} numbers as before laws had names,
    so the paper sweep's cache stays valid."""
    for name in ("silicone", "polyurethane"):
        m = get_material(name)
        assert material_content(name) == {"hyperfoam": _floats(m.law.to_dict()), "prony": _floats(m.prony.to_dict())}


@pytest.mark.parametrize("law", sorted(TABLES))
def test_key_changes_with_law_and_each_parameter(tmp_path, law):
    p = tmp_path / "m.toml"
    table = TABLES[law]
    p.write_text(_toml(law, table))
    base = cache_key(Scene(material=str(p)))
    keys = {base}
    for k, x in table.items():                       # every parameter, every list entry
        for i in range(len(x) if isinstance(x, list) else 1):
            t = {kk: (list(vv) if isinstance(vv, list) else vv) for kk, vv in table.items()}
            if isinstance(x, list):
                t[k][i] *= 1.01
            else:
                t[k] = x * 1.01
            p.write_text(_toml(law, t))
            keys.add(cache_key(Scene(material=str(p))))
    n = sum(len(x) if isinstance(x, list) else 1 for x in table.values())
    assert len(keys) == n + 1
    p.write_text(_toml(law, table, prony="[prony]\ng = [0.1]\ntau = [0.6]\n"))
    assert cache_key(Scene(material=str(p))) != base
    p.write_text(_toml(law, table))
    assert cache_key(Scene(material=str(p))) == base


def test_same_numbers_under_another_law_is_another_key(tmp_path):
    """Mooney-Rivlin with c01 = 0 is the neo-Hookean law with mu = 2 c10, but a change of law
    name must still change the key (the law is part of what produced the result)."""
    a, b = tmp_path / "a.toml", tmp_path / "b.toml"
    a.write_text(_toml("neo_hookean", {"mu": 0.02, "kappa": 1.5}))
    b.write_text(_toml("mooney_rivlin", {"c10": 0.01, "c01": 0.0, "kappa": 1.5}))
    assert cache_key(Scene(material=str(a))) != cache_key(Scene(material=str(b)))
