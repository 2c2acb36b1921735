"""Checking predictions against walks that were made: the predicted duration of each recorded
walk's own route (its ground-truth fixes, landmark by landmark) against how long it took, with
the pace measured on the *other* walks of the building (leave one out)."""

from __future__ import annotations

import numpy as np

from workstation.geo import distance_to_segments
from workstation.graph import LandmarkGraph
from workstation.survey_plan.pace import measure_pace
from workstation.survey_plan.plan import level_edges, route_walk


def fixes_route(graph: LandmarkGraph, gt) -> list[str]:
    """The landmark nearest each ground-truth fix on its floor, in order."""
    xyf, ids = graph.xyf(), graph.ids
    out = []
    for x, y, f in zip(gt.x, gt.y, gt.floor):
        d = np.where(xyf[:, 2] == f, np.hypot(xyf[:, 0] - x, xyf[:, 1] - y), np.inf)
        out.append(ids[int(np.argmin(d))])
    return out


def durations(graph: LandmarkGraph, sessions, results) -> list[dict]:
    """Per walk: its real duration (first to last fix), the predicted one, the relative error."""
    rows = []
    for i, s in enumerate(sessions):
        gt = s.ground_truth
        pace = measure_pace([r for k, r in enumerate(results) if k != i])
        w = route_walk(graph, fixes_route(graph, gt), pace)
        real = float(gt.t[-1] - gt.t[0])
        rows.append({"real_s": round(real, 1), "predicted_s": round(w.duration_s, 1),
                     "error": round(w.duration_s / real - 1.0, 3)})  # fmt: skip
    return rows


def edge_cover(graph: LandmarkGraph, rm, within_m: float = 2.0) -> float:
    """Share of the level edges with an accepted reference point of ``rm`` (a pipeline radio
    map) within ``within_m`` of them, on their floor."""
    hit = []
    for u, v in level_edges(graph):
        a, b = graph.node(u), graph.node(v)
        on = rm.accepted & (rm.floor == a.floor)
        seg = np.array([[[a.x, a.y], [b.x, b.y]]])
        hit.append(bool((distance_to_segments(rm.x[on], rm.y[on], seg) <= within_m).any()))
    return float(np.mean(hit)) if hit else 1.0


def track_error(session, result) -> float:
    """Mean distance of the backward-corrected track from a simulated walk's dense truth."""
    gt, tr = session.ground_truth, result.track
    x, y, _ = tr.position_at(gt.t, corrected=True)
    m = gt.t >= tr.start.time
    return float(np.mean(np.hypot(x - gt.x, y - gt.y)[m]))
