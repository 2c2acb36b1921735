"""The tracker's model (§III-B, eq. 7–10): the corrected trajectory it produces
(:class:`Track`), a chain of matches (:class:`Match`, :class:`TrackerState`), the dead reckoning from
the last matched landmark to a detection (:class:`WalkToDetection`, eq. 7–8) and :class:`Tracker`, which
walks, scores candidates (:mod:`.candidates`, eq. 11–14) and advances a chain at a match
(eq. 10). :mod:`.tracking` runs it; :mod:`.association` chooses the chain; :mod:`.replay` turns
the chosen chain into a :class:`Track`.
"""

from __future__ import annotations

import numpy as np

from workstation.params import COMPASS_HEADING, GYRO_HEADING, PDRParams
from workstation.pipeline.confidence import circmean, direction_known_m, distance_sd, wrap
from workstation.pipeline.floors import FloorModel
from workstation.pipeline.heading import Heading
from workstation.pipeline.landmarks import Detections
from workstation.pipeline.pdr import ALIGN_STEPS, dead_reckon, gyro_offset
from workstation.pipeline.reach import Reach
from workstation.pipeline.steps import Steps
from workstation.pipeline.tracking.candidates import Candidate, CandidateScoring
from workstation.pipeline.tracking.state import Match, TrackerState, WalkToDetection, pressure_at
from workstation.rules import FLOOR_EXIT
from workstation.session import Scalar

SUM_CHUNK = 128  # steps summed ahead at a time per hypothesis (see Tracker._unit_sums)


