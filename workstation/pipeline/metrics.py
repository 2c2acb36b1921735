"""What a run achieved, and how it compares with ground truth when the session has it.

Dense ground truth (the simulator): error at every step. Sparse ground truth (POSI fixes,
waypoints): error at each fix, and whether the tracker associated the right landmark there —
the landmark matched within ±``window`` s of the fix, or else the landmark nearest the
estimated position on the estimated floor.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace
from functools import partial
from typing import Protocol

import numpy as np

from workstation.graph import LandmarkGraph
from workstation.pipeline.belief import Belief
from workstation.pipeline.continuity import facing_jump
from workstation.pipeline.heading import Heading
from workstation.pipeline.landmarks import KINDS, Detections
from workstation.pipeline.posi_metrics import _posi_association
from workstation.pipeline.radiomap import RadioMap
from workstation.pipeline.steps import Steps
from workstation.pipeline.summary import EndClosure, Figure, StartInference, Summary
from workstation.pipeline.tracking.state import START_AMBIGUOUS_MARGIN, Track
from workstation.pipeline.verdict import MAX_HOLE_S, mark, sensor_hole
from workstation.session import Session
from workstation.session.split import inertial_start
from workstation.stats import error_stats


class Stages(Protocol):
    """What the summary reads of a run (:class:`workstation.pipeline.Result`)."""

    @property
    def steps(self) -> Steps: ...

    @property
    def heading(self) -> Heading: ...

    @property
    def landmarks(self) -> Detections: ...

    @property
    def track(self) -> Track: ...

    @property
    def belief(self) -> Belief: ...

    @property
    def radiomap(self) -> RadioMap: ...


def _stats(err: np.ndarray, prefix: str) -> dict[str, float]:
    st = error_stats(err, prefix=prefix)
    st.pop(f"{prefix}_p75_m", None)
    return st


def start_inference(tr: Track) -> StartInference | None:
    """What summary.json says of an inferred start (None when it was given): the best start
    elsewhere, how much less likely, and whether that is too close to call."""
    if np.isnan(tr.start.margin):
        return None
    return StartInference(
        tr.start.alternative or None,
        tr.start.margin if np.isfinite(tr.start.margin) else None,
        bool(tr.start.margin < START_AMBIGUOUS_MARGIN),
        tuple((n, m) for n, m in tr.start.candidates),
    )


def summarize(result: Stages, session: Session | None, graph: LandmarkGraph | None) -> Summary:
    tr, bel, rm, det = result.track, result.belief, result.radiomap, result.landmarks
    walking = tr.steps.segment >= 0
    has_graph = graph is None or bool(graph.nodes)
    summary = mark(
        Summary(
            steps=int(walking.sum()),
            steps_before_start=int((~walking).sum()),
            start_node=tr.start.node,
            start_time_s=round(tr.start.time, 2),
            start_time_how=tr.start.time_how,
            landmarks_detected=len(det),
            landmarks_detected_by_kind={k: det.count(k) for k in KINDS},
            landmarks_matched=int(tr.detections.matched.sum()),
            # what eq. 10, weighed over the matched paths, made of the walker's step by the end
            step_length_m=round(float(tr.steps.step_length[-1]), 3)
            if tr.steps.step_length.size
            else None,
            segments=int(tr.segments.from_node.size),
            # the landmark the walk ends on (walk_end.py), None while its last segment stays open
            end=EndClosure(
                tr.end.node or None,
                tr.end.how,
                tr.end.margin if np.isfinite(tr.end.margin) else None,
                tr.end.sigma if np.isfinite(tr.end.sigma) else None,
            ),
            # what a radio map of the building's other walks did to the chain of matches
            # (map_prior.py): None without a map; rank 0: the sensors' best was kept
            chain_by_map=tr.map_rerank if tr.map_rerank.chains else None,
            # …and how it turned a walk that matched nothing after its start (open_by_map.py):
            # None when not tried (a map, no match, an end that does not check the walk, scans)
            open_by_map=tr.open_fit if tr.open_fit.scans else None,
            segments_accepted=int(bel.accepted.sum()),
            scans=len(rm),
            reference_points=rm.reference_points,
            reference_points_at_landmarks=int(rm.at_landmark.sum()),
            reference_points_gap_fill=int(rm.filled.sum()),
            scans_not_points=rm.not_points(),
            # what the reader and the sanity checks said about the input (dropped samples, a
            # missing sensor, times sorted): shown first by ``run``, kept with the result
            input_warnings=session.metadata.warnings if session else (),
            start=start_inference(tr),
            sensor_hole=_hole(session),
            clock_jump=_clock_jump(session),
            facing_jump=_facing_jump(session, result.heading),
            off_graph_m=(
                off_graph_m(tr, graph)
                if graph is not None
                and graph.edges
                and not tr.detections.matched.any()
                and walking.any()
                else None
            ),
        ),
        has_graph,
    )
    truth = _truth(result, session, graph)
    return replace(summary, truth=truth) if truth else summary


def _hole(session: Session | None) -> tuple[float, float] | None:
    """The inertial streams' longest pause, when longer than ``verdict.MAX_HOLE_S``."""
    if session is None:
        return None
    hole = sensor_hole([session.accelerometer.t, session.gyroscope.t])
    return hole if hole is not None and hole[1] > MAX_HOLE_S else None


