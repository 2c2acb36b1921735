"""The trajectory of a chosen association: dead reckoning (eq. 7–8) from match to match, the
floor from pressure (eq. 9), what each detection became and why, and the backward correction
(each closed segment bent to end on its landmark — the survey is offline)."""

from __future__ import annotations

import numpy as np

from workstation.params import COMPASS_HEADING
from workstation.pipeline.pdr import dead_reckon
from workstation.pipeline.tracking.state import (
    Detections,
    Match,
    Segments,
    Start,
    Steps,
    Track,
    TrackerState,
    pressure_at,
)
from workstation.pipeline.tracking.tracker import Candidate, Tracker


def replay(trk: Tracker, st: TrackerState, matches: tuple[Match, ...]) -> Track:
    det, reach, ts = trk.det, trk.reach, trk.ts
    n, m = ts.size, len(det)
    x, y, th, sl, fl, xb, yb = (np.zeros(n) for _ in range(7))
    seg = np.full(n, -1, dtype=np.int64)
    det_node = np.full(m, "", dtype=object)
    det_conf = np.zeros(m)
    det_cand = np.full(m, "", dtype=object)
    det_reason = np.full(m, "", dtype=object)
    first = trk.first
    start = st.node
    x[:first], y[:first], fl[:first] = st.ax, st.ay, st.floors.f_ref
    xb[:first], yb[:first] = st.ax, st.ay
    seg_from, seg_to, seg_t0, seg_t1, seg_missed = [start], [], [trk.t0], [], []
    chosen = {mt.k: mt for mt in matches}
    for k in range(m):
        tk = float(det.t[k])
        if trk.still_at_anchor(st, k):
            det_reason[k] = (
                "before the walk starts" if tk <= trk.t0 else "at the last matched landmark"
            )
            continue
        w = trk.walk_to_detection(st, k, path=True)
        mt = chosen.get(k)
        if mt is None:
            cands, why = trk.scoring.candidates(st, k, w)
            if cands:
                c = cands[0]
                det_conf[k], det_cand[k] = c.confidence, c.node
                why = f"{c.node} (confidence {c.confidence:.2f}) does not fit the best association of the whole walk"
            det_reason[k] = why
            continue
        # --- match: finalize the segment, snap, recalibrate (eq. 10) ---------------------
        v = mt.node
        vx, vy, vf = reach.pos[v]
        sl_ = slice(st.a_idx, w.i_end)
        assert w.px is not None and w.py is not None  # walked with its path (path=True)
        x[sl_], y[sl_], th[sl_], sl[sl_] = w.px, w.py, w.theta, st.length
        seg[sl_] = len(seg_from) - 1
        if mt.route is not None and not mt.route.floor_change:
            fl[sl_] = vf  # matched along a level route: on its floor (the barometer lags)
        elif w.i_end > st.a_idx:
            fl[sl_] = st.floors.nearest(pressure_at(trk.pressure, ts[sl_]))
        xb[sl_], yb[sl_] = bend(w.px, w.py, st.ax, st.ay, w.ex, w.ey, vx, vy)
        det_node[k], det_conf[k], det_cand[k] = v, mt.confidence, v
        seg_to.append(v)
        seg_t1.append(tk)
        seg_missed.append(mt.route.missed if mt.route is not None else -1)
        st = trk.advance(st, k, Candidate(v, mt.route, mt.confidence, 0.0), w)
        seg_from.append(v)
        seg_t0.append(tk)
    if st.a_idx < n:  # the open last segment
        px, py, theta = trk.walk(st, n)
        sl_ = slice(st.a_idx, n)
        x[sl_], y[sl_], th[sl_], sl[sl_] = px, py, theta, st.length
        xb[sl_], yb[sl_] = px, py
        seg[sl_] = len(seg_from) - 1
        fl[sl_] = st.floors.nearest(pressure_at(trk.pressure, ts[sl_]))
    seg_to.append("")
    seg_t1.append(float(ts[-1]) if n else trk.t0)
    seg_missed.append(0)

    raw_x, raw_y = _plain_pdr(trk, start)
    fm = st.floors
    gaps = {
        f"{fm.floors[i]:g}→{fm.floors[i + 1]:g}": round(float(fm.gaps[i]), 3)
        for i in range(fm.gaps.size)
    }
    return Track(
        Steps(t=ts, x=x, y=y, floor=fl, heading=th, step_length=sl, segment=seg, x_bc=xb,
              y_bc=yb, raw_x=raw_x, raw_y=raw_y),
        Detections(node=det_node.astype(str), confidence=det_conf,
                   candidate=det_cand.astype(str), reason=det_reason.astype(str),
                   spread=np.zeros(m)),  # one association: no alternative (track() sets it)
        Segments(from_node=np.array(seg_from, dtype=str), to_node=np.array(seg_to, dtype=str),
                 t0=np.array(seg_t0, float), t1=np.array(seg_t1, float),
                 missed=np.array(seg_missed, np.int64)),
        Start(node=start, time=float(trk.t0)),
        floor_gaps_hpa=gaps,
    )  # fmt: skip


def _plain_pdr(trk: Tracker, start: str) -> tuple[np.ndarray, np.ndarray]:
    """Plain PDR from the start landmark, for comparison: the initial step length, the gyro and
    the initial compass offset (or the compass), no graph."""
    p, n = trk.p, trk.ts.size
    sx, sy, _ = trk.reach.pos.get(start, (0.0, 0.0, 0.0))
    hg = trk.hg if p.heading_source != COMPASS_HEADING else trk.hc
    theta0 = hg + (trk.offset0 if p.heading_source != COMPASS_HEADING else 0.0)
    moving = np.arange(n) >= trk.first
    return dead_reckon(sx, sy, np.where(moving, p.initial_step_length_m, 0.0),
                       np.where(moving, theta0, 0.0))  # fmt: skip


def bend(
    px: np.ndarray, py: np.ndarray, ax: float, ay: float, ex: float, ey: float, vx: float,
    vy: float,
) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
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
