"""Landmark-graph PDR (§III-B, eq. 7–14).

Between landmarks: x += l cos θ, y += l sin θ (eq. 7–8) per step, the floor from pressure
(eq. 9, with the building's own floor spacings: :mod:`.floors`). The heading θ is the sensor
heading (gyro, offset-aligned to the graph at each match, or the compass) snapped to the heading
of a graph edge leaving the last landmark when within ε_θ. At each detection the candidates are
the landmarks met next after the last matched one (:mod:`.reach`); at a match the position snaps
to the landmark and the step length is recalibrated as path length / steps (eq. 10).

Which detection is which landmark is decided by :mod:`.association`: ``greedy`` matches each
detection as it comes by the paper's confidence (eq. 11–14); ``hmm`` (the default) keeps the
association hypotheses that best explain the whole walk. docs/decisions.md lists every choice
beyond the paper.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from ..graph import LandmarkGraph
from ..params import PDRParams
from ..session import Scalar
from ..session.model import sample_path
from .confidence import confidence, distance_sd, gaussian_ll, heading_sd, wrap
from .floors import FloorModel
from .heading import Heading
from .landmarks import Detections
from .reach import Reach, Route
from .start import find_start_time
from .steps import Steps

# σ of the compass heading per leg on real phones (median error 4.5-6°, p90 14-17°, per-walk
# bias up to 25°): loose on purpose
COMPASS_SD = np.radians(30.0)
# an inferred start is reported ambiguous against chains starting further away than this
ALTERNATIVE_START_M = 5.0
# pressure change allowed on one floor between matches: noise of a 1-s mean and door drafts
# (0.014 hPa on the museum walks, 0.05 with drafts) plus weather drift (up to 0.065 hPa/min)
LEVEL_SD_HPA = 0.08
DRIFT_HPA_PER_MIN = 0.1

__all__ = ["Track", "circmean", "find_start_time", "track", "wrap"]


def circmean(a) -> float:
    a = np.asarray(a, float)
    a = a[np.isfinite(a)]
    return float(math.atan2(np.sin(a).sum(), np.cos(a).sum())) if a.size else 0.0


@dataclass(frozen=True)
class Track:
    """The corrected trajectory (one row per step) and what the tracker decided."""

    t: np.ndarray
    x: np.ndarray  # forward, as the paper: snapped at each matched landmark
    y: np.ndarray
    floor: np.ndarray
    heading: np.ndarray
    step_length: np.ndarray
    segment: np.ndarray  # segment index per step (-1 = before the walk starts)
    x_bc: np.ndarray  # backward-corrected: each closed segment bent to end on its landmark
    y_bc: np.ndarray
    raw_x: np.ndarray  # plain PDR from the start landmark (no graph after the start)
    raw_y: np.ndarray
    # per detection
    det_node: np.ndarray  # matched node id or ""
    det_confidence: np.ndarray  # best candidate's confidence, eq. 11–14 (0 if none)
    det_candidate: np.ndarray  # best candidate's node id (matched or not) or ""
    det_reason: np.ndarray  # why not matched ("" when matched)
    # per segment
    seg_from: np.ndarray
    seg_to: np.ndarray  # "" for the open last segment
    seg_t0: np.ndarray
    seg_t1: np.ndarray
    seg_missed: np.ndarray  # landmarks with a rule the matched path passed undetected (−1: lost)
    start_node: str
    start_time: float
    floor_gaps_hpa: dict  # {"f0→f1": hPa} spacing of neighbouring floors at the end of the walk
    # an inferred start: the best chain from a start elsewhere (another floor or > 5 m away),
    # and how much less likely it is (log-likelihood); "" / nan when the start was given
    start_alternative: str = ""
    start_margin: float = float("nan")

    @property
    def matched(self) -> np.ndarray:
        return self.det_node != ""

    def position_at(self, t, corrected: bool = False):
        """x, y, floor at times ``t`` (linear between steps, eq. 19–20)."""
        x, y = (self.x_bc, self.y_bc) if corrected else (self.x, self.y)
        return sample_path(self.t, x, y, self.floor, t)


def track(
    steps: Steps,
    heading: Heading,
    detections: Detections,
    graph: LandmarkGraph,
    pressure: Scalar | None,
    p: PDRParams,
    start_node: str | None = None,
    start_time: float | None = None,
    _reach: Reach | None = None,
) -> Track:
    """Run the landmark-graph PDR from ``start_node`` (or ``p.start_node``; inferred if neither)."""
    from .association import associate

    start_node = start_node or p.start_node
    t0 = find_start_time(steps, p) if start_time is None else start_time
    reach = _reach or Reach(graph, p.max_hops)
    trk = _Tracker(steps, heading, detections, reach, pressure, p, t0)
    from .replay import replay

    if not graph.nodes:  # no landmarks yet: plain PDR from the origin
        return replay(trk, trk.start(""), ())
    if start_node and start_node not in reach.pos:
        from ..errors import GraphError

        raise GraphError(f"start node {start_node}: not in the landmark graph")
    starts = [start_node] if start_node else list(graph.ids)
    ranked = associate(trk, starts)
    best = ranked[0]
    out = replay(trk, trk.start(best.matches[0].node), best.matches[1:])
    if len(starts) > 1:
        alt = _alternative_start(reach, ranked)
        out = replace(out, start_alternative=alt.matches[0].node if alt else "",
                      start_margin=round(best.score - alt.score, 2) if alt else float("inf"))  # fmt: skip
    return out


def _alternative_start(reach: Reach, ranked: list[_State]) -> _State | None:
    """The best surviving chain that starts somewhere else: another floor, or more than
    ``ALTERNATIVE_START_M`` from the chosen start."""
    x0, y0, f0 = reach.pos[ranked[0].matches[0].node]
    for st in ranked[1:]:
        x, y, f = reach.pos[st.matches[0].node]
        if f != f0 or math.hypot(x - x0, y - y0) > ALTERNATIVE_START_M:
            return st
    return None


def _pressure_at(pressure: Scalar | None, t) -> np.ndarray:
    if pressure is None or len(pressure) == 0:
        return np.zeros(np.size(t))
    return np.interp(t, pressure.t, pressure.value)


class Match(NamedTuple):
    k: int  # detection index (-1 for the start)
    node: str
    route: Route | None  # None: the start, or a relocalization (no route)
    confidence: float  # eq. 11–14


@dataclass(frozen=True)
class _State:
    """Where the tracker stands: the last matched landmark (the anchor) and what it has learnt."""

    node: str
    ax: float
    ay: float
    a_idx: int  # first step after the anchor
    a_t: float
    floors: FloorModel
    length: float  # step length (eq. 10)
    offset: float  # gyro heading offset
    score: float = 0.0
    matches: tuple[Match, ...] = ()


@dataclass(frozen=True)
class _Walk:
    """The steps from the anchor to a detection, walked with the state's model (eq. 7–8)."""

    i_end: int
    px: np.ndarray | None  # per step (only when asked for: the replay)
    py: np.ndarray | None
    theta: np.ndarray | None
    ex: float
    ey: float
    d_star: float
    th_star: float
    p_now: float  # pressure at the detection


