"""Stream the pipeline to Rerun, stage by stage (an observer: the core never imports this).

One timeline, ``time`` (session seconds). Bulk series go through ``send_columns``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import rerun as rr

from workstation.building.floorplan import FloorPlan
from workstation.fingerprints.localize import Fingerprints
from workstation.graph import LandmarkGraph
from workstation.pipeline.tracking.walk_end import HOW as END_HOW
from workstation.session import Session
from workstation.viz.colours import KINDS, legend_markdown, point_kinds, rgb
from workstation.viz.follow import (
    log_walker_floor,
    log_walker_floor_plans,
    log_walker_floor_points,
    log_walker_floor_route,
)
from workstation.viz.layouts import APP_ID, floor_path
from workstation.viz.plan_image import log_plan_images, log_quality
from workstation.viz.rerun_graph import graph_on_floor, route_on_floor, truth_on_floor
from workstation.viz.rerun_marks import log_walk_marks
from workstation.viz.run_summary import summary_markdown
from workstation.viz.viewer_process import free_port, spawn_viewer, stop_viewer  # noqa: F401 - re-exported
from workstation.viz.walk_marks import walk_marks

TIME = "time"


def _xy(x, y) -> np.ndarray:
    """Map coordinates for display: Rerun's 2D views grow y downwards; north (+y) goes up."""
    return np.column_stack([np.asarray(x, float), -np.asarray(y, float)])


def _series(rec: rr.RecordingStream, path: str, t: np.ndarray, v: np.ndarray) -> None:
    if t.size:
        rec.send_columns(
            path, indexes=[rr.TimeColumn(TIME, duration=t)], columns=rr.Scalars.columns(scalars=v)
        )


def _split_by_floor(x, y, fl):
    """Runs of consecutive samples on one floor: {floor: [strip, ...]}."""
    out: dict[float, list[np.ndarray]] = {}
    if x.size == 0:
        return out
    cut = np.flatnonzero(np.diff(fl) != 0) + 1
    for idx in np.split(np.arange(x.size), cut):
        if idx.size >= 2:
            out.setdefault(float(fl[idx[0]]), []).append(_xy(x[idx], y[idx]))
    return out


def detection_log(d, tr) -> tuple[list[float], list[str], list[str]]:
    """The landmarks' text log: per detection its time, what it was and its verdict (matched,
    with its confidence and a nearly as likely other place; or why it was rejected), then
    where the walk's end was closed (walk_end.py) — times, texts, levels."""
    texts, levels, times = [], [], list(d.t)
    for k in range(len(d)):
        node = tr.detections.node[k]
        # the time in the text: the viewer's time column is too narrow for "+1min 23s"
        head = f"t {d.t[k]:7.1f} s  {d.kind[k]} (value {d.value[k]:.2f})"
        if node:
            text = f"{head} → matched {node}, confidence {tr.detections.confidence[k]:.2f}"
            spread = tr.detections.spread[k]  # a nearly as likely association put it elsewhere
            if spread > 0:
                text += f"; a nearly as likely association puts it {spread:.1f} m away"
            texts.append(text)
            levels.append("WARN" if spread > 0 else "INFO")
        else:
            texts.append(f"{head} → rejected: {tr.detections.reason[k]}")
            levels.append("WARN")
    if tr.end.node:  # walk_end.py: the walk's end closed its last segment
        times.append(float(tr.steps.t[-1]))
        if tr.end.how.startswith("given"):  # the surveyor's end (walk_end.HOW)
            other = END_HOW[tr.end.how]
        elif np.isfinite(tr.end.margin):
            other = f"every other place ≥ {tr.end.margin:.1f} less likely, log-likelihood"
        else:
            other = "no other place"
        texts.append(
            f"t {tr.steps.t[-1]:7.1f} s  the walk ends on {tr.end.node} "
            f"(σ {tr.end.sigma:.1f} m, {other})"
        )
        levels.append("WARN" if tr.end.how == "given_far" else "INFO")
    return times, texts, levels


