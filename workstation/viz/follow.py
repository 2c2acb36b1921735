"""The "Walker's floor" view: one map that follows the floor the walker is on.

Rerun's views cannot switch tabs as time moves, so the map is logged again under
``/walker_floor`` at every moment the tracked floor changes (the graph and the corrected
trajectory of the floor entered; a handful of rows per walk), and the walker's position at every
step. Scrubbing the time line then shows whichever floor the walker was on.

The floors' plan images: logged with a time, Rerun 0.41 drew an image in pixels, not through its
transform (tried; screenshot). So each floor's image is static under ``/walker_floor/plan/<floor>``
with its own static transform, and only the transform of its parent changes with time: in place
while the walker is on that floor, ``FAR_M`` away while not (Rerun has no visibility over time).
"""

from __future__ import annotations

import numpy as np
import rerun as rr

from workstation.viz.colours import point_kinds, rgb
from workstation.viz.layouts import floor_path
from workstation.viz.plan_image import log_plan_image
from workstation.viz.rerun_graph import graph_on_floor, index_runs, route_on_floor, truth_on_floor
from workstation.viz.rerun_marks import marks_on_floor
from workstation.viz.walk_marks import walk_marks

ORIGIN = "/walker_floor"
FAR_M = 1e6  # where a plan not on view is moved (the view's bounds are set: it never frames it)


def floor_changes(floor: np.ndarray) -> np.ndarray:
    """Indices of the steps where the floor differs from the step before (and the first)."""
    floor = np.asarray(floor, float)
    if floor.size == 0:
        return np.empty(0, int)
    return np.flatnonzero(np.r_[True, floor[1:] != floor[:-1]])


def log_walker_floor(rec, tr, graph, time: str, again=(), gt=None, marks=None) -> list[float]:
    """Log the follow view for track ``tr`` (with plain PDR and ground truth ``gt`` when given;
    the reference points follow from :func:`log_walker_floor_points`); returns the times
    logged. ``again``: times logged for an earlier track (the editor re-runs): logged anew with
    this track's floor, so a floor change an edit removed leaves no stale map behind."""
    if tr.steps.t.size == 0:
        return []
    times = sorted({float(tr.steps.t[i]) for i in floor_changes(tr.steps.floor)} | set(again))
    walking = tr.steps.segment >= 0
    marks = marks or walk_marks(tr, corrected=True)  # the start, end and direction
    for t in times:
        f = _floor_at(tr, t)
        rec.set_time(time, duration=t)
        rec.log(f"{ORIGIN}/label", rr.TextDocument(f"floor {f:g}"))
        _log_floor(rec, f, tr, walking, graph, gt)
        for name, what in marks_on_floor(marks, f).items():  # start, end, direction
            rec.log(f"{ORIGIN}/walk_marks/{name}", what or rr.Clear(recursive=False))
    rec.reset_time()
    rec.send_columns(
        f"{ORIGIN}/walker",
        indexes=[rr.TimeColumn(time, duration=tr.steps.t)],
        columns=rr.Points2D.columns(positions=np.column_stack([tr.steps.x, -tr.steps.y])),
    )
    rec.log(
        f"{ORIGIN}/walker",
        rr.Points2D.from_fields(colors=[rgb("walker")], radii=[1.2]),
        static=True,
    )
    return times


def _strips(x, y, m, colour, radius) -> rr.LineStrips2D:
    return rr.LineStrips2D([np.column_stack([x[r], -y[r]]) for r in index_runs(m)],
                           colors=[colour], radii=[radius])  # fmt: skip


def _log_floor(rec, f, tr, walking, graph, gt=None) -> None:
    for sub, what in graph_on_floor(graph, f).items():
        rec.log(f"{ORIGIN}/{sub}", what if what is not None else rr.Clear(recursive=False))
    m = walking & (tr.steps.floor == f)
    rec.log(
        f"{ORIGIN}/trajectory_corrected",
        _strips(tr.steps.x_bc, tr.steps.y_bc, m, rgb("trajectory_corrected"), 0.07),
    )
    rec.log(f"{ORIGIN}/raw_pdr", _strips(tr.steps.raw_x, tr.steps.raw_y, m, rgb("raw_pdr"), 0.05))
    if gt is not None and len(gt) > 1:  # the fixes too (issue #50 item 5: none drawn here)
        for sub, what in truth_on_floor(gt, f).items():
            rec.log(f"{ORIGIN}/{sub}", what if what is not None else rr.Clear(recursive=False))


def log_walker_floor_points(rec, rm, times, tr, time: str) -> None:
    """The reference points (kept, on standby, left out) of the floor the walker is on, at the times the
    follow view changes floor (:func:`log_walker_floor`)."""
    for t in times:
        f = _floor_at(tr, t)
        rec.set_time(time, duration=t)
        for name, sel in point_kinds(rm):
            m = sel & (rm.floor == f)
            rec.log(
                f"{ORIGIN}/reference_points/{name}",
                rr.Points2D(np.column_stack([rm.x[m], -rm.y[m]]), colors=[rgb(name)],
                            radii=[0.35]),
            )  # fmt: skip
    rec.reset_time()


def log_walker_floor_route(rec, legs, graph, times, tr, time: str) -> None:
    """A survey plan's legs (:func:`~.rerun_graph.route_on_floor`) on the floor the walker is
    on, at the times the follow view changes floor."""
    for t in times:
        f = _floor_at(tr, t)
        rec.set_time(time, duration=t)
        strips = route_on_floor(legs, graph, f)
        rec.log(f"{ORIGIN}/plan_route", strips if strips is not None else rr.Clear(recursive=False))
    rec.reset_time()


def log_walker_floor_plans(rec, building, tr, times, time: str) -> None:
    """The plan image of each floor of ``building`` in the follow view, shown at the ``times``
    (from :func:`log_walker_floor`) the walker is on its floor, moved out of sight otherwise."""
    if building is None or not len(times):  # no step, no floor change
        return
    floor_at = {t: _floor_at(tr, t) for t in times}
    first = min(times)
    for f, info in sorted(building.floors.items()):
        if info.image is None:
            continue
        base = f"{ORIGIN}/plan/{floor_path(f)}"
        log_plan_image(rec, f"{base}/image", info.image)
        for t in sorted({*times, min(first, 0.0)}):
            here = floor_at.get(t, floor_at[first]) == f
            rec.set_time(time, duration=t)
            rec.log(
                base, rr.Transform3D(translation=[0.0, 0.0, 0.0] if here else [FAR_M, FAR_M, 0.0])
            )
    rec.reset_time()


def _floor_at(tr, t: float) -> float:
    return float(
        tr.steps.floor[
            int(np.clip(np.searchsorted(tr.steps.t, t, "right") - 1, 0, tr.steps.t.size - 1))
        ]
    )
