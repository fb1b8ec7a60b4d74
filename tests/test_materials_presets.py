"""Material presets (paper Table I) and user-defined materials from TOML."""

from __future__ import annotations

import pytest

from tactileskin.errors import ParameterError
from tactileskin.materials import Material, get_material, list_materials


def test_presets_are_table_i():
    assert list_materials() == ["polyurethane", "silicone"]
    si = get_material("silicone")
    assert si.hyperfoam.mu == (0.080, 0.010) and si.hyperfoam.alpha == (0.001, 15.5)
    assert si.hyperfoam.nu == 0.49
    assert si.prony.g == (0.015, 0.044, 0.029) and si.prony.tau == (0.025, 0.150, 0.300)
    pu = get_material("polyurethane")
    assert pu.hyperfoam.mu == (0.100, 0.063) and pu.hyperfoam.alpha == (5.5, 8.25)
    assert pu.hyperfoam.nu == 0.47
    assert pu.prony.g == (0.167, 0.158, 0.113) and pu.prony.tau == (0.100, 1.380, 25.472)
    for m in (si, pu):
        assert "Table I" in m.source
        hash(m)  # frozen, hashable: usable as a cache key


def test_unknown_material_lists_valid_names():
    with pytest.raises(ParameterError, match="polyurethane, silicone"):
        get_material("rubber")


def test_user_material_from_toml(tmp_path):
    top = tmp_path / "gel.toml"
    top.write_text(
        'name = "soft gel"\nsource = "lab fit 2024"\n'
        "[hyperfoam]\nmu = [0.02]\nalpha = [4.0]\nnu = 0.45\n"
        "[prony]\ng = [0.3]\ntau = [0.5]\n")
    m = Material.from_toml(top)
    assert m.name == "soft gel" and m.hyperfoam.mu0 == pytest.approx(0.02)
    assert m.prony.g_inf == pytest.approx(0.7)
    assert get_material(str(top)) == m
    # presets.toml shape (one named table), no [prony]: purely elastic
    named = tmp_path / "named.toml"
    named.write_text("[foam]\n[foam.hyperfoam]\nmu = [0.05, 0.01]\nalpha = [2.0, -2.0]\nnu = 0.3\n")
    m2 = Material.from_toml(named)
    assert m2.name == "foam" and m2.prony.g_inf == 1.0 and m2.prony.n_terms == 0
    # round trip through to_dict
    assert Material.from_dict(m.name, m.to_dict()) == m


@pytest.mark.parametrize("text", [
    "[hyperfoam]\nmu = [0.02]\nalpha = [4.0]\n",                         # nu missing
    "[hyperfoam]\nmu = [0.02]\nalpha = [4.0]\nnu = 0.5\n",              # nu out of range
    "[hyperfoam]\nmu = [0.02]\nalpha = [4.0]\nnu = 0.3\n[prony]\ng = [0.3]\n",  # tau missing
    "[a.hyperfoam]\nmu=[1.0]\nalpha=[2.0]\nnu=0.3\n[b.hyperfoam]\nmu=[1.0]\nalpha=[2.0]\nnu=0.3\n",
    "this is not toml",
])
def test_bad_material_files_raise(tmp_path, text):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(ParameterError):
        Material.from_toml(path)


def test_missing_material_file_raises(tmp_path):
    with pytest.raises(ParameterError):
        get_material(str(tmp_path / "nope.toml"))
