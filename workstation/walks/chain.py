"""A walk begins where the walk before it ended (beyond the paper; issue #28 item 4).

A surveyor records walk after walk: stop the recording, save it, start the next one where they
stand. The phone's clock says which walk came right before which and how long nobody
recorded: on mall F1, 88 of the 105 gaps between one walk's end and the next walk's start are
under 120 s (75 under 30 s), and no two walks overlap. Where the walk before ended is known
once its start is (given by the surveyor, or inferred beyond doubt): the next walk began within
walking distance of there. So its start is searched only among the landmarks in that reach —
the tracker's own search (eq. 11–14 and the chain of matches) over fewer starts, not a new
score — and its margin is taken against the other starts in the reach.

The reach, around where the walk before ended (its last step, backward-corrected):

    r = ``WALK_SPEED_MS`` · gap + 3 σ_end + ``SLACK_M``

— a walking pace over the time nobody recorded (the walker may have walked on: 0–15 m in the
mall's 5–20-s gaps), three σ of that end, and the landmark's own size. σ_end is
``sigma.AT_LANDMARK_M``-small where the end closed on a landmark placed to within
``state.END_CHECK_M``, else the open end's drift (sigma.py: hypot(σ₀, 2 · drift · d) with d
walked since the last match) or the loose end's own σ, whichever is larger. The reach is on the
floor the walk before ended on when the recordings name the same floor (the Microsoft
format's ``FloorName``), else on every floor.

Only walks that follow each other are linked: sorted by their wall clock, a walk and the next
one, 0–``MAX_GAP_S`` apart, recorded by the same device model where both name one, and no other
walk of the building recorded between the first one's start and the second one's end (two
surveyors at once would interleave their walks). Measured on mall F1 (every 2nd walk's start
given, the others inferred): 11 walks handed a start beyond doubt, all 11 right (none before;
docs/decisions.md).
"""

from __future__ import annotations

import math
from collections.abc import Collection, Sequence
from dataclasses import dataclass, field

import numpy as np

from workstation.graph import LandmarkGraph
from workstation.params import Params
from workstation.pipeline import Pipeline, Result
from workstation.pipeline.confidence import open_sigma
from workstation.pipeline.start import HandedStart, Region
from workstation.pipeline.summary import Reason
from workstation.pipeline.tracking.state import END_CHECK_M, Track
from workstation.pipeline.verdict import quarantine
from workstation.session import Session

WALK_SPEED_MS = 1.3  # a walking pace: how far the walker may have gone while nobody recorded
SLACK_M = 2.0  # a landmark is a place a stride or two across
MAX_GAP_S = 120.0  # longer gaps link nothing (the reach would be the whole floor anyway)
CLOSED_END_M = 0.7  # σ of an end closed on a landmark it was placed near (hypot(0.5, 0.5))
#: quarantine reasons (verdict.py) that leave unknown where a walk ended: it hands nothing on
DOUBTFUL_END = frozenset({"start_ambiguous", "end_far", "no_walking"})


@dataclass(frozen=True)
class Handover:
    """Where the walk before (``before``) ended and the landmarks within reach of it."""

    before: str
    gap_s: float
    x: float
    y: float
    floor: float
    sigma_m: float
    radius_m: float
    among: tuple[str, ...] = field(repr=False)
    same_floor: bool = True  # the reach is on ``floor`` only (else on every floor)

    @property
    def region(self) -> Region:
        """(x, y, floor — None: every floor —, radius): what ``--start-within`` takes."""
        return self.x, self.y, self.floor if self.same_floor else None, self.radius_m

    def handed(self) -> HandedStart:
        """What the walk handed this start keeps of it (its summary's ``start_after``)."""
        return HandedStart(self.before, round(self.gap_s, 1),
                           (round(self.x, 2), round(self.y, 2), self.floor),
                           round(self.radius_m, 1), len(self.among), not self.same_floor)  # fmt: skip


def wall_clock(session: Session) -> tuple[float, float] | None:
    """The walk's recording (start, end) in seconds since the epoch; None when the file does
    not say when it was recorded."""
    ms = session.metadata.start_time_ms
    if ms is None or not math.isfinite(float(ms)):
        return None
    t0 = float(ms) / 1000.0
    return t0 + session.start, t0 + session.end


def end_sigma(track: Track) -> float:
    """σ (m) of where the walk ended (module doc)."""
    if track.end.node and track.end.sigma <= END_CHECK_M:
        return CLOSED_END_M
    t0 = track.segments.t0[-1] if track.segments.t0.size else track.steps.t[0]
    k = track.steps.t >= t0
    d = (
        float(np.hypot(np.diff(track.steps.x[k]), np.diff(track.steps.y[k])).sum())
        if k.sum() > 1
        else 0.0
    )
    drift = open_sigma(0.0, d)
    loose = track.end.sigma if math.isfinite(track.end.sigma) else 0.0
    return max(drift, loose)


