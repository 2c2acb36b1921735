"""Belief per segment (§IV-A, eq. 15–18).

bel(S) = (Σ χ(T_i)·T_i / Σ T_i) · 1/σ(T'), χ(T) = 1 if T ∈ [T_min, T_max]; T' are the valid
periods. A segment is trusted when bel > ε_S. Segments with fewer than ``min_valid_steps``
valid steps get belief 0 (nothing to judge regularity on); σ is floored at ``min_period_sd_s``
since periods are only measured to about a sample.

Beyond the paper (docs/decisions.md, "Segment boundaries at landmark stops"): a segment is the
walk *between* its two landmarks. A step period T_i spans (t_{i−1}, t_i]; it is left out of the
segment when it began before the segment did (the stand before the walk, the step across the
detection) or when it spans a stop (a still run of the motion state) that lies within
``boundary_window_s`` of either landmark's detection — the walker tapping, waiting or turning on
the spot at the landmark is not irregular walking. Stops in the middle of a segment still count
against it, as the paper intends. A closed segment whose matched path passes a landmark with a
detection rule that was not detected, or that was re-found after the track was lost (its path is
unknown), is not trusted whatever its belief.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workstation.params import BeliefParams
from workstation.pipeline.steps import Steps
from workstation.pipeline.tracking.state import Track


@dataclass(frozen=True)
class Belief:
    belief: np.ndarray  # per segment
    accepted: np.ndarray  # bool per segment
    valid_ratio: np.ndarray
    period_sd: np.ndarray
    steps: np.ndarray  # steps per segment
    threshold: float
    reason: np.ndarray  # per segment: why not trusted ("" when trusted)
    counted: np.ndarray  # per step: its period counts in its segment's belief
    # per segment, the stop (still run) at its first landmark: start, end (NaN: no stop)
    stop_t0: np.ndarray
    stop_t1: np.ndarray


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


def still_runs(steps: Steps) -> tuple[np.ndarray, np.ndarray]:
    """(start, end) times of the runs where the motion state is still."""
    still = ~np.asarray(steps.walking, bool)
    if not still.any():
        return np.empty(0), np.empty(0)
    d = np.diff(np.concatenate([[0], still.astype(np.int8), [0]]))
    a, b = np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1
    return steps.state_t[a], steps.state_t[b]


def landmark_stops(
    steps: Steps, times: np.ndarray, window_s: float
) -> tuple[np.ndarray, np.ndarray]:
    """Per time in ``times`` (landmark detections) the span (start, end) of the stops within
    ``window_s`` of it, merged into one span; NaN where there is none."""
    a, b = still_runs(steps)
    times = np.asarray(times, float)
    lo, hi = np.full(times.size, np.nan), np.full(times.size, np.nan)
    if a.size == 0 or times.size == 0:
        return lo, hi
    near = (a[None, :] <= times[:, None] + window_s) & (b[None, :] >= times[:, None] - window_s)
    has = near.any(axis=1)
    lo[has] = np.where(near, a[None, :], np.inf).min(axis=1)[has]
    hi[has] = np.where(near, b[None, :], -np.inf).max(axis=1)[has]
    return lo, hi


def counted_periods(steps: Steps, track: Track, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Per step: whether its period counts in its segment's belief (see the module doc).
    ``lo``/``hi``: the stop at each segment's first landmark (:func:`landmark_stops`)."""
    seg = np.asarray(track.steps.segment)
    if seg.size == 0 or track.segments.t0.size == 0:
        return np.zeros(seg.size, bool)
    t = np.asarray(steps.t, float)
    prev = t - np.where(np.isfinite(steps.period), steps.period, np.inf)
    ok = (seg >= 0) & (prev >= track.segments.t0[np.clip(seg, 0, None)])
    for j in np.flatnonzero(np.isfinite(lo)).tolist():  # a few landmarks per walk, not per sample
        # the stop at segment j's first landmark is also at segment j − 1's last one
        mine = (seg == j) | ((seg == j - 1) & (track.segments.to_node[max(j - 1, 0)] != ""))
        ok &= ~(mine & (prev <= hi[j]) & (t >= lo[j]))
    return ok


def compute_belief(steps: Steps, track: Track, p: BeliefParams) -> Belief:
    n_seg = track.segments.from_node.size
    bel = np.zeros(n_seg)
    ratio = np.zeros(n_seg)
    sd = np.full(n_seg, np.nan)
    lo, hi = landmark_stops(steps, track.segments.t0, p.boundary_window_s)
    counted = (
        counted_periods(steps, track, lo, hi)
        if p.landmark_stops_apart
        else (track.steps.segment >= 0) & np.isfinite(steps.period)
    )
    count = np.bincount(track.steps.segment[track.steps.segment >= 0], minlength=n_seg)[:n_seg]
    order = np.argsort(track.steps.segment, kind="stable")
    bounds = np.searchsorted(track.steps.segment[order], np.arange(n_seg + 1))
    for s in range(n_seg):
        idx = order[bounds[s] : bounds[s + 1]]
        idx = idx[counted[idx]]
        bel[s], ratio[s], sd[s] = segment_belief(steps.period[idx], p)
    accepted = bel > p.threshold
    reason = np.array([f"belief {b:.1f} ≤ ε_S {p.threshold:g}" for b in bel], dtype=object)
    missed = track.segments.missed
    accepted &= missed == 0
    for j in np.flatnonzero(missed > 0):
        reason[j] = f"its path passes {missed[j]} landmark(s) with a rule, not detected"
    for j in np.flatnonzero(missed < 0):
        reason[j] = "re-found after the track was lost: path unknown"
    if not p.accept_open_segments and n_seg:
        open_ = track.segments.to_node == ""
        accepted[open_] = False
        reason[open_] = "open: no landmark closes it"
    reason[accepted] = ""
    return Belief(bel, accepted, ratio, sd, count, p.threshold, reason.astype(str), counted, lo, hi)