def _clock_jump(session: Session | None) -> tuple[float, str] | None:
    """Where a second recording begins on the walk's clock, from the walk's first inertial
    sample, and the evidence (:mod:`workstation.session.clocks`); None for one recording."""
    cj = session.metadata.clock_jump if session is not None else None
    if cj is None or session is None:
        return None
    return round(cj.t - inertial_start(session), 2), cj.what


def _facing_jump(session: Session | None, heading: Heading) -> tuple[float, float] | None:
    """Where the compass turned and the gyroscope did not (a second recording joined on with
    every clock re-timed, :mod:`.continuity`), from the walk's first inertial sample."""
    if session is None:
        return None
    jump = facing_jump(heading, session.accelerometer, session.pressure)
    if jump is None:
        return None
    return round(jump[0] - inertial_start(session), 2), round(jump[1], 1)


def _truth(
    result: Stages, session: Session | None, graph: LandmarkGraph | None
) -> dict[str, Figure]:
    """The figures against the session's ground truth (empty without one)."""
    tr, rm = result.track, result.radiomap
    walking = tr.steps.segment >= 0
    out: dict[str, Figure] = {}
    gt = None if session is None else session.ground_truth
    if gt is None or len(gt) == 0 or tr.steps.t.size == 0:
        return out
    dense = len(gt) > 2 * max(tr.steps.t.size, 1)
    if dense:
        m = walking & (tr.steps.t >= gt.t[0]) & (tr.steps.t <= gt.t[-1])
        gx, gy, gf = gt.at(tr.steps.t[m])
        err = np.hypot(tr.steps.x[m] - gx, tr.steps.y[m] - gy)
        out.update(_stats(err, "trajectory_error"))
        out["floor_accuracy"] = (
            round(float(np.mean(tr.steps.floor[m] == gf)), 4) if m.any() else None
        )
        out.update(
            _stats(
                np.hypot(tr.steps.x_bc[m] - gx, tr.steps.y_bc[m] - gy), "corrected_trajectory_error"
            )
        )
        out.update(
            _stats(np.hypot(tr.steps.raw_x[m] - gx, tr.steps.raw_y[m] - gy), "raw_pdr_error")
        )
        out["ground_truth"] = "dense"
    else:
        fixes = (gt.t >= tr.start.time) & (gt.t <= tr.steps.t[-1])
        t = gt.t[fixes]
        x, y, f = tr.position_at(t)
        err = np.hypot(x - gt.x[fixes], y - gt.y[fixes])
        out.update(_stats(err, "trajectory_error"))
        out["floor_accuracy"] = round(float(np.mean(f == gt.floor[fixes])), 4) if t.size else None
        # the trajectory the radio map is placed on: backward-corrected when that is on
        xm, ym = tr.position_at(t, corrected=result.radiomap.corrected)[:2]
        fe = error_stats(
            np.hypot(xm - gt.x[fixes], ym - gt.y[fixes]), f - gt.floor[fixes], "fix_error"
        )
        out.update({k: fe[k] for k in ("fix_error_mean_m", "fix_error_p90_m") if k in fe})
        if "fix_error_evaal_p75_m" in fe:
            out["evaal_p75_m"] = fe["fix_error_evaal_p75_m"]
        xb, yb, _ = tr.position_at(t, corrected=True)
        out.update(
            _stats(np.hypot(xb - gt.x[fixes], yb - gt.y[fixes]), "corrected_trajectory_error")
        )
        rx = np.interp(t, tr.steps.t, tr.steps.raw_x)
        ry = np.interp(t, tr.steps.t, tr.steps.raw_y)
        out.update(_stats(np.hypot(rx - gt.x[fixes], ry - gt.y[fixes]), "raw_pdr_error"))
        out["ground_truth"] = f"{int(fixes.sum())} fixes"
        if graph is not None and graph.nodes:
            out.update(_posi_association(result, gt, fixes, graph, xm, ym, f))
    # radio map quality: RP position error where ground truth covers the scan
    acc = rm.accepted & (rm.t >= gt.t[0]) & (rm.t <= gt.t[-1])
    if acc.any():
        gx, gy, gf = gt.at(rm.t[acc])
        out.update(_stats(np.hypot(rm.x[acc] - gx, rm.y[acc] - gy), "reference_point_error"))
    return out


