"""Landmark-graph PDR (§III-B, eq. 7–14).

Between landmarks: x += l cos θ, y += l sin θ (eq. 7–8) per step, the floor from pressure
(eq. 9). The heading θ is the sensor heading (gyro, offset-aligned to the graph at each match, or
the compass) snapped to the heading of a graph edge leaving the last landmark when within ε_θ.
At each detection, the candidates are the landmarks met next after the last matched one (those
without rules, which cannot be detected, are passed; ``max_hops`` > 1 reaches past missed ones);
con = δ(rule) · r(|θ_k − θ*| < ε_θ) · 1/|d_k − d*| (eq. 11–14), where
θ_k, d_k are the direction and path length from the last landmark to the candidate and θ*, d*
the heading and distance walked since. The best candidate above ε_v is matched: the position
snaps to it and the step length is recalibrated as edge length / steps (eq. 10). Unmatched
detections are ignored; missed landmarks are tolerated (the walk continues to the next match).

Beyond the paper, and said so: over a floor change (stairs, elevator) the distance walked is no
measure, so g compares the floor reached (from pressure) with the candidate's floor instead;
eq. 10 is not applied on floor-changing paths (stair steps are short) and its result is clamped.
``association = "beam"`` replaces the greedy choice by a search over association hypotheses.
docs/decisions.md lists every such choice.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..graph import LandmarkGraph
from ..params import PDRParams
from ..session import Scalar
from ..session.model import sample_path
from .heading import Heading
from .landmarks import Detections
from .steps import Steps


def wrap(a):
    return (np.asarray(a) + np.pi) % (2 * np.pi) - np.pi


def circmean(a) -> float:
    a = np.asarray(a, float)
    a = a[np.isfinite(a)]
    return float(np.arctan2(np.sin(a).mean(), np.cos(a).mean())) if a.size else 0.0


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
    det_confidence: np.ndarray  # best candidate's confidence (0 if none)
    det_candidate: np.ndarray  # best candidate's node id (matched or not) or ""
    det_reason: np.ndarray  # why not matched ("" when matched)
    # per segment
    seg_from: np.ndarray
    seg_to: np.ndarray  # "" for the open last segment
    seg_t0: np.ndarray
    seg_t1: np.ndarray
    start_node: str
    start_time: float

    @property
    def matched(self) -> np.ndarray:
        return self.det_node != ""

    def position_at(self, t, corrected: bool = False):
        """x, y, floor at times ``t`` (linear between steps, eq. 19–20)."""
        x, y = (self.x_bc, self.y_bc) if corrected else (self.x, self.y)
        return sample_path(self.t, x, y, self.floor, t)


def find_start_time(steps: Steps, p: PDRParams) -> float:
    """End of the first still period of ``start_still_s`` within ``start_search_s`` (else 0)."""
    t, walking = steps.state_t, steps.walking
    if t.size < 2 or p.start_still_s <= 0:
        return float(t[0]) if t.size else 0.0
    d = np.diff(np.concatenate([[1], walking.astype(np.int8), [1]]))
    s, e = np.flatnonzero(d == -1), np.flatnonzero(d == 1)
    for a, b in zip(s, e):
        if t[a] > t[0] + p.start_search_s:
            break
        if t[min(b, t.size - 1)] - t[a] >= p.start_still_s and b < t.size:
            return float(t[b - 1])
    return float(t[0])


class _Graph:
    """Pre-computed reachability over the landmark graph.

    Candidates of a source are the landmarks reachable through fewer than ``max_hops``
    landmarks that have detection rules; landmarks without rules cannot be detected, so
    passing them is free (up to ``MAX_PATH`` nodes). Paths end at a floor change. The tracker
    tries the nearest tier first (no detectable landmark missed), then the next.
    """

    MAX_PATH = 12

    def __init__(self, graph: LandmarkGraph, max_hops: int):
        self.g = graph
        self.pos = {n.id: (n.x, n.y, n.floor) for n in graph.nodes}
        self.rules = {n.id: n.rules for n in graph.nodes}
        # per source: (node, path length, floor change on the path, path, horizontal length of
        # the floor-changing edges, landmarks with rules passed on the way, distance to the
        # last of them)
        self.reach: dict[str, list[tuple[str, float, bool, tuple[str, ...], float, int]]] = {}
        self.edge_headings: dict[str, np.ndarray] = {}
        dg = graph.digraph
        for src in graph.ids:
            out: dict[str, tuple[str, float, bool, tuple[str, ...], float, int]] = {}
            headings: set[float] = set()
            stack = [(src, 0.0, False, (src,), 0.0, 0, 0.0)]
            while stack:
                node, dist, fc, path, fcl, hops, passed = stack.pop()
                for v in dg.successors(node):
                    if v in path:
                        continue
                    e = dg.edges[node, v]
                    changes = e["floor_change"] != 0
                    if e["length"] > 0.5 and not changes:
                        headings.add(round(e["heading"], 9))
                    item = (
                        v,
                        dist + e["length"],
                        fc or changes,
                        path + (v,),
                        fcl + (e["length"] if changes else 0.0),
                    )
                    # landmarks with rules passed on the way (missed detections) come last
                    if v not in out or (hops, item[1]) < (out[v][5], out[v][1]):
                        out[v] = (*item, hops, passed)
                    h = hops + (1 if self.rules[v] else 0)
                    # paths end at a floor change: its exit is matched first
                    if not item[2] and h < max_hops and len(item[3]) < self.MAX_PATH:
                        stack.append((*item, h, item[1] if self.rules[v] else passed))
            self.reach[src] = list(out.values())
            self.edge_headings[src] = np.array(sorted(headings))


def _snap(theta: np.ndarray, headings: np.ndarray, eps: float) -> np.ndarray:
    if headings.size == 0 or theta.size == 0:
        return theta
    diff = np.abs(wrap(theta[:, None] - headings[None, :]))
    k = np.argmin(diff, axis=1)
    best = diff[np.arange(theta.size), k]
    snapped = theta + wrap(headings[k] - theta)
    return np.where(best < eps, snapped, theta)


def track(
    steps: Steps,
    heading: Heading,
    detections: Detections,
    graph: LandmarkGraph,
    pressure: Scalar | None,
    p: PDRParams,
    start_node: str | None = None,
    start_time: float | None = None,
    _reach: _Graph | None = None,
) -> Track:
    """Run the landmark-graph PDR from ``start_node`` (or ``p.start_node``; inferred if neither)."""
    start_node = start_node or p.start_node
    t0 = find_start_time(steps, p) if start_time is None else start_time
    reach = _reach or _Graph(graph, p.max_hops)
    if not graph.nodes:  # no landmarks yet: plain PDR from the origin
        return _run(steps, heading, detections, reach, pressure, p, "", t0)
    if not start_node:
        return infer_start(steps, heading, detections, graph, pressure, p, t0, reach)
    if start_node not in reach.pos:
        from ..errors import GraphError

        raise GraphError(f"start node {start_node}: not in the landmark graph")
    return _run(steps, heading, detections, reach, pressure, p, start_node, t0)


def _score(tr: Track) -> tuple[int, float]:
    return int(tr.matched.sum()), float(tr.det_confidence[tr.matched].sum())


def infer_start(steps, heading, detections, graph, pressure, p, t0, reach) -> Track:
    """Try every landmark as the start; keep the one whose run matches most (then most confident)."""
    best = None
    for nid in graph.ids:
        tr = _run(steps, heading, detections, reach, pressure, p, nid, t0)
        if best is None or _score(tr) > _score(best):
            best = tr
    return best


def _pressure_at(pressure: Scalar | None, t) -> np.ndarray:
    if pressure is None or len(pressure) == 0:
        return np.zeros(np.size(t))
    return np.interp(t, pressure.t, pressure.value)


@dataclass(frozen=True)
class _State:
    """Where the tracker stands: the last matched landmark (the anchor) and what it has learnt."""

    node: str
    ax: float
    ay: float
    a_idx: int  # first step after the anchor
    a_t: float
    p_ref: float  # eq. 9 reference: pressure at f_ref
    f_ref: float
    length: float  # step length (eq. 10)
    offset: float  # gyro heading offset
    score: float = 0.0
    matches: tuple[tuple[int, str], ...] = ()


@dataclass(frozen=True)
class _Walk:
    """The steps from the anchor to a detection, walked with the state's model (eq. 7–8)."""

    i_end: int
    px: np.ndarray
    py: np.ndarray
    theta: np.ndarray
    ex: float
    ey: float
    d_star: float
    th_star: float
    f_cont: float


