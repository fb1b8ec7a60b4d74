"""A discretised boundary-value problem: mesh, material law, QLV history, BCs, contact.

`Model` evaluates the global residual (and, when asked, the consistent tangent) for a
trial displacement at a given time, without changing its committed state; `commit()`
accepts a converged increment (QLV internal variables).
"""

from __future__ import annotations

import inspect
import logging
import time
from collections import defaultdict
from dataclasses import dataclass
from typing import Callable

import numpy as np
from skfem import CellBasis
from skfem.element import (ElementQuad1, ElementQuad2, ElementTetP1, ElementTetP2,
                           ElementTriP1, ElementTriP2, ElementHex1, ElementHex2)

from tactileskin.errors import ParameterError
from tactileskin.fe import kernels
from tactileskin.fe.assembly import Pattern, assemble_vector, vector_dofs
from tactileskin.fe.contact import ContactSurface
from tactileskin.threads import numba_threads

log = logging.getLogger(__name__)

PENALTY_FACTOR = 20.0  # penalty = factor * modulus / facet size (MPa/mm)
# penetration tolerance over the contact facet size, per model dimension (Contact.tol_relative
# None). 2D 1e-4: 5e-4 left t1 silicone flat 0.16 % below its 1e-6 mm answer (lock-up), and
# 1e-3 moved the 2D Braille ridges by up to 0.09 % for 8 % fewer Newton iterations. 3D 1e-3:
# the Uzawa updates that settle the last 1e-4 h cost 14-45 % of the 3D dots' Newton iterations
# for peak changes of at most 0.07 %, against 3D preset errors of 1-2 %
# (benchmarks/results/contact_tolerance3d.md)
TOL_RELATIVE = {2: 1e-4, 3: 1e-3}
# ... and at most this fraction of the scene's travel (Contact.travel): on a local 3D plan h is
# the coarse surface's (0.48 mm on the t = 1 dot), and a shallow press (0.02 mm) read the
# polyurethane dot's peak 1.2 % low against a 100x tighter tolerance
# (benchmarks/results/contact_tolerance3d.md, "Shallow presses"); the paper's depths are not
# capped except the t = 1 mm 3D cases'. Never below TOL_TRAVEL_FLOOR x the facet rule.
TOL_TRAVEL = 1e-3
TOL_TRAVEL_FLOOR = 1e-2
Law = Callable[..., tuple]  # law(C (...,3,3), tangent=True) -> (S, D or None, ok)


def scalar_element(mesh, order: int):
    name = type(mesh).__name__
    table = {
        "Tri": (ElementTriP1, ElementTriP2),
        "Quad": (ElementQuad1, ElementQuad2),
        "Tet": (ElementTetP1, ElementTetP2),
        "Hex": (ElementHex1, ElementHex2),
    }
    for key, els in table.items():
        if key in name:
            return els[order - 1]()
    raise ParameterError("mesh", name, "a scikit-fem triangle, quad, tetrahedral or hexahedral mesh")


@dataclass(frozen=True)
class Dirichlet:
    """Prescribed displacement component(s) on a named boundary.

    value: a constant, value(t), or (with `field=True`) value(t, X) -> (n, len(components))
    from the reference coordinates X (n, m) of the boundary nodes.
    """

    boundary: str
    components: tuple[int, ...]
    value: float | Callable = 0.0
    field: bool = False

    def at(self, t: float, X: np.ndarray) -> np.ndarray:
        n, k = len(X), len(self.components)
        if self.field:
            v = np.asarray(self.value(t, X), float)
        elif callable(self.value):
            v = float(self.value(t))
        else:
            v = float(self.value)
        return np.broadcast_to(v, (n, k)).ravel()


