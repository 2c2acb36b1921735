"""When a walk starts (where the walker first sets off) and where: a landmark id given by the user, or ``first-fix`` (the landmark at the
session's first ground-truth fix: for checking the tracker on walks with ground truth)."""

from __future__ import annotations

import difflib
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from workstation.errors import WorkstationError as StartError
from workstation.graph import LandmarkGraph
from workstation.params import PDRParams
from workstation.pipeline.heading import Heading
from workstation.pipeline.steps import Steps
from workstation.session import Session

#: where an inferred start is searched: x, y, floor (None: every floor), radius (m)
Region = tuple[float, float, float | None, float]


@dataclass(frozen=True)
class HandedStart:
    """A start searched within walking reach of where the walk recorded just before ended (a
    campaign's hand-over, :class:`workstation.walks.chain.Handover`), as the walk's summary
    keeps it: that walk, the gap (s), where it ended (x, y, floor), the reach (m), how many
    landmarks lay within it, and whether every floor was searched."""

    walk_before: str
    gap_s: float
    ended_at: tuple[float, float, float]
    reach_m: float
    landmarks_in_reach: int
    any_floor: bool = False

    @property
    def region(self) -> Region:
        """Where the start was searched, as ``--start-within`` takes it."""
        x, y, f = self.ended_at
        return float(x), float(y), None if self.any_floor else float(f), float(self.reach_m)

    def to_json(self) -> dict[str, object]:
        return {"walk_before": self.walk_before, "gap_s": self.gap_s,
                "ended_at": list(self.ended_at), "reach_m": self.reach_m,
                "landmarks_in_reach": self.landmarks_in_reach, "any_floor": self.any_floor}  # fmt: skip

    @classmethod
    def from_json(cls, d: Mapping[str, Any]) -> HandedStart:
        x, y, f = d["ended_at"]
        return cls(str(d["walk_before"]), d["gap_s"], (x, y, f), d["reach_m"],
                   int(d.get("landmarks_in_reach") or 0), bool(d.get("any_floor")))  # fmt: skip


def resolve_start(start: str, session: Session, graph: LandmarkGraph) -> str | None:
    """A node id, ``first-fix``: the landmark at the session's first ground-truth fix, or
    ``infer``: None (the tracker infers it)."""
    if start == "infer":
        return None
    if start != "first-fix":
        return _landmark("--start", start, graph, ("first-fix", "infer"))
    return _at_fix("--start first-fix", session, graph, 0)


def resolve_end(end: str, session: Session, graph: LandmarkGraph) -> str:
    """A node id, or ``last-fix``: the landmark at the session's last ground-truth fix (the
    walk's end as the surveyor gives it: ``pdr.end_node``)."""
    if end != "last-fix":
        return _landmark("--end", end, graph, ("last-fix",))
    return _at_fix("--end last-fix", session, graph, -1)


def _landmark(option: str, node: str, graph: LandmarkGraph, words: tuple[str, ...]) -> str:
    """``node`` when the graph has it; else a :class:`StartError` naming the nearest id."""
    if node not in graph.ids:
        close = difflib.get_close_matches(node, [*words, *graph.ids], n=1)
        takes = ", ".join(["a landmark id", *words[:-1]]) + f" or {words[-1]}"
        raise StartError(
            f"{option} {node}: no such landmark in the graph"
            + (f" — did you mean {close[0]}?" if close else "")
            + f" ({option} takes {takes})"
        )
    return node


def _at_fix(what: str, session: Session, graph: LandmarkGraph, i: int) -> str:
    """The landmark nearest the session's ground-truth fix ``i`` on its floor."""
    gt = session.ground_truth
    if gt is None or not len(gt):
        raise StartError(f"{what}: the session has no ground truth")
    gt = session.in_frame(graph.frame).ground_truth
    assert gt is not None  # in_frame keeps the ground truth checked above
    xyf = graph.xyf()
    d = np.hypot(xyf[:, 0] - gt.x[i], xyf[:, 1] - gt.y[i]) + np.where(
        xyf[:, 2] == gt.floor[i], 0, 1e9
    )
    return graph.ids[int(np.argmin(d))]


