"""Element kernels: consistent tangent (finite differences), patch test, admissibility guard."""

import numpy as np
import pytest
from skfem import MeshTet, MeshTri

from tactileskin.errors import ConvergenceError
from tactileskin.fe import Dirichlet, Model, SolverOptions, material_law, run
from tactileskin.materials import get_material


def _neo_hookean(mu=1.0, lmbda=10.0):
    """Compressible neo-Hookean PK2 and D = dS/dE (an independent law for the tangent check)."""
    def law(C):
        Ci = np.linalg.inv(C)
        lnJ = 0.5 * np.log(np.linalg.det(C))
        S = mu * (np.eye(3) - Ci) + lmbda * lnJ[..., None, None] * Ci
        D = lmbda * np.einsum("...ij,...kl->...ijkl", Ci, Ci) + (mu - lmbda * lnJ)[..., None, None, None, None] * (
            np.einsum("...ik,...jl->...ijkl", Ci, Ci) + np.einsum("...il,...jk->...ijkl", Ci, Ci))
        return S, D, np.ones(C.shape[:-2], bool)
    return law


def _fd_check(model, u, h=1e-6):
    ev = model.evaluate(u, 0.0, 1.0)
    K = model.pattern.matrix(ev.K).toarray()
    Kfd = np.empty_like(K)
    for j in range(model.ndof):
        e = np.zeros(model.ndof)
        e[j] = h
        Kfd[:, j] = (model.evaluate(u + e, 0.0, 1.0, tangent=False).R
                     - model.evaluate(u - e, 0.0, 1.0, tangent=False).R) / (2 * h)
    return np.abs(K - Kfd).max() / np.abs(K).max()


MESHES = {
    "tri": lambda: MeshTri.init_tensor(np.linspace(0, 1, 3), np.linspace(0, 1, 3)),
    "tet": lambda: MeshTet.init_tensor(*(np.linspace(0, 1, 2),) * 3),
}


@pytest.mark.parametrize("formulation", ["mixed", "displacement"])
@pytest.mark.parametrize("kind", ["tri", "tet"])
@pytest.mark.parametrize("law", ["neo-hookean", "polyurethane"])
def test_tangent_matches_finite_differences(kind, formulation, law):
    """Central differences (h = 1e-6) have truncation ~h^2 |R'''| and round-off ~eps |R|/h:
    both ~1e-9 relative here, so 1e-6 detects any missing tangent term (those are O(1))."""
    mesh = MESHES[kind]()
    fn = _neo_hookean() if law == "neo-hookean" else material_law(get_material(law).hyperfoam)
    model = Model(mesh, {"x0": mesh.facets_satisfying(lambda x: x[0] < 1e-9)}, fn,
                  [Dirichlet("x0", (0,))], formulation=formulation)
    u = 0.03 * np.random.default_rng(1).standard_normal(model.ndof)
    assert _fd_check(model, u) < 1e-6


@pytest.mark.parametrize("formulation", ["mixed", "displacement"])
def test_patch_test_affine_field_is_exact(formulation):
    """Prescribe u = A X + b on the boundary of a distorted mesh: the interior nodes must
    reproduce the affine field (uniform stress is an exact discrete solution)."""
    m = MeshTri.init_tensor(np.linspace(0, 1, 5), np.linspace(0, 1, 5))
    p = m.p.copy()
    inner = (p[0] > 1e-9) & (p[0] < 1 - 1e-9) & (p[1] > 1e-9) & (p[1] < 1 - 1e-9)
    p[:, inner] += 0.08 * np.random.default_rng(3).uniform(-1, 1, (2, inner.sum()))
    m = MeshTri(p, m.t)
    A = np.array([[-0.05, 0.02], [0.01, -0.08]])
    b = np.array([0.01, -0.02])
    bnd = {"all": m.boundary_facets()}
    bc = Dirichlet("all", (0, 1), value=lambda t, X: t * (X @ A.T + b), field=True)
    model = Model(m, bnd, material_law(get_material("polyurethane").hyperfoam), [bc],
                  formulation=formulation)
    run(model, 1.0, SolverOptions(dt0_fraction=0.5))
    X = model.basis.doflocs.T
    assert np.abs(model.u.reshape(-1, 2) - (X @ A.T + b)).max() < 1e-10


