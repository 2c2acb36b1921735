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

The constants are set from what PDR is known to do (drift of 5–10 % of the distance walked;
a landmark known to half a metre), not fitted to a building. Checked against the ground truth
(`workstation evaluate --walks`, per-point rank correlation; docs/decisions.md): museum 0.72,
mall F1 0.52 — belief itself correlates at 0.04 and 0.01 there.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .tracker import Track

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
    s0, s1 = anchor_spread(track)
    d_prev = np.maximum(along(times) - along(track.seg_t0[s]), 0.0)
    d_next = np.maximum(along(track.seg_t1[s]) - along(times), 0.0)
    from_start = np.hypot(s0[s], np.where(closed, 1.0, OPEN_FACTOR) * DRIFT * d_prev)
    from_end = np.where(closed, np.hypot(s1[s], DRIFT * d_next), np.inf)
    xf, yf, _ = track.position_at(times)
    xb, yb, _ = track.position_at(times, corrected=True)
    correction = np.hypot(xb - xf, yb - yf)
    sigma = np.hypot(BASE_M, np.minimum(from_start, from_end)) + 0.5 * np.maximum(
        correction - CORRECTION_FREE_M, 0.0
    )
    out = np.where(seg >= 0, sigma, np.inf)
    out[at] = np.hypot(AT_LANDMARK_M, s0[s[at]])  # placed on the segment's start landmark
    return out


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


SIGMA_BINS_M = (0.0, 0.5, 1.0, 1.5, 2.0, 3.0, 5.0, np.inf)


def sigma_calibration(se: np.ndarray) -> dict[str, Any]:
    """Rank correlation (Spearman) of σ with the placement error over scans with a finite σ,
    and the calibration table: per σ bin, scans and mean / median error."""
    se = se[np.isfinite(se).all(axis=1)]
    if len(se) < 3:
        return {}
    from scipy.stats import spearmanr

    rho = float(spearmanr(se[:, 0], se[:, 1]).statistic)
    rows = []
    for lo, hi in zip(SIGMA_BINS_M, SIGMA_BINS_M[1:]):
        m = (se[:, 0] >= lo) & (se[:, 0] < hi)
        if m.any():
            rows.append({"sigma_m": f"{lo:g}–{hi:g}", "scans": int(m.sum()),
                         "mean_error_m": round(float(se[m, 1].mean()), 3),
                         "median_error_m": round(float(np.median(se[m, 1])), 3)})  # fmt: skip
    return {"scans": int(len(se)), "rank_correlation": round(rho, 3), "bins": rows}
