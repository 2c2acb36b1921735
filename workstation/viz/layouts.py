"""Rerun blueprints, declared as code (the files in ``layouts/`` are generated from these).

Entity paths mirror the pipeline: ``/sensors/*`` raw traces, ``/steps/*``, ``/heading/*``,
``/landmarks/*``, ``/belief/*``, ``/radiomap/*`` and ``/map/<floor>/*`` for the spatial scene.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import rerun.blueprint as rrb
from rerun.blueprint.encodings import TimelineColumn

from workstation.building.floorplan import FloorPlan
from workstation.errors import WorkstationError
from workstation.graph import LandmarkGraph
from workstation.session.model import GroundTruth

APP_ID = "workstation"
LAYOUTS = ("overview", "landmarks", "radiomap")
# the candidate log: level and message, the time inside the message (the viewer's time column
# cuts "+1min 23.4s" to "+1…")
_LOG_COLUMNS = rrb.TextLogColumns(
    timeline_columns=[TimelineColumn("time", visible=False)],
    text_log_columns=["loglevel", "body"],
)


def floor_path(f: float) -> str:
    """Entity path segment of a floor: 0 → floor_0, -1 → floor_m1, 1.5 → floor_1p5."""
    s = f"{int(f)}" if float(f).is_integer() else f"{f:g}".replace(".", "p")
    return "floor_" + s.replace("-", "m")


BOUNDS_PAD_M = 5.0  # around a floor's landmarks in its view


def _bounds(extent):
    """A view's framing for (xmin, xmax, ymin, ymax) in metres, the map drawn north up (−y)."""
    if extent is None:
        return None
    x0, x1, y0, y1 = extent
    p = BOUNDS_PAD_M
    return rrb.VisualBounds2D(x_range=[x0 - p, x1 + p], y_range=[-y1 - p, -y0 + p])


def _floor_views(floors, name="Floor {f:g}", hide=("quality",), extents=None, follow=None):
    """One 2-D view per floor. ``hide``: sub-trees left out (quality maps only show in the
    radiomap layout; per-AP heatmaps are listed there, off until switched on). ``extents``:
    floor → (xmin, xmax, ymin, ymax) of its landmarks, each view framed on them (left to
    itself Rerun framed the plan image and cut landmarks off: museum L08/L09, L34/L35)."""
    extents = extents or {}
    if len(floors) == 1 and follow:  # the one floor's view is the walker's: framed on the walk
        extents = {floors[0]: follow}
    contents = ["+ $origin/**"] + [f"- $origin/{h}/**" for h in hide]
    views = [
        rrb.Spatial2DView(
            origin=f"/map/{floor_path(f)}",
            name=name.format(f=f),
            contents=contents,
            visual_bounds=_bounds(extents.get(f)),
        )  # fmt: skip
        for f in floors
    ]
    if len(views) == 1:
        return views[0]
    # first, and open: the map that follows the floor the walker is on (viz/follow.py)
    every = [e for e in extents.values() if e is not None]
    whole = (
        (min(e[0] for e in every), max(e[1] for e in every),
         min(e[2] for e in every), max(e[3] for e in every)) if every else None
    )  # fmt: skip
    # framed on where the walk went when that is known (issue #50 item 5: on the mall's whole
    # 145-m graph the walk was a speck), else on every floor's graph
    walker = rrb.Spatial2DView(
        origin="/walker_floor", name="Walker's floor", visual_bounds=_bounds(follow or whole)
    )
    return rrb.Tabs(walker, *views, active_tab=0)