def test_inadmissible_state_never_yields_nan_and_raises_a_diagnosis():
    """Silicone confined to lambda = 0.05 needs J^(-379.75) ~ 1e494: beyond what the
    material accepts as admissible (overflow guard) -> the solver stops with a
    ConvergenceError carrying the diagnosis, not a NaN."""
    m = MeshTri.init_tensor(np.linspace(0, 1, 2), np.linspace(0, 1, 2))
    b = {n: m.facets_satisfying(f) for n, f in {"l": lambda x: x[0] < 1e-9, "r": lambda x: x[0] > 1 - 1e-9,
                                                 "b": lambda x: x[1] < 1e-9, "t": lambda x: x[1] > 1 - 1e-9}.items()}
    bcs = [Dirichlet("l", (0,)), Dirichlet("r", (0,)), Dirichlet("b", (1,)),
           Dirichlet("t", (1,), value=lambda t: -0.95 * t)]
    model = Model(m, b, material_law(get_material("silicone").hyperfoam), bcs)
    with pytest.raises(ConvergenceError) as ei:
        run(model, 1.0, SolverOptions(dt_min_fraction=1e-3, max_newton=8))
    d = ei.value.diagnosis
    assert {"time", "dt", "reason"} <= set(d)
    assert 0.0 < d["time"] < 1.0


# --- compiled kernels vs a literal transcription of the formulas ------------------------

@pytest.mark.parametrize("formulation", ["mixed", "displacement"])
@pytest.mark.parametrize("kind", ["tri", "tet"])
def test_kernels_match_literal_formulas(kind, formulation):
    """The compiled loops (Voigt/rank-one evaluation of the tangent, cofactor det/inv)
    against the literal transcription tests/reference_kernels.py, on a real law's S and D:
    only the order of floating-point operations differs, so agreement to 1e-12 relative
    (observed ~1e-15)."""
    from reference_kernels import residual_tangent

    from tactileskin.fe import kernels

    mesh = (MeshTri.init_tensor(*(np.linspace(0, 1, 4),) * 2) if kind == "tri"
            else MeshTet.init_tensor(*(np.linspace(0, 1, 3),) * 3))
    law = material_law(get_material("polyurethane").hyperfoam)
    model = Model(mesh, {"x0": mesh.facets_satisfying(lambda x: x[0] < 1e-9)}, law,
                  [Dirichlet("x0", (0,))], formulation=formulation)
    m = model.m
    u = 0.02 * np.random.default_rng(2).standard_normal(model.ndof)
    ue = u.reshape(-1, m)[model.sdofs]
    kin = kernels.Kinematics(ue, model.G, model.w, model.mixed)
    assert kin.admissible
    S3, D3, ok = law(kin.C)
    assert ok.all()
    S, D = S3[..., :m, :m], np.ascontiguousarray(D3[..., :m, :m, :m, :m])
    f_ref, K_ref = residual_tangent(ue, model.G, model.w, model.mixed, S, D)
    f, K = kernels.residual(kin, S), kernels.tangent(kin, S, D)
    assert np.abs(f - f_ref).max() <= 1e-12 * np.abs(f_ref).max()
    assert np.abs(K - K_ref).max() <= 1e-12 * np.abs(K_ref).max()
    F = kin.F
    assert np.abs(kin.J - np.linalg.det(F)).max() <= 1e-14
    assert np.abs(kin.Finv - np.linalg.inv(F)).max() <= 1e-13


def test_material_law_plane_path_serves_2d_and_3d():
    """fe.material_law takes the closed-form plane path for a plane C and must return the
    full 3x3x3x3 D there (a 3D model at C = I passes a plane C too)."""
    from tactileskin.materials import pk2_tangent

    hf = get_material("silicone").hyperfoam
    law = material_law(hf)
    rng = np.random.default_rng(4)
    F = np.eye(3) + 0.03 * rng.standard_normal((6, 3, 3))
    F[:, 2, :2] = F[:, :2, 2] = 0.0
    F[:, 2, 2] = 1.0
    C = np.einsum("nki,nkj->nij", F, F)
    C[0] = np.eye(3)
    for Cs in (C, C[:1]):
        S, D, ok = law(Cs)
        S0, D0, ok0 = pk2_tangent(hf, Cs)
        assert D.shape == D0.shape and np.array_equal(ok, ok0)
        # same formulas, closed-form vs LAPACK eigenvectors: rounding only
        assert np.abs(D - D0).max() <= 1e-12 * np.abs(D0).max()
        assert np.abs(S - S0).max() <= 1e-12 * np.abs(D0).max() * 0.03
