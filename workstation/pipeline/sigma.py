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
- **standing at a matched landmark**: the scan is placed on the landmark (σ = ``AT_LANDMARK_M``).

σ = hypot(σ₀, ``DRIFT`` · d) + ½ · max(correction − ``CORRECTION_FREE_M``, 0), with σ₀ the
position of a landmark itself (``BASE_M``) and d the anchor distance above.

The constants are set from what PDR is known to do (drift of 5–10 % of the distance walked;
a landmark known to half a metre), not fitted to a building. Checked against the ground truth
(`workstation evaluate --walks`, per-point rank correlation; docs/decisions.md): museum 0.72,
mall F1 0.52 — belief itself correlates at 0.04 and 0.01 there.
"""

from __future__ import annotations

import numpy as np

from .tracking import Track

BASE_M = 0.5  # σ of a landmark's own position
DRIFT = 0.1  # σ grows by this per metre walked from the nearest anchor
OPEN_FACTOR = 2.0  # on the open last segment (one anchor, no correction) drift counts double
CORRECTION_FREE_M = 2.0  # a backward correction up to this is ordinary drift
AT_LANDMARK_M = 0.3  # standing on a matched landmark


def placement_sigma(track: Track, times: np.ndarray, seg: np.ndarray, at: np.ndarray) -> np.ndarray:
    """σ (m) for scans at ``times`` in segments ``seg`` (−1: before the walk started: inf);
    ``at``: placed on the landmark it was taken standing at."""
    out = np.full(times.size, np.inf)
    if track.t.size < 2 or not track.seg_t0.size:
        out[at] = AT_LANDMARK_M
        return out
    walked = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(track.x), np.diff(track.y)))])

    def along(t):
        return np.interp(t, track.t, walked)

    s = np.clip(seg, 0, None)
    closed = track.seg_to[s] != ""
    d_prev = along(times) - along(track.seg_t0[s])
    d_next = along(track.seg_t1[s]) - along(times)
    d = np.where(closed, np.minimum(d_prev, d_next), OPEN_FACTOR * d_prev)
    xf, yf, _ = track.position_at(times)
    xb, yb, _ = track.position_at(times, corrected=True)
    correction = np.hypot(xb - xf, yb - yf)
    sigma = np.hypot(BASE_M, DRIFT * np.maximum(d, 0.0)) + 0.5 * np.maximum(
        correction - CORRECTION_FREE_M, 0.0
    )
    out = np.where(seg >= 0, sigma, np.inf)
    out[at] = AT_LANDMARK_M
    return out
