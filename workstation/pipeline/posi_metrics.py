"""The landmark figures at the ground-truth fixes (IPIN's "POSI" fixes stand on landmarks):
which landmark each fix stands on, the visits, and how often the tracker matched it there —
:func:`_posi_association`, read by :func:`.metrics.summarize`."""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np

from workstation.graph import LandmarkGraph
from workstation.graph.importers import MIN_LEG_M, turn_points
from workstation.pipeline.landmarks import Detections
from workstation.pipeline.steps import Steps
from workstation.pipeline.tracking.state import Track
from workstation.rules import TURN
from workstation.session import GroundTruth

POSI_MATCH_WINDOW_S = 3.0
POSI_NODE_RADIUS_M = 1.0
END_STEPS = 2  # steps after the last fix of a walk that ends on a landmark (the walker stops)


class _Run(Protocol):
    """What these figures read of a run."""

    @property
    def steps(self) -> Steps: ...

    @property
    def landmarks(self) -> Detections: ...

    @property
    def track(self) -> Track: ...


def _fix_landmarks(xyf: np.ndarray, ids: np.ndarray, gx: np.ndarray, gy: np.ndarray,
                   gfl: np.ndarray) -> list[str | None]:  # fmt: skip
    """The landmark each fix stands on (within ``POSI_NODE_RADIUS_M`` on its floor), or None."""
    truth: list[str | None] = []
    for i in range(gx.size):
        d = np.hypot(xyf[:, 0] - gx[i], xyf[:, 1] - gy[i])
        d = np.where(xyf[:, 2] == gfl[i], d, np.inf)
        j = int(np.argmin(d)) if d.size else -1
        truth.append(str(ids[j]) if j >= 0 and d[j] <= POSI_NODE_RADIUS_M else None)
    return truth


def _visits(truth: list[str | None]) -> tuple[np.ndarray, np.ndarray]:
    """Per fix, the first and last fix of its visit: runs of consecutive fixes on the same
    landmark."""
    n = len(truth)
    first = np.arange(n)
    for i in range(1, n):
        if truth[i] is not None and truth[i] == truth[i - 1]:
            first[i] = first[i - 1]
    last = np.arange(n)
    for i in range(n - 2, -1, -1):
        if truth[i] is not None and truth[i] == truth[i + 1]:
            last[i] = last[i + 1]
    return first, last