class Candidate(NamedTuple):
    node: str
    route: Route | None  # None: relocalization
    confidence: float  # eq. 11–14
    score: float  # log-likelihood gain of matching (hmm association)


class _Tracker:
    """Dead reckoning from an anchor, candidate scoring and state updates, shared by the greedy
    pass (the paper) and the whole-walk association."""

    def __init__(
        self, steps, heading, det: Detections, reach: Reach, pressure, p: PDRParams, t0: float
    ):
        self.ts = steps.t
        n = self.ts.size
        self.det, self.reach, self.pressure, self.p, self.t0 = det, reach, pressure, p, t0
        self.eps = np.radians(p.heading_threshold_deg)
        self.hg = heading.at(self.ts, "gyro") if n else np.empty(0)
        self.hc = heading.at(self.ts, "compass") if n else np.empty(0)
        self.use_compass = bool(heading.compass.size and np.isfinite(heading.compass).any())
        self.first = int(np.searchsorted(self.ts, t0, side="right"))
        self.init = slice(self.first, min(self.first + 15, n))
        self.offset0 = (
            circmean(self.hc[self.init] - self.hg[self.init]) if self.use_compass and n else 0.0
        )
        if p.heading_source == "compass":
            self.hg = self.hc
            self.offset0 = 0.0
        self.floors_known = sorted({v[2] for v in reach.pos.values()}) or [0.0]
        self.p_det = _pressure_at(pressure, det.t)
        self.p_det_start = _pressure_at(pressure, det.t_start)
        self.det_step = np.searchsorted(self.ts, det.t, side="right")
        self.det_step_start = np.searchsorted(self.ts, det.t_start, side="right")
        self._sums: dict[tuple, tuple[int, float, float]] = {}
        self._fitting: dict[tuple[str, str], list[Route]] = {}

    def start(self, node: str) -> _State:
        ax, ay, afl = self.reach.pos.get(node, (0.0, 0.0, 0.0))
        p0 = float(_pressure_at(self.pressure, [self.t0])[0])
        fm = FloorModel.prior(
            self.floors_known, self.p.floor_hpa, p0, afl, self.reach.g.floor_levels_hpa()
        )
        return _State(
            node, ax, ay, self.first, self.t0, fm, self.p.initial_step_length_m, self.offset0,
            matches=(Match(-1, node, None, 0.0),),
        )  # fmt: skip

    def still_at_anchor(self, st: _State, k: int) -> bool:
        """Detection k comes before any step since the chain's last match: the walker is still
        at that landmark — unless a floor change ends there (a lift ride takes no steps)."""
        return float(self.det.t[k]) <= st.a_t or (
            self.det_step[k] <= st.a_idx and self.det.kind[k] != "baro_exit"
        )

    def walk(self, st: _State, i_end: int):
        sl_ = slice(st.a_idx, i_end)
        theta = self.hg[sl_] + st.offset
        if self.p.snap_heading:
            theta = _snap(theta, self.reach.edge_headings.get(st.node, np.empty(0)), self.eps)
        return (
            st.ax + np.cumsum(st.length * np.cos(theta)),
            st.ay + np.cumsum(st.length * np.sin(theta)),
            theta,
        )

    def _unit_sums(self, st: _State, i_end: int) -> tuple[float, float]:
        """Σ (cos θ, sin θ) over the steps from the anchor to ``i_end`` (eq. 7–8 without the
        step length), extended from the last sum taken for the same anchor and gyro offset:
        the association asks for it at every detection, and re-summing from the anchor each
        time made it quadratic in the length of a stretch without matches."""
        key = (st.node, st.a_idx, st.offset)
        i0, sc, ss = self._sums.get(key, (st.a_idx, 0.0, 0.0))
        if i_end < i0:
            i0, sc, ss = st.a_idx, 0.0, 0.0
        if i_end > i0:
            theta = self.hg[i0:i_end] + st.offset
            if self.p.snap_heading:
                theta = _snap(theta, self.reach.edge_headings.get(st.node, np.empty(0)), self.eps)
            sc, ss = sc + float(np.cos(theta).sum()), ss + float(np.sin(theta).sum())
            self._sums[key] = (i_end, sc, ss)
        return sc, ss

    def walk_to_detection(self, st: _State, k: int, path: bool = False) -> _Walk:
        """The walk from the anchor to detection k; ``path``: with the per-step positions."""
        i_end = int(self.det_step[k])
        n_s = i_end - st.a_idx
        if path:
            px, py, theta = self.walk(st, i_end)
            ex, ey = (float(px[-1]), float(py[-1])) if n_s > 0 else (st.ax, st.ay)
        else:
            px = py = theta = None
            sc, ss = self._unit_sums(st, i_end) if n_s > 0 else (0.0, 0.0)
            ex, ey = st.ax + st.length * sc, st.ay + st.length * ss
        th_star = float(np.arctan2(ey - st.ay, ex - st.ax)) if n_s > 0 else np.nan
        return _Walk(
            i_end, px, py, theta, ex, ey, max(n_s, 0) * st.length, th_star, float(self.p_det[k])
        )

    # ---- candidates ----------------------------------------------------------------------
    def _routes_for(self, node: str, kind: str) -> list[Route]:
        """The routes from ``node`` whose landmark can be the detection's: it carries the rule,
        and an entry starts a floor change at a landmark on this floor, an exit ends one."""
        key = (node, kind)
        out = self._fitting.get(key)
        if out is None:
            out = self._fitting[key] = [
                r for r in self.reach.routes.get(node, [])
                if kind in self.reach.rules[r.node]
                and not ((kind == "baro_entry" and r.floor_change)
                         or (kind == "baro_exit" and not r.floor_change))
            ]  # fmt: skip
        return out

    def _level_steps(self, st: _State, k: int) -> int:
        """Steps walked before the floor change that ends at detection k began."""
        return max(int(self.det_step_start[k]) - st.a_idx, 0)

    def candidates(self, st: _State, k: int, w: _Walk) -> tuple[list[Candidate], str]:
        """The landmarks detection k may be, best first, and why none fits when the list is empty.

        Each gets the paper's confidence (eq. 11–14) and a log-likelihood gain: distance walked
        against the path length, direction walked against the direction to the landmark,
        pressure change against the floors' spacing, detections missed on the way."""
        p, reach = self.p, self.reach
        ax, ay = st.ax, st.ay
        fm = st.floors
        f_now = fm.nearest_floor(w.p_now)
        out: list[Candidate] = []
        why = "no landmark with this rule within reach"
        walk_parts: dict = {}  # what the compass term needs of this walk, computed once
        for r in self._routes_for(st.node, str(self.det.kind[k])):
            vx, vy, vf = reach.pos[r.node]
            if r.floor_change:
                ll_f = fm.change_loglik(w.p_now - fm.p_ref, fm.f_ref, vf)
                if ll_f < -4.5:
                    why = f"{r.node}: floor {vf:g} not reached"
                    continue
                if self.det.kind[k] in ("baro_entry", "baro_exit"):
                    # the level part of the path against the steps before the floor change began
                    level = r.length - r.climb_length
                    excess = self._level_steps(st, k) * st.length - level
                    sd = distance_sd(level, p.confidence_threshold, p.step_length_cv)
                else:  # a turn or stop after the stairs: stair steps are shorter, widen σ
                    level = r.length
                    excess = w.d_star - level
                    sd = distance_sd(level, p.confidence_threshold, 2 * p.step_length_cv)
                ll = ll_f + gaussian_ll(excess, sd)
                conf = confidence(level, level + excess, True, p.min_distance_m)
            else:
                if f_now != vf:
                    why = f"{r.node}: on another floor"
                    continue
                heading_ok, ll_h = True, 0.0
                span = math.hypot(vx - ax, vy - ay)
                walked = math.hypot(w.ex - ax, w.ey - ay)
                if span >= 1.0 and walked >= 1.0 and np.isfinite(w.th_star):
                    dth = (math.atan2(vy - ay, vx - ax) - w.th_star + math.pi) % (
                        2 * math.pi
                    ) - math.pi
                    heading_ok = abs(dth) < self.eps  # eq. 13
                    ll_h = gaussian_ll(dth, heading_sd(self.eps, span, p.confidence_threshold))
                    if not heading_ok and not out:
                        why = f"{r.node}: heading off by {np.degrees(abs(dth)):.0f}°"
                sd = distance_sd(r.length, p.confidence_threshold, p.step_length_cv)
                ll = ll_h + gaussian_ll(w.d_star - r.length, sd)
                ll += self._compass_ll(st, r, w, walk_parts)
                if "level" not in walk_parts:
                    walk_parts["level"] = self._level_ll(st, k, w)
                ll += walk_parts["level"]
                conf = confidence(
                    r.length, w.d_star, heading_ok, p.min_distance_m, p.distance_slack
                )
                if r.missed and w.d_star < r.missed_at - 2 * sd:
                    continue  # not yet past the landmark it would have missed
            if ll < -4.5:
                if not out:
                    why = f"{r.node}: does not fit what was walked"
                continue
            out.append(Candidate(r.node, r, conf, p.match_gain + ll - p.miss_cost * r.missed))
        if self.det.kind[k] == "baro_entry" and "baro_entry" in reach.rules.get(st.node, ()):
            # a floor change starting at the landmark just matched
            sd = distance_sd(0.0, p.confidence_threshold, p.step_length_cv)
            ll = gaussian_ll(w.d_star, sd)
            if ll > -4.5:
                r0 = Route(st.node, 0.0, False, (st.node,), 0.0, 0, 0.0)
                conf = confidence(0.0, w.d_star, True, p.min_distance_m)
                out.append(Candidate(st.node, r0, conf, p.match_gain + ll))
        if w.d_star > p.relocalize_after_m:
            out += self._relocalize(st, k, w, f_now, {c.node for c in out})
        out.sort(key=lambda c: -c.score)
        return out, why

    def _level_ll(self, st: _State, k: int, w: _Walk) -> float:
        """A same-floor match against the pressure change since the anchor: it should be no
        more than noise and weather drift. Without it a hypothesis could stay on its floor
        through a stair or an elevator ride it chose not to match."""
        if self.pressure is None or not np.isfinite(w.p_now):
            return 0.0
        minutes = max(float(self.det.t[k]) - st.a_t, 0.0) / 60.0
        sd = math.hypot(LEVEL_SD_HPA, DRIFT_HPA_PER_MIN * minutes)
        return gaussian_ll(w.p_now - st.floors.p_ref, sd)

    def _compass_ll(self, st: _State, r: Route, w: _Walk, cache: dict) -> float:
        """Along one edge, the gyro offset the edge implies against the compass's: the only
        absolute heading there is, so it tells mirror-image routes apart. Magnetic
        disturbances make it heavy-tailed: σ = ``COMPASS_SD`` and the penalty capped.

        The implied offset is circmean(h_edge − g) = h_edge − circmean(g) over the last two
        thirds of the walk, so the walk's part (``cache``) is computed once for all routes."""
        if not self.use_compass or len(r.path) != 2 or w.i_end - st.a_idx < 6:
            return 0.0
        if "g" not in cache:
            tail = slice(st.a_idx + (w.i_end - st.a_idx) // 3, w.i_end)
            g = self.hg[tail]
            cache["g"] = circmean(g) + circmean(self.hc[tail] - g)  # mean gyro + compass offset
        implied_minus_compass = self.reach.first_edge_heading(r) - cache["g"]
        return max(gaussian_ll(float(wrap(implied_minus_compass)), COMPASS_SD), -3.0)

    def _relocalize(self, st: _State, k: int, w: _Walk, f_now: float, seen) -> list[Candidate]:
        """Recovery after a long stretch without a match: every landmark with the detected rule
        on this floor, scored by where the whole path since the last match ends."""
        p, out = self.p, []
        kind = self.det.kind[k]
        sd = distance_sd(w.d_star, p.confidence_threshold, 2 * p.step_length_cv)
        for v, (vx, vy, vf) in self.reach.pos.items():
            if v in seen or v == st.node or vf != f_now or kind not in self.reach.rules[v]:
                continue
            if kind in ("baro_entry", "baro_exit"):
                continue  # a floor change needs its route
            ll = gaussian_ll(math.hypot(vx - w.ex, vy - w.ey), sd)
            if ll > -4.5:
                out.append(Candidate(v, None, 0.0, p.match_gain + ll - p.relocalize_cost))
        return out

    def paper_choice(self, cands: list[Candidate]) -> Candidate | None:
        """The paper's greedy rule: the most confident candidate above ε_v, nearest tier first."""
        ok = [c for c in cands if c.confidence > self.p.confidence_threshold or c.route is None]
        if not ok:
            return None
        tier = min(c.route.missed if c.route else 99 for c in ok)
        ok = [c for c in ok if (c.route.missed if c.route else 99) == tier] or ok
        return max(ok, key=lambda c: (c.confidence, c.score))

    # ---- update --------------------------------------------------------------------------
    def advance(self, st: _State, k: int, c: Candidate, w: _Walk) -> _State:
        """Snap to the matched landmark and recalibrate (eq. 10), the gyro offset and floors."""
        p, r = self.p, c.route
        vx, vy, vf = self.reach.pos[c.node]
        n_s = w.i_end - st.a_idx
        length, offset = st.length, st.offset
        level = r is not None and not r.floor_change
        if level and n_s >= 3 and r.length >= p.min_calibration_m:
            length = float(np.clip(r.length / n_s, p.min_step_length_m, p.max_step_length_m))
        if p.heading_source != "compass" and n_s >= 3:
            if level and len(r.path) == 2:  # along one edge: align the gyro with its heading
                tail = slice(st.a_idx + n_s // 3, w.i_end)
                if w.i_end - (st.a_idx + n_s // 3) >= 2:
                    offset = circmean(self.reach.first_edge_heading(r) - self.hg[tail])
            elif (r is None or (level and len(r.path) > 2)) and np.hypot(
                w.ex - st.ax, w.ey - st.ay
            ) > 1.0:
                # several edges, or a relocalization: turn the walked displacement onto the true one
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
        return _State(
            c.node, vx, vy, w.i_end, float(self.det.t[k]), fm, length, offset,
            st.score + c.score, st.matches + (Match(k, c.node, r, c.confidence),),
        )  # fmt: skip


def _snap(theta: np.ndarray, headings: np.ndarray, eps: float) -> np.ndarray:
    if headings.size == 0 or theta.size == 0:
        return theta
    diff = np.abs(wrap(theta[:, None] - headings[None, :]))
    k = np.argmin(diff, axis=1)
    best = diff[np.arange(theta.size), k]
    snapped = theta + wrap(headings[k] - theta)
    return np.where(best < eps, snapped, theta)
