"""The landmark graph a surveyor would draw from many tapped walks (``graph from-waypoints``).

One landmark per tap (the old way) gives hundreds of landmarks a few metres apart on straight
corridors, most of which no sensor can see. A surveyor draws landmarks where walks *turn*
(the gyroscope sees it), where they *begin and end* (the start of a walk must be a landmark),
and where walks *meet*; edges follow the walked legs. So:

1. each walk's tapped polyline is reduced to its ends and the taps where its direction turns
   by more than ``TURN_RULE_DEG`` (legs shorter than ``MIN_LEG_M`` carry the heading through);
2. those points are clustered per floor (complete linkage: no two points of one landmark more
   than ``CLUSTER_M`` apart) — a landmark is the mean of its cluster;
3. each walk passes, in order along its polyline, every landmark within ``PASS_M`` of it —
   that is where walks meet: a walk going straight through another's turn passes its landmark —
   and consecutive landmarks of a walk are joined by an edge;
4. rules from what the phones saw there: the pipeline's detectors run on each walk, and a
   landmark gets ``gyro`` when a turn was detected within ``PASS_WINDOW_S`` of the walk
   passing it in at least half of the passes where the walk turned there, ``acc`` when a
   stop was detected in at least half of all its passes; floor changes between consecutive
   landmarks give the barometer rules as in :func:`workstation.graph.importers.graph_from_routes`.

The distances are corridor scale, not fitted to a building: a corridor is 2–4 m wide, and a
tap lies within a metre or two of where the walker was.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from workstation.errors import InputError
from workstation.geo import LocalFrame
from workstation.graph import BARO_RULES, Landmark, LandmarkGraph
from workstation.graph.importers import MIN_LEG_M, TURN_RULE_DEG, turn_points
from workstation.params import Params
from workstation.pipeline.heading import estimate_heading
from workstation.pipeline.landmarks import detect_landmarks
from workstation.pipeline.steps import detect_steps
from workstation.rules import STOP, TURN
from workstation.session import Session

CLUSTER_M = 1.5  # the most two points of one landmark may lie apart
PASS_M = 2.0  # a walk passes a landmark it comes this close to
PASS_WINDOW_S = 3.0  # a detection this close in time to passing a landmark is seen there


@dataclass
class LandmarkReport:
    """Why a landmark is there and why it has its rules (``graph from-waypoints`` prints it)."""

    id: str
    points: int = 0  # turn/end points of walks merged into it
    walks: int = 0  # walks passing it
    turns: int = 0  # passes where the walk turned there
    turns_seen: int = 0  # of those, passes where the gyro detector fired
    stops_seen: int = 0  # passes where the stop (acc) detector fired
    ends: int = 0  # walks starting or ending there
    why: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class _Walk:
    name: str
    xy: np.ndarray  # (N, 2) taps
    floor: np.ndarray
    t: np.ndarray
    turn: np.ndarray  # bool per tap: the walk turns there
    det_t: np.ndarray  # detection times
    det_kind: np.ndarray


def _walk(k: int, s: Session, frame: LocalFrame | None, params: Params) -> _Walk:
    if not s.has_path:
        raise InputError(
            s.metadata.path, "needs at least two ground-truth points to build a graph"
        )
    gt = s.in_frame(frame).ground_truth
    assert gt is not None  # has_path
    xy = np.column_stack([gt.x, gt.y])
    floor = np.where(np.isfinite(gt.floor), gt.floor, 0.0)
    # dense ground truth (a simulator's) kept every MIN_LEG_M along the path, floor changes and
    # both ends kept: sparse taps pass through unchanged unless closer than that
    arc = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(xy, axis=0).T))])
    _, keep = np.unique(np.floor(arc / MIN_LEG_M), return_index=True)
    flips = np.flatnonzero(np.diff(floor) != 0)
    keep = np.unique(np.concatenate([keep, flips, flips + 1, [0, len(xy) - 1]]))
    xy, floor, t_gt = xy[keep], floor[keep], gt.t[keep]
    turn = turn_points(xy, MIN_LEG_M)
    steps = detect_steps(s.accelerometer, params.steps)
    heading = estimate_heading(s, params.heading)
    det = detect_landmarks(steps, heading, s.pressure, params)
    return _Walk(f"W{k + 1}", xy, floor, t_gt, turn, det.t, det.kind)


def _clusters(pts: np.ndarray) -> np.ndarray:
    """Cluster labels of points (x, y) so no two points of a cluster are CLUSTER_M apart."""
    if len(pts) == 1:
        return np.zeros(1, int)
    from scipy.cluster.hierarchy import fcluster, linkage

    return fcluster(linkage(pts, "complete"), CLUSTER_M, "distance") - 1


def _passes(w: _Walk, pos: np.ndarray) -> tuple[list, list]:
    """(time, landmark index) of the landmarks on the walk's floor within PASS_M of its tapped
    polyline, in order along it, the time interpolated along the leg it is nearest: each time
    the walk passes one, and only where it comes nearest. A walk that comes back to a landmark
    (a loop back to its start, an out-and-back past it) passes it again: near legs are one pass
    while the taps between them stay within PASS_M of it (the walker turned there), else the
    walker went away and came back."""
    a, b = w.xy[:-1], w.xy[1:]
    same = w.floor[:-1] == w.floor[1:]
    ab = b - a
    L2 = np.maximum((ab**2).sum(1), 1e-12)
    every, nearest = [], []
    for j in range(len(pos)):  # landmarks on this walk's floors: one vectorized test each leg
        if not np.any(w.floor == pos[j, 2]):
            continue
        u = np.clip(((pos[j, :2] - a) * ab).sum(1) / L2, 0.0, 1.0)
        d = np.hypot(*(a + u[:, None] * ab - pos[j, :2]).T)
        d = np.where(same & (w.floor[:-1] == pos[j, 2]), d, np.inf)
        near = np.flatnonzero(d <= PASS_M)
        if not near.size:
            continue
        k = int(near[np.argmin(d[near])])
        nearest.append((k + u[k], j))
        # a new pass where near legs are apart, or the tap between them is away
        tap_d = np.hypot(*(w.xy[near[:-1] + 1, :2] - pos[j, :2]).T)
        for run in np.split(near, np.flatnonzero((np.diff(near) > 1) | (tap_d > PASS_M)) + 1):
            k = int(run[np.argmin(d[run])])
            every.append((k + u[k], j))

    def timed(out: list[tuple[int, int]]) -> list[tuple[float, int]]:
        return [(float(np.interp(s, np.arange(len(w.t)), w.t)), j) for s, j in sorted(out)]

    return timed(every), timed(nearest)


def graph_from_walks(
    sessions: Sequence[Session], params: Params | None = None,
    progress: Callable[..., None] | None = None,
) -> tuple[LandmarkGraph, list[LandmarkReport]]:
    """The landmark graph of the module doc from walks with tapped ground truth, and per
    landmark why it is there and why it has its rules. ``progress(i, n, what, phase=)``: each
    walk's sensors read (the long part: steps, turns and stops of every walk)."""
    params = params or Params()
    frame = next((s.frame for s in sessions if s.frame is not None), None)
    walks = []
    for k, s in enumerate(sessions):
        walks.append(_walk(k, s, frame, params))
        if progress is not None:
            progress(k + 1, len(sessions), f"walk {k + 1}", phase="reading their sensors")
    P, label, pos = _landmark_points(walks)
    ids = [f"L{c + 1:02d}" for c in range(len(pos))]
    reports = [LandmarkReport(i) for i in ids]
    for c in label:
        reports[c].points += 1
    # 3-4: each walk's landmarks in order, the edges between them, what its sensors saw there
    edges: list[tuple[str, str]] = []
    rules: list[set[str]] = [set() for _ in ids]
    for wi, w in enumerate(walks):
        own = {int(label[k]): int(P[k, 4]) for k in np.flatnonzero(P[:, 3] == wi)}
        _walk_through(w, own, pos, ids, reports, rules, edges)
    for j, r in enumerate(reports):
        _rules_of(r, rules[j])
    nodes = tuple(
        Landmark(
            ids[j],
            float(pos[j][0]),
            float(pos[j][1]),
            float(pos[j][2]),
            frozenset(rules[j]),
            f"{_count(reports[j].walks, 'walk')}, {_count(reports[j].points, 'point')}",
        )  # fmt: skip
        for j in range(len(ids))
    )
    # a landmark is the mean of taps up to CLUSTER_M apart: placed no better than that
    graph = LandmarkGraph(
        nodes, tuple(edges), frame, source="from-walks", landmark_sigma_m=CLUSTER_M
    )
    return graph, reports


