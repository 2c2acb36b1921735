"""Walk, graph and building checked against each other before a run: a graph from another
building is otherwise accepted silently and gives a radio map that is wrong everywhere (the
museum graph on the office walk: 49 points 41 m off, floor accuracy 0).

Each check returns a sentence naming the mismatch; ``run``, ``view`` and ``edit`` refuse with it
(exit 2) unless ``--force``. Radio maps are checked too (issue #30): a walk localized on another
building's map, or maps of two buildings merged, share (almost) no access point — the mall's map
on a museum walk printed "floor accuracy 0.0 %" and exit 0. ``localize`` refuses a walk that
shares no access point with the map and ``merge`` maps of different sites; fewer shared APs
are said, not refused (one building's walks in different parts share few).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from workstation.errors import WorkstationError

FRAMES_APART_M = 2000.0  # geographic frames further apart than this are different sites
OUTSIDE_M = 50.0  # ground truth this far outside the graph's extent is another building
OFF_CORRIDOR_M = 5.0  # ground truth this far from every edge on its floor is off the graph
MIN_SHARED_AP_SHARE = 0.1  # a walk (or map) of the building hears most of its APs in the map


def _heard(fp) -> np.ndarray:
    """The APs a radio map or a walk's scans actually heard."""
    return fp.bssids[np.isfinite(fp.rss).any(axis=0)] if len(fp) else fp.bssids[:0]


def _placed(what: str, a, other: str, b) -> str | None:
    """Said when one side is georeferenced and the other is not: nothing shows they are of one
    site (a museum map, placed by its .cal, drawn on the mall's unplaced plan said "100 %
    covered")."""
    if (a is None) == (b is None):
        return None
    has, lacks = (what, other) if a is not None else (other, what)
    f = a if a is not None else b
    return (
        f"{has} is georeferenced ({f.origin_lat:.5f}, {f.origin_lon:.5f}) and {lacks} is not: "
        "nothing shows they are of one site"
    )


def _apart(a, b) -> float:
    """Metres between two geographic frames' origins (0 when either has none)."""
    if a is None or b is None:
        return 0.0
    return float(np.hypot(*b.to_xy(a.origin_lat, a.origin_lon)))


def map_mismatches(radio_map, queries) -> tuple[list[str], list[str]]:
    """A walk's scans (``queries``) against the radio map they are to be localized on: what
    refuses (another site; no access point in common — no scan can match anything) and what
    only warns (few in common: another building, or a part the map does not reach — on mall F1
    12 % of pairs of walks share under a tenth of their APs)."""
    refuse: list[str] = []
    warn: list[str] = []
    d = _apart(queries.frame, radio_map.frame)
    if d > FRAMES_APART_M:
        refuse.append(
            f"the walk was recorded {d / 1000:.1f} km from the map's origin: another site"
        )
    heard, mine = _heard(queries), _heard(radio_map)
    shared = np.intersect1d(heard, mine).size
    if heard.size and shared < MIN_SHARED_AP_SHARE * heard.size:
        text = (
            f"the walk heard {heard.size} access points and the map holds {mine.size}; they "
            f"share {shared}: another building, or a part of it the map does not reach"
        )
        (refuse if shared == 0 else warn).append(text)
    return refuse, warn


def merge_mismatches(maps, names) -> tuple[list[str], list[str]]:
    """Radio maps to be merged: refused across sites (geographic frames km apart, or one
    georeferenced and another not); a map that shares (almost) no access point with the others
    is said — another building of the site, or a part of this one no other walk reached
    (merging those is fine)."""
    refuse, warn = [], []
    frames = [m.frame for m in maps]
    for i in range(1, len(maps)):
        d = _apart(frames[0], frames[i])
        if d > FRAMES_APART_M:
            refuse.append(f"{names[i]} lies {d / 1000:.1f} km from {names[0]}: another site")
        placed = _placed(names[0], frames[0], names[i], frames[i])
        if placed:
            refuse.append(placed)
    heard = [_heard(m) for m in maps]
    for i, (h, name) in enumerate(zip(heard, names)):
        others = np.unique(np.concatenate([o for j, o in enumerate(heard) if j != i] or [h[:0]]))
        shared = np.intersect1d(h, others).size
        if len(maps) > 1 and h.size and shared < MIN_SHARED_AP_SHARE * h.size:
            warn.append(
                f"{name} shares {shared} of its {h.size} access points with the other maps: "
                "another building, or a part of this one no other map reaches"
            )
    return refuse, warn


def _other_site(mine, what: str, theirs) -> list[str]:
    """The map's frame against ``what``'s: km apart, or one placed on the globe and not the
    other."""
    d = _apart(mine, theirs)
    far = [f"the map lies {d / 1000:.1f} km from {what}'s origin"] if d > FRAMES_APART_M else []
    placed = _placed("the map", mine, what, theirs)
    return far + ([placed] if placed else [])


