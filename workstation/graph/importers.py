"""Landmark graphs made from what a surveyor has: IPIN ``.tra`` route files (landmarks at the
tapped fixes, turns inferred), or the tapped waypoints of walks."""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from workstation.errors import InputError
from workstation.geo import LocalFrame
from workstation.graph.model import BARO_RULES, MIN_EDGE_LENGTH_M, Landmark, LandmarkGraph
from workstation.rules import TURN

TURN_RULE_DEG = 30.0  # a route turning more than this at a fix gets a gyro rule there
MIN_LEG_M = 1.0  # a leg of a tapped walk shorter than this has no direction of its own


def read_tra(path: str | Path) -> np.ndarray:
    """Rows (index, lat, lon, floor) of an IPIN ``.tra`` route file, in route order."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except FileNotFoundError:
        raise InputError(path, "no such file") from None
    rows = []
    for i, line in enumerate(text.splitlines(), start=1):
        parts = line.split()
        if not parts or parts[0].lower().startswith("point"):
            continue
        if len(parts) < 4:
            raise InputError(
                path, f"expected 'index lat lon floor [building]', got {line.strip()[:60]!r}", i
            )
        try:
            vals = [float(p) for p in parts[:4]]
        except ValueError:
            raise InputError(path, f"non-numeric field in {line.strip()[:60]!r}", i) from None
        if not all(math.isfinite(v) for v in vals) or abs(vals[1]) > 90 or abs(vals[2]) > 180:
            raise InputError(path, f"latitude/longitude out of range in {line.strip()[:60]!r}", i)
        rows.append(vals)
    if not rows:
        raise InputError(path, "no landmarks in route file")
    return np.array(rows)


def graph_from_tra(paths: Sequence[str | Path], frame: LocalFrame | None = None) -> LandmarkGraph:
    """Landmark graph from IPIN route files (see :func:`graph_from_routes`): one landmark per
    distinct (lat, lon, floor)."""
    routes = [(Path(p), read_tra(p)) for p in sorted(map(str, paths))]
    if frame is None:
        r0 = routes[0][1][0]
        frame = LocalFrame.around(r0[1], r0[2])
    named = []
    for path, rows in routes:
        m = re.search(r"Trial(\d+)", path.stem)
        x, y = frame.to_xy(rows[:, 1], rows[:, 2])
        named.append(
            (
                f"T{m.group(1)}" if m else path.stem,
                rows[:, 0].astype(int),
                np.column_stack([x, y, rows[:, 3]]),
            )
        )
    return graph_from_routes(named, frame, merge_radius_m=0.001, source="from-tra")


def graph_from_waypoints(sessions, merge_radius_m: float = 1.0) -> LandmarkGraph:
    """Landmark graph from the ground-truth points of walks (e.g. the waypoints a surveyor tapped
    on Microsoft ILC walks), landmarks closer than ``merge_radius_m`` on one floor merged."""
    named = []
    frame = next((s.frame for s in sessions if s.frame is not None), None)
    for k, s in enumerate(sessions):
        if not s.has_path:
            raise InputError(
                s.metadata.path, "needs at least two ground-truth points to build a graph"
            )
        gt = s.in_frame(frame).ground_truth
        floor = np.where(np.isfinite(gt.floor), gt.floor, 0.0)
        named.append((f"W{k + 1}", np.arange(1, len(gt) + 1), np.column_stack([gt.x, gt.y, floor])))
    return graph_from_routes(named, frame, merge_radius_m, source="from-waypoints")


def graph_from_routes(
    routes, frame: LocalFrame | None, merge_radius_m: float, source: str
) -> LandmarkGraph:
    """Landmark graph from walked routes, each (name, point numbers, (N, 3) x/y/floor).

    One node per distinct point (within ``merge_radius_m`` on one floor); an edge (both
    directions) between consecutive distinct points of each route; rules inferred: a floor
    change gives both ends ``baro_entry`` and ``baro_exit`` (either can start the change,
    depending on direction); a turn of more than 30° between the legs around a point gives it
    ``gyro``.
    """
    pos: dict[str, tuple[float, float, float]] = {}
    names: dict[str, str] = {}
    rules: dict[str, set[str]] = {}
    edges: list[tuple[str, str]] = []
    for name, numbers, pts in routes:
        seq: list[str] = []
        for num, (x, y, floor) in zip(numbers, pts):
            nid = next(
                (
                    k
                    for k, (px, py, pf) in pos.items()
                    if pf == floor and math.hypot(px - x, py - y) <= merge_radius_m
                ),
                None,
            )
            if nid is None:
                nid = f"L{len(pos) + 1:02d}"
                pos[nid] = (float(x), float(y), float(floor))
                names[nid] = f"{name}#{int(num)}"
                rules[nid] = set()
            if not seq or seq[-1] != nid:
                seq.append(nid)
        for a, b in zip(seq, seq[1:]):
            if pos[a][2] != pos[b][2]:
                rules[a] |= BARO_RULES
                rules[b] |= BARO_RULES
            for e in ((a, b), (b, a)):
                if e not in edges:
                    edges.append(e)
        _infer_turns(seq, pos, rules)
    nodes = tuple(
        Landmark(nid, *pos[nid], frozenset(rules[nid]), names[nid])
        for nid in sorted(pos, key=lambda s: int(s[1:]))
    )
    return LandmarkGraph(nodes, tuple(edges), frame, source=source)


def _infer_turns(seq: list[str], pos: dict, rules: dict) -> None:
    """Mark ``gyro`` where the walking direction turns by more than 30° (zero-length legs,
    e.g. an elevator ride, carry the previous heading through)."""
    xy = np.array([pos[n][:2] for n in seq], float).reshape(-1, 2)
    for n, turned in zip(seq, turn_points(xy, MIN_EDGE_LENGTH_M)):
        if turned:
            rules[n].add(TURN)


def turn_points(xy: np.ndarray, min_leg_m: float) -> np.ndarray:
    """Per point of a walked polyline: the direction turns there by more than
    ``TURN_RULE_DEG`` — between the last leg of at least ``min_leg_m`` that reached it and the
    leg that leaves it (shorter legs carry the heading through)."""
    out = np.zeros(len(xy), bool)
    d = np.diff(xy, axis=0)
    long = np.flatnonzero(np.hypot(d[:, 0], d[:, 1]) >= min_leg_m)
    if long.size < 2:
        return out
    h = np.arctan2(d[long, 1], d[long, 0])
    turn = np.abs((np.diff(h) + np.pi) % (2 * np.pi) - np.pi)
    out[long[1:][np.degrees(turn) > TURN_RULE_DEG]] = True  # where the new leg begins
    return out
