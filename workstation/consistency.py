"""Walk, graph and building checked against each other before a run: a graph from another
building is otherwise accepted silently and gives a radio map that is wrong everywhere (the
museum graph on the office walk: 49 points 41 m off, floor accuracy 0).

Each check returns a sentence naming the mismatch; ``run``, ``view`` and ``edit`` refuse with it
(exit 2) unless ``--force``.
"""

from __future__ import annotations

import numpy as np

FRAMES_APART_M = 2000.0  # geographic frames further apart than this are different sites
OUTSIDE_M = 50.0  # ground truth this far outside the graph's extent is another building
OFF_CORRIDOR_M = 5.0  # ground truth this far from every edge on its floor is off the graph


def mismatches(session, graph, building=None) -> list[str]:
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
    gt = session.ground_truth
    if gt is not None and len(gt) and graph.nodes:
        if gf is not None and sf is not None:
            session = session.in_frame(gf)
            gt = session.ground_truth
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
    if building is not None and graph.nodes:
        plans = {f for f, i in building.floors.items() if i.image is not None}
        stray = sorted(set(graph.floors) & plans)
        ext = building.extent()
        if ext is not None and stray:
            xy = np.array([[n.x, n.y] for n in graph.nodes if n.floor in plans])
            inside = ((xy >= ext[0] - OUTSIDE_M) & (xy <= ext[1] + OUTSIDE_M)).all(axis=1)
            if xy.size and inside.mean() < 0.5:
                out.append("most landmarks lie outside the floor-plan images: another building?")
    return out


def check(session, graph, building=None, force: bool = False, say=print) -> None:
    """Refuse (WorkstationError, exit 2) on any mismatch unless ``force``; then only warn."""
    from .errors import WorkstationError

    found = mismatches(session, graph, building)
    if not found:
        return
    where = f"{session.metadata.get('path', 'the walk')} and {graph.source or 'the graph'}"
    text = f"{where} do not belong together: " + "; ".join(found)
    if not force:
        raise WorkstationError(text + " (--force runs anyway)")
    say("warning: " + text)


def _off_corridors(gt, graph) -> float:
    """Share of ground-truth points (at most 2,000) farther than OFF_CORRIDOR_M from every edge
    of the graph on their floor."""
    from .geo import distance_to_segments

    step = max(1, len(gt) // 2000)
    x, y, f = gt.x[::step], gt.y[::step], gt.floor[::step]
    best = np.full(x.size, np.inf)
    for fl in np.unique(f):
        segs = [[[a.x, a.y], [b.x, b.y]] for a, b in ((graph.node(u), graph.node(v))
                for u, v in graph.edges) if fl in (a.floor, b.floor)]  # fmt: skip
        on = f == fl
        best[on] = distance_to_segments(x[on], y[on], segs)
    return float((best > OFF_CORRIDOR_M).mean())
