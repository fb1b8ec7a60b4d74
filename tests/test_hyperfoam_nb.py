"""Compiled hyperfoam laws (materials._hyperfoam_nb: the plane-strain loop and the 3x3 loop)
against their oracle, the numpy 3x3 path `pk2_tangent` (for the plane loop on the embedded C,
C33 = 1, C13 = C23 = 0).

All evaluate the same formulas; the compiled loops solve the eigenproblem in closed form
(2x2) or by Jacobi rotations (3x3), LAPACK eigh in the oracle, and form some powers as products of shared
exponentials (c^(alpha/2 - 1) = c^(alpha/2) / c, ...), a few ulp from the 3x3 path's
single exp. Differences therefore stay at rounding level: observed <= 8e-14 of the point's
largest entry (at the overflow guard, exponents ~300), ~1e-15 elsewhere; 1e-12 leaves a
margin for the amplification by the spread of the principal values (the same bound as
the plane-vs-3D test in test_materials_hyperfoam.py).
"""

from __future__ import annotations

import numpy as np
import pytest

from tactileskin.errors import ParameterError
from tactileskin.fe import material_law
from tactileskin.materials import EXP_CAP, LOG_C_CAP, Hyperfoam, get_material
from tactileskin.materials.hyperfoam import pk2_tangent, pk2_tangent_plane, pk2_tangent_solid

MATERIALS = {name: get_material(name).hyperfoam for name in ("silicone", "polyurethane")}
# ln J range keeping J^(-alpha beta) within ~e^10 (as in test_materials_hyperfoam.py)
LNJ_RANGE = {"silicone": 0.025, "polyurethane": 0.15}
TOL = 1e-12


def _rot2(theta, d1, d2):
    c, s = np.cos(theta), np.sin(theta)
    R = np.array([[c, -s], [s, c]])
    return R @ np.diag([d1, d2]) @ R.T


def _lnj_cap(mat):
    """ln J at which the largest volumetric exponent alpha_i beta |ln J| reaches EXP_CAP."""
    return -EXP_CAP / (max(mat.alpha) * mat.beta)


def ordinary_states(name, n=200, seed=3):
    """Random rotated plane states of moderate J, plus the hard admissible cases: exact
    C = I, strains of 1e-8, equal and nearly equal in-plane stretches (relative gaps down
    to 1e-16, 1e-10 among them), an in-plane stretch equal to c_3 = 1 (to rounding), and a
    compression just inside the overflow guard."""
    mat = MATERIALS[name]
    rng = np.random.default_rng(seed)
    l1 = rng.uniform(0.7, 1.4, n)
    l2 = np.exp(rng.uniform(-1, 1, n) * LNJ_RANGE[name]) / l1
    th = rng.uniform(0, np.pi, n)
    Cs = [_rot2(t, a * a, b * b) for t, a, b in zip(th, l1, l2)]
    Cs += [np.eye(2), np.diag([1 + 2e-8, 1 - 1e-8]), _rot2(0.4, 1 + 1e-8, 1 - 3e-8),
           np.array([[1.0, 1e-8], [1e-8, 1.0]]), np.diag([1.0, 1 + 1e-8])]
    for g in (0.0, 1e-16, 1e-14, 1e-12, 1e-10, 1e-8):
        Cs += [_rot2(0.9, 0.97 * (1 + g), 0.97), _rot2(2.1, 1.03, 1.03 * (1 - g)),
               np.diag([1.0 + g, 1.0]), _rot2(0.3, 1.0, 1.0 + g)]
    cap = _lnj_cap(mat)
    for lnj in (cap + 1e-3, cap + 0.05):       # large compression, just inside the guard
        Cs += [np.diag([np.exp(2 * lnj), 1.0]), _rot2(0.7, np.exp(lnj), np.exp(lnj))]
    return np.array(Cs)