def _landmark_points(walks: list) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Steps 1–2: the turn and end points of every walk (x, y, floor, walk, index), their
    cluster per floor, and each cluster's mean position (x, y, floor)."""
    pts = []
    for wi, w in enumerate(walks):
        keep = w.turn.copy()
        keep[0] = keep[-1] = True
        for i in np.flatnonzero(keep).tolist():
            pts.append((w.xy[i, 0], w.xy[i, 1], w.floor[i], wi, i))
    P = np.array(pts, float)
    label = np.full(len(P), -1)
    nxt = 0
    for f in np.unique(P[:, 2]):
        m = P[:, 2] == f
        label[m] = _clusters(P[m, :2]) + nxt
        nxt = label.max() + 1
    return P, label, np.array([P[label == c, :3].mean(0) for c in range(nxt)])


def _walk_through(w: _Walk, own: dict[int, int], pos: np.ndarray, ids: list[str],
                  reports: list[LandmarkReport], rules: list[set[str]],
                  edges: list[tuple[str, str]]) -> None:  # fmt: skip
    """Steps 3–4 for one walk: the landmarks it passes in order (``own``: its own turn and end
    points, landmark → index), what its sensors saw at each (into ``reports``), the edges it
    walked (into ``edges``) and the barometer rule where it changed floors (into ``rules``)."""
    passes, seq = _passes(w, pos)
    for c, i in own.items():  # a walk's own turn and end points are on it, whatever
        if all(j != c for _, j in seq):
            seq.append((float(w.t[i]), c))
    seq.sort()
    order = [j for _, j in seq]
    order = [j for k, j in enumerate(order) if k == 0 or j != order[k - 1]]
    for t_pass, j in seq:
        r = reports[j]
        r.walks += 1
        near = np.abs(w.det_t - t_pass) <= PASS_WINDOW_S
        turned = j in own and bool(w.turn[own[j]])
        r.turns += turned
        r.turns_seen += turned and bool(np.any(near & (w.det_kind == TURN)))
        r.stops_seen += bool(np.any(near & (w.det_kind == STOP)))
    for j in (order[0], order[-1]):
        reports[j].ends += 1
    _walked(w, passes, own, pos, ids, rules, edges)


