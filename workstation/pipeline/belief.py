"""Belief per segment (§IV-A, eq. 15–18).

bel(S) = (Σ χ(T_i)·T_i / Σ T_i) · 1/σ(T'), χ(T) = 1 if T ∈ [T_min, T_max]; T' are the valid
periods. A segment is trusted when bel > ε_S. Segments with fewer than ``min_valid_steps``
valid steps get belief 0 (nothing to judge regularity on); σ is floored at ``min_period_sd_s``
since periods are only measured to about a sample.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..params import BeliefParams
from .steps import Steps
from .tracking import Track


@dataclass(frozen=True)
class Belief:
    belief: np.ndarray  # per segment
    accepted: np.ndarray  # bool per segment
    valid_ratio: np.ndarray
    period_sd: np.ndarray
    steps: np.ndarray  # steps per segment
    threshold: float


def segment_belief(periods: np.ndarray, p: BeliefParams) -> tuple[float, float, float]:
    """(belief, valid ratio, σ of valid periods) of one segment's step periods (eq. 17)."""
    t = periods[np.isfinite(periods)]
    if t.size == 0 or t.sum() <= 0:
        return 0.0, 0.0, float("nan")
    valid = (t >= p.t_min_s) & (t <= p.t_max_s)
    ratio = float(t[valid].sum() / t.sum())
    if valid.sum() < max(p.min_valid_steps, 2):
        return 0.0, ratio, float("nan")
    sd = float(np.std(t[valid]))
    return ratio / max(sd, p.min_period_sd_s, 1e-9), ratio, sd


def compute_belief(steps: Steps, track: Track, p: BeliefParams) -> Belief:
    n_seg = track.seg_from.size
    bel = np.zeros(n_seg)
    ratio = np.zeros(n_seg)
    sd = np.full(n_seg, np.nan)
    count = np.bincount(track.segment[track.segment >= 0], minlength=n_seg)[:n_seg]
    order = np.argsort(track.segment, kind="stable")
    bounds = np.searchsorted(track.segment[order], np.arange(n_seg + 1))
    for s in range(n_seg):
        idx = order[bounds[s] : bounds[s + 1]]
        bel[s], ratio[s], sd[s] = segment_belief(steps.period[idx], p)
    accepted = bel > p.threshold
    if not p.accept_open_segments and n_seg:
        accepted[track.seg_to == ""] = False
    return Belief(bel, accepted, ratio, sd, count, p.threshold)