def inadmissible_states(mat):
    """Just beyond every guard, plus garbage."""
    cap = _lnj_cap(mat)
    return np.array([
        np.diag([np.exp(2 * (cap - 1e-3)), 1.0]),       # volumetric exponent above EXP_CAP
        _rot2(0.2, np.exp(cap - 0.5), np.exp(cap - 0.5)),
        np.diag([np.exp(LOG_C_CAP + 0.01), 1.0]),       # |ln c| beyond LOG_C_CAP
        np.diag([np.exp(-LOG_C_CAP - 0.01), 1.0]),
        np.diag([1e300, 1e300]),
        np.diag([-0.1, 1.0]),                           # not positive definite
        np.zeros((2, 2)),
        np.full((2, 2), np.nan),
        np.diag([np.inf, 1.0]),
        np.array([[1.0, np.nan], [0.0, 1.0]]),
    ])


def oracle(mat, C2, detF=None):
    """pk2_tangent of the plane-strain C whose in-plane block is C2: (S, full D, ok)."""
    C = np.zeros(C2.shape[:-2] + (3, 3))
    C[..., :2, :2] = C2
    C[..., 2, 2] = 1.0
    return pk2_tangent(mat, C, detF=detF)


def _max_rel(a, b):
    """Worst per-point difference relative to the point's largest entry (b = 0 must be exact)."""
    a = a.reshape(a.shape[0], -1)
    b = b.reshape(b.shape[0], -1)
    return np.max(np.abs(a - b).max(axis=1) / np.maximum(np.abs(b).max(axis=1), np.finfo(float).tiny))


@pytest.mark.parametrize("name", MATERIALS)
@pytest.mark.parametrize("out_of_plane", [False, True])
def test_compiled_equals_oracle_on_admissible_states(name, out_of_plane):
    mat = MATERIALS[name]
    C2 = ordinary_states(name)
    S, D, ok = pk2_tangent_plane(mat, C2, out_of_plane=out_of_plane)
    S0, D0, ok0 = oracle(mat, C2)
    if not out_of_plane:
        D0 = D0[..., :2, :2, :2, :2]
    assert ok0.all() and np.array_equal(ok, ok0)
    assert D.shape == D0.shape and S.shape == S0.shape
    assert _max_rel(S, S0) < TOL
    assert _max_rel(D, D0) < TOL
    # the undeformed state: S = 0 exactly; plane strain: S13 = S23 = 0 exactly
    i0 = 200
    assert np.array_equal(C2[i0], np.eye(2)) and not np.any(S[i0])
    assert not np.any(S[..., 2, :2]) and not np.any(S[..., :2, 2])


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")  # the oracle, C = 1e300
@pytest.mark.parametrize("name", MATERIALS)
def test_compiled_guard_flags_equal_oracle_and_values_are_finite(name):
    mat = MATERIALS[name]
    bad = inadmissible_states(mat)
    C2 = np.concatenate([bad, ordinary_states(name, n=5)])
    detF = np.ones(len(C2))
    detF[-1] = -1.0                                     # admissible C, flagged by det F only
    S, D, ok = pk2_tangent_plane(mat, C2, detF=detF, out_of_plane=True)
    S0, D0, ok0 = oracle(mat, C2, detF=detF)
    assert np.array_equal(ok, ok0)
    assert not ok[:len(bad)].any() and not ok[-1] and ok[len(bad):-1].all()
    assert np.isfinite(S).all() and np.isfinite(D).all()
    adm = ok | (np.arange(len(C2)) == len(C2) - 1)      # the det F-flagged point has ordinary values
    assert _max_rel(S[adm], S0[adm]) < TOL and _max_rel(D[adm], D0[adm]) < TOL


