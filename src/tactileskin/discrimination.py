"""Can the sensors under the skin tell the indenters apart?

For one material and thickness, the three pressure profiles P(s) along the bone are
compared pairwise on a common s grid by the relative L2 distance

    d(P, Q) = ||P - Q||_2 / max(||P||_2, ||Q||_2),    ||P||_2 = sqrt(int P^2 ds),

which weighs both shape and magnitude (the paper discriminates by both: Figs. 10-13).
Two profiles count as distinguishable when d >= THRESHOLD = 0.2. Why 0.2: a measured
profile carries about +-10 % error (pressure-film accuracy; the paper's 1 mm
simulation-experiment peak differences are 1.3-9 %, but 33 % for polyurethane's Braille), so two profiles can only be told
apart reliably when they differ by more than twice that. A set of indenters is
distinguishable when every pair is.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from tactileskin.errors import ParameterError
from tactileskin.results import fold_profile

THRESHOLD = 0.2


def _on_grid(s: np.ndarray, p: np.ndarray, grid: np.ndarray) -> np.ndarray:
    order = np.argsort(s)
    return np.interp(grid, s[order], p[order], left=0.0, right=0.0)


def _sorted(s: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    order = np.argsort(s, kind="stable")
    return s[order], p[order]


def _l2(grid: np.ndarray, f: np.ndarray) -> float:
    return float(np.sqrt(np.trapezoid(f * f, grid)))


def profile_distance(s1, p1, s2, p2, n: int = 2001) -> float:
    """Relative L2 distance of two profiles over the union of their s ranges. A profile across
    the centre (a whole model's, s < 0 too) against one from the symmetry line (a halved
    model's) is folded onto s >= 0 first: the halved model's missing side is no difference."""
    s1, p1, s2, p2 = (np.asarray(v, float) for v in (s1, p1, s2, p2))
    for which, name, v in ((1, "s", s1), (1, "P", p1), (2, "s", s2), (2, "P", p2)):
        if v.size == 0 or not np.all(np.isfinite(v)):
            # a NaN distance compared below the threshold: "not distinguishable", silently
            raise ParameterError(f"profile {which} {name}", "empty or non-finite", "finite samples")
    if s1.shape != p1.shape or s2.shape != p2.shape:
        raise ParameterError("profile", f"{s1.shape}/{p1.shape}, {s2.shape}/{p2.shape}", "s and P of one length")
    tol = 1e-9 * max(np.abs(s1).max(), np.abs(s2).max(), 1.0)
    two1, two2 = s1.min() < -tol, s2.min() < -tol
    if two1 and not two2:
        s1, p1, _ = fold_profile(*_sorted(s1, p1))
    elif two2 and not two1:
        s2, p2, _ = fold_profile(*_sorted(s2, p2))
    lo = min(s1.min(), s2.min())
    hi = max(s1.max(), s2.max())
    grid = np.linspace(lo, hi, n)
    a, b = _on_grid(s1, p1, grid), _on_grid(s2, p2, grid)
    scale = max(_l2(grid, a), _l2(grid, b))
    if scale == 0.0:
        return 0.0
    return _l2(grid, a - b) / scale


@dataclass(frozen=True)
class Verdict:
    distances: dict          # (name_a, name_b) -> d
    min_distance: float
    distinguishable: bool


def discriminate(profiles: dict[str, tuple[np.ndarray, np.ndarray]],
                 threshold: float = THRESHOLD) -> Verdict:
    """Pairwise distances among named profiles {name: (s, P)} and the verdict."""
    if len(profiles) < 2:
        return Verdict({}, float("nan"), False)
    dist = {}
    for (na, (sa, pa)), (nb, (sb, pb)) in itertools.combinations(sorted(profiles.items()), 2):
        try:
            dist[(na, nb)] = profile_distance(sa, pa, sb, pb)
        except ParameterError as e:  # name the record, not "profile 2"
            which = na if e.name.startswith("profile 1") else nb
            raise ParameterError(f"profile {which!r} {e.name.split()[-1]}", e.value, e.valid) from None
    dmin = min(dist.values())
    return Verdict(dist, dmin, dmin >= threshold)