def _walked(w: _Walk, passes: list, own: dict[int, int], pos: np.ndarray, ids: list[str],
            rules: list[set[str]], edges: list[tuple[str, str]]) -> None:  # fmt: skip
    """The edges a walk walked and the barometer rule where it changed floors: they follow
    every pass (the rules take each walk once per landmark, where it comes nearest) — a walk
    that ends where it began also walked its first leg."""
    walked = sorted(passes + [(float(w.t[i]), c) for c, i in own.items()])
    order = [j for _, j in walked]
    order = [j for k, j in enumerate(order) if k == 0 or j != order[k - 1]]
    for a, b in zip(order, order[1:]):
        if pos[a, 2] != pos[b, 2]:
            rules[a] |= BARO_RULES
            rules[b] |= BARO_RULES
        for e in ((ids[a], ids[b]), (ids[b], ids[a])):
            if e not in edges:
                edges.append(e)


def _rules_of(r: LandmarkReport, rules: set[str]) -> None:
    """A landmark's gyro and acc rules from what the walks' sensors saw there (most of the
    turns, most of the passes), and why it has each."""
    if r.turns and 2 * r.turns_seen >= r.turns:
        rules.add(TURN)
        r.why.append(f"gyro: {r.turns_seen} of {r.turns} turns here seen by the gyroscope")
    elif r.turns:
        r.why.append(f"no gyro: only {r.turns_seen} of {r.turns} turns here seen")
    if r.walks and 2 * r.stops_seen >= r.walks:
        rules.add(STOP)
        r.why.append(f"acc: walkers stopped in {r.stops_seen} of {r.walks} passes")
    if rules & BARO_RULES:
        r.why.append("barometer: a floor change to or from here")


def report_markdown(
    g: LandmarkGraph, reports: list[LandmarkReport], walks: list[str], skipped: Sequence[str] = ()
) -> str:
    """The report ``graph from-waypoints`` writes beside the graph (``skipped``: the walks left
    out for having fewer than two taps)."""
    L = [
        "# Landmark graph from tapped walks",
        "",
        f"{len(g.nodes)} landmarks and {len(g.undirected_pairs())} edges from {len(walks)} walks: "
        f"landmarks where walks turn by more than {TURN_RULE_DEG:g}°, begin, end or meet (turn "
        f"and end points within {CLUSTER_M:g} m merged; a walk passing within {PASS_M:g} m of a "
        "landmark meets it). Rules from what the phones saw within "
        f"{PASS_WINDOW_S:g} s of passing (workstation/walks/graph_from_walks.py).",
        "",
        *(
            [f"Left out, fewer than two taps (nothing to draw): {', '.join(skipped)}.", ""]
            if skipped
            else []
        ),
        "| landmark | x | y | floor | rules | points merged | walks passing | walks starting/ending "
        "| why |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for n, r in zip(g.nodes, reports):
        L.append(
            f"| {n.id} | {n.x:.2f} | {n.y:.2f} | {n.floor:g} | {', '.join(sorted(n.rules)) or '–'} "
            f"| {r.points} | {r.walks} | {r.ends} | {'; '.join(r.why) or 'a walk begins or ends here'} |"
        )
    return "\n".join(L) + "\n"


def _count(n: int, what: str) -> str:
    return f"{n} {what}" if n == 1 else f"{n} {what}s"