def blueprint(
    name: str, floors: list[float], pressure: bool = True, extents: dict | None = None,
    follow: tuple | None = None,
) -> rrb.Blueprint:  # fmt: skip
    """Per-floor tabs behind a first "Walker's floor" tab that follows the walker (open by
    default: the recording opens on the floor the walk is on). ``pressure``: a pressure plot
    (walks with no barometer get none: it was an empty box). ``extents``: floor → (xmin, xmax,
    ymin, ymax) of its landmarks, to frame each floor's view on its whole graph."""
    floors = sorted(floors) or [0.0]
    baro = (
        [rrb.TimeSeriesView(origin="/sensors/pressure", name="Pressure (hPa)")] if pressure else []
    )

    if name == "overview":
        body = rrb.Horizontal(
            _floor_views(floors, extents=extents, follow=follow),
            rrb.Vertical(
                rrb.TimeSeriesView(origin="/belief", name="Belief per segment"),
                *baro,
                rrb.TimeSeriesView(origin="/steps/period", name="Step period (s)"),
                rrb.Tabs(  # the summary first: a quarantined walk says so on opening
                    rrb.TextDocumentView(origin="/summary", name="Summary"),
                    rrb.TextLogView(
                        origin="/landmarks/log", name="Landmarks", columns=_LOG_COLUMNS
                    ),
                    rrb.TextDocumentView(origin="/legend", name="Legend"),
                ),
            ),
            column_shares=[3, 2],
        )
    elif name == "landmarks":
        body = rrb.Horizontal(
            rrb.Vertical(
                rrb.TimeSeriesView(origin="/sensors/accelerometer", name="Accelerometer (m/s²)"),
                rrb.TimeSeriesView(origin="/steps/walking", name="Walking (1) / still (0)"),
                rrb.TimeSeriesView(
                    origin="/steps",
                    contents=["/steps/variance", "/steps/variance_threshold"],
                    name="Acceleration variance ((m/s²)²)",
                ),
                rrb.TimeSeriesView(
                    origin="/heading",
                    contents=["/heading/vertical_rate/**"],
                    name="Vertical rate (rad/s)",
                ),
                *baro,
                rrb.TimeSeriesView(origin="/landmarks/confidence", name="Candidate confidence"),
            ),
            rrb.Vertical(
                rrb.TextLogView(origin="/landmarks/log", name="Candidates", columns=_LOG_COLUMNS),
                _floor_views(floors, extents=extents, follow=follow),
            ),
            column_shares=[3, 2],
        )
    elif name == "radiomap":
        body = rrb.Horizontal(
            _floor_views(floors, hide=("quality/ap",), extents=extents, follow=follow),
            rrb.Vertical(
                rrb.TimeSeriesView(origin="/belief", name="Belief per segment"),
                rrb.TimeSeriesView(origin="/sensors/wifi", name="APs per scan"),
                rrb.TextDocumentView(origin="/summary", name="Summary"),
            ),
            column_shares=[3, 2],
        )
    else:
        raise WorkstationError(f"unknown layout {name!r}: choose from {', '.join(LAYOUTS)}")
    return rrb.Blueprint(body, rrb.TimePanel(state="collapsed"), collapse_panels=False)


def write_layouts(folder: str | Path, floors: list[float] | None = None) -> list[Path]:
    """Generate ``layouts/<name>.rbl`` for the given floors (default: 0 and 1)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for name in LAYOUTS:
        p = folder / f"{name}.rbl"
        blueprint(name, floors or [0.0, 1.0]).save(APP_ID, str(p))
        out.append(p)
    return out


def default_blueprint(
    layout: str, graph: LandmarkGraph, plan: FloorPlan | None, pressure: bool = True, session=None,
    track=None,
):  # fmt: skip
    """The layout with one tab per floor of the graph and the plan, behind the "Walker's floor"
    tab that opens first (it shows the floor the walk is on); ``pressure``: the walk has a
    barometer (else no empty pressure plot). Each floor's view is framed on its landmarks and,
    given the walk (``session``) with a ground truth, where the walk went on it (the museum's
    floor −1 has two landmarks: framed on them alone it showed 14 × 21 m of a 60-m walk); given
    its run's ``track`` too, where the track went (issue #50 item 5: a walk without a ground
    truth opened on the whole graph, a walk placed 57 m off opened without its track)."""
    truth = None if session is None else session.in_frame(graph.frame).ground_truth
    where = _walked(track, truth)  # x, y, floor of where the walk went (and its track)
    floors = sorted(set(graph.floors) | (set(plan.floors) if plan else set()))
    xyf = graph.xyf()
    pts = {f: xyf[xyf[:, 2] == f, :2] for f in graph.floors}
    for f in np.unique(where[:, 2]):
        on = where[where[:, 2] == f, :2]
        pts[float(f)] = np.vstack([pts.get(float(f), np.empty((0, 2))), on])
    extents = {
        f: (p[:, 0].min(), p[:, 0].max(), p[:, 1].min(), p[:, 1].max())
        for f, p in pts.items()
        if len(p)
    }
    walked = (  # the Walker's floor frames where the walk went, when that is known
        tuple(float(v) for v in (where[:, 0].min(), where[:, 0].max(), where[:, 1].min(),
                                 where[:, 1].max()))
        if len(where) else None
    )  # fmt: skip
    return blueprint(
        layout, floors, pressure, {f: tuple(map(float, e)) for f, e in extents.items()}, walked
    )


def _walked(track, truth: GroundTruth | None) -> np.ndarray:
    """(N, 3) x, y, floor: the ground truth's points and where a run's ``track`` went (either
    may be None)."""
    parts = [np.empty((0, 3))]
    if truth is not None and len(truth):
        parts.append(np.column_stack([truth.x, truth.y, truth.floor]))
    if track is not None:
        on = (track.steps.segment >= 0) & np.isfinite(track.steps.x) & np.isfinite(track.steps.y)
        parts.append(np.column_stack([track.steps.x[on], track.steps.y[on], track.steps.floor[on]]))
    return np.vstack(parts)