class RerunLogger:
    """Pipeline observer: ``Pipeline(..., observers=[RerunLogger(rec, session, graph, plan)])``."""

    def __init__(
        self,
        rec: rr.RecordingStream,
        session: Session,
        graph: LandmarkGraph,
        plan: FloorPlan | None = None,
        building=None,
    ):
        self.rec = rec
        self.session = session
        self.graph = graph
        self.plan = plan
        self.building = building  # workstation.building.Building: floor-plan images
        self.floors = sorted(set(graph.floors) | (set(plan.floors) if plan else set()))
        self.logged_static = False
        self._logged: dict[str, tuple] = {}  # stage → (value, what else its drawing shows)

    # ---- static scene and raw traces ------------------------------------------------------
    def log_inputs(self) -> None:
        rec, s = self.rec, self.session
        for name, stream in (
            ("accelerometer", s.accelerometer),
            ("gyroscope", s.gyroscope),
            ("magnetometer", s.magnetometer),
        ):
            for i, axis in enumerate("xyz"):
                _series(rec, f"/sensors/{name}/{axis}", stream.t, stream.xyz[:, i])
        if len(s.accelerometer):
            _series(
                rec,
                "/sensors/accelerometer/magnitude",
                s.accelerometer.t,
                np.linalg.norm(s.accelerometer.xyz, axis=1),
            )
        if s.pressure is not None:
            _series(rec, "/sensors/pressure", s.pressure.t, s.pressure.value)
        if len(s.wifi):
            times, counts = np.unique(s.wifi.t, return_counts=True)
            rec.log(
                "/sensors/wifi/aps_per_scan",
                rr.SeriesPoints(colors=[rgb("aps_per_scan")], marker_sizes=[3.0]),
                static=True,
            )
            _series(rec, "/sensors/wifi/aps_per_scan", times, counts.astype(float))
        self.log_graph(self.graph)

        log_plan_images(rec, self.building, floor_path)
        if self.plan is not None:
            for f in self.plan.floors:
                walls = self.plan.walls(f) * np.array([1, -1, 1, -1])
                if walls.size:
                    rec.log(
                        f"/map/{floor_path(f)}/plan/walls",
                        rr.LineStrips2D(
                            walls.reshape(-1, 2, 2), colors=[rgb("walls")], radii=[0.08]
                        ),
                        static=True,
                    )
        gt = s.ground_truth
        if gt is not None and len(gt):
            for f in np.unique(gt.floor):
                for sub, what in truth_on_floor(gt, float(f)).items():
                    if what is not None:
                        rec.log(f"/map/{floor_path(f)}/{sub}", what, static=True)

    def log_graph(self, graph: LandmarkGraph) -> None:
        for f in graph.floors:
            for sub, what in graph_on_floor(graph, f).items():
                if what is not None:
                    self.rec.log(f"/map/{floor_path(f)}/{sub}", what, static=True)

    def log_route(self, legs, graph: LandmarkGraph) -> None:
        """A survey plan's legs ((walk.leg, from, to): ``survey_plan.output.plan_legs``) as a
        layer under the graph on every floor; a floor the plan does not walk is cleared."""
        for f in sorted(set(graph.floors) | set(self.floors)):
            path = f"/map/{floor_path(f)}/plan_route"
            strips = route_on_floor(legs, graph, f)
            self.rec.log(
                path, strips if strips is not None else rr.Clear(recursive=False), static=True
            )
        self._route = (legs, graph)
        tr = getattr(self, "_follow_track", None)
        if tr is not None:
            times = getattr(self, "_follow_times", ())
            log_walker_floor_route(self.rec, legs, graph, times, tr, TIME)

    # ---- the observer ----------------------------------------------------------------------
    def __call__(self, stage: str, value: Any, pipeline) -> None:
        if not self.logged_static:
            self.log_inputs()
            self.logged_static = True
        elif pipeline.graph is not self.graph:  # edited in the panel: redraw the graph
            self.graph = pipeline.graph
            self.log_graph(self.graph)
            self._logged.clear()
        fn = getattr(self, f"_log_{stage}", None)
        if fn is None:
            return
        # a stage the pipeline took from its cache is drawn already (a threshold change re-ran
        # only belief and the radio map: re-drawing the tracks took most of its latency)
        extra = pipeline.params.gyro.threshold_rad_s if stage == "heading" else None
        last = self._logged.get(stage)
        if last is not None and last[0] is value and last[1] == extra:
            return
        fn(value, pipeline)
        self._logged[stage] = (value, extra)

    def _log_steps(self, st, pipeline) -> None:
        rec = self.rec
        rec.log(
            "/steps/period",
            rr.SeriesPoints(colors=[rgb("step_period")], marker_sizes=[2.0]),
            static=True,
        )
        # a gap of more than twice T_max is a stand, not a step period: one 30-s stand
        # stretched the axis until the steps were a flat line (issue #30)
        ok = np.isfinite(st.period) & (st.period <= 2 * pipeline.params.belief.t_max_s)
        _series(rec, "/steps/period", st.t[ok], st.period[ok])
        _series(rec, "/steps/walking", st.state_t, st.walking.astype(float))
        _series(rec, "/steps/variance", st.state_t, st.variance)
        _series(
            rec,
            "/steps/variance_threshold",
            st.state_t[[0, -1]] if st.state_t.size else st.state_t,
            np.full(min(2, st.state_t.size), pipeline.params.steps.variance_threshold),
        )

    def _log_heading(self, h, pipeline) -> None:
        _series(self.rec, "/heading/vertical_rate/rate", h.t, h.vertical_rate)
        thr = pipeline.params.gyro.threshold_rad_s
        ends = h.t[[0, -1]] if h.t.size else h.t
        _series(self.rec, "/heading/vertical_rate/threshold_pos", ends, np.full(ends.size, thr))
        _series(self.rec, "/heading/vertical_rate/threshold_neg", ends, np.full(ends.size, -thr))
        _series(self.rec, "/heading/gyro", h.t, h.gyro)
        _series(self.rec, "/heading/compass", h.t, h.compass)

    def _log_landmarks(self, d, pipeline) -> None:
        pass  # detections are logged with their verdicts once tracking has run

    def _log_tracking(self, tr, pipeline) -> None:
        rec = self.rec
        d = pipeline.last("landmarks")
        if len(d) or tr.end.node:
            times, texts, levels = detection_log(d, tr)
            rec.send_columns(
                "/landmarks/log",
                indexes=[rr.TimeColumn(TIME, duration=np.asarray(times, float))],
                columns=rr.TextLog.columns(text=texts, level=levels),
            )
            for kind, col in KINDS.items():
                m = d.kind == kind
                if m.any():
                    rec.log(
                        f"/landmarks/confidence/{kind}",
                        rr.SeriesPoints(colors=[col], marker_sizes=[4.0]),
                        static=True,
                    )
                    conf = tr.detections.confidence[m]
                    _series(rec, f"/landmarks/confidence/{kind}", d.t[m], conf)
            thr = pipeline.params.pdr.confidence_threshold
            if len(d):
                _series(rec, "/landmarks/confidence/threshold", d.t[[0, -1]], np.full(2, thr))
        # spatial: raw PDR, corrected trajectory, walker position over time, matched landmarks
        st = tr.steps
        walking = st.segment >= 0
        for name, (x, y), col in (
            ("raw_pdr", (st.raw_x, st.raw_y), rgb("raw_pdr")),
            ("trajectory", (st.x, st.y), rgb("trajectory")),
            ("trajectory_corrected", (st.x_bc, st.y_bc), rgb("trajectory_corrected")),
        ):
            for f, strips in _split_by_floor(x[walking], y[walking], st.floor[walking]).items():
                rec.log(
                    f"/map/{floor_path(f)}/{name}",
                    rr.LineStrips2D(strips, colors=[col], radii=[0.07]),
                    static=True,
                )
        for f in np.unique(st.floor):
            m = st.floor == f
            if m.any():  # at every step: here, or no dot (it stayed on floors already left)
                rec.send_columns(
                    f"/map/{floor_path(f)}/walker",
                    indexes=[rr.TimeColumn(TIME, duration=st.t)],
                    columns=rr.Points2D.columns(positions=_xy(st.x[m], st.y[m])).partition(
                        m.astype(np.int32)
                    ),
                )
                rec.log(
                    f"/map/{floor_path(f)}/walker",
                    rr.Points2D.from_fields(colors=[rgb("walker")], radii=[1.2]),
                    static=True,
                )

        marks = walk_marks(tr, corrected=True)  # once: each floor's map and the walker's
        log_walk_marks(rec, marks)
        self._follow_times = log_walker_floor(
            rec, tr, self.graph, TIME,
            getattr(self, "_follow_times", ()), self.session.ground_truth, marks,
        )  # fmt: skip
        log_walker_floor_plans(rec, self.building, tr, self._follow_times, TIME)
        self._follow_track = tr
        if getattr(self, "_route", None):
            log_walker_floor_route(rec, *self._route, self._follow_times, tr, TIME)
        det = tr.detections
        matched = [*det.node[det.matched], *([tr.end.node] if tr.end.node else [])]
        for f in self.graph.floors:
            ids = [n for n in matched if self.graph.node(n).floor == f]
            if ids:
                pts = [[self.graph.node(n).x, -self.graph.node(n).y] for n in ids]
                rec.log(
                    f"/map/{floor_path(f)}/matched_landmarks",
                    rr.Points2D(pts, radii=[0.7], colors=[rgb("matched_landmarks")]),
                    static=True,
                )

    def _log_belief(self, b, pipeline) -> None:
        tr = pipeline.last("tracking")
        rec = self.rec
        if b.belief.size:
            # each segment's belief held from its start to the next segment (capped for display)
            rec.log(
                "/belief/segment",
                rr.SeriesLines(
                    colors=[rgb("belief")],
                    interpolation_mode=rr.components.InterpolationMode.StepAfter,
                ),
                static=True,
            )
            t0 = np.asarray(tr.segments.t0, float)
            keep = np.concatenate([[True], np.diff(t0) > 0])
            _series(rec, "/belief/segment", t0[keep], np.minimum(b.belief, 200.0)[keep])
            ends = np.array([t0[0], max(float(tr.segments.t1[-1]), t0[0])])
            rec.log("/belief/threshold", rr.SeriesLines(colors=[rgb("threshold")]), static=True)
            _series(rec, "/belief/threshold", ends, np.full(2, b.threshold))

    def _log_radiomap(self, rm, pipeline) -> None:
        rec = self.rec
        for f in np.unique(rm.floor):
            for name, m in point_kinds(rm):
                col = rgb(name)
                mm = m & (rm.floor == f)
                if mm.any():
                    rec.log(
                        f"/map/{floor_path(f)}/reference_points/{name}",
                        rr.Points2D(_xy(rm.x[mm], rm.y[mm]), colors=[col], radii=[0.35]),
                        static=True,
                    )
        tr = pipeline.last("tracking")
        if tr is not None and tr.steps.t.size:  # the map that follows the walker's floor, too
            log_walker_floor_points(rec, rm, getattr(self, "_follow_times", ()), tr, TIME)

        log_quality(rec, Fingerprints.of_walk(rm), self.graph, floor_path)

    def _log_done(self, result, pipeline) -> None:
        summ = result.summary(pipeline.session, pipeline.graph)
        self.rec.log(
            "/summary",
            rr.TextDocument(summary_markdown(summ), media_type=rr.MediaType.MARKDOWN),
            static=True,
        )
        st = result.track.steps
        w = st.segment >= 0
        if summ.quarantined:  # a wrong walk must not look like a good one
            for f, strips in _split_by_floor(st.x_bc[w], st.y_bc[w], st.floor[w]).items():
                line = rr.LineStrips2D(strips, colors=[rgb("quarantined")], radii=[0.12])
                self.rec.log(f"/map/{floor_path(f)}/trajectory_corrected", line, static=True)
        self.rec.log(
            "/legend",
            rr.TextDocument(legend_markdown(), media_type=rr.MediaType.MARKDOWN),
            static=True,
        )


# ---- where the recording goes -------------------------------------------------------------
def new_recording(recording_id: str | None = None) -> rr.RecordingStream:
    rec = rr.RecordingStream(APP_ID, recording_id=recording_id)
    rec.set_log_time_enabled(False)
    return rec