def off_graph_m(tr: Track, graph: LandmarkGraph, most: int = 400) -> float | None:
    """How far the walk's track runs from the graph: the median over its steps after the start
    (up to ``most`` of them, evenly) of the distance to the nearest edge on the step's floor
    (inf on a floor without an edge). What a walk that matched nothing says of its start and
    the graph (verdict.py, ``off_graph``)."""
    idx = np.flatnonzero(tr.steps.segment >= 0)
    if not idx.size:
        return None
    idx = idx[np.linspace(0, idx.size - 1, min(most, idx.size)).astype(int)]
    # as the sensors walked it (forward: no end bent it)
    near = graph.distance_to_edges(tr.steps.x[idx], tr.steps.y[idx], tr.steps.floor[idx])
    return round(float(np.median(near)), 2)


def _number(figures: Mapping[str, Figure], key: str) -> float:
    v = figures.get(key)
    return 0.0 if v is None else float(v)


def pooled_fix_metrics(
    runs: Sequence[tuple[Stages, Session, LandmarkGraph]],
) -> dict[str, Figure]:
    """The association and fix figures pooled over walks with sparse ground truth: ``runs`` is
    a list of (result, session in the graph's frame, graph). Rates are pooled over fixes (not
    averaged over walks); errors are over all fixes of all walks, on the trajectory each radio
    map is placed on."""
    err, ferr, fwd = [], [], []
    node = fixes = match = rule_fixes = strict = strict_fixes = 0.0
    passed_straight = turned_match = 0.0
    for result, session, graph in runs:
        tr, gt = result.track, session.ground_truth
        if gt is None:
            raise ValueError("pooled fix metrics: a walk without ground truth")
        m = summarize(result, session, graph).truth
        num = partial(_number, m)
        n, nr = num("landmark_fixes"), num("landmark_rule_fixes")
        node += num("landmark_node_accuracy") * n
        match += num("landmark_fix_match_rate") * nr
        ns_ = num("landmark_rule_fixes_passed_straight")
        passed_straight += ns_
        turned_match += num("landmark_fix_match_rate_turned") * (nr - ns_)
        fixes, rule_fixes = fixes + n, rule_fixes + nr
        ns = num("landmark_rule_fixes_strict")
        strict += num("landmark_fix_match_rate_strict") * ns
        strict_fixes += ns
        at = (
            (gt.t >= tr.start.time) & (gt.t <= tr.steps.t[-1])
            if tr.steps.t.size
            else gt.t < -np.inf
        )
        x, y, f = tr.position_at(gt.t[at], corrected=result.radiomap.corrected)
        err.append(np.hypot(x - gt.x[at], y - gt.y[at]))
        ferr.append(f - gt.floor[at])
        xf, yf, _ = tr.position_at(gt.t[at])
        fwd.append(np.hypot(xf - gt.x[at], yf - gt.y[at]))
    e, fe = np.concatenate(err or [np.empty(0)]), np.concatenate(ferr or [np.empty(0)])
    st = error_stats(e, fe, "fix_error")
    out: dict[str, Figure] = {
        "walks": len(runs),
        "fixes": int(e.size),
        "landmark_fixes": int(fixes),
        "landmark_node_accuracy": round(node / fixes, 4) if fixes else None,
        "landmark_rule_fixes": int(rule_fixes),
        "landmark_fix_match_rate": round(match / rule_fixes, 4) if rule_fixes else None,
        "landmark_fix_match_rate_strict": round(strict / strict_fixes, 4) if strict_fixes else None,
        "landmark_rule_fixes_passed_straight": int(passed_straight),
        "landmark_fix_match_rate_turned": (
            round(turned_match / (rule_fixes - passed_straight), 4)
            if rule_fixes > passed_straight
            else None
        ),
        "floor_accuracy": st.get("fix_error_floor_accuracy"),
        "fix_error_mean_m": st.get("fix_error_mean_m"),
        "fix_error_p90_m": st.get("fix_error_p90_m"),
        "evaal_p75_m": st.get("fix_error_evaal_p75_m"),
    }
    fw = error_stats(np.concatenate(fwd or [np.empty(0)]), prefix="forward_fix_error")
    out.update(
        {k: fw[k] for k in ("forward_fix_error_mean_m", "forward_fix_error_p90_m") if k in fw}
    )
    return out