#: how the start time was found (:data:`HOW` says each in words)
StartTimeHow = Literal["walking", "after_stand", "after_handling", "no_walking", "given"]


@dataclass(frozen=True)
class StartTime:
    """When the walk starts and how that was found (said in summary.json)."""

    t: float
    how: StartTimeHow  # one of HOW


# a non-handled walking run this long is someone walking: no stand after it is the start's
SUSTAINED_WALK_S = 3.0
STAND_MIN_S = 1.0  # still this long before the first walking: a stand, else setting off at once
HOW: dict[StartTimeHow, str] = {
    "walking": "the walk sets off at once: it starts with its first walking",
    "after_stand": "the walk starts where the walker sets off after standing",
    "after_handling": "the walk starts where the walker sets off after handling the phone",
    "no_walking": "no sustained walking found: the walk starts with its first sample",
    "given": "the start time was given",
}


def walking_bouts(
    steps: Steps, heading: Heading | None = None, handling_rate: float = np.inf
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Runs of the walking state (indices into ``steps.state_t``, end exclusive) and, per
    run, whether it is the phone being handled: the mean |ω| over the run exceeds
    ``handling_rate`` (walking with a phone in hand turns it at 0.2–0.6 rad/s; a calibration
    figure-eight at 2–6 rad/s)."""
    t, walking = steps.state_t, steps.walking
    d = np.diff(np.concatenate([[0], walking.astype(np.int8), [0]]))
    a, b = np.flatnonzero(d == 1), np.flatnonzero(d == -1)
    handled = np.zeros(a.size, bool)
    rr = None if heading is None else heading.rotation_rate
    if heading is not None and rr is not None and rr.size and a.size and np.isfinite(handling_rate):
        c = np.concatenate([[0.0], np.cumsum(rr)])
        i0 = np.searchsorted(heading.t, t[a])
        i1 = np.searchsorted(heading.t, t[b - 1], side="right")
        n = np.maximum(i1 - i0, 1)
        handled = (c[i1] - c[i0]) / n > handling_rate
    return a, b, handled


def start_time(steps: Steps, p: PDRParams, heading: Heading | None = None) -> StartTime:
    """The walk starts where the walker first sets off: the beginning of the first run of the
    walking state that lasts ``start_walk_s``. Walkers who move from the first sample start at
    once, and a mid-walk stop cannot pull the start later.

    "A stand is used when there is one": a still period of ``start_still_s`` before the first
    sustained walking (a run of ``SUSTAINED_WALK_S`` that is not the phone being handled,
    :func:`walking_bouts`) is the stand at the start landmark, and the walk starts with the
    first run after it — the museum's walkers calibrate the phone (figure-eights, which the
    accelerometer alone takes for steps), stand, then set off."""
    t = steps.state_t
    if t.size < 2:
        return StartTime(float(t[0]) if t.size else 0.0, "no_walking")
    a, b, handled = walking_bouts(steps, heading, p.handling_rate)
    dur = t[b - 1] - t[a]
    long = dur >= p.start_walk_s
    if not long.any():
        return StartTime(float(t[0]), "no_walking")
    sustained = np.flatnonzero(long & ~handled & (dur >= SUSTAINED_WALK_S))
    j = int(sustained[0]) if sustained.size else a.size
    # still time after each run before the next one (the last run: to the end)
    nxt = np.append(a[1:] - 1, t.size - 1)
    stands = np.flatnonzero((t[nxt] - t[b - 1])[:j] >= p.start_still_s)
    after = np.flatnonzero(long & (np.arange(a.size) > stands[-1])) if stands.size else a[:0]
    k = int(after[0]) if after.size else int(np.flatnonzero(long)[0])
    t0 = float(t[a[k] - 1] if a[k] > 0 else t[0])  # the last still sample before it
    if after.size and handled[:k].any():
        return StartTime(t0, "after_handling")
    return StartTime(t0, "after_stand" if t0 - t[0] >= STAND_MIN_S else "walking")


def find_start_time(steps: Steps, p: PDRParams, heading: Heading | None = None) -> float:
    """:func:`start_time`'s time."""
    return start_time(steps, p, heading).t