@pytest.mark.parametrize("name", MATERIALS)
def test_tangent_false_gives_the_same_stress_without_D(name):
    mat = MATERIALS[name]
    C2 = np.concatenate([ordinary_states(name, n=20), inadmissible_states(mat)])
    S, D, ok = pk2_tangent_plane(mat, C2, out_of_plane=True)
    S1, D1, ok1 = pk2_tangent_plane(mat, C2, out_of_plane=True, tangent=False)
    assert D1 is None and np.array_equal(ok1, ok) and np.array_equal(S1, S)
    _, D2, _ = pk2_tangent_plane(mat, C2)
    assert np.array_equal(D[..., :2, :2, :2, :2], D2)   # in-plane block of the full D


@pytest.mark.parametrize("mu,alpha,nu", [((0.2,), (3.0,), 0.3),
                                         ((0.05, 0.1, -0.01), (0.01, 4.0, -2.0), 0.45)])
def test_any_number_of_terms(mu, alpha, nu):
    mat = Hyperfoam(mu, alpha, nu)
    rng = np.random.default_rng(7)
    C2 = np.array([_rot2(t, a, b) for t, a, b in rng.uniform([0, 0.6, 0.6], [np.pi, 1.5, 1.5], (50, 3))])
    S, D, ok = pk2_tangent_plane(mat, C2, out_of_plane=True)
    S0, D0, ok0 = oracle(mat, C2)
    assert ok.all() and np.array_equal(ok, ok0)
    assert _max_rel(S, S0) < TOL and _max_rel(D, D0) < TOL


def test_shapes_layouts_and_detF_broadcast():
    mat = MATERIALS["polyurethane"]
    C2 = np.broadcast_to(_rot2(0.3, 1.1, 0.95), (4, 5, 2, 2))   # read-only view
    S, D, ok = pk2_tangent_plane(mat, C2, detF=2.0)
    assert S.shape == (4, 5, 3, 3) and D.shape == (4, 5, 2, 2, 2, 2) and ok.shape == (4, 5) and ok.all()
    S1, D1, ok1 = pk2_tangent_plane(mat, C2[1, 2])
    assert S1.shape == (3, 3) and D1.shape == (2, 2, 2, 2) and ok1.shape == ()
    assert np.array_equal(S[1, 2], S1) and np.array_equal(D[1, 2], D1)
    # a strided in-plane block, as material_law passes it
    C = np.zeros((3, 4, 3, 3))
    C[..., :2, :2] = ordinary_states("polyurethane", n=12)[:12].reshape(3, 4, 2, 2)
    C[..., 2, 2] = 1.0
    S2, D2, _ = pk2_tangent_plane(mat, C[..., :2, :2], out_of_plane=True)
    S3, D3, _ = pk2_tangent_plane(mat, np.ascontiguousarray(C[..., :2, :2]), out_of_plane=True)
    assert np.array_equal(S2, S3) and np.array_equal(D2, D3)
    assert pk2_tangent_plane(mat, np.empty((0, 2, 2)))[0].shape == (0, 3, 3)


def test_material_law_passes_tangent_through():
    mat = MATERIALS["silicone"]
    law = material_law(mat)
    C = np.zeros((6, 3, 3))
    C[:, :2, :2] = ordinary_states("silicone", n=6)[:6]
    C[:, 2, 2] = 1.0
    S, D, ok = law(C)
    S1, D1, ok1 = law(C, tangent=False)
    assert D.shape == (6, 3, 3, 3, 3) and D1 is None
    assert np.array_equal(S, S1) and np.array_equal(ok, ok1)
    C[0, 2, 2] = 1.01                                    # not plane: the compiled 3x3 loop
    S3, D3, ok3 = law(C)
    S4, D4, ok4 = law(C, tangent=False)
    assert D3.shape == (6, 3, 3, 3, 3) and D4 is None
    assert np.array_equal(S3, S4) and np.array_equal(ok3, ok4) and ok3.all()
    assert _max_rel(S3, pk2_tangent(mat, C)[0]) < TOL


# --- the compiled 3x3 loop (pk2_tangent_solid), same oracle -------------------------------------