def _posi_association(
    result: _Run, gt: GroundTruth, fixes: np.ndarray, graph: LandmarkGraph, x: np.ndarray,
    y: np.ndarray, f: np.ndarray,
) -> dict[str, Any]:  # fmt: skip
    """At each fix that stands on a landmark (within ``POSI_NODE_RADIUS_M`` on its floor):

    - ``landmark_node_accuracy``: the landmark matched within ±``POSI_MATCH_WINDOW_S`` of the
      fix, else the landmark nearest the estimate, is the fix's landmark;
    - ``landmark_fix_match_rate`` (over the fixes whose landmark carries a detection rule): that
      landmark was matched while the walker stood on it — within ±``POSI_MATCH_WINDOW_S`` of
      the *visit* (consecutive fixes on the same landmark: the walker arrives, turns, waits,
      leaves), or before it with no step between the match and the fix. The start landmark
      counts as matched when the walk starts. A visit that ends the walk (the walker stops
      there and records at most ``END_STEPS`` more steps) is left out: no rule's event can
      happen at it;
    - ``landmark_fix_match_rate_strict``: the same fixes (the last visit too), matched within
      ±``POSI_MATCH_WINDOW_S`` of the fix itself, nothing else credited;
    - ``landmark_rule_fixes_passed_straight``: of the fixes ``landmark_fix_match_rate`` counts,
      those on a landmark whose only rule is a turn where the tapped walk did not turn (its
      polyline turns by at most ``TURN_RULE_DEG`` on that visit, as ``graph from-waypoints``
      judges a turn; the start is matched by definition): no rule's event happened there.
      ``landmark_fix_match_rate_turned`` is the rate over the other fixes — beside the strict
      figure, never instead of it.
    """
    tr, det = result.track, result.landmarks
    xyf = graph.xyf()
    ids = np.array(graph.ids)
    rules = {n.id: n.rules for n in graph.nodes}
    gx, gy, gfl, gt_t = gt.x[fixes], gt.y[fixes], gt.floor[fixes], gt.t[fixes]
    W = POSI_MATCH_WINDOW_S
    mt = np.concatenate([[tr.start.time], det.t[tr.detections.matched]])
    mn = np.concatenate([[tr.start.node], tr.detections.node[tr.detections.matched]])
    step_t = result.steps.t
    truth = _fix_landmarks(xyf, ids, gx, gy, gfl)
    first, last = _visits(truth)
    right = detected = known = ruled = matched_rule = ruled_strict = strict = 0
    turned = turn_points(np.column_stack([gx, gy]), MIN_LEG_M)
    straight = matched_turned = 0
    for i, v in enumerate(truth):
        if v is None:
            continue  # this fix is not a landmark of the graph
        known += 1
        near = np.flatnonzero(np.abs(mt - gt_t[i]) <= W)
        if near.size:
            pred = mn[near[np.argmin(np.abs(mt[near] - gt_t[i]))]]
            detected += pred == v
        else:
            same_est = xyf[:, 2] == f[i]
            de = np.where(same_est, np.hypot(xyf[:, 0] - x[i], xyf[:, 1] - y[i]), np.inf)
            pred = ids[int(np.argmin(de))]
        right += pred == v
        if not rules.get(v):
            continue
        ruled_strict += 1
        strict += bool(np.any(mn[near] == v))
        t0, t1 = gt_t[first[i]], gt_t[last[i]]
        if last[i] == gx.size - 1 and np.count_nonzero(step_t > t1) <= END_STEPS:
            continue  # the walk ends on this landmark
        ruled += 1
        hit = _matched_on_visit(mt, mn, v, t0, t1, float(gt_t[i]), step_t)
        matched_rule += hit
        if first[i] and set(rules[v]) == {TURN} and not turned[first[i] : last[i] + 1].any():
            straight += 1
        else:
            matched_turned += hit
    if not known:
        return {}
    return _rates(known, right, detected, ruled, matched_rule, straight, matched_turned,
                  ruled_strict, strict)  # fmt: skip


def _matched_on_visit(
    mt: np.ndarray, mn: np.ndarray, v: str, t0: float, t1: float, t_fix: float,
    step_t: np.ndarray,
) -> bool:  # fmt: skip
    """Landmark ``v`` matched (at times ``mt``, nodes ``mn``) within ±``POSI_MATCH_WINDOW_S`` of
    the visit t0…t1, or matched before the fix with no step and no other match since."""
    W = POSI_MATCH_WINDOW_S
    if np.any((mn == v) & (mt >= t0 - W) & (mt <= t1 + W)):
        return True
    before = np.flatnonzero((mt < t_fix) & (mn == v))
    if not before.size:
        return False
    t_m = mt[before[-1]]
    moved = np.any((step_t > t_m) & (step_t < t_fix - W))
    later = np.any((mt > t_m) & (mt < t_fix))
    return bool(not moved and not later)


def _rates(
    known: int, right: int, detected: int, ruled: int, matched_rule: int, straight: int,
    matched_turned: int, ruled_strict: int, strict: int,
) -> dict[str, Any]:  # fmt: skip
    """The counts of :func:`_posi_association` as its rates."""
    out: dict[str, Any] = {
        "landmark_fixes": known,
        "landmark_node_accuracy": round(right / known, 4),
        "landmark_detected_rate": round(detected / known, 4),
    }
    if ruled:
        out["landmark_rule_fixes"] = ruled
        out["landmark_fix_match_rate"] = round(matched_rule / ruled, 4)
        out["landmark_rule_fixes_passed_straight"] = straight
        if ruled > straight:
            out["landmark_fix_match_rate_turned"] = round(matched_turned / (ruled - straight), 4)
    if ruled_strict:
        out["landmark_rule_fixes_strict"] = ruled_strict
        out["landmark_fix_match_rate_strict"] = round(strict / ruled_strict, 4)
    return out
