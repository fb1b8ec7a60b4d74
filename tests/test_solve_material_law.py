"""A 2D fingertip solve end to end with a non-hyperfoam law from a material file:
neo-Hookean with the small-strain moduli of the paper's silicone (mu0 = 0.090, K0 = 4.47 MPa)
and its Prony series, through Scene(material="file.toml")."""

from __future__ import annotations

import pytest

from tactileskin.fe import solve
from tactileskin.materials import get_material
from tactileskin.scene import Scene

COARSE = dict(thickness=1.0, indenter="flat", mesh_size=0.4)


@pytest.fixture(scope="module")
def nh_file(tmp_path_factory):
    si = get_material("silicone")
    p = tmp_path_factory.mktemp("mat") / "nh_silicone.toml"
    p.write_text(f'law = "neo_hookean"\nsource = "silicone small-strain moduli"\n[neo_hookean]\n'
                 f"mu = {si.law.mu0!r}\nkappa = {si.law.K0!r}\n"
                 f"[prony]\ng = {list(si.prony.g)}\ntau = {list(si.prony.tau)}\n")
    return str(p)


def _peaks(nh_file, frac):
    a = solve(Scene(material="silicone", depth_fraction=frac, **COARSE))
    b = solve(Scene(material=nh_file, depth_fraction=frac, **COARSE))
    assert a.summary()["status"] == b.summary()["status"] == "ok"
    return a.summary()["peak_mpa"], b.summary()["peak_mpa"]


def test_neo_hookean_matches_hyperfoam_at_small_strain(nh_file):
    """Same mu0, K0 and Prony: the laws' stresses differ at second order in the strain, so the
    relative difference of the peaks grows like the strain. At 1 % nominal strain: measured
    -0.12 % on the default mesh, bound 0.5 % (same mesh for both: the discretisation error
    cancels to first order). At 5 %: measured -2.3 %, asserted beyond -1 % (the hyperfoam's
    alpha = 15.5 term stiffens), which shows that the file's law is the one solved."""
    hf, nh = _peaks(nh_file, 0.01)
    assert nh > 0 and abs(nh / hf - 1) < 5e-3
    hf5, nh5 = _peaks(nh_file, 0.05)
    assert nh5 / hf5 - 1 < -1e-2
