"""The walk's start, end and direction (:mod:`.walk_marks`) logged to Rerun: on the floor each
lies on (``/map/<floor>/walk_marks``) and in the Walker's floor view, over the corrected track
the radio map is placed on."""

from __future__ import annotations

import numpy as np
import rerun as rr

from workstation.viz.colours import rgb
from workstation.viz.layouts import floor_path
from workstation.viz.walk_marks import WalkMarks

ARROW_M = 2.5  # drawn length of a direction arrow
LABEL_BELOW_M = 1.4  # a start/end label's anchor below its mark (past the walker's sphere)


def marks_on_floor(marks: WalkMarks | None, f: float) -> dict[str, rr.AsComponents | None]:
    """What of the marks lies on floor ``f``: start, end, direction (None: nothing there)."""
    out: dict[str, rr.AsComponents | None] = {"start": None, "end": None, "direction": None,
                                              "start_label": None, "end_label": None}  # fmt: skip
    if marks is None:
        return out
    col = rgb("walk_marks")
    text = tuple(int(v + (255 - v) * 0.6) for v in col[:3])  # on Rerun's dark label box
    for (x, y, fl), label, name in ((marks.start, marks.start_label, "start"),
                                    (marks.end, marks.end_label, "end")):  # fmt: skip
        if fl == f:
            out[name] = rr.Points2D([[x, -y]], radii=[1.0], colors=[col], labels=[label],
                                    show_labels=False)  # fmt: skip
            # the words on an anchor of their own, below the mark: the walker's sphere (1.2 m)
            # sat on the start and hid them, and the mark's dark teal did not read on the box
            out[f"{name}_label"] = rr.Points2D([[x, -y + LABEL_BELOW_M]], radii=[0.0],
                                               colors=[text], labels=[label], show_labels=True)  # fmt: skip
    a = marks.on_floor(f)
    if len(a):
        out["direction"] = rr.Arrows2D(
            origins=np.column_stack([a[:, 0], -a[:, 1]]),
            vectors=ARROW_M * np.column_stack([a[:, 3], -a[:, 4]]),
            colors=[col],
            radii=[0.12],
        )
    return out


def log_walk_marks(rec: rr.RecordingStream, marks: WalkMarks | None) -> None:
    """The marks (of the corrected track: :func:`.walk_marks.walk_marks`) on each floor's map,
    static."""
    if marks is None:
        return
    floors = {marks.start[2], marks.end[2], *marks.arrows[:, 2].tolist()}
    for f in sorted(floors):
        for name, what in marks_on_floor(marks, f).items():
            if what is not None:
                rec.log(f"/map/{floor_path(f)}/walk_marks/{name}", what, static=True)


def log_estimates(rec: rr.RecordingStream, est, track) -> None:
    """A walk's scans localized on the building's map (``view --map``: walk_estimates.py), per
    floor: the estimates (static points) and a thin line from each to where the walk's
    corrected track was at that scan — where the map's WiFi and the track disagree, and by
    how much."""
    c = est.columns
    ok = c["localized"]
    t = c["t"][ok]
    x, y, f = c["x"][ok], c["y"][ok], c["floor"][ok]
    on = track.steps.segment >= 0
    tx = (
        np.interp(t, track.steps.t[on], track.steps.x_bc[on])
        if on.any()
        else np.full(t.size, np.nan)
    )
    ty = (
        np.interp(t, track.steps.t[on], track.steps.y_bc[on])
        if on.any()
        else np.full(t.size, np.nan)
    )
    col = rgb("localized")
    for fl in np.unique(f):
        m = f == fl
        root = f"/map/{floor_path(fl)}/localized"
        rec.log(f"{root}/estimates", rr.Points2D(np.column_stack([x[m], -y[m]]), colors=[col],
                radii=[0.3]), static=True)  # fmt: skip
        both = m & np.isfinite(tx)
        if both.any():
            strips = np.stack([np.column_stack([x[both], -y[both]]),
                               np.column_stack([tx[both], -ty[both]])], axis=1)  # fmt: skip
            rec.log(f"{root}/to_track", rr.LineStrips2D(strips, colors=[col], radii=[0.03]),
                    static=True)  # fmt: skip