def _rot3(angles, stretches2):
    """R diag(c) R^T for the rotation of the (z, y, x) Euler angles."""
    from scipy.spatial.transform import Rotation

    R = Rotation.from_euler("zyx", angles).as_matrix()
    return R @ np.diag(stretches2) @ R.T


def solid_states(name, n=300, seed=5):
    """Random rotated 3D states of moderate J, plus the hard admissible cases of the 3x3
    eigenproblem: C = I, strains of 1e-8 (off-diagonal only among them), two and three equal
    or nearly equal stretches (relative gaps down to 1e-16), a plane-strain C (already
    diagonal in e_z: no rotation needed), and a compression just inside the overflow guard."""
    mat = MATERIALS[name]
    rng = np.random.default_rng(seed)
    l = np.exp(rng.uniform(-0.35, 0.35, (n, 3)))
    l[:, 2] = np.exp(rng.uniform(-1, 1, n) * LNJ_RANGE[name]) / (l[:, 0] * l[:, 1])
    ang = rng.uniform(0, 2 * np.pi, (n, 3))
    Cs = [_rot3(a, s * s) for a, s in zip(ang, l)]
    Cs += [np.eye(3), np.diag([1 + 2e-8, 1, 1 - 1e-8]), _rot3((0.3, 0.2, 0.1), (1 + 1e-8, 1 - 3e-8, 1)),
           np.array([[1.0, 1e-8, 0.0], [1e-8, 1.0, 2e-8], [0.0, 2e-8, 1.0]])]
    for g in (0.0, 1e-16, 1e-14, 1e-12, 1e-10, 1e-8):
        Cs += [_rot3((0.9, 0.4, 1.3), (0.97 * (1 + g), 0.97, 1.05)),
               _rot3((2.1, 0.7, 0.2), (1.03, 1.03 * (1 - g), 1.03 * (1 + g))),
               np.diag([1.0 + g, 1.0, 1.0])]
    C2 = ordinary_states(name, n=10)
    P = np.zeros((len(C2), 3, 3))
    P[:, :2, :2], P[:, 2, 2] = C2, 1.0
    cap = _lnj_cap(mat)
    for lnj in (cap + 1e-3, cap + 0.05):
        Cs += [_rot3((0.5, 0.1, 0.8), (np.exp(2 * lnj / 3),) * 3), np.diag([np.exp(2 * lnj), 1.0, 1.0])]
    return np.concatenate([np.array(Cs), P])


@pytest.mark.parametrize("name", MATERIALS)
def test_solid_loop_equals_oracle_on_admissible_states(name):
    mat = MATERIALS[name]
    C = solid_states(name)
    S, D, ok = pk2_tangent_solid(mat, C)
    S0, D0, ok0 = pk2_tangent(mat, C)
    assert ok0.all() and np.array_equal(ok, ok0)
    assert _max_rel(S, S0) < TOL and _max_rel(D, D0) < TOL
    assert not np.any(S[300])                            # C = I: S = 0 exactly
    # D's minor and major symmetries hold to rounding, as the solver's tangent needs
    assert _max_rel(D, np.swapaxes(D, -1, -2)) < TOL and _max_rel(D, np.transpose(D, (0, 3, 4, 1, 2))) < TOL
    S1, D1, ok1 = pk2_tangent_solid(mat, C, tangent=False)
    assert D1 is None and np.array_equal(S1, S) and np.array_equal(ok1, ok)


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")  # the oracle, C = 1e300
@pytest.mark.parametrize("name", MATERIALS)
def test_solid_loop_guard_flags_equal_oracle_and_values_are_finite(name):
    mat = MATERIALS[name]
    bad2 = inadmissible_states(mat)
    bad = np.zeros((len(bad2), 3, 3))
    bad[:, :2, :2], bad[:, 2, 2] = bad2, 1.0
    bad[-1, 2, 2] = np.nan                                # non-finite out of the plane too
    C = np.concatenate([bad, solid_states(name, n=5)])
    detF = np.ones(len(C))
    detF[-1] = -1.0
    S, D, ok = pk2_tangent_solid(mat, C, detF=detF)
    S0, D0, ok0 = pk2_tangent(mat, C, detF=detF)
    assert np.array_equal(ok, ok0)
    assert not ok[:len(bad)].any() and not ok[-1] and ok[len(bad):-1].all()
    assert np.isfinite(S).all() and np.isfinite(D).all()
    adm = ok | (np.arange(len(C)) == len(C) - 1)
    assert _max_rel(S[adm], S0[adm]) < TOL and _max_rel(D[adm], D0[adm]) < TOL


