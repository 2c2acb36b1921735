"""What a run achieved, and how it compares with ground truth when the session has it.

Dense ground truth (the simulator): error at every step. Sparse ground truth (POSI fixes,
waypoints): error at each fix, and whether the tracker associated the right landmark there —
the landmark matched within ±``window`` s of the fix, or else the landmark nearest the
estimated position on the estimated floor.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..graph import LandmarkGraph
from ..session import Session
from .landmarks import KINDS

POSI_MATCH_WINDOW_S = 3.0
POSI_NODE_RADIUS_M = 1.0


def _stats(err: np.ndarray, prefix: str) -> dict[str, float]:
    if err.size == 0:
        return {}
    return {
        f"{prefix}_mean_m": round(float(err.mean()), 3),
        f"{prefix}_median_m": round(float(np.median(err)), 3),
        f"{prefix}_p90_m": round(float(np.percentile(err, 90)), 3),
    }


def summarize(result, session: Session | None, graph: LandmarkGraph | None) -> dict[str, Any]:
    tr, bel, rm, det = result.track, result.belief, result.radiomap, result.landmarks
    walking = tr.segment >= 0
    out: dict[str, Any] = {
        "steps": int(walking.sum()),
        "steps_before_start": int((~walking).sum()),
        "start_node": tr.start_node,
        "start_time_s": round(tr.start_time, 2),
        "landmarks_detected": len(det),
        "landmarks_detected_by_kind": {k: det.count(k) for k in KINDS},
        "landmarks_matched": int(tr.matched.sum()),
        "segments": int(tr.seg_from.size),
        "segments_accepted": int(bel.accepted.sum()),
        "scans": len(rm),
        "reference_points": rm.reference_points,
    }
    gt = None if session is None else session.ground_truth
    if gt is None or len(gt) == 0 or tr.t.size == 0:
        return out
    dense = len(gt) > 2 * max(tr.t.size, 1)
    if dense:
        m = walking & (tr.t >= gt.t[0]) & (tr.t <= gt.t[-1])
        gx, gy, gf = gt.at(tr.t[m])
        err = np.hypot(tr.x[m] - gx, tr.y[m] - gy)
        out.update(_stats(err, "trajectory_error"))
        out["floor_accuracy"] = round(float(np.mean(tr.floor[m] == gf)), 4) if m.any() else None
        out.update(_stats(np.hypot(tr.x_bc[m] - gx, tr.y_bc[m] - gy), "corrected_trajectory_error"))
        out.update(_stats(np.hypot(tr.raw_x[m] - gx, tr.raw_y[m] - gy), "raw_pdr_error"))
        out["ground_truth"] = "dense"
    else:
        fixes = (gt.t >= tr.start_time) & (gt.t <= tr.t[-1])
        t = gt.t[fixes]
        x, y, f = tr.position_at(t)
        err = np.hypot(x - gt.x[fixes], y - gt.y[fixes])
        out.update(_stats(err, "trajectory_error"))
        out["floor_accuracy"] = round(float(np.mean(f == gt.floor[fixes])), 4) if t.size else None
        xb, yb, _ = tr.position_at(t, corrected=True)
        out.update(
            _stats(np.hypot(xb - gt.x[fixes], yb - gt.y[fixes]), "corrected_trajectory_error")
        )
        rx = np.interp(t, tr.t, tr.raw_x)
        ry = np.interp(t, tr.t, tr.raw_y)
        out.update(_stats(np.hypot(rx - gt.x[fixes], ry - gt.y[fixes]), "raw_pdr_error"))
        out["ground_truth"] = f"{int(fixes.sum())} fixes"
        if graph is not None and graph.nodes:
            out.update(_posi_association(result, gt, fixes, graph, x, y, f))
    # radio map quality: RP position error where ground truth covers the scan
    acc = rm.accepted & (rm.t >= gt.t[0]) & (rm.t <= gt.t[-1])
    if acc.any():
        gx, gy, gf = gt.at(rm.t[acc])
        out.update(_stats(np.hypot(rm.x[acc] - gx, rm.y[acc] - gy), "reference_point_error"))
    return out


def _posi_association(result, gt, fixes, graph: LandmarkGraph, x, y, f) -> dict[str, Any]:
    tr, det = result.track, result.landmarks
    xyf = graph.xyf()
    ids = np.array(graph.ids)
    gx, gy, gfl = gt.x[fixes], gt.y[fixes], gt.floor[fixes]
    right = detected = known = 0
    mt = det.t[tr.matched]
    mn = tr.det_node[tr.matched]
    for i in range(gx.size):
        same = xyf[:, 2] == gfl[i]
        d = np.hypot(xyf[:, 0] - gx[i], xyf[:, 1] - gy[i])
        d = np.where(same, d, np.inf)
        j = int(np.argmin(d))
        if d[j] > POSI_NODE_RADIUS_M:
            continue  # this fix is not a landmark of the graph
        known += 1
        truth = ids[j]
        near = np.flatnonzero(np.abs(mt - gt.t[fixes][i]) <= POSI_MATCH_WINDOW_S)
        if near.size:
            pred = mn[near[np.argmin(np.abs(mt[near] - gt.t[fixes][i]))]]
            detected += pred == truth
        else:
            same_est = xyf[:, 2] == f[i]
            de = np.where(same_est, np.hypot(xyf[:, 0] - x[i], xyf[:, 1] - y[i]), np.inf)
            pred = ids[int(np.argmin(de))]
        right += pred == truth
    if not known:
        return {}
    return {
        "landmark_fixes": known,
        "landmark_node_accuracy": round(right / known, 4),
        "landmark_detected_rate": round(detected / known, 4),
    }