def plan_mismatches(fp, graph=None, building=None) -> list[str]:
    """A radio map against the graph and the building whose plans it is drawn over
    (``quality``): another site, or most points outside the plan images or the graph."""
    out = []
    p = np.column_stack([fp.x, fp.y])
    if building is not None:
        out += _other_site(fp.frame, "the building file", building.frame)
        plans = {f for f, i in building.floors.items() if i.image is not None}
        lacking = sorted(set(np.unique(fp.floor).tolist()) - set(building.floors)) if len(p) else []
        if plans and lacking:
            out.append(
                f"the map has points on floor(s) {', '.join(f'{f:g}' for f in lacking)}, which "
                f"the building file lacks (it has {', '.join(f'{f:g}' for f in building.floors)})"
            )
        ext = building.extent()
        if ext is not None and len(p):
            inside = ((p >= ext[0] - OUTSIDE_M) & (p <= ext[1] + OUTSIDE_M)).all(axis=1)
            if inside.mean() < 0.5:
                out.append("most reference points lie outside the floor-plan images")
    if graph is not None and graph.nodes and len(p):
        out += _other_site(fp.frame, "the graph", graph.frame)
        xy = np.array([[n.x, n.y] for n in graph.nodes])
        lo, hi = xy.min(axis=0) - OUTSIDE_M, xy.max(axis=0) + OUTSIDE_M
        if (~((p >= lo) & (p <= hi)).all(axis=1)).mean() > 0.2:
            out.append(f"most reference points lie more than {OUTSIDE_M:g} m outside the graph")
    return out


def mismatches(session, graph, building=None) -> list[str]:
    """What says the walk, the graph and the building file are not of one place: frames far
    apart, the walk's truth on floors or ground the graph lacks, landmarks off the plans."""
    return [*_frames_apart(session, graph, building), *_truth_off_graph(session, graph),
            *_landmarks_off_plans(graph, building)]  # fmt: skip


def _frames_apart(session, graph, building) -> list[str]:
    out = []
    sf, gf = session.frame, graph.frame
    if sf is not None and gf is not None:
        x, y = gf.to_xy(sf.origin_lat, sf.origin_lon)
        d = float(np.hypot(x, y))
        if d > FRAMES_APART_M:
            out.append(
                f"the walk was recorded {d / 1000:.1f} km from the graph's origin "
                f"({sf.origin_lat:.5f}, {sf.origin_lon:.5f} against "
                f"{gf.origin_lat:.5f}, {gf.origin_lon:.5f}): another site"
            )
    if building is not None and building.frame is not None and gf is not None:
        x, y = gf.to_xy(building.frame.origin_lat, building.frame.origin_lon)
        if float(np.hypot(x, y)) > FRAMES_APART_M:
            out.append("the building file's frame is far from the graph's: another site")
    return out


def _truth_off_graph(session, graph) -> list[str]:
    out: list[str] = []
    gt = session.ground_truth
    if gt is None or not len(gt) or not graph.nodes:
        return out
    gt = session.in_frame(graph.frame).ground_truth
    missing = sorted(set(np.unique(gt.floor).tolist()) - set(graph.floors))
    if missing:
        out.append(
            f"the walk's ground truth is on floor(s) {', '.join(f'{f:g}' for f in missing)}, "
            f"which the graph lacks (it has {', '.join(f'{f:g}' for f in graph.floors)})"
        )
    xy = np.array([[n.x, n.y] for n in graph.nodes])
    lo, hi = xy.min(axis=0) - OUTSIDE_M, xy.max(axis=0) + OUTSIDE_M
    p = np.column_stack([gt.x, gt.y])
    outside = ~((p >= lo) & (p <= hi)).all(axis=1)
    if outside.mean() > 0.2:
        out.append(
            f"{100 * outside.mean():.0f} % of the walk's ground truth lies more than "
            f"{OUTSIDE_M:g} m outside the graph's extent"
        )
    elif graph.edges:
        off = _off_corridors(gt, graph)
        if off > 0.3:
            out.append(
                f"{100 * off:.0f} % of the walk's ground truth is more than "
                f"{OFF_CORRIDOR_M:g} m from every corridor (edge) of the graph on its floor"
            )
    return out


def _landmarks_off_plans(graph, building) -> list[str]:
    if building is None or not graph.nodes:
        return []
    plans = {f for f, i in building.floors.items() if i.image is not None}
    stray = sorted(set(graph.floors) & plans)
    ext = building.extent()
    if ext is not None and stray:
        xy = np.array([[n.x, n.y] for n in graph.nodes if n.floor in plans])
        inside = ((xy >= ext[0] - OUTSIDE_M) & (xy <= ext[1] + OUTSIDE_M)).all(axis=1)
        if xy.size and inside.mean() < 0.5:
            return ["most landmarks lie outside the floor-plan images: another building?"]
    return []


def check(session, graph, building=None, force: bool = False, say=print) -> None:
    """Refuse (WorkstationError, exit 2) on any mismatch unless ``force``; then only warn."""
    where = f"{session.metadata.path or 'the walk'} and {graph.source or 'the graph'}"
    refuse(where, mismatches(session, graph, building), force, say)


def refuse(
    where: str, found: list[str], force: bool = False, say=print, warn: Sequence[str] = ()
) -> None:
    """Raise a WorkstationError (exit 2) naming ``found`` unless ``force``; then only warn.
    ``warn``: said, never refused."""
    for w in warn:
        say(f"warning: {where}: {w}")
    if not found:
        return
    text = f"{where} do not belong together: " + "; ".join(found)
    if not force:
        raise WorkstationError(text + " (--force runs anyway)")
    say("warning: " + text)


def _off_corridors(gt, graph) -> float:
    """Share of ground-truth points (at most 2,000) farther than OFF_CORRIDOR_M from every edge
    of the graph on their floor."""
    step = max(1, len(gt) // 2000)
    best = graph.distance_to_edges(gt.x[::step], gt.y[::step], gt.floor[::step])
    return float((best > OFF_CORRIDOR_M).mean())
