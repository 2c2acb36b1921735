"""Per-point placement uncertainty σ (m) of each scan on the corrected trajectory — beyond the
paper, whose belief (eq. 15–18) trusts or rejects a whole segment (issue #29).

What the tracker knows of a scan's position:

- **distance to the nearest anchor**: dead reckoning drifts with the distance walked from the
  last landmark it was snapped to; on a closed segment (both ends matched) the backward
  correction pins both ends, so the nearer of the two counts; on the open last segment only
  the last one does, and nothing corrected the drift since — it counts ``OPEN_FACTOR`` times;
- **the size of the backward correction** there: a segment that had to be bent by metres to
  end on its landmark was walked differently from what the sensors said (a missed turn, a wrong
  step length); beyond ``CORRECTION_FREE_M`` it adds itself (``CORRECTION_WEIGHT``);
- **how sure the match itself is**: an anchor is only as good as the association that chose
  it — where a nearly as likely chain of matches gave the same detection another landmark,
  that landmark's distance (``Track.detections.spread``) is the anchor's own uncertainty;
- **standing at a matched landmark**: the scan is placed on the landmark (σ = ``AT_LANDMARK_M``,
  with the landmark's spread);
- **an end closed loosely** (its σ over ``state.END_CHECK_M``) anchors no better than that
  σ: it is the end anchor's spread (:func:`.tracking.state.anchor_spread`);
- **a match that made the track jump** farther than dead reckoning drifts — more than
  ``SNAP_GATES`` times hypot(``BASE_M``, ``DRIFT`` · the distance walked since the anchor
  before) — anchors the segment it starts no better than that jump: the walker may be where
  dead reckoning said, the landmark a wrong one (:func:`snap_spread`; the four mall floors:
  map ÷ tap oracle B1 1.158 → 1.143, one walk placed > 5 m off fewer on F3, the others within
  0.002; docs/experiments.md);
- **a stretch the compass denies**: the phone's compass agrees with the walker's direction on
  one offset per floor, to 5–7° a walk (benchmarks/compass_north.py; the tracker already takes
  the plan's +x for the compass's east, tracking/candidates.py) — a wrong match re-aligns the
  gyro onto a wrong edge and the track walks off where the phone does not point. Where the
  placed track's direction over ``COMPASS_WINDOW_S`` either side of a step is Δ more than
  ``COMPASS_GATE_DEG`` off the compass (steadily: the deviation's resultant at least
  ``continuity.STEADY``; on a level segment: a stair's or a lift's steel turns the compass for
  as long as the ride), the walker went elsewhere — beyond what the compass itself strays —
  by the chord 2 sin((Δ − gate)/2) per metre walked: that distance, summed since the segment
  began, is added to σ as it is (c below, a distance, not a spread: outside ``SCALE``), and a
  landmark reached along such a stretch anchors no better than its whole sum
  (:func:`compass_drift`). The gate is where the compass strays from the walker's true
  direction in one ±3-s window of ten (p90 21–32° on the four mall floors and the museum,
  p99 42–59°: benchmarks/compass_north.py); measured in docs/experiments.md ("The compass
  knows where north is").

σ = k · [hypot(σ_L, min over the anchors a of hypot(s_a, ``DRIFT`` · d_a)) + w · max(correction −
``CORRECTION_FREE_M``, 0)] + c, with σ_L how well the graph's landmarks are placed (the graph's
``landmark_sigma_m``: ``BASE_M`` for a plan drawn by hand, the taps' merge distance for a graph
from walks), s_a the anchor's spread, d_a the distance walked from it (the open segment: its
start, doubled), c the compass's chord since the segment began; standing at a matched
landmark, k · hypot(max(``AT_LANDMARK_M``, σ_L), s).

**What σ means** (issue #49): the radius that holds about two thirds of the points — 68 %
within 1σ and at least 90 % within 2σ. The terms above are spreads; ``SCALE`` k turns their sum
into that radius. The constants were fitted once on both buildings together (the museum's
10 walks, hand-drawn graph; the mall's 106 walks, graph from their taps; the accepted points
of their first runs, start given), one set for both. Over the points the merged maps hold
(``radiomap.max_sigma_m`` 2.5 m): museum 72.6 % within 1σ, 91.0 % within 2σ; mall 71.9 % /
93.0 % (split), 73.4 % / 93.1 % (leave one out) — docs/decisions.md. ``evaluate --walks``
prints the share within 1σ, 2σ, 3σ.
What differs between the two is where their landmarks are: on a graph from taps the walker
passing a landmark is a metre or so from its point (the taps it merged lie up to 1.5 m apart),
on a plan drawn at the turns half a metre — the graph says which (``landmark_sigma_m``).

The end of a walk is matched (:mod:`.walk_end`) and the next walk's start searched
(:mod:`workstation.walks.chain`) with :func:`.confidence.open_sigma`, the uncalibrated
dead-reckoning spread (``GATE_BASE_M``, ``GATE_DRIFT``, ``OPEN_FACTOR``): a matching tolerance
those modules were measured with, not a placement figure.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from workstation.pipeline.confidence import OPEN_FACTOR
from workstation.pipeline.continuity import STEADY
from workstation.pipeline.heading import Heading
from workstation.pipeline.tracking.state import Track, anchor_spread
from workstation.session.model import Times

BASE_M = 0.5  # σ of a landmark's own position, drawn on a plan (the graph may say otherwise)
DRIFT = 0.15  # σ grows by this per metre walked from the nearest anchor
CORRECTION_FREE_M = 1.0  # a backward correction up to this is ordinary drift
CORRECTION_WEIGHT = 1.0  # the share of a larger correction that adds to σ
AT_LANDMARK_M = 0.6  # standing on a matched landmark
#: a match that moved the track by more than this many times what dead reckoning drifts over
#: the segment before (hypot(``BASE_M``, ``DRIFT`` per metre)) anchors no better than that jump
#: (:func:`snap_spread`)
SNAP_GATES = 3.0
#: a stretch of the placed track whose direction over ± ``COMPASS_WINDOW_S`` (where the walker
#: moved at least ``COMPASS_MIN_M``) is more than this off the compass (:func:`compass_drift`)
COMPASS_GATE_DEG = 30.0
COMPASS_WINDOW_S = 3.0
COMPASS_MIN_M = 3.0
SCALE = 0.7  # the spreads' sum → the radius that holds 68 % of the points (module doc)


@dataclass(frozen=True)
class Shape:
    """The constants of σ's equation (module doc); the defaults are the module's."""

    base_m: float = BASE_M
    drift: float = DRIFT
    open_factor: float = OPEN_FACTOR
    correction_free_m: float = CORRECTION_FREE_M
    correction_weight: float = CORRECTION_WEIGHT
    at_landmark_m: float = AT_LANDMARK_M
    scale: float = SCALE

    def landmarks(self, landmark_sigma_m: float | None) -> Shape:
        """This shape for a graph whose landmarks are placed to ``landmark_sigma_m`` (None:
        ``base_m``)."""
        if landmark_sigma_m is None:
            return self
        return replace(self, base_m=float(landmark_sigma_m))


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
    compass: np.ndarray  # the compass's chord since the segment began (m; :func:`compass_drift`)


def terms(track: Track, times: np.ndarray, seg: np.ndarray, at: np.ndarray,
          heading: Heading | None = None) -> Terms | None:  # fmt: skip
    """σ's terms for scans at ``times`` in segments ``seg`` (−1: before the walk started);
    ``at``: placed on the landmark it was taken standing at; ``heading``: the compass (None:
    no compass term). None when the track has fewer than two steps or no segment."""
    if track.steps.t.size < 2 or not track.segments.t0.size:
        return None
    walked = np.concatenate(
        [[0.0], np.cumsum(np.hypot(np.diff(track.steps.x), np.diff(track.steps.y)))]
    )

    def along(t: Times) -> np.ndarray:
        return np.interp(t, track.steps.t, walked)

    s = np.clip(seg, 0, None)
    s0, s1 = anchor_spread(track)
    s0 = np.maximum(s0, snap_spread(track, SNAP_GATES))
    along_c, denied = compass_drift(track, heading)
    s1 = np.maximum(s1, np.where(track.segments.to_node != "", denied, 0.0))
    s0[1:] = np.maximum(s0[1:], denied[:-1])  # the landmark it was reached along
    closed = track.segments.to_node[s] != ""
    xf, yf, _ = track.position_at(times)
    xb, yb, _ = track.position_at(times, corrected=True)
    return Terms(
        seg >= 0,
        closed,
        s0[s],
        s1[s],
        np.maximum(along(times) - along(track.segments.t0[s]), 0.0),
        np.maximum(along(track.segments.t1[s]) - along(times), 0.0),
        np.hypot(xb - xf, yb - yf),
        np.asarray(at, bool),
        np.where(seg >= 0, np.interp(times, track.steps.t, along_c), 0.0),
    )


def compass_drift(track: Track, heading: Heading | None) -> tuple[np.ndarray, np.ndarray]:
    """Per step, how far the placed (backward-corrected) track has gone from where the compass
    pointed since its segment began — the chord 2 sin((Δ − gate)/2) per metre over the
    stretches whose direction is Δ > the gate ``COMPASS_GATE_DEG`` off it (module doc); and
    per segment that sum over all of it. Zeros without a compass."""
    st, n_seg = track.steps, track.segments.t0.size
    n = st.t.size
    zero = np.zeros(n), np.zeros(n_seg)
    ok_c = np.isfinite(heading.compass) if heading is not None else np.zeros(0, bool)
    if heading is None or n < 3 or ok_c.sum() < 2:
        return zero
    dx, dy = np.diff(st.x_bc), np.diff(st.y_bc)
    length = np.hypot(dx, dy)
    seg = np.clip(st.segment, 0, None)
    lo_f, hi_f = np.full(n_seg, np.inf), np.full(n_seg, -np.inf)
    on = st.segment >= 0
    np.minimum.at(lo_f, seg[on], st.floor[on])
    np.maximum.at(hi_f, seg[on], st.floor[on])
    # within one level segment: a stair's or a lift's steel turns the compass (continuity.py)
    same = (st.segment[1:] == st.segment[:-1]) & (st.segment[1:] >= 0) & (length > 0)
    same &= (lo_f == hi_f)[seg[1:]]
    tm = 0.5 * (st.t[1:] + st.t[:-1])
    psi_c = np.interp(tm, heading.t[ok_c], np.unwrap(heading.compass[ok_c]))
    zw, counts = compass_windows(tm, np.where(same, length, 0.0), np.arctan2(dy, dx) - psi_c)
    dev = np.abs(np.angle(zw))
    gate = np.radians(COMPASS_GATE_DEG)
    over = same & counts & (dev > gate)
    chord = np.where(over, length * 2 * np.sin((dev - gate) / 2), 0.0)
    acc = np.concatenate([[0.0], np.cumsum(chord)])
    first = np.searchsorted(st.segment, np.arange(n_seg))  # each segment's first step
    along = np.where(st.segment >= 0, acc - acc[np.clip(first[seg], 0, n - 1)], 0.0)
    total = np.bincount(seg[1:][same], chord[same], minlength=n_seg)[:n_seg]
    return along, total


def compass_windows(t: np.ndarray, length: np.ndarray,
                    deviation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Over ± ``COMPASS_WINDOW_S`` of each of the steps at times ``t`` (sorted; ``length`` 0
    for a step left out): Σ length · e^{i deviation} — its angle is the window's deviation —
    and whether the window counts: at least ``COMPASS_MIN_M`` walked, the deviation steady
    (the sum's length at least ``continuity.STEADY`` of the distance walked)."""
    z = np.where(length > 0, length * np.exp(1j * np.where(length > 0, deviation, 0.0)), 0.0)
    cz = np.concatenate([[0.0], np.cumsum(z)])
    cl = np.concatenate([[0.0], np.cumsum(length)])
    lo = np.searchsorted(t, t - COMPASS_WINDOW_S)
    hi = np.searchsorted(t, t + COMPASS_WINDOW_S, side="right")
    zw, moved = cz[hi] - cz[lo], cl[hi] - cl[lo]
    return zw, (moved >= COMPASS_MIN_M) & (np.abs(zw) >= STEADY * np.maximum(moved, 1e-9))