def where_ended(track: Track) -> tuple[float, float, float, float]:
    """Where ``track`` ended — x, y, floor of its last step (backward-corrected) — and σ (m)."""
    return (
        float(track.steps.x_bc[-1]),
        float(track.steps.y_bc[-1]),
        float(track.steps.floor[-1]),
        end_sigma(track),
    )


def handover(
    end: Sequence[float], gap_s: float, graph: LandmarkGraph, before: str = "",
    same_floor: bool = True,
) -> Handover:  # fmt: skip
    """The landmarks within reach of ``end`` (:func:`where_ended` of the walk before,
    ``before``) for a walk that started ``gap_s`` later (module doc)."""
    x, y, f, sigma = (float(v) for v in end)
    r = WALK_SPEED_MS * max(gap_s, 0.0) + 3.0 * sigma + SLACK_M
    among = graph.within(x, y, f if same_floor else None, r)
    return Handover(before, float(gap_s), x, y, f, sigma, r, among, same_floor)


def follows(clocks: list, devices: list | None = None) -> dict[int, tuple[int, float]]:
    """For each walk that follows another (module doc): its index → (the walk before, the gap
    in seconds). ``clocks``: per walk (start, end) or None; ``devices``: per walk its device
    model or ""/None."""
    known = sorted((c[0], c[1], i) for i, c in enumerate(clocks) if c is not None)
    # the latest end among the walks that began before each one: another walk still recording
    ends_before = np.maximum.accumulate([-math.inf] + [e for _, e, _ in known])
    out: dict[int, tuple[int, float]] = {}
    for k in range(len(known) - 1):
        s0, e0, a = known[k]
        s1, e1, b = known[k + 1]
        gap = s1 - e0
        if not 0.0 <= gap <= MAX_GAP_S:
            continue
        if devices is not None and devices[a] and devices[b] and devices[a] != devices[b]:
            continue
        # no third walk recorded within [s0, e1]: one surveyor, one phone at a time (sorted by
        # start, that is one begun before ``a`` still running, or the next one begun before
        # ``b`` ended)
        if ends_before[k] > s0 or (k + 2 < len(known) and known[k + 2][0] < e1):
            continue
        out[b] = (a, gap)
    return out


def same_floor_named(fa: str | None, fb: str | None) -> bool:
    """Both recordings name their floor (the reader's ``floor_name``), and it is the same one."""
    return bool(fa) and fa == fb


def region_arg(region: Region) -> str:
    """``region`` as ``--start-within`` takes it: X,Y,FLOOR,R (FLOOR ``any``: every floor)."""
    x, y, f, r = region
    return f"{x:g},{y:g},{'any' if f is None else f'{f:g}'},{r:g}"


def hand_over(
    sessions: Sequence[Session], graph: LandmarkGraph, params: Params, results: list[Result],
    given: Collection[int] = frozenset(), names: Sequence[str] | None = None,
) -> dict[int, Handover]:  # fmt: skip
    """Each walk whose start was inferred and is ambiguous, that follows (:func:`follows`) a walk
    whose start is certain — given (``given``: indices), or inferred beyond doubt — and not
    otherwise doubtful, run again with its start searched within the reach of where that walk
    ended; in time order, so a walk made certain hands over to the next. ``results`` (one per
    session, in order) are replaced in place; returns the :class:`Handover` per walk run
    again."""

    names = names or [str(i) for i in range(len(sessions))]
    clocks = [wall_clock(s) for s in sessions]
    links = follows(clocks, [s.metadata.device for s in sessions])
    p = params.updated(**{"pdr.start_node": None})

    def doubts(i: int) -> set[Reason]:
        held = {q.reason for q in quarantine(results[i].summary())}
        return held - {"start_ambiguous"} if i in given else held

    out: dict[int, Handover] = {}
    began = {i: c[0] for i, c in enumerate(clocks) if c is not None}
    for b in sorted(links, key=began.__getitem__):
        a, gap = links[b]
        if b in given or "start_ambiguous" not in doubts(b):
            continue
        if doubts(a) & DOUBTFUL_END:
            continue  # where the walk before ended is not known
        floors = (s.metadata.floor_name for s in (sessions[a], sessions[b]))
        h = handover(where_ended(results[a].track), gap, graph, names[a], same_floor_named(*floors))
        if not h.among:
            continue
        pipe = Pipeline(sessions[b], graph, p, start_within=h.region)
        results[b] = pipe.run()
        out[b] = h
    return out