class _Tracker:
    """Candidate scoring (eq. 11–14) and state updates shared by the greedy pass (the paper)
    and the beam search over association hypotheses (beyond the paper)."""

    def __init__(
        self, steps, heading, det: Detections, reach: _Graph, pressure, p: PDRParams, t0: float
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
        self.floors_known = np.array(sorted({v[2] for v in reach.pos.values()}) or [0.0])
        self.window = 1.0 / max(p.confidence_threshold, 1e-6)

    def start(self, node: str) -> _State:
        ax, ay, afl = self.reach.pos.get(node, (0.0, 0.0, 0.0))
        return _State(
            node,
            ax,
            ay,
            self.first,
            self.t0,
            float(_pressure_at(self.pressure, [self.t0])[0]),
            afl,
            self.p.initial_step_length_m,
            self.offset0,
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

    def floor_at(self, st: _State, t):
        f = st.f_ref - (_pressure_at(self.pressure, t) - st.p_ref) / self.p.floor_hpa  # eq. 9
        k = np.abs(f[:, None] - self.floors_known[None, :]).argmin(axis=1)
        return self.floors_known[k], f

    def walk_to_detection(self, st: _State, k: int) -> _Walk:
        tk = float(self.det.t[k])
        i_end = int(np.searchsorted(self.ts, tk, side="right"))
        px, py, theta = self.walk(st, i_end)
        n_s = i_end - st.a_idx
        ex, ey = (float(px[-1]), float(py[-1])) if n_s else (st.ax, st.ay)
        th_star = float(np.arctan2(ey - st.ay, ex - st.ax)) if n_s else np.nan
        return _Walk(
            i_end,
            px,
            py,
            theta,
            ex,
            ey,
            n_s * st.length,
            th_star,
            float(self.floor_at(st, np.array([tk]))[1][0]),
        )

    def candidates(self, st: _State, k: int, w: _Walk):
        """(passing [(confidence, candidate)], best candidate, its confidence, why not)."""
        p, reach, kind = self.p, self.reach, self.det.kind[k]
        best, best_c, why = None, 0.0, "no landmark with this rule within reach"
        # a detectable landmark counts as missed only once the walker is past its match window
        cands = [
            (*c[:5], False, c[5])
            for c in reach.reach.get(st.node, [])
            if c[5] == 0 or w.d_star > c[6] * (1 + p.distance_slack) + self.window
        ]
        if w.d_star > p.relocalize_after_m:  # lost: every landmark on this floor, by distance
            near = {c[0] for c in cands}
            cands += [
                (
                    v,
                    w.d_star + float(np.hypot(vx - w.ex, vy - w.ey)),
                    False,
                    (st.node, v),
                    0.0,
                    True,
                    p.max_hops,
                )
                for v, (vx, vy, vf) in reach.pos.items()
                if v not in near and v != st.node and abs(vf - w.f_cont) < 0.5
            ]
        passing, tier_ok = [], None
        for v, dist, fchange, path, fc_len, reloc, tier in sorted(cands, key=lambda c: c[6]):
            if tier_ok is not None and tier > tier_ok:
                break  # a nearer tier already has a match above the threshold
            if kind not in reach.rules[v]:
                continue
            # an entry starts a floor change at a landmark on this floor; an exit ends one
            if (kind == "baro_entry" and fchange) or (kind == "baro_exit" and not fchange):
                continue
            vx, vy, vf = reach.pos[v]
            if abs(w.f_cont - vf) > 0.5:
                why = f"{v}: floor {vf:g} not reached" if fchange else f"{v}: on another floor"
                continue
            if fchange:
                # on stairs the distance walked is no measure: the level part of the path must
                # fit what was walked before the floor change began, and the floor must fit
                n_level = (
                    int(np.searchsorted(self.ts, self.det.t_start[k], side="right")) - st.a_idx
                )
                excess = abs(max(n_level, 0) * st.length - (dist - fc_len))
                c = 1.0 / max(abs(w.f_cont - vf) * p.floor_distance_m + excess, p.min_distance_m)
            else:
                g = 1.0 / max(
                    abs(dist - w.d_star) - p.distance_slack * dist, p.min_distance_m
                )  # eq. 14
                th_k = np.arctan2(vy - st.ay, vx - st.ax)
                if not (
                    reloc or np.hypot(vx - st.ax, vy - st.ay) < 1.0 or not np.isfinite(w.th_star)
                ):
                    if abs(wrap(th_k - w.th_star)) >= self.eps:  # eq. 13
                        if best is None:
                            why = f"{v}: heading off by {np.degrees(abs(wrap(th_k - w.th_star))):.0f}°"
                        continue
                c = g
            cand = (v, dist, fchange, path, fc_len, reloc)
            if c > best_c:
                best, best_c = cand, c
            if c > p.confidence_threshold:
                passing.append((c, cand))
                tier_ok = tier if tier_ok is None else tier_ok
        if best is not None and best_c <= p.confidence_threshold:
            why = f"{best[0]}: confidence {best_c:.2f} ≤ {p.confidence_threshold:g}"
        passing.sort(key=lambda x: -x[0])
        return passing, best, best_c, why

    def advance(self, st: _State, k: int, cand, w: _Walk, conf: float) -> _State:
        """Snap to the matched landmark and recalibrate (eq. 10)."""
        p = self.p
        v, dist, fchange, path, _, reloc = cand
        vx, vy, vf = self.reach.pos[v]
        n_s = w.i_end - st.a_idx
        length, offset = st.length, st.offset
        if not fchange and not reloc and n_s >= 3 and dist >= p.min_calibration_m:
            length = float(np.clip(dist / n_s, p.min_step_length_m, p.max_step_length_m))
            if p.heading_source != "compass":
                if len(path) == 2:  # along one edge: align the gyro with the edge's heading
                    edge_h = self.reach.g.digraph.edges[path[0], path[1]]["heading"]
                    tail = slice(st.a_idx + n_s // 3, w.i_end)
                    if w.i_end - (st.a_idx + n_s // 3) >= 2:
                        offset = circmean(edge_h - self.hg[tail])
                elif np.hypot(w.ex - st.ax, w.ey - st.ay) > 1.0:  # several edges: turn the walked
                    # displacement onto the true one
                    offset = float(
                        offset
                        + wrap(
                            np.arctan2(vy - st.ay, vx - st.ax)
                            - np.arctan2(w.ey - st.ay, w.ex - st.ax)
                        )
                    )
        tk = float(self.det.t[k])
        p_ref, f_ref = st.p_ref, st.f_ref
        # re-anchor eq. 9 on the landmark's floor only where the pressure agrees with it
        if self.floor_at(st, np.array([tk]))[0][0] == vf:
            p_ref, f_ref = float(_pressure_at(self.pressure, [tk])[0]), vf
        gain = 1.0 + np.log(conf / max(p.confidence_threshold, 1e-6))
        return _State(
            v,
            vx,
            vy,
            w.i_end,
            tk,
            p_ref,
            f_ref,
            length,
            offset,
            st.score + gain,
            st.matches + ((k, v),),
        )

    def beam(self, start: str, width: int) -> dict[int, str]:
        """Association hypotheses: at each detection every hypothesis may ignore it or match one
        of its passing candidates; the ``width`` best (most, and most confident, matches) live on.
        A wrong early match is dropped when the chain after it stops fitting."""
        states = [self.start(start)]
        for k in range(len(self.det)):
            tk = float(self.det.t[k])
            nxt = []
            for st in states:
                nxt.append(st)
                if tk <= st.a_t:
                    continue
                w = self.walk_to_detection(st, k)
                passing, *_ = self.candidates(st, k, w)
                for c, cand in passing[:3]:
                    nxt.append(self.advance(st, k, cand, w, c))
            best: dict[tuple[str, int], _State] = {}
            for st in nxt:
                key = (st.node, st.a_idx)
                if key not in best or st.score > best[key].score:
                    best[key] = st
            states = sorted(best.values(), key=lambda s: -s.score)[:width]
        return dict(states[0].matches) if states else {}


def _run(
    steps, heading, det: Detections, reach: _Graph, pressure, p: PDRParams, start: str, t0: float
) -> Track:
    trk = _Tracker(steps, heading, det, reach, pressure, p, t0)
    forced = trk.beam(start, p.beam_width) if p.association == "beam" else None
    ts = trk.ts
    n = ts.size
    x, y, th, sl, fl, xb, yb = (np.zeros(n) for _ in range(7))
    seg = np.full(n, -1, dtype=np.int64)
    m = len(det)
    det_node = np.full(m, "", dtype=object)
    det_conf = np.zeros(m)
    det_cand = np.full(m, "", dtype=object)
    det_reason = np.full(m, "", dtype=object)
    st = trk.start(start)
    first = trk.first
    x[:first], y[:first], fl[:first] = st.ax, st.ay, st.f_ref
    xb[:first], yb[:first] = st.ax, st.ay
    seg_from, seg_to, seg_t0, seg_t1 = [start], [], [trk.t0], []
    for k in range(m):
        tk = float(det.t[k])
        if tk <= st.a_t:
            det_reason[k] = (
                "before the walk starts" if tk <= trk.t0 else "at the last matched landmark"
            )
            continue
        w = trk.walk_to_detection(st, k)
        passing, best, best_c, why = trk.candidates(st, k, w)
        det_conf[k] = best_c
        det_cand[k] = best[0] if best else ""
        if forced is None:
            chosen = passing[0] if passing else None
        else:
            chosen = next((pc for pc in passing if pc[1][0] == forced.get(k)), None)
            if chosen is None and passing:
                why = f"{passing[0][1][0]} (confidence {passing[0][0]:.2f}) does not fit the best association of the whole walk"
        if chosen is None:
            det_reason[k] = why
            continue
        # --- match: finalize the segment, snap, recalibrate (eq. 10) ---------------------
        conf, cand = chosen
        v = cand[0]
        vx, vy, _ = reach.pos[v]
        sl_ = slice(st.a_idx, w.i_end)
        x[sl_], y[sl_], th[sl_], sl[sl_] = w.px, w.py, w.theta, st.length
        seg[sl_] = len(seg_from) - 1
        if w.i_end > st.a_idx:
            fl[sl_] = trk.floor_at(st, ts[sl_])[0]
        # backward correction: similarity transform about the anchor taking the end onto v
        xb[sl_], yb[sl_] = _bend(w.px, w.py, st.ax, st.ay, w.ex, w.ey, vx, vy)
        det_node[k], det_conf[k], det_cand[k] = v, conf, v
        seg_to.append(v)
        seg_t1.append(tk)
        st = trk.advance(st, k, cand, w, conf)
        seg_from.append(v)
        seg_t0.append(tk)
    # the open last segment
    if st.a_idx < n:
        px, py, theta = trk.walk(st, n)
        sl_ = slice(st.a_idx, n)
        x[sl_], y[sl_], th[sl_], sl[sl_] = px, py, theta, st.length
        xb[sl_], yb[sl_] = px, py
        seg[sl_] = len(seg_from) - 1
        fl[sl_] = trk.floor_at(st, ts[sl_])[0]
    seg_to.append("")
    seg_t1.append(float(ts[-1]) if n else trk.t0)

    # plain PDR for comparison: initial step length, gyro + initial compass offset, no graph
    sx, sy, _ = reach.pos.get(start, (0.0, 0.0, 0.0))
    hg = heading.at(ts, "gyro") if n else np.empty(0)
    theta0 = hg + (circmean(trk.hc[trk.init] - hg[trk.init]) if (trk.use_compass and n) else 0.0)
    moving = np.arange(n) >= first
    raw_x = sx + np.cumsum(np.where(moving, p.initial_step_length_m * np.cos(theta0), 0.0))
    raw_y = sy + np.cumsum(np.where(moving, p.initial_step_length_m * np.sin(theta0), 0.0))
    return Track(
        t=ts,
        x=x,
        y=y,
        floor=fl,
        heading=th,
        step_length=sl,
        segment=seg,
        x_bc=xb,
        y_bc=yb,
        raw_x=raw_x,
        raw_y=raw_y,
        det_node=det_node.astype(str),
        det_confidence=det_conf,
        det_candidate=det_cand.astype(str),
        det_reason=det_reason.astype(str),
        seg_from=np.array(seg_from, dtype=str),
        seg_to=np.array(seg_to, dtype=str),
        seg_t0=np.array(seg_t0, float),
        seg_t1=np.array(seg_t1, float),
        start_node=start,
        start_time=float(trk.t0),
    )


def _bend(px, py, ax, ay, ex, ey, vx, vy):
    """Rotate and scale a segment about its start (ax, ay) so that its end (ex, ey) lands on
    (vx, vy); when the walked displacement is tiny, shift linearly instead."""
    if px.size == 0:
        return px, py
    d0 = np.array([ex - ax, ey - ay])
    d1 = np.array([vx - ax, vy - ay])
    n0, n1 = np.hypot(*d0), np.hypot(*d1)
    if n0 < 1.0 or n1 < 1.0:
        w = np.arange(1, px.size + 1) / px.size
        return px + w * (vx - ex), py + w * (vy - ey)
    s = n1 / n0
    a = np.arctan2(d1[1], d1[0]) - np.arctan2(d0[1], d0[0])
    c, si = np.cos(a), np.sin(a)
    qx, qy = px - ax, py - ay
    return ax + s * (c * qx - si * qy), ay + s * (si * qx + c * qy)