def snap_spread(track: Track, gate_k: float) -> np.ndarray:
    """Per segment, the jump its start landmark's match made the track take beyond the step's
    length, where that jump exceeds ``gate_k`` times what dead reckoning drifts over the
    segment before (0 else): an anchor that needed a jump dead reckoning cannot explain is
    only as sure as the jump."""
    st, sg = track.steps, track.segments
    n = sg.t0.size
    out = np.zeros(n)
    if n < 2 or st.t.size < 2:
        return out
    walked = np.concatenate([[0.0], np.cumsum(np.nan_to_num(st.step_length[1:]))])
    first = np.searchsorted(st.segment, np.arange(n))  # each segment's first step
    k = np.clip(first[1:], 1, st.t.size - 1)
    jump = np.hypot(st.x[k] - st.x[k - 1], st.y[k] - st.y[k - 1]) - np.nan_to_num(st.step_length[k])
    before = walked[k] - walked[np.clip(first[:-1], 0, st.t.size - 1)]
    gate = np.hypot(BASE_M, DRIFT * before)
    out[1:] = np.where(jump > gate_k * gate, jump, 0.0)
    return out


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
    at = np.hypot(max(k.at_landmark_m, k.base_m), t.spread0)
    return k.scale * np.where(t.at, at, out) + np.where(t.at, 0.0, t.compass)


def placement_sigma(
    track: Track,
    times: np.ndarray,
    seg: np.ndarray,
    at: np.ndarray,
    landmark_sigma_m: float | None = None,
    heading: Heading | None = None,
) -> np.ndarray:
    """σ (m) for scans at ``times`` in segments ``seg`` (−1: before the walk started: inf);
    ``at``: placed on the landmark it was taken standing at; ``landmark_sigma_m``: the graph's
    (None: ``BASE_M``); ``heading``: the compass (None: no compass term)."""
    return sigma_and_compass(track, times, seg, at, landmark_sigma_m, heading)[0]


def sigma_and_compass(
    track: Track,
    times: np.ndarray,
    seg: np.ndarray,
    at: np.ndarray,
    landmark_sigma_m: float | None = None,
    heading: Heading | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`placement_sigma`, and the part of it the compass added (m per scan; 0 without)."""
    shape = Shape().landmarks(landmark_sigma_m)
    tm = terms(track, times, seg, at, heading)
    if tm is None:
        out = np.full(times.size, np.inf)
        out[at] = shape.scale * max(shape.at_landmark_m, shape.base_m)
        return out, np.zeros(times.size)
    return sigma_of(tm, shape), np.where(tm.at, 0.0, tm.compass)
