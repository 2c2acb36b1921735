"""The candidates of a detection and their scores (§III-B, eq. 11–14, and the likelihood terms
of the whole-walk association): a mixin of the tracker (:mod:`.tracking`), which holds the
detections, the routes (:mod:`.reach`), the headings and the pressure it reads.

- the landmarks a detection may be: reached by a route from the last match whose landmark
  carries the detected rule (an entry starts a floor change, an exit ends one);
- each scored by the paper's confidence (eq. 11–14) and a log-likelihood: the distance walked
  against the path length, the direction walked against the direction to the landmark, the
  pressure change against the floors' spacing, the compass against the offset an edge implies,
  minus a cost per detectable landmark passed without a detection;
- after a long stretch without a match, every landmark with the detected rule on the floor
  (recovery), scored by where the whole path since the last match ends.
"""

from __future__ import annotations

import math
from bisect import bisect_left, bisect_right
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from workstation.pipeline.confidence import (
    LL_3SD,
    circmean,
    confidence,
    distance_sd,
    distance_window,
    gaussian_ll,
    heading_sd,
    wrap1,
)
from workstation.pipeline.reach import Reach, Route
from workstation.rules import FLOOR_CHANGE, FLOOR_ENTRY, FLOOR_EXIT, TURN

if TYPE_CHECKING:
    from workstation.params import PDRParams
    from workstation.pipeline.landmarks import Detections
    from workstation.pipeline.tracking.state import TrackerState, WalkToDetection
    from workstation.session import Scalar

# σ of the compass heading per leg on real phones (median error 4.5-6°, p90 14-17°, per-walk
# bias up to 25°): loose on purpose
COMPASS_SD = np.radians(30.0)
# pressure change allowed on one floor between matches: noise of a 1-s mean and door drafts
# (0.014 hPa on the museum walks, 0.05 with drafts) plus weather drift (up to 0.065 hPa/min)
LEVEL_SD_HPA = 0.08
# a turn landmark is where the walk leaves along one of the landmark's edges: the direction
# walked in the few seconds after the turn, as a likelihood ratio against no knowledge
EXIT_SD = np.radians(30.0)
EXIT_OUTLIER = 0.1  # share of turns that leave where no edge goes (a graph lacks one; a sway)
EXIT_AFTER_S = (0.3, 3.0)  # the steps that far after the turn ends give the way out
DRIFT_HPA_PER_MIN = 0.1


class Candidate(NamedTuple):
    node: str
    route: Route | None  # None: relocalization
    confidence: float  # eq. 11–14
    score: float  # log-likelihood gain of matching (hmm association)


class _Terms(NamedTuple):
    """A route's part of a candidate's score that the walk does not change."""

    route: Route
    floor: float  # the landmark's
    level: float  # path length compared with the distance walked
    sd: float  # σ of that distance
    span: float  # straight-line distance from the anchor
    direction: float  # from the anchor to the landmark (rad)
    heading_sd: float  # σ of the direction walked against it


class _Fitting(NamedTuple):
    """The routes from one anchor whose landmark can be one kind of detection, in the order of
    :class:`.reach.Reach` (fewest missed, then shortest), and how to find the level ones whose
    length fits a distance walked without scoring the rest."""

    terms: list[_Terms]
    changes: list[int]  # indices of the floor-changing routes (always scored)
    tiers: list[tuple[list[float], list[int]]]  # per missed count: level routes' lengths, indices

    def fitting(self, lo: float, hi: float) -> list[int]:
        """Indices of the floor-changing routes and of the level ones of length in [lo, hi],
        in route order."""
        sel = list(self.changes)
        for lengths, idx in self.tiers:
            sel += idx[bisect_left(lengths, lo) : bisect_right(lengths, hi)]
        if len(self.tiers) > 1 or self.changes:
            sel.sort()
        return sel


