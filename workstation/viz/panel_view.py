"""Where the panel opens: the floor and the view of the walk (pure functions over its track;
:class:`~workstation.viz.panel.SurveyPanel` frames its camera with them)."""

from __future__ import annotations

import numpy as np

WALK_MARGIN_M = 5.0  # the view opens this far around the walk (as Rerun's walker's map)
MIN_VIEW_M = 40.0  # and at least this wide (a walk that hardly moved: the plan around it)
UNDER_PANEL = 0.15  # of the view's width: how far right of the walk's middle the view looks


def walk_floor(tr, graph, floors: list[float], start: str | None) -> float:
    """The floor the panel opens on: where the walk spends most of its time (issue #64 item 5:
    the museum walk opened on floor 0, a short stretch of it, with 221 of its 350 rows on −1);
    its start's floor when it never set off; the first floor else."""
    on = (tr.steps.segment >= 0) & np.isfinite(tr.steps.floor)
    if on.any():
        fl, n = np.unique(tr.steps.floor[on], return_counts=True)
        return float(fl[int(np.argmax(n))])
    if start in graph.ids:
        return graph.node(start).floor
    return floors[0] if floors else 0.0


def walk_view(tr, gt, floor: float) -> tuple[tuple[float, float], float] | None:
    """(centre, extent) of a view over the walk on ``floor`` (and where it really went); None
    when it has no step there."""
    on = (
        (tr.steps.segment >= 0)
        & (tr.steps.floor == floor)
        & np.isfinite(tr.steps.x)
        & np.isfinite(tr.steps.y)
    )
    if not on.any():
        return None
    xy = [np.column_stack([tr.steps.x[on], tr.steps.y[on]])]
    if gt is not None and len(gt):  # and where it really went: a walk placed off shows so
        xy.append(np.column_stack([gt.x, gt.y])[gt.floor == floor])
    pts = np.concatenate(xy)
    lo, hi = pts.min(axis=0) - WALK_MARGIN_M, pts.max(axis=0) + WALK_MARGIN_M
    c, ext = (lo + hi) / 2, float(max(max(hi - lo), MIN_VIEW_M))
    # looked at a little east of it: the control panel covers the canvas's right quarter
    return (float(c[0]) + UNDER_PANEL * ext, float(c[1])), ext