@dataclass
class Contact:
    """Rigid indenter on a named boundary; travel d(t) = rate * t."""

    indenter: object
    boundary: str = "outer_surface"
    rate: float = 1.0
    penalty: float | None = None   # MPa/mm; None: from the material stiffness and mesh size
    # penetration tolerance (mm) of the augmented Lagrangian; None: tol_relative x the
    # contact facet size (Model.surface_size), so that it shrinks with the mesh and a
    # convergence study sees no fixed floor (lock-up: the stress moves ~ alpha beta x gap /
    # thickness; benchmarks/results/contact_newton.md)
    tol_penetration: float | None = None
    tol_relative: float | None = None  # None: TOL_RELATIVE of the model's dimension
    travel: float | None = None  # the scene's largest travel (mm): caps the tolerance (TOL_TRAVEL)
    # The indenter-curvature term -lambda dn/dx of the consistent tangent. The solver adds it
    # only after its first iterates (SolverOptions.curvature_after): it is negative
    # semi-definite, and early iterates with overshooting multipliers made the tangent
    # indefinite (ascent directions, cutbacks: t1 silicone curved 166 Newton iterations with
    # it throughout, 54 without); without it at all the tail converges linearly (x16 per
    # iteration on the Braille dots) instead of quadratically.
    curvature_tangent: bool = False
    max_uzawa: int = 30


class _State:
    """What an evaluation computes from u, dt and the committed QLV history alone:
    kinematics, elastic and total PK2, internal forces and, once a tangent asks, D (from
    the spectral data `kept` by the stress evaluation where the law keeps it). Shared by the
    evaluations of one state that differ only in contact (a release, an Uzawa update, the
    sticky set grown) and by its tangent."""

    __slots__ = ("kin", "S0", "S", "gamma", "fint", "D", "kept")

    def __init__(self, kin, S0, S, gamma, fint, D, kept):
        self.kin, self.S0, self.S, self.gamma, self.fint, self.D, self.kept = kin, S0, S, gamma, fint, D, kept


@dataclass
class Evaluation:
    R: np.ndarray                  # global residual (internal - external), (ndof,)
    ok: bool                       # admissible state everywhere
    K: np.ndarray | None = None    # CSR data of the tangent
    contact: tuple | None = None   # (g, lamN, x, n) at contact points
    S0: np.ndarray | None = None   # elastic PK2 (E, Q, 3, 3) at the trial state
    kin: kernels.Kinematics | None = None
    fint: np.ndarray | None = None
    why: str = ""