@pytest.mark.parametrize("mu,alpha,nu", [((0.2,), (3.0,), 0.3),
                                         ((0.05, 0.1, -0.01), (0.01, 4.0, -2.0), 0.45)])
def test_solid_loop_any_number_of_terms_and_shapes(mu, alpha, nu):
    mat = Hyperfoam(mu, alpha, nu)
    rng = np.random.default_rng(11)
    C = np.array([_rot3(a, s) for a, s in zip(rng.uniform(0, 6, (40, 3)), rng.uniform(0.6, 1.5, (40, 3)))])
    S, D, ok = pk2_tangent_solid(mat, C)
    S0, D0, ok0 = pk2_tangent(mat, C)
    assert ok.all() and np.array_equal(ok, ok0)
    assert _max_rel(S, S0) < TOL and _max_rel(D, D0) < TOL
    Cb = np.broadcast_to(C[3], (2, 5, 3, 3))             # read-only view, any leading shape
    S2, D2, ok2 = pk2_tangent_solid(mat, Cb, detF=1.0)
    assert S2.shape == (2, 5, 3, 3) and D2.shape == (2, 5, 3, 3, 3, 3) and ok2.shape == (2, 5)
    assert np.array_equal(S2[1, 4], S[3]) and np.array_equal(D2[0, 2], D[3])
    assert pk2_tangent_solid(mat, np.empty((0, 3, 3)))[0].shape == (0, 3, 3)


