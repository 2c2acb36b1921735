"""Per-point placement uncertainty σ (m) of each scan on the corrected trajectory — beyond the
paper, whose belief (eq. 15–18) trusts or rejects a whole segment (issue #29).

What the tracker knows of a scan's position:

- **distance to the nearest anchor**: dead reckoning drifts with the distance walked from the
  last landmark it was snapped to; on a closed segment (both ends matched) the backward
  correction pins both ends, so the nearer of the two counts; on the open last segment only
  the last one does, and nothing corrected the drift since — it counts ``OPEN_FACTOR`` times;
- **the size of the backward correction** there: a segment that had to be bent by metres to
  end on its landmark was walked differently from what the sensors said (a missed turn, a wrong
  step length); beyond ``CORRECTION_FREE_M`` it adds half of itself;
- **how sure the match itself is**: an anchor is only as good as the association that chose
  it — where a nearly as likely chain of matches gave the same detection another landmark,
  that landmark's distance (``Track.det_spread``) is the anchor's own uncertainty;
- **standing at a matched landmark**: the scan is placed on the landmark (σ = ``AT_LANDMARK_M``,
  with the landmark's spread).

σ = min over the anchors a of hypot(σ₀, s_a, ``DRIFT`` · d_a) + ½ · max(correction −
``CORRECTION_FREE_M``, 0), with σ₀ the position of a landmark itself (``BASE_M``), s_a the
anchor's spread and d_a the distance walked from it (the open segment: its start, doubled).

The constants (:class:`Shape`) start from what PDR is known to do (drift of 5–10 % of the
distance walked; a landmark known to half a metre); their ratios were chosen on a small grid
over the museum and the mall together (docs/decisions.md). ``evaluate --walks`` checks σ
against the ground truth (rank correlation, calibration table) and again on walks its
constants were not chosen on (:mod:`..evaluate.sigma_check`): mall F1 0.54 (held out 0.55),
museum 0.70 (0.69); belief itself correlates at 0.04 and 0.01 there.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .tracker import Track

BASE_M = 0.5  # σ of a landmark's own position
DRIFT = 0.1  # σ grows by this per metre walked from the nearest anchor
OPEN_FACTOR = 2.0  # on the open last segment (one anchor, no correction) drift counts double
CORRECTION_FREE_M = 2.0  # a backward correction up to this is ordinary drift
CORRECTION_WEIGHT = 0.5  # the share of a larger correction that adds to σ
AT_LANDMARK_M = 0.3  # standing on a matched landmark


@dataclass(frozen=True)
class Shape:
    """The constants of σ's equation (module doc); the defaults are the module's."""

    base_m: float = BASE_M
    drift: float = DRIFT
    open_factor: float = OPEN_FACTOR
    correction_free_m: float = CORRECTION_FREE_M
    correction_weight: float = CORRECTION_WEIGHT
    at_landmark_m: float = AT_LANDMARK_M


class Terms(NamedTuple):
    """What σ is made of, per scan (:func:`terms`): whatever the constants."""

    walking: np.ndarray  # bool: after the walk started (else σ = inf)
    closed: np.ndarray  # bool: on a closed segment (both ends matched)
    spread0: np.ndarray  # the spread of the segment's start landmark (m)
    spread1: np.ndarray  # … and of its end landmark (m; 0 when open)
    d_prev: np.ndarray  # distance walked from the segment's start (m)
    d_next: np.ndarray  # … to its end (m)
    correction: np.ndarray  # size of the backward correction there (m)
    at: np.ndarray  # bool: taken standing at a matched landmark, placed on it


def terms(track: Track, times: np.ndarray, seg: np.ndarray, at: np.ndarray) -> Terms | None:
    """σ's terms for scans at ``times`` in segments ``seg`` (−1: before the walk started);
    ``at``: placed on the landmark it was taken standing at. None when the track has fewer
    than two steps or no segment."""
    if track.t.size < 2 or not track.seg_t0.size:
        return None
    walked = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(track.x), np.diff(track.y)))])

    def along(t):
        return np.interp(t, track.t, walked)

    s = np.clip(seg, 0, None)
    s0, s1 = anchor_spread(track)
    xf, yf, _ = track.position_at(times)
    xb, yb, _ = track.position_at(times, corrected=True)
    return Terms(
        seg >= 0,
        track.seg_to[s] != "",
        s0[s],
        s1[s],
        np.maximum(along(times) - along(track.seg_t0[s]), 0.0),
        np.maximum(along(track.seg_t1[s]) - along(times), 0.0),
        np.hypot(xb - xf, yb - yf),
        np.asarray(at, bool),
    )


def sigma_of(t: Terms, shape: Shape = Shape()) -> np.ndarray:
    """σ (m) per scan from its terms (the module's equation with ``shape``'s constants)."""
    k = shape
    from_start = np.hypot(t.spread0, np.where(t.closed, 1.0, k.open_factor) * k.drift * t.d_prev)
    from_end = np.where(t.closed, np.hypot(t.spread1, k.drift * t.d_next), np.inf)
    sigma = np.hypot(k.base_m, np.minimum(from_start, from_end)) + k.correction_weight * np.maximum(
        t.correction - k.correction_free_m, 0.0
    )
    out = np.where(t.walking, sigma, np.inf)
    # placed on the segment's start landmark
    return np.where(t.at, np.hypot(k.at_landmark_m, t.spread0), out)


def placement_sigma(track: Track, times: np.ndarray, seg: np.ndarray, at: np.ndarray) -> np.ndarray:
    """σ (m) for scans at ``times`` in segments ``seg`` (−1: before the walk started: inf);
    ``at``: placed on the landmark it was taken standing at."""
    tm = terms(track, times, seg, at)
    if tm is None:
        out = np.full(times.size, np.inf)
        out[at] = AT_LANDMARK_M
        return out
    return sigma_of(tm)


def open_sigma(spread: float, walked_m: float) -> float:
    """σ (m) of a place on the open last segment ``walked_m`` from its anchor, whose own
    spread is ``spread``: hypot(σ₀, s, ``OPEN_FACTOR`` · ``DRIFT`` · d) — the module's σ with
    nothing after it (:mod:`.walk_end` matches the walk's end with it)."""
    return float(np.hypot(BASE_M, np.hypot(spread, OPEN_FACTOR * DRIFT * walked_m)))


def anchor_spread(track: Track) -> tuple[np.ndarray, np.ndarray]:
    """Per segment, the spread (m) of the landmark it starts from and of the one it ends on
    (0 for the start landmark, which is given or quarantined when ambiguous, and for the open
    end). Segments follow the matched detections in order."""
    n = track.seg_t0.size
    s0, s1 = np.zeros(n), np.zeros(n)
    if n == 0:
        return s0, s1
    spread = track.det_spread[track.matched]
    k = min(spread.size, n - 1)
    s1[:k] = spread[:k]
    s0[1 : k + 1] = spread[:k]
    if track.end_node:
        s1[n - 1] = track.end_spread
    return s0, s1