class CandidateScoring:
    """Candidate scoring over what the tracker knows of one walk: its detections, the routes of
    the graph, the parameters, the headings per step and the pressure. The tracker holds one
    (composition: nothing here reads the tracker) and the caches are this walk's."""

    def __init__(
        self,
        det: Detections,
        reach: Reach,
        p: PDRParams,
        pressure: Scalar | None,
        ts: np.ndarray,
        hg: np.ndarray,
        hc: np.ndarray,
        use_compass: bool,
    ):
        self.det, self.reach, self.p, self.pressure = det, reach, p, pressure
        self.ts, self.hg, self.hc, self.use_compass = ts, hg, hc, use_compass
        self.eps = float(np.radians(p.heading_threshold_deg))
        self.det_step_start = np.searchsorted(ts, det.t_start, side="right")
        # (anchor, rule) → routes' terms: walk-free, so kept with the routes for the next walk
        self._fitting: dict[tuple[str, str], _Fitting] = reach.memo.setdefault(
            ("fitting", p.confidence_threshold, p.step_length_cv, self.eps), {}
        )
        self._rule_nodes_cache: dict[
            tuple[str, float], tuple[list[str], np.ndarray, np.ndarray]
        ] = {}
        self._after: np.ndarray | None = None  # per detection, the heading after the turn
        self._exit_cache: dict[str, np.ndarray] = {}  # landmark → headings of its ways out

    def _routes_for(self, node: str, kind: str) -> _Fitting:
        """The routes from ``node`` whose landmark can be the detection's — it carries the rule,
        and an entry starts a floor change at a landmark on this floor, an exit ends one — with
        what each candidate's score needs that does not depend on the walk (the anchor is
        always the landmark ``node`` itself)."""
        key = (node, kind)
        hit = self._fitting.get(key)
        if hit is None:
            p, reach = self.p, self.reach
            ax, ay, _ = reach.pos.get(node, (0.0, 0.0, 0.0))
            out: list[_Terms] = []
            for r in reach.routes_from(node):
                if kind not in reach.rules[r.node] or (
                    (kind == FLOOR_ENTRY and r.floor_change)
                    or (kind == FLOOR_EXIT and not r.floor_change)
                ):
                    continue
                vx, vy, vf = reach.pos[r.node]
                span = math.hypot(vx - ax, vy - ay)
                if r.floor_change and kind in FLOOR_CHANGE:
                    level = r.length - r.climb_length  # the part before the floor change
                    sd = distance_sd(level, p.confidence_threshold, p.step_length_cv)
                elif r.floor_change:  # a turn or stop after the stairs: stair steps are shorter
                    level = r.length
                    sd = distance_sd(level, p.confidence_threshold, 2 * p.step_length_cv)
                else:
                    level = r.length
                    sd = distance_sd(level, p.confidence_threshold, p.step_length_cv)
                out.append(_Terms(
                    r, vf, level, sd, span, math.atan2(vy - ay, vx - ax),
                    heading_sd(self.eps, span, p.confidence_threshold),
                ))  # fmt: skip
            tiers: dict[int, tuple[list[float], list[int]]] = {}
            for i, t in enumerate(out):  # level routes: by length within a missed count
                if not t.route.floor_change:
                    lengths, idx = tiers.setdefault(t.route.missed, ([], []))
                    lengths.append(t.route.length)
                    idx.append(i)
            changes = [i for i, t in enumerate(out) if t.route.floor_change]
            hit = self._fitting[key] = _Fitting(out, changes, list(tiers.values()))
        return hit

    def _level_steps(self, st: TrackerState, k: int) -> int:
        """Steps walked before the floor change that ends at detection k began."""
        return max(int(self.det_step_start[k]) - st.a_idx, 0)

    def candidates(
        self, st: TrackerState, k: int, w: WalkToDetection
    ) -> tuple[list[Candidate], str]:
        """The landmarks detection k may be, best first, and why none fits when the list is empty.

        Each gets the paper's confidence (eq. 11–14) and a log-likelihood gain: distance walked
        against the path length, direction walked against the direction to the landmark,
        pressure change against the floors' spacing, detections missed on the way."""
        p, reach = self.p, self.reach
        ax, ay = st.ax, st.ay
        fm = st.floors
        f_now = fm.nearest_floor(w.p_now)
        out: list[Candidate] = []
        walk_parts: dict = {}  # what the compass term needs of this walk, computed once
        kind = str(self.det.kind[k])
        baro = kind in FLOOR_CHANGE
        walked = math.hypot(w.ex - ax, w.ey - ay)
        heading_known = walked >= 1.0 and math.isfinite(w.th_star)
        fit = self._routes_for(st.node, kind)
        lo, hi = distance_window(w.d_star, p.confidence_threshold, p.step_length_cv)
        for i in fit.fitting(lo, hi):  # a level route of another length fails its distance term
            r, vf, level, sd, span, direction, h_sd = fit.terms[i]
            if r.floor_change:
                ll_f = fm.change_loglik(w.p_now - fm.p_ref, fm.f_ref, vf)
                if ll_f < LL_3SD:
                    continue
                if baro:  # the level part of the path against the steps before the change began
                    excess = self._level_steps(st, k) * st.length - level
                else:
                    excess = w.d_star - level
                ll = ll_f + gaussian_ll(excess, sd)
                conf = confidence(level, level + excess, True, p.min_distance_m)
            else:
                if f_now != vf or (r.missed and w.d_star < r.missed_at - 2 * sd):
                    continue  # another floor, or not yet past the landmark it would have missed
                ll, conf = self._level_route(st, k, w, fit.terms[i], heading_known, walk_parts)
            if ll < LL_3SD:
                continue
            out.append(Candidate(r.node, r, conf, p.match_gain + ll - p.miss_cost * r.missed))
        if kind == FLOOR_ENTRY and FLOOR_ENTRY in reach.rules.get(st.node, ()):
            # a floor change starting at the landmark just matched
            sd = distance_sd(0.0, p.confidence_threshold, p.step_length_cv)
            ll = gaussian_ll(w.d_star, sd)
            if ll > LL_3SD:
                r0 = Route(st.node, 0.0, False, 0, 0.0, 0, 0.0)
                conf = confidence(0.0, w.d_star, True, p.min_distance_m)
                out.append(Candidate(st.node, r0, conf, p.match_gain + ll))
        if w.d_star > p.relocalize_after_m:
            out += self._relocalize(st, k, w, f_now, {c.node for c in out})
        out.sort(key=lambda c: -c.score)
        return out, ("" if out else self._why_none(st, w, fit.terms, f_now, heading_known))

    def _level_route(self, st: TrackerState, k: int, w: WalkToDetection, terms: _Terms,
                     heading_known: bool, walk_parts: dict) -> tuple[float, float]:  # fmt: skip
        """A route on this floor: its log-likelihood (distance, direction, and when those fit
        the compass, the pressure and the way out of a turn) and the paper's confidence."""
        p = self.p
        r, _, _, sd, span, direction, h_sd = terms
        heading_ok, ll_h = True, 0.0
        if span >= 1.0 and heading_known:
            dth = wrap1(direction - w.th_star)
            heading_ok = abs(dth) < self.eps  # eq. 13
            ll_h = gaussian_ll(dth, h_sd)
        ll = ll_h + gaussian_ll(w.d_star - r.length, sd)
        if ll >= LL_3SD:  # the compass and pressure terms are ≤ 0: only then are they needed
            ll += self._compass_ll(st, r, w, walk_parts)
            if "level" not in walk_parts:
                walk_parts["level"] = self._level_ll(st, k, w)
            ll += walk_parts["level"]
            if str(self.det.kind[k]) == TURN and p.turn_exits:
                ll += self._exit_ll(st, k, r.node)
        conf = confidence(r.length, w.d_star, heading_ok, p.min_distance_m, p.distance_slack)
        return ll, conf

    def _why_none(
        self, st: TrackerState, w: WalkToDetection, terms: list[_Terms], f_now: float,
        heading_known: bool,
    ) -> str:  # fmt: skip
        """Why no route fits: what failed on the last route in order (the association scores
        routes in that order, and a level route's last test is its distance)."""
        fm = st.floors
        for r, vf, _, sd, span, direction, _ in reversed(terms):
            if r.floor_change:
                if fm.change_loglik(w.p_now - fm.p_ref, fm.f_ref, vf) < LL_3SD:
                    return f"{r.node}: floor {vf:g} not reached"
                return f"{r.node}: does not fit what was walked"
            if f_now != vf:
                return f"{r.node}: on another floor"
            if not (r.missed and w.d_star < r.missed_at - 2 * sd):
                return f"{r.node}: does not fit what was walked"
            if span >= 1.0 and heading_known:  # not yet past a landmark it would have missed
                dth = wrap1(direction - w.th_star)
                if not abs(dth) < self.eps:
                    return f"{r.node}: heading off by {math.degrees(abs(dth)):.0f}°"
        return "no landmark with this rule within reach"

    def _level_ll(self, st: TrackerState, k: int, w: WalkToDetection) -> float:
        """A same-floor match against the pressure change since the anchor: it should be no
        more than noise and weather drift. Without it a hypothesis could stay on its floor
        through a stair or an elevator ride it chose not to match."""
        if self.pressure is None or not np.isfinite(w.p_now):
            return 0.0
        minutes = max(float(self.det.t[k]) - st.a_t, 0.0) / 60.0
        sd = math.hypot(LEVEL_SD_HPA, DRIFT_HPA_PER_MIN * minutes)
        return gaussian_ll(w.p_now - st.floors.p_ref, sd)

    def _exit_ll(self, st: TrackerState, k: int, node: str) -> float:
        """A turn at ``node``: log p(h | its ways out) − log p(h | nothing known), h the
        direction walked just after the turn (the gyro with this chain's offset); p(h | ways
        out) a mixture of a normal (σ ``EXIT_SD``) about each level edge leaving the landmark
        and a uniform share ``EXIT_OUTLIER``. 0 where nothing is known (stairs or a lift leave
        the landmark: a flight's straight line is not how a switchback is walked, a lift has no
        direction), positive where the walk left along an edge, negative where no edge goes."""
        h = self._after_turn()[k]
        outs = self._exits(node)
        if not math.isfinite(h) or outs.size == 0:
            return 0.0
        d = np.angle(np.exp(1j * (h + st.offset - outs)))
        dens = np.exp(-0.5 * (d / EXIT_SD) ** 2) / (math.sqrt(2 * math.pi) * EXIT_SD)
        p = (1 - EXIT_OUTLIER) * float(dens.mean()) + EXIT_OUTLIER / (2 * math.pi)
        return math.log(p * 2 * math.pi)

    def _after_turn(self) -> np.ndarray:
        """Per detection, the circular mean gyro heading over the steps ``EXIT_AFTER_S`` after it
        ends (NaN with fewer than two, and for a turn inside a detected floor change: on a
        switchback's landing the way on is up the stairs, which no level edge gives — the
        simulated varied walk matched such a turn at the stairs to the corridor landmark beside
        them, placed 0.996 → 1.285 m)."""
        if self._after is None:
            d = self.det
            out = np.full(len(d), np.nan)
            lo = np.searchsorted(self.ts, d.t_end + EXIT_AFTER_S[0])
            hi = np.searchsorted(self.ts, d.t_end + EXIT_AFTER_S[1])
            ex = d.kind == FLOOR_EXIT
            climbing = ((d.t[:, None] >= d.t_start[ex][None, :])
                        & (d.t[:, None] <= d.t[ex][None, :])).any(axis=1)  # fmt: skip
            for k in np.flatnonzero((hi - lo >= 2) & ~climbing):
                out[k] = circmean(self.hg[lo[k] : hi[k]])
            self._after = out
        return self._after

    def _exits(self, node: str) -> np.ndarray:
        """Headings of the landmark's level ways out; none where stairs or a lift leave it."""
        cache = self._exit_cache
        if node not in cache:
            g = self.reach.g
            outs = g.successors(node)
            floors = any(g.edge(node, v)["floor_change"] for v in outs)
            cache[node] = np.array(
                [] if floors else [self.reach.edge_heading(node, v) for v in outs]
            )
        return cache[node]

    def _compass_ll(self, st: TrackerState, r: Route, w: WalkToDetection, cache: dict) -> float:
        """Along one edge, the gyro offset the edge implies against the compass's: the only
        absolute heading there is, so it tells mirror-image routes apart. Magnetic
        disturbances make it heavy-tailed: σ = ``COMPASS_SD`` and the penalty capped.

        The implied offset is circmean(h_edge − g) = h_edge − circmean(g) over the last two
        thirds of the walk, so the walk's part (``cache``) is computed once for all routes."""
        if not self.use_compass or r.edges != 1 or w.i_end - st.a_idx < 6:
            return 0.0
        if "g" not in cache:
            tail = slice(st.a_idx + (w.i_end - st.a_idx) // 3, w.i_end)
            g = self.hg[tail]
            cache["g"] = circmean(g) + circmean(self.hc[tail] - g)  # mean gyro + compass offset
        implied_minus_compass = self.reach.edge_heading(st.node, r.node) - cache["g"]
        return max(gaussian_ll(wrap1(implied_minus_compass), COMPASS_SD), -3.0)

    def _relocalize(
        self, st: TrackerState, k: int, w: WalkToDetection, f_now: float, seen: set[str]
    ) -> list[Candidate]:
        """Recovery after a long stretch without a match: every landmark with the detected rule
        on this floor, scored by where the whole path since the last match ends."""
        p, out = self.p, list[Candidate]()
        kind = str(self.det.kind[k])
        if kind in FLOOR_CHANGE:
            return out  # a floor change needs its route
        ids, xs, ys = self._rule_nodes(kind, f_now)
        if not ids:
            return out
        sd = distance_sd(w.d_star, p.confidence_threshold, 2 * p.step_length_cv)
        ll = gaussian_ll(np.hypot(xs - w.ex, ys - w.ey), sd)  # for all of them at once
        for i in np.flatnonzero(ll > LL_3SD).tolist():
            v = ids[i]
            if v not in seen and v != st.node:
                out.append(Candidate(v, None, 0.0, p.match_gain + float(ll[i]) - p.relocalize_cost))
        return out

    def _rule_nodes(self, kind: str, floor: float) -> tuple[list[str], np.ndarray, np.ndarray]:
        """The landmarks on ``floor`` that carry rule ``kind`` (graph order), with x and y."""
        cache = self._rule_nodes_cache
        hit = cache.get((kind, floor))
        if hit is None:
            sel = [(v, x, y) for v, (x, y, f) in self.reach.pos.items()
                   if f == floor and kind in self.reach.rules[v]]  # fmt: skip
            hit = cache[kind, floor] = (
                [v for v, _, _ in sel],
                np.array([x for _, x, _ in sel], float),
                np.array([y for _, _, y in sel], float),
            )
        return hit

    def paper_choice(self, cands: list[Candidate]) -> Candidate | None:
        """The paper's greedy rule: the most confident candidate above ε_v, nearest tier first."""
        ok = [c for c in cands if c.confidence > self.p.confidence_threshold or c.route is None]
        if not ok:
            return None
        tier = min(c.route.missed if c.route else 99 for c in ok)
        ok = [c for c in ok if (c.route.missed if c.route else 99) == tier] or ok
        return max(ok, key=lambda c: (c.confidence, c.score))