def test_threaded_solid_loop_has_the_serial_bits():
    """From PARALLEL_MIN_POINTS points the 3x3 loop runs on numba's threads in point ranges:
    each point's arithmetic is the serial loop's, so the outputs are bit for bit the same
    (on a one-CPU machine numba's pool has one thread and both calls are serial)."""
    from tactileskin.materials import hyperfoam
    from tactileskin.threads import numba_threads

    mat = MATERIALS["silicone"]
    C = np.concatenate([solid_states("silicone")] * (hyperfoam.PARALLEL_MIN_POINTS // 300 + 1))
    assert len(C) >= hyperfoam.PARALLEL_MIN_POINTS
    with numba_threads(1):
        one = pk2_tangent_solid(mat, C)
    with numba_threads(2):
        two = pk2_tangent_solid(mat, C)
        s_only = pk2_tangent_solid(mat, C, tangent=False)
    for a, b in zip(one, two):
        assert np.array_equal(a, b)
    assert np.array_equal(s_only[0], one[0]) and np.array_equal(s_only[2], one[2])


_CAPS_PROBE = """
import json
import numpy as np
from tactileskin.materials import get_material, hyperfoam as hf
mat = get_material("silicone").law
c = float(np.exp(25.0))   # |ln c| = 25: admissible under LOG_C_CAP = 30, not under 20
ok2 = hf.pk2_tangent_plane(mat, np.diag([c, 1.0 / c])[None], tangent=False)[2][0]
ok3 = hf.pk2_tangent(mat, np.diag([c, 1.0 / c, 1.0])[None])[2][0]
print(json.dumps({"compiled": bool(ok2), "numpy": bool(ok3)}))
"""


def test_a_cap_edited_in_hyperfoam_py_is_not_run_by_a_stale_compiled_kernel(tmp_path):
    """numba keys the kernels it caches in __pycache__ by the bytes of the file defining them:
    the caps _hyperfoam_nb imported from hyperfoam.py were frozen into its cache, so after
    LOG_C_CAP 30 -> 20 in hyperfoam.py the plane kernel still took |ln c| = 25 as admissible
    (the 3x3 path did not), while the result cache's key named the edited code. The caps are
    written in _hyperfoam_nb.py itself, and an edit of hyperfoam.py's alone is refused."""
    import json
    import os
    import shutil
    import subprocess
    import sys
    from pathlib import Path

    import tactileskin

    pkg = tmp_path / "src"
    shutil.copytree(Path(tactileskin.__file__).parent, pkg / "tactileskin",
                    ignore=shutil.ignore_patterns("__pycache__"))

    def probe():
        return subprocess.run([sys.executable, "-c", _CAPS_PROBE], capture_output=True, text=True,
                              env=dict(os.environ, PYTHONPATH=str(pkg)))

    r = probe()   # compiles the kernels into the copy's __pycache__
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout) == {"compiled": True, "numpy": True}
    src = pkg / "tactileskin" / "materials" / "hyperfoam.py"
    text = src.read_text()
    assert "\nLOG_C_CAP = 30.0 " in text
    src.write_text(text.replace("\nLOG_C_CAP = 30.0 ", "\nLOG_C_CAP = 20.0 "))
    r = probe()
    assert r.returncode != 0 and "LOG_C_CAP" in r.stderr, r.stdout   # not the cached kernel's 30


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")
@pytest.mark.parametrize("name", MATERIALS)
def test_kept_spectral_data_gives_the_fresh_tangent_bits(name):
    """pk2_kept_solid's S and ok are those of the S-only loop, and tangent_kept_solid's D
    those of the S + D loop at the same C, bit for bit (the same arithmetic on the same
    eigen-decomposition): admissible states, C = I, coincident stretches and the guard's
    clipped points. D from another state's kept data is not this state's D."""
    from tactileskin.materials.hyperfoam import pk2_kept_solid, tangent_kept_solid

    mat = MATERIALS[name]
    bad2 = inadmissible_states(mat)
    bad = np.zeros((len(bad2), 3, 3))
    bad[:, :2, :2], bad[:, 2, 2] = bad2, 1.0
    C = np.concatenate([solid_states(name), bad])
    C = C[:len(C) // 2 * 2].reshape(2, -1, 3, 3)          # any leading shape
    S, D, ok = pk2_tangent_solid(mat, C)
    Sk, okk, kept = pk2_kept_solid(mat, C)
    assert kept.shape == C.shape[:-2] + (18,)
    assert np.array_equal(Sk, S) and np.array_equal(okk, ok) and not ok.all() and ok.any()
    assert np.array_equal(tangent_kept_solid(mat, kept), D)
    other = pk2_kept_solid(mat, np.flip(C, axis=1))[2]
    assert not np.array_equal(tangent_kept_solid(mat, other), D)
    with pytest.raises(ParameterError, match="kept"):
        tangent_kept_solid(mat, kept[..., :9])


def test_threaded_kept_tangent_has_the_serial_bits():
    from tactileskin.materials import hyperfoam
    from tactileskin.materials.hyperfoam import pk2_kept_solid, tangent_kept_solid
    from tactileskin.threads import numba_threads

    mat = MATERIALS["silicone"]
    C = np.concatenate([solid_states("silicone")] * (hyperfoam.PARALLEL_MIN_POINTS // 300 + 1))
    with numba_threads(1):
        S, D, ok = pk2_tangent_solid(mat, C)
    with numba_threads(2):
        Sk, okk, kept = pk2_kept_solid(mat, C)
        Dk = tangent_kept_solid(mat, kept)
    assert np.array_equal(Sk, S) and np.array_equal(okk, ok) and np.array_equal(Dk, D)
