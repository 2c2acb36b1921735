"""How well a detection fits a candidate landmark: the paper's confidence (eq. 11–14) and the
log-likelihood the whole-walk association sums (beyond the paper, docs/decisions.md).

Both compare what was walked since the last matched landmark u — distance d*, direction θ* of
the displacement — with the candidate v's route from u — path length d_k, direction θ_k.
"""

from __future__ import annotations

import math
from typing import TypeVar

import numpy as np
from numpy.typing import ArrayLike

F = TypeVar("F", float, np.ndarray)  # one value or an array of them


def wrap(a: ArrayLike) -> np.ndarray:
    """Angle(s) wrapped to [−π, π)."""
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def wrap1(a: float) -> float:
    """:func:`wrap` for one angle, without numpy (the association's hot path)."""
    return (a + math.pi) % (2 * math.pi) - math.pi


def confidence(
    d_k: float,
    d_star: float,
    heading_ok: bool,
    min_distance_m: float,
    distance_slack: float = 0.0,
) -> float:
    """Eq. 11–14: con = δ(rule) · r(|θ_k − θ*| < ε_θ) · g, g = 1/|d_k − d*| (eq. 14), the
    difference floored at ``min_distance_m`` and reduced by ``distance_slack`` · d_k. The rule
    δ is checked by the caller (a candidate without the rule never gets here)."""
    if not heading_ok:
        return 0.0
    return 1.0 / max(abs(d_k - d_star) - distance_slack * d_k, min_distance_m)


def distance_sd(length_m: float, eps_v: float, step_length_cv: float) -> float:
    """σ of the distance walked against a path of ``length_m``: half the paper's tolerance
    1/ε_v, plus the step-length variation along the path."""
    return 0.5 / max(eps_v, 1e-6) + step_length_cv * length_m


def distance_window(d_star: float, eps_v: float, step_length_cv: float) -> tuple[float, float]:
    """The path lengths L whose distance term is within 3σ of the distance walked d*, σ =
    :func:`distance_sd` (L): |d* − L| ≤ 3σ solved for L, widened by a hair for rounding. A
    route outside fails whatever its other terms (they are ≤ 0): the association skips it
    without scoring it."""
    s0 = 0.5 / max(eps_v, 1e-6)
    pad = 1e-6 * (1.0 + abs(d_star))
    lo = (d_star - 3 * s0) / (1 + 3 * step_length_cv) - pad
    hi = (d_star + 3 * s0) / (1 - 3 * step_length_cv) + pad if 3 * step_length_cv < 1 else math.inf
    return lo, hi


def heading_sd(eps_theta: float, span_m: float, eps_v: float) -> float:
    """σ of the direction to a landmark ``span_m`` away: half the paper's ε_θ, widened when
    the landmark is near (a position error of σ_0 turns the direction more)."""
    return math.hypot(eps_theta / 2, math.atan2(0.5 / max(eps_v, 1e-6), max(span_m, 1e-3)))


def direction_known_m(eps_theta: float, eps_v: float) -> float:
    """How far apart two places must be for the direction between them to be known to within
    ε_θ/2 (the heading term's own σ) when each is known to the paper's tolerance σ₀ = 0.5/ε_v:
    σ₀ / tan(ε_θ/2) — 7.5 m with the defaults. A shorter walked displacement says less about
    the heading than the heading itself."""
    return 0.5 / max(eps_v, 1e-6) / math.tan(max(eps_theta, 1e-6) / 2)


# an inferred start is reported ambiguous against chains starting further away than this; a
# walk's end (walk_end.py) is ambiguous against landmarks that far from the one it closes on
ALTERNATIVE_START_M = 5.0
# chains of matches at most this much less likely (log-odds: 1 in 4.5) are plausible alternatives:
# where one of them gives a detection another landmark, the match is that far uncertain
AMBIGUOUS_LOGODDS = 1.5

LL_3SD = -4.5  # gaussian_ll at 3σ: a term beyond it rules a candidate out


def gaussian_ll(residual: F, sd: float) -> F:
    """−½ (residual/σ)²: 0 for a perfect fit, ``LL_3SD`` (−4.5) at 3σ."""
    return -0.5 * (residual / sd) ** 2


def circmean(a: ArrayLike) -> float:
    v = np.asarray(a, float)
    v = v[np.isfinite(v)]
    return float(math.atan2(np.sin(v).sum(), np.cos(v).sum())) if v.size else 0.0


def odds(gap_ll: float) -> str:
    """How much less likely a candidate is than the best, in words a surveyor reads: "likeliest",
    "2.9× less likely" (the log-likelihood gap, exponentiated; issue #50 item 8: the rank beside
    a distance read as wrong where the distances did not rise with it)."""
    if gap_ll != gap_ll:
        return "no scan to judge by"
    times = math.exp(min(max(gap_ll, 0.0), 50.0))
    if times < 1.05:
        return "likeliest" if gap_ll <= 0 else "as likely"
    if times > 1000.0:
        return "over 1000× less likely"
    return f"{times:.2g}× less likely" if times < 10 else f"{times:.0f}× less likely"


# how far a dead-reckoned place may be from where the walker was, uncalibrated: the tolerance
# with which the walk's end is matched (tracking/walk_end) and the next walk's start searched
# (walks/chain) — measured with these, not a placement figure (that is pipeline/sigma's σ)
GATE_BASE_M = 0.5  # σ₀: the anchor landmark's own place
GATE_DRIFT = 0.1  # per metre walked from it
OPEN_FACTOR = 2.0  # on the open last segment (one anchor, no correction) drift counts double


def open_sigma(spread: float, walked_m: float) -> float:
    """σ (m) of a place on the open last segment ``walked_m`` from its anchor, whose own
    spread is ``spread``: hypot(σ₀, s, ``OPEN_FACTOR`` · ``GATE_DRIFT`` · d) — the dead-reckoning
    gate above (pipeline/sigma's σ with nothing after it, uncalibrated)."""
    return float(np.hypot(GATE_BASE_M, np.hypot(spread, OPEN_FACTOR * GATE_DRIFT * walked_m)))