class Model:
    def __init__(self, mesh, boundaries: dict, law: Law, dirichlet: list[Dirichlet], *,
                 prony=None, formulation: str = "mixed", contact: Contact | None = None,
                 order: int = 2, intorder: int | None = None, stiffness: float = 1.0,
                 qlv_order: int = 2):
        if formulation not in ("mixed", "displacement"):
            raise ParameterError("formulation", formulation, "'mixed' or 'displacement'")
        self.mesh, self.boundaries, self.law, self.prony = mesh, dict(boundaries), law, prony
        params = inspect.signature(law).parameters
        self._law_tangent_kw = "tangent" in params
        # laws that keep the spectral data of a stress evaluation for the tangent at that state
        self._law_keeps = "keep" in params and getattr(law, "tangent_kept", None) is not None
        # ... and can give the in-plane block of D alone (a 2D tangent uses no more; the full
        # D's 81 entries and their strided slice cost a 2D preview sweep ~0.1 s)
        self._kept_in_plane = self._law_keeps and "in_plane" in inspect.signature(law.tangent_kept).parameters
        self.mixed = formulation == "mixed"
        if qlv_order not in (1, 2):
            raise ParameterError("qlv_order", qlv_order, "1 (linear S0 per increment) or 2 (parabola)")
        self.qlv_order = qlv_order
        self.formulation = formulation
        self.element = scalar_element(mesh, order)
        if intorder is None:
            # the rule of Abaqus' CPE6/C3D10 (3 / 4 points): exact for the straight-sided
            # P2 stiffness, half the material evaluations of the default 6-point rule
            intorder = 2 if order == 2 and ("Tri" in type(mesh).__name__ or "Tet" in type(mesh).__name__) else None
        self.basis = CellBasis(mesh, self.element, **({} if intorder is None else {"intorder": intorder}))
        b = self.basis
        self.m = m = mesh.dim()
        self.nsdof = b.N
        self.ndof = b.N * m
        self.G = np.stack([np.moveaxis(b.basis[a][0].grad, 0, -1) for a in range(b.Nbfun)], axis=2)
        self.w = np.asarray(b.dx)
        self.sdofs = b.element_dofs.T                                   # (E, A)
        self.edofs = vector_dofs(self.sdofs, m).reshape(len(self.sdofs), -1)
        self.stiffness = stiffness  # a modulus (MPa) for scaling penalties and tolerances
        # copies of the modelled part in the whole 3D skin (its mirror planes; fe.model_for_scene):
        # the indenter's force is the modelled reaction times this (output.indenter_force)
        self.force_factor = 1.0
        self.timing = defaultdict(float)  # s spent per phase (residual, tangent, contact)
        self._Ke = None  # the tangent's element matrices (a buffer reused per tangent)
        # reuse of the last admissible state (_State) when u (bit for bit), dt and the committed
        # history are the same, and of the stress evaluation's spectral data for the tangent;
        # False: every evaluation computes afresh (the tests' oracle)
        self.reuse_state = True
        self._last = None  # (u copy, dt bytes, history, (history.commits, dt_prev)), _State
        self.counts = defaultdict(int)  # law_stress / law_tangent / tangent_kept calls, state_reused

        # Dirichlet dofs
        self.dirichlet = list(dirichlet)
        fixed, self._bc_groups = [], []
        for bc in self.dirichlet:
            if bc.boundary not in self.boundaries:
                raise ParameterError("boundary", bc.boundary, "one of " + ", ".join(sorted(self.boundaries)))
            sd = self.facet_scalar_dofs(bc.boundary)
            dofs = (sd[:, None] * m + np.asarray(bc.components)[None, :]).ravel()
            self._bc_groups.append((bc, dofs, b.doflocs[:, sd].T))
            fixed.append(dofs)
        self.fixed = np.unique(np.concatenate(fixed)) if fixed else np.zeros(0, int)
        self.free = np.setdiff1d(np.arange(self.ndof), self.fixed)
        self.pattern = Pattern(self.ndof, self.edofs, self.free, m)

        # contact
        self.contact = contact
        self.surface = None
        if contact is not None:
            if contact.boundary not in self.boundaries:
                raise ParameterError("contact boundary", contact.boundary, "one of " + ", ".join(sorted(self.boundaries)))
            # 2 points per P2 edge (2D), 3 per P2 triangle (3D): with 6 per triangle the
            # multipliers over-constrain the facet and Newton cycled (3D flat plate: failed
            # at 5.7 um of travel; with 3: 10 increments, no cutback)
            self.surface = ContactSurface(mesh, self.element, self.boundaries[contact.boundary], m,
                                          intorder=3 if m == 2 else 2)
            if contact.penalty is None:
                h = self.surface_size()
                contact.penalty = PENALTY_FACTOR * stiffness / h
                log.debug("contact penalty %.3g MPa/mm (h = %.3g mm)", contact.penalty, h)
            if contact.tol_penetration is None:
                rel = TOL_RELATIVE[m] if contact.tol_relative is None else contact.tol_relative
                if not (np.isfinite(rel) and 0 < rel < 1):
                    raise ParameterError("contact tol_relative", rel, "(0, 1) of the contact facet size")
                tol = rel * self.surface_size()
                if contact.travel is not None and contact.travel > 0:
                    tol = max(min(tol, TOL_TRAVEL * contact.travel), TOL_TRAVEL_FLOOR * tol)
                contact.tol_penetration = tol

        # committed state
        E, Q = self.w.shape
        self.u = np.zeros(self.ndof)
        # the committed state before the last commit and that increment's length (the
        # solver's secant predictor extrapolates from them)
        self.u_prev, self.dt_prev = None, None
        # the viscoelastic state belongs to the material's Prony series (any law inside it)
        from tactileskin.materials.prony import Prony

        self.history = (Prony.elastic() if prony is None else prony).history((E, Q, 3, 3), qlv_order)
        self.t = 0.0
        # threads of the compiled element and material loops (fe.solver.run sets them with
        # PARDISO's: more than one for the large 3D models only)
        self.threads = 1
        # loading (fe.loading): the travel as a function of time (None: contact.rate * t), or
        # under force control the fixed trial travel of the increment being solved
        self.travel_path: Callable | None = None
        self.travel_fixed: float | None = None
        self.d = 0.0  # committed travel (mm)

    # -- helpers ------------------------------------------------------------------------------
    def _law(self, C: np.ndarray, tangent: bool, keep: bool = False) -> tuple:
        """The material law at C, (S, D, ok); D may be None when not asked for (a law without
        the `tangent` keyword always returns it). keep: (S, D, ok, kept), kept the spectral
        data for `law.tangent_kept` (None where the law keeps none)."""
        self.counts["law_tangent" if tangent else "law_stress"] += 1
        if keep and self._law_keeps:
            return self.law(C, tangent=tangent, keep=True)
        out = self.law(C, tangent=tangent) if self._law_tangent_kw else self.law(C)
        return (*out, None) if keep else out

    def _reusable(self, u: np.ndarray, dt: float) -> _State | None:
        """The last admissible state if it was evaluated at these very u (bit for bit), dt and
        committed history (its commits and its previous step dt_prev, which fe.loading resets
        at a segment's start without a commit), else None."""
        if not self.reuse_state or self._last is None:
            return None
        (u0, dt0, hist, commits), state = self._last
        if (hist is not self.history or commits != (hist.commits, hist.dt_prev)
                or np.float64(dt).tobytes() != dt0):
            return None
        u = np.ascontiguousarray(u, dtype=np.float64)
        if u.shape != u0.shape or not np.array_equal(u.view(np.int64), u0.view(np.int64)):
            return None
        return state

    def facet_scalar_dofs(self, name: str) -> np.ndarray:
        return np.unique(self.basis.get_dofs(self.boundaries[name]).all())

    def penalty(self) -> np.ndarray:
        """Penalty (MPa/mm) at each contact point: the contact's times the points' scale,
        which the Uzawa loop raises where it contracts slowly (fe.solver)."""
        return self.contact.penalty * self.surface.scale

    def surface_size(self) -> float:
        """Typical facet size on the contact boundary (mm)."""
        w = self.surface.w.sum(axis=1)
        return float(np.median(w)) if self.m == 2 else float(np.sqrt(np.median(w)))

    def prescribed(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        dofs, vals = [], []
        for bc, d, X in self._bc_groups:
            dofs.append(d)
            vals.append(bc.at(t, X))
        if not dofs:
            return np.zeros(0, int), np.zeros(0)
        return np.concatenate(dofs), np.concatenate(vals)

    def travel(self, t: float) -> float:
        """Indenter travel d (mm) at time t (force control: the trial travel)."""
        if self.contact is None:
            return 0.0
        if self.travel_fixed is not None:
            return float(self.travel_fixed)
        if self.travel_path is not None:
            return float(self.travel_path(t))
        return self.contact.rate * t

    def qlv(self, dt: float):
        """(gamma, decay, gain, back) of the Prony update for a step dt from the committed
        state (materials.prony.QLVHistory.factors); elastic: (1, [], [], [])."""
        return self.history.factors(dt)

    # -- evaluation ---------------------------------------------------------------------------
    def evaluate(self, u: np.ndarray, t: float, dt: float, lam_k: np.ndarray | None = None,
                 tangent: bool = True, sticky: np.ndarray | None = None) -> Evaluation:
        """Residual at a trial state; with tangent=True also the tangent (else `tangent(ev)` later)."""
        t0 = time.perf_counter()
        try:
            with numba_threads(self.threads):
                return self._evaluate(u, t, dt, lam_k, tangent, sticky)
        finally:
            self.timing["residual"] += time.perf_counter() - t0

    def _evaluate(self, u, t, dt, lam_k, tangent, sticky) -> Evaluation:
        m = self.m
        st = self._reusable(u, dt)
        if st is not None:
            self.counts["state_reused"] += 1
        else:
            ue = u.reshape(-1, m)[self.sdofs]
            kin = kernels.Kinematics(ue, self.G, self.w, self.mixed)
            if not kin.admissible:
                return Evaluation(R=np.full(self.ndof, np.nan), ok=False, why="J <= 0")
            # residual-only evaluations (line-search trials) skip D: the accepted iterate's
            # tangent computes it then, from the spectral data kept here where the law keeps it
            if self.reuse_state and not tangent:
                S0, D0, ok, kept = self._law(kin.C, False, keep=True)
            else:
                (S0, D0, ok), kept = self._law(kin.C, tangent), None
            if not np.all(ok) or not np.all(np.isfinite(S0)):
                return Evaluation(R=np.full(self.ndof, np.nan), ok=False, why="material state inadmissible")
            S, gamma = self.history.stress(S0, dt)
            fint = assemble_vector(self.ndof, self.edofs, kernels.residual(kin, S[..., :m, :m]))
            st = _State(kin, S0, S, gamma, fint, D0, kept)
            if self.reuse_state:
                self._last = ((np.array(u, dtype=np.float64), np.float64(dt).tobytes(), self.history,
                               (self.history.commits, self.history.dt_prev)), st)
        kin, S0, S, gamma, fint = st.kin, st.S0, st.S, st.gamma, st.fint
        R = fint.copy()
        cinfo = None
        if self.surface is not None:
            c = self.contact
            lam = self.surface.lam if lam_k is None else lam_k
            tc = time.perf_counter()
            fc, _, cinfo = self.surface.evaluate(u, c.indenter, self.travel(t), self.penalty(), lam, False,
                                                 sticky)
            self.timing["contact"] += time.perf_counter() - tc
            R += assemble_vector(self.ndof, self.surface.vdofs, fc)
        if not np.all(np.isfinite(R)):
            return Evaluation(R=np.full(self.ndof, np.nan), ok=False, why="non-finite residual")
        ev = Evaluation(R=R, ok=True, contact=cinfo, S0=S0, kin=kin, fint=fint)
        ev.S, ev._state, ev._u, ev._t, ev._lam = S, st, u, t, (None if self.surface is None else lam)
        ev._sticky = sticky
        if tangent:
            tt = time.perf_counter()
            self.tangent(ev)
            self.timing["residual"] -= time.perf_counter() - tt  # counted as tangent
        return ev

    def tangent(self, ev: Evaluation, curvature: bool | None = None) -> np.ndarray:
        """CSR data of the tangent at an admissible evaluation (cached on it); curvature:
        include the indenter-curvature term (None: Contact.curvature_tangent)."""
        if ev.K is not None and (curvature is None or getattr(ev, "_curv", None) == curvature):
            return ev.K
        t0 = time.perf_counter()
        m = self.m
        with numba_threads(self.threads):
            st = ev._state
            if st.D is None:
                if st.kept is not None:
                    self.counts["tangent_kept"] += 1
                    st.D = (self.law.tangent_kept(st.kept, in_plane=True) if m == 2 and self._kept_in_plane
                            else self.law.tangent_kept(st.kept))
                else:
                    st.D = self._law(ev.kin.C, True)[1]
                st.kept = None   # D supersedes it
            Dm = st.gamma * st.D[..., :m, :m, :m, :m]
            # the element matrices only live until the scatter: one buffer per model (a new
            # 59 MB array per tangent on the 3D t = 5 dot cost its page faults, ~6 ms)
            E, nd = self.edofs.shape
            if self._Ke is None:
                self._Ke = np.empty((E, nd, nd))
            Ke = kernels.tangent(ev.kin, ev.S[..., :m, :m], Dm, out=self._Ke)
            Kd = self.pattern.data(Ke)   # threaded: the solve's share of the cores
        if self.surface is not None:
            c = self.contact
            tc = time.perf_counter()
            _, Kc, _ = self.surface.evaluate(ev._u, c.indenter, self.travel(ev._t), self.penalty(), ev._lam, True,
                                             ev._sticky,
                                             c.curvature_tangent if curvature is None else curvature)
            self.pattern.add(Kd, self.surface.vdofs, Kc)
            self.timing["contact"] += time.perf_counter() - tc
        self.timing["tangent"] += time.perf_counter() - t0
        if not np.all(np.isfinite(Kd)):
            raise FloatingPointError("non-finite tangent")
        ev.K, ev._curv = Kd, curvature
        return Kd

    def commit(self, ev: Evaluation, u: np.ndarray, t: float, dt: float) -> None:
        self.history.commit(ev.S0, dt)
        self._last = None  # the history it was evaluated with is gone
        self.u_prev, self.dt_prev = self.u, dt
        self.u = u.copy()
        self.d = self.travel(t)
        self.t = t
        if self.surface is not None and ev.contact is not None:
            self.surface.lam_prev = self.surface.lam
            self.surface.lam = np.maximum(ev.contact[1], 0.0)  # no adhesion carried over

    # -- output -------------------------------------------------------------------------------
    def stress(self, ev: Evaluation) -> np.ndarray:
        """Cauchy stress (E, Q, 3, 3) at the evaluation's state (total QLV stress)."""
        return kernels.cauchy(ev.kin, ev.S)
