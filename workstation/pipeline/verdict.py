"""Whether a walk's result may go into a radio map: "never a wrong walk in the map".

A walk the pipeline is unsure of still writes its result, but its reference points are
*quarantined*: not merged, not exported from a campaign, refused by ``merge`` and
``localize --map`` (unless ``--include-quarantined``), marked in ``summary.json`` and in
``run``'s exit status (:data:`EXIT_QUARANTINED`), and listed in ``campaign.md`` as "needs the
surveyor", each with its reason and what to do.

The reasons (beyond the paper; docs/decisions.md):

- ``start_ambiguous``: the start was inferred, and the best start elsewhere explains the
  sensors almost as well (:data:`metrics.START_AMBIGUOUS_MARGIN`). Every point hangs on the
  start: a wrong one puts the whole walk on another corridor.
- ``no_walking``: no step after the start (a phone lying still, or an accelerometer that
  missed the steps): every scan lands on the start landmark, which nobody checked (issue #33:
  a phone lying still gave 58 reference points and exit 0).
- ``nothing_matched``: the start was *inferred*, and no landmark after it was matched — no
  detection, and the walk's end did not close on one placed to within ``END_CHECK_M``
  (:mod:`.walk_end`): the start itself rests on nothing the sensors saw. A walk from a *given*
  start that matched nothing is plain dead reckoning from a known place: not a reason by
  itself (issue #49: on the mall's hidden floors most such walks were placed within 2 m). Its
  points carry the open stretch's σ, which grows with the distance walked from the start
  (:mod:`.sigma`), and the σ cut keeps the near ones; the building's other walks check it
  (:mod:`workstation.walks.joint`).
  An end that closes unambiguously, that tightly, checks the whole walk: on the mall's 106
  walks with every detection removed, the 11 such ends lie 0.6 m (mean; at most 1.8 m) from
  the walk's last tap. A looser one does not: a walk given a start 400 m from where it was
  closes its 60-m end (σ 12 m) on a landmark of a sparse graph.
- ``off_graph``: a walk from a given start matched nothing, and its dead-reckoned track runs
  farther than ``OFF_GRAPH_M`` from the graph's edges (median over its steps): the sensors
  contradict the start or the graph — walkers walk where the graph's edges are.
- ``end_far``: the surveyor gave the walk's end (``pdr.end_node``: "End here", ``--end``),
  but the sensors end the walk elsewhere (farther than 3σ and 5 m): the walk, its start or
  the given end is wrong. A given end the sensors agree with checks the walk as a match
  does — the surveyor knows where the recording stopped as they know where it started.
- ``sensor_hole``: the accelerometer or the gyroscope recorded nothing for longer than
  :data:`MAX_HOLE_S` (issue #55 item 6): nothing says where the walker went meanwhile, and two
  recordings joined into one file look exactly so — a second walk's points placed where the
  first ended (two mall walks joined so: 1–103 m off, none quarantined before). The 116 real
  walks here (106 mall, 10 museum) have no hole longer than 0.1 s.
- ``two_clocks``: the file's second clock or the phone's state says a second recording
  begins at some moment (:mod:`workstation.session.clocks`: samples on another sensor clock,
  WiFi seen after its own scan, another magnetometer calibration where the raw field jumps,
  another phone's magnetometer resolution) —
  two walks joined with no pause, which the inertial sensors do not show. None of the real
  walks here (the mall's 462 and samples, the museum's 10).
- ``facing_jump``: the compass turned by :data:`.continuity.JUMP_DEG` or more where the
  gyroscope saw no turn, the phone held alike and on one floor (:mod:`.continuity`) — a second
  recording joined on with every clock re-timed, facing elsewhere. None of the 488 real and
  bundled walks here (66° at most); about half of the mall's joins.
- ``no_reference_point``: no scan became a reference point.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from workstation.pipeline.confidence import ALTERNATIVE_START_M, odds
from workstation.pipeline.summary import Quarantine, Reason, Summary
from workstation.pipeline.tracking.state import END_CHECK_M

#: ``workstation run``'s exit status when it wrote the results of a quarantined walk
#: (2 is bad input; 0 a walk whose points may go into a map)
EXIT_QUARANTINED = 3
#: a walk that matched nothing from a given start and runs, by the median of its steps, farther
#: than this from every edge of the graph contradicts it (corridors are 2–4 m wide; a graph
#: drawn along them, or from the walks' own taps, has an edge within a few metres of a walker)
OFF_GRAPH_M = 10.0
#: the inertial streams may pause this long: five times the longest pause in the 116 real
#: walks here (0.10 s); 0.5 s of walking is under a metre the next fix absorbs
MAX_HOLE_S = 0.5

REMEDY: dict[Reason, str] = {
    "start_ambiguous": (
        "give the start: 'Start here' on the landmark in the panel (workstation edit), or "
        "--start LANDMARK; or run it with the building's other walks (a campaign with "
        "start: infer), where walks that stood together decide"
    ),
    "no_walking": (
        "look at the accelerometer trace (workstation view, sensors/accelerometer): was the "
        "phone carried? If it lay at one place on purpose, give --start and --include-quarantined"
        " where it is merged"
    ),
    "nothing_matched": (
        "check the landmark graph along this walk (workstation edit: are its turns and doors "
        "landmarks with rules, is the start right?) and the thresholds, then run it again; a "
        "walk that went straight on without stopping gives the sensors nothing to check it by: "
        "walk it again with a stop of a few seconds on a landmark that has the stop rule (acc); "
        "or, if you know where the walk ended, give that: 'End here' on the landmark in the "
        "panel, or --end LANDMARK"
    ),
    "off_graph": (
        "check the start given (workstation edit: is the walk's track on the plan where it "
        "was walked?) and the graph along the walk: its corridors need edges; then run it again"
    ),
    "end_far": (
        "check the end given ('End here', --end) and the start on the plan (workstation edit); "
        "if both are right, the walk went wrong where the panel shows its track leave the graph"
    ),
    "sensor_hole": (
        "look at the walk across the hole (workstation view: sensors/ and the track at that "
        "time): if the file holds two recordings joined, cut it there (workstation split WALK "
        "--out DIR) and run each part with its own start; if it is one walk the phone paused, "
        "include it where it is merged (--include-quarantined) once its track is right on both "
        "sides"
    ),
    "two_clocks": (
        "cut the file where the second recording begins (workstation split WALK --out DIR; "
        "it cuts there) and run each part with its own start"
    ),
    "facing_jump": (
        "look at the walk there (workstation view: its track and WiFi around that time): if the "
        "file holds two recordings joined, cut it there (workstation split WALK --out DIR cuts "
        "at that moment) and run each part with its own start; if it is one walk (a strong "
        "magnet near the phone), include it where it is merged (--include-quarantined)"
    ),
    "no_reference_point": (
        "look at the belief of its segments (workstation view) and at the graph along the walk; "
        "walk it again if it is too short to hold a segment between two landmarks"
    ),
}


def held(reason: Reason, detail: str) -> Quarantine:
    """A quarantine reason with what was seen and what the surveyor can do (:data:`REMEDY`)."""
    return Quarantine(reason, detail, REMEDY[reason])


def quarantine(summary: Summary, graph_has_landmarks: bool = True) -> list[Quarantine]:
    """Why this walk's points must stay out of merged maps (empty: they may go in), from the
    figures of its run summary (:func:`metrics.summarize`): each rule of :data:`RULES` in
    order, with what it saw."""
    out: list[Quarantine] = []
    for reason, rule in RULES:
        detail = rule(summary, graph_has_landmarks)
        if detail is not None:
            out.append(held(reason, detail))
    return out


def _start_ambiguous(s: Summary, _graph: bool) -> str | None:
    start = s.start
    if start is None or not start.ambiguous:
        return None
    return (f"{s.start_node} was inferred as the start, but a walk from {start.alternative} "
            f"explains the sensors almost as well ({odds(start.margin or 0.0)}: log-likelihood "
            f"{start.margin} lower)")  # fmt: skip


def _no_walking(s: Summary, _graph: bool) -> str | None:
    if s.steps:
        return None
    return ("no step was detected after the start: the phone did not walk, or its steps were "
            "missed")  # fmt: skip


def _nothing_matched(s: Summary, graph: bool) -> str | None:
    if not (graph and s.inferred and not s.landmarks_matched and not end_checks(s)):
        return None
    return _nothing_matched_words(s)


def _off_graph(s: Summary, graph: bool) -> str | None:
    off = s.off_graph_m
    if not (graph and not s.inferred and not s.landmarks_matched and off is not None
            and off > OFF_GRAPH_M):  # fmt: skip
        return None
    return (f"no landmark matched from the given start {s.start_node}, and the walk's track "
            f"runs {off:g} m from the graph's edges (median; more than {OFF_GRAPH_M:g} m): the "
            "start or the graph is wrong")  # fmt: skip


def _end_far(s: Summary, _graph: bool) -> str | None:
    if s.end.how != "given_far":
        return None
    return (f"the walk was given the end {s.end.node}, but the sensors end it elsewhere: "
            f"farther from there than 3σ (σ {s.end.sigma_m} m) and {ALTERNATIVE_START_M:g} m")


def _sensor_hole(s: Summary, _graph: bool) -> str | None:
    if s.sensor_hole is None or s.sensor_hole[1] <= MAX_HOLE_S:
        return None
    at, length = s.sensor_hole
    return (f"the inertial sensors recorded nothing for {length:.1f} s from {at:.1f} s (more "
            f"than {MAX_HOLE_S:g} s): where the walker went meanwhile is unknown, and two "
            "recordings joined into one file look so")  # fmt: skip


def _two_clocks(s: Summary, _graph: bool) -> str | None:
    if s.clock_jump is None:
        return None
    at, what = s.clock_jump
    return (f"a second recording begins at {at:.1f} s ({what}): two walks joined into one "
            "file, the second placed where the first ended")


def _facing_jump(s: Summary, _graph: bool) -> str | None:
    if s.facing_jump is None:
        return None
    at, deg = s.facing_jump
    return (f"at {at:.1f} s the compass turned {deg:.0f}° where the gyroscope saw no turn "
            "(the phone held alike, on one floor): a second recording joined on, facing "
            "elsewhere, its points placed where the first ended")


def _no_reference_point(s: Summary, _graph: bool) -> str | None:
    if s.reference_points:
        return None
    return (f"none of its {s.scans} WiFi scans became a reference point"
            + (" (it has no WiFi scan)" if not s.scans else ""))


#: the quarantine's rules in the order a walk's reasons are said: reason (:data:`REMEDY`'s
#: key) → what it saw in the summary (None: the rule does not hold); the second argument says
#: whether the graph has landmarks at all
RULES: tuple[tuple[Reason, Callable[[Summary, bool], str | None]], ...] = (
    ("start_ambiguous", _start_ambiguous),
    ("no_walking", _no_walking),
    ("nothing_matched", _nothing_matched),
    ("off_graph", _off_graph),
    ("end_far", _end_far),
    ("sensor_hole", _sensor_hole),
    ("two_clocks", _two_clocks),
    ("facing_jump", _facing_jump),
    ("no_reference_point", _no_reference_point),
)


def sensor_hole(times: list[np.ndarray]) -> tuple[float, float] | None:
    """The longest pause of the streams ``times`` (the accelerometer's, the gyroscope's):
    (where it begins, from the first sample of them all; its length), s; None without one."""
    t0 = min((float(t[0]) for t in times if t.size), default=None)
    best: tuple[float, float] | None = None
    for t in times:
        if t.size < 2:
            continue
        d = np.diff(t)
        i = int(np.argmax(d))
        if best is None or d[i] > best[1]:
            best = (round(float(t[i]) - (t0 or 0.0), 2), round(float(d[i]), 2))
    return best


def end_checks(s: Summary) -> bool:
    """The walk's end closed on a landmark, placed to within ``END_CHECK_M``, or on the end the
    surveyor gave, where the sensors agree."""
    how, sd = s.end.how, s.end.sigma_m
    if how == "given":
        return True
    return how != "given_far" and bool(s.end.node) and (sd or math.inf) <= END_CHECK_M


def _nothing_matched_words(s: Summary) -> str:
    """What was missing when nothing matched: no steps, no detections, or none in reach."""
    steps, det = s.steps, s.landmarks_detected
    if not steps:
        return "no landmark matched: no step was detected after the start"
    end = _loose_end(s)
    if not det:
        return (
            f"no landmark matched: {steps} steps but no turn, stop or floor change was detected "
            f"along the walk, and {end}"
        )
    kinds = ", ".join(f"{n} {k}" for k, n in s.landmarks_detected_by_kind.items() if n)
    return (
        f"no landmark matched: {det} detections ({kinds}) but none fitted a landmark within "
        f"reach of the start, and {end}"
    )


def _loose_end(s: Summary) -> str:
    """Why the walk's end did not check it: no landmark it alone points at, or one placed
    more loosely than ``END_CHECK_M``."""
    sd = s.end.sigma_m
    if s.end.node and sd is not None:
        return (
            f"its end closed on {s.end.node} only to within σ {sd:g} m (a check needs "
            f"{END_CHECK_M:g} m or less)"
        )
    return "its end is near no landmark it alone points at"


def mark(summary: Summary, graph_has_landmarks: bool = True) -> Summary:
    """The summary with its quarantine (reasons, details, what to do) from its other figures."""
    return replace(summary, quarantine=tuple(quarantine(summary, graph_has_landmarks)))


def reasons(summary: Summary) -> str:
    """The quarantine reasons of a marked summary, comma-separated ("" when none)."""
    return ", ".join(summary.reasons)