class Tracker:
    """Dead reckoning from an anchor, candidate scoring and state updates, shared by the greedy
    pass (the paper) and the whole-walk association."""

    def __init__(
        self, steps: Steps, heading: Heading, det: Detections, reach: Reach,
        pressure: Scalar | None, p: PDRParams, t0: float,
    ) -> None:  # fmt: skip
        self.ts = steps.t
        n = self.ts.size
        self.det, self.reach, self.pressure, self.p, self.t0 = det, reach, pressure, p, t0
        self.hg = heading.at(self.ts, GYRO_HEADING) if n else np.empty(0)
        self.hc = heading.at(self.ts, COMPASS_HEADING) if n else np.empty(0)
        self.use_compass = bool(heading.compass.size and np.isfinite(heading.compass).any())
        self.first = int(np.searchsorted(self.ts, t0, side="right"))
        self.init = slice(self.first, min(self.first + ALIGN_STEPS, n))
        self.offset0 = (
            gyro_offset(self.hc[self.first :], self.hg[self.first :])
            if self.use_compass and n
            else 0.0
        )
        if p.heading_source == COMPASS_HEADING:
            self.hg = self.hc
            self.offset0 = 0.0
        self.floors_known = sorted({v[2] for v in reach.pos.values()}) or [0.0]
        self.p_det = pressure_at(pressure, det.t)
        self.p_det_start = pressure_at(pressure, det.t_start)
        self.det_step = np.searchsorted(self.ts, det.t, side="right")
        self._sums: dict[tuple, np.ndarray] = {}  # (anchor, step, offset) → running Σ exp(iθ)
        self._priors: dict[float, FloorModel] = {}  # start floor → floor model (frozen)
        self.scoring = CandidateScoring(
            det, reach, p, pressure, self.ts, self.hg, self.hc, self.use_compass
        )
        self.direction_known_m = direction_known_m(self.scoring.eps, p.confidence_threshold)

    def start(self, node: str) -> TrackerState:
        ax, ay, afl = self.reach.pos.get(node, (0.0, 0.0, 0.0))
        fm = self._priors.get(afl)  # one per floor: every landmark starts a chain when inferred
        if fm is None:
            p0 = float(pressure_at(self.pressure, [self.t0])[0])
            fm = self._priors[afl] = FloorModel.prior(
                self.floors_known, self.p.floor_hpa, p0, afl, self.reach.g.floor_levels_hpa()
            )
        return TrackerState(
            node, ax, ay, self.first, self.t0, fm, self.p.initial_step_length_m,
            self.p.step_length_sd_m**2, self.offset0, matches=(Match(-1, node, None, 0.0),),
        )  # fmt: skip

    def still_at_anchor(self, st: TrackerState, k: int) -> bool:
        """Detection k comes before any step since the chain's last match: the walker is still
        at that landmark — unless a floor change ends there (a lift ride takes no steps)."""
        return float(self.det.t[k]) <= st.a_t or (
            self.det_step[k] <= st.a_idx and self.det.kind[k] != FLOOR_EXIT
        )

    def walk(self, st: TrackerState, i_end: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        sl_ = slice(st.a_idx, i_end)
        theta = self.hg[sl_] + st.offset
        if self.p.snap_heading:
            theta = _snap(theta, self.reach.headings_from(st.node), self.scoring.eps)
        x, y = dead_reckon(st.ax, st.ay, st.length, theta)
        return x, y, theta

    def _unit_sums(self, st: TrackerState, i_end: int) -> tuple[float, float]:
        """Σ (cos θ, sin θ) over the steps from the anchor to ``i_end`` (eq. 7–8 without the
        step length). The association asks for it at every detection for every hypothesis, so
        the running sums from the anchor (same anchor and gyro offset) are kept for a stretch of
        ``SUM_CHUNK`` steps at a time and read off: re-summing from the anchor made it quadratic
        in the length of a stretch without matches, and summing per call cost more in numpy's
        per-call overhead than in the sums."""
        key = (st.node, st.a_idx, st.offset)
        cum = self._sums.get(key)  # Σ exp(iθ) from the anchor: cos in the real part, sin imaginary
        n = i_end - st.a_idx
        if cum is None or n >= cum.size:
            i0 = st.a_idx + (cum.size - 1 if cum is not None else 0)
            i1 = min(max(i_end, i0 + SUM_CHUNK), self.hg.size)
            theta = self.hg[i0:i1] + st.offset
            if self.p.snap_heading:
                theta = _snap(theta, self.reach.headings_from(st.node), self.scoring.eps)
            more = np.empty(theta.size + 1, complex)
            more[0] = cum[-1] if cum is not None else 0.0
            np.cumsum(np.exp(1j * theta), out=more[1:])
            more[1:] += more[0]
            cum = more if cum is None else np.concatenate([cum, more[1:]])
            self._sums[key] = cum
        c = cum[n]
        return c.real, c.imag

    def walk_to_detection(self, st: TrackerState, k: int, path: bool = False) -> WalkToDetection:
        """The walk from the anchor to detection k; ``path``: with the per-step positions."""
        i_end = int(self.det_step[k])
        n_s = i_end - st.a_idx
        px: np.ndarray | None
        py: np.ndarray | None
        theta: np.ndarray | None
        if path:
            px, py, theta = self.walk(st, i_end)
            ex, ey = (float(px[-1]), float(py[-1])) if n_s > 0 else (st.ax, st.ay)
        else:
            px = py = theta = None
            sc, ss = self._unit_sums(st, i_end) if n_s > 0 else (0.0, 0.0)
            ex, ey = st.ax + st.length * sc, st.ay + st.length * ss
        th_star = float(np.arctan2(ey - st.ay, ex - st.ax)) if n_s > 0 else np.nan
        return WalkToDetection(
            i_end, px, py, theta, ex, ey, max(n_s, 0) * st.length, th_star, float(self.p_det[k])
        )

    # ---- candidates ----------------------------------------------------------------------
    # ---- update --------------------------------------------------------------------------
    def advance(self, st: TrackerState, k: int, c: Candidate, w: WalkToDetection) -> TrackerState:
        """Snap to the matched landmark and recalibrate (eq. 10), the gyro offset and floors."""
        p, r = self.p, c.route
        vx, vy, vf = self.reach.pos[c.node]
        n_s = w.i_end - st.a_idx
        length, length_var, offset = st.length, st.length_var, st.offset
        level = r is not None and not r.floor_change
        if r is not None and level and n_s >= 3 and r.length >= p.min_calibration_m:
            length, length_var = fuse_step_length(length, length_var, r.length, n_s, p)
        if p.heading_source != COMPASS_HEADING and n_s >= 3:
            # along one edge: align the gyro with its heading
            if r is not None and level and r.edges == 1:
                tail = slice(st.a_idx + n_s // 3, w.i_end)
                if w.i_end - (st.a_idx + n_s // 3) >= 2:
                    offset = circmean(self.reach.edge_heading(st.node, r.node) - self.hg[tail])
            elif (r is None or (level and r.edges > 1)) and np.hypot(
                w.ex - st.ax, w.ey - st.ay
            ) >= self.direction_known_m:
                # several edges, or a relocalization: turn the walked displacement onto the true
                # one — when it is long enough for its direction to say more than the heading
                offset = float(
                    offset
                    + wrap(
                        np.arctan2(vy - st.ay, vx - st.ax) - np.arctan2(w.ey - st.ay, w.ex - st.ax)
                    )
                )
        fm = st.floors
        if r is not None and r.floor_change:
            fm = fm.learned(float(self.p_det_start[k]), fm.f_ref, w.p_now, vf)
        elif fm.nearest_floor(w.p_now) == vf:
            fm = fm.moved(w.p_now, vf)  # re-anchor eq. 9 where the pressure agrees
        return TrackerState(
            c.node, vx, vy, w.i_end, float(self.det.t[k]), fm, length, length_var, offset,
            st.score + c.score, st.matches + (Match(k, c.node, r, c.confidence),),
        )  # fmt: skip


def fuse_step_length(
    length: float, var: float, path_m: float, n_steps: int, p: PDRParams
) -> tuple[float, float]:
    """Eq. 10, weighed: the step length a matched level path of ``path_m`` over ``n_steps``
    steps measures, L_m = path / steps, fused with what the chain knew (``length`` ± √var) as a
    Kalman update, L ← L + K (L_m − L), K = var / (var + σ_m²), var ← (1 − K) var, with σ_m =
    σ_d(path) / steps the distance term's own σ (:func:`.confidence.distance_sd`: the landmarks'
    tolerance plus the step-length spread along the path: a match accepts a walked distance that
    far off, so its path length says no more). A short path nudges the length, paths add up; a
    wrong match, or a path walked well off the graph's line, no longer resets it outright (on
    mall walks one short wrong match took the length 0.63 → 1.0 m). ``pdr.step_length_sd_m`` = 0
    is eq. 10 as printed: each calibration replaces the length. Clamped to [min, max] as before.
    """
    measured = path_m / n_steps
    if p.step_length_sd_m <= 0:
        length, var = measured, 0.0
    else:
        var_m = (distance_sd(path_m, p.confidence_threshold, p.step_length_cv) / n_steps) ** 2
        gain = var / (var + var_m)
        length, var = length + gain * (measured - length), (1.0 - gain) * var
    return float(np.clip(length, p.min_step_length_m, p.max_step_length_m)), var


def _snap(theta: np.ndarray, headings: np.ndarray, eps: float) -> np.ndarray:
    """Each θ moved onto the nearest of ``headings`` (sorted, in [−π, π]) when within ``eps``
    (eq. 7–8's snapping). The nearest is one of the two headings either side of θ wrapped,
    found by bisection (the two ends are neighbours across ±π): O(n log m), not the n × m
    table of every difference (4× faster on a tap graph's ~50 headings)."""
    if headings.size == 0 or theta.size == 0:
        return theta
    i = np.searchsorted(headings, (theta + np.pi) % (2 * np.pi) - np.pi)
    m = headings.size
    d_lo = (headings[(i - 1) % m] - theta + np.pi) % (2 * np.pi) - np.pi  # edge − θ, wrapped
    d_hi = (headings[i % m] - theta + np.pi) % (2 * np.pi) - np.pi
    dk = np.where(np.abs(d_hi) < np.abs(d_lo), d_hi, d_lo)
    return np.where(np.abs(dk) < eps, theta + dk, theta)
