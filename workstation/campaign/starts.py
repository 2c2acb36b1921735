"""Single walks' starts in a campaign: the surveyor's fix for a walk whose inferred start was
ambiguous, and what the building's map says of its candidate starts.

A walk quarantined as ``start_ambiguous`` keeps its points out of the merged map until a
surveyor gives its start (``starts.yaml`` beside the building's graph, or ``starts:`` in the
campaign file). To help choose, the report ranks the walk's candidate starts (the association's
distinct surviving starts, ``start_candidates``) by how well each agrees with the building's
map: the walk run from that start places its scans; 1-NN on the map of the walks already in it
places them too; the candidate's figure is the median distance between the two (m). Where the
map covers the walk, the right start's scans land a few metres from where the map puts them and
a wrong start's tens of metres away (mall F1, session 18: with every other walk's scans at their
true positions the smallest distance was the right start's on 54 of the 56 walks whose right
start was a candidate). It is evidence for the surveyor, not a decision: chosen automatically it
let wrong walks into the map (docs/decisions.md), so no start is ever taken from it.
"""

from __future__ import annotations

import difflib

import numpy as np

from ..errors import InputError


def check_starts(spec, keys: list[str]) -> dict[str, str]:
    """The building's single-walk starts as {walk key: landmark}, checked: every walk named is
    one of the building's (``keys``: their names in the output), every landmark is in its
    graph. Raises :class:`InputError` naming the file and the entry."""
    if not spec.starts:
        return {}
    from ..graph import LandmarkGraph

    src = spec.starts_source
    ids = set(LandmarkGraph.load(spec.graph).ids)
    out = {}
    for walk, node in spec.starts:
        if walk not in keys:
            close = difflib.get_close_matches(walk, keys, n=1)
            raise InputError(src, f"starts: {walk!r} is no walk of building {spec.name}"
                             + (f" — did you mean {close[0]!r}?" if close else "")
                             + f" (its walks: {', '.join(keys[:8])}{' …' if len(keys) > 8 else ''})")  # fmt: skip
        if node not in ids:
            close = difflib.get_close_matches(node, sorted(ids), n=1)
            raise InputError(src, f"starts: {walk}: {node!r} is no landmark of {spec.graph}"
                             + (f" — did you mean {close[0]}?" if close else ""))  # fmt: skip
        out[walk] = node
    return out


#: the first seconds of a walk whose scans say where it began (1-NN on the building's map)
FIRST_S = 10.0


def rank_by_map(session, graph, params, candidates: list[str], index) -> dict:
    """What the building's map (``index``, a :class:`..localize.RadioMapIndex`) says of a walk's
    start: ``ranked``, each candidate start with the median distance (m) between where the walk
    run from it places its scans and where 1-NN puts them, nearest first (NaN: no scan); and
    ``near``, the landmark nearest to where 1-NN puts the scans of its first ``FIRST_S`` seconds
    (the median position; "" without such scans) — where to look on the plan when no candidate
    agrees."""
    from ..localize import Fingerprints
    from ..pipeline import Pipeline

    s = session.in_frame(graph.frame)
    ranked, first = [], None
    for node in candidates:
        r = Pipeline(s, graph, params.updated(**{"pdr.start_node": node})).run()
        rm = r.radiomap
        q = Fingerprints.from_radiomap(rm, graph.frame, accepted_only=False)
        if not len(q):
            ranked.append((node, float("nan")))
            continue
        est = index.localize(q, align_device=False)
        ranked.append((node, round(float(np.median(np.hypot(est.x - q.x, est.y - q.y))), 1)))
        if first is None:  # the same scans from every start: where the map puts the first ones
            t = rm.t[rm.segment >= 0]
            m = t <= r.track.start_time + FIRST_S
            first = (float(np.median(est.x[m])), float(np.median(est.y[m])),
                     float(np.median(est.floor[m]))) if m.any() else None  # fmt: skip
    near = ""
    if first is not None:
        on = [n for n in graph.nodes if n.floor == first[2]] or list(graph.nodes)
        near = min(on, key=lambda n: (n.x - first[0]) ** 2 + (n.y - first[1]) ** 2).id
    return {"ranked": sorted(ranked, key=lambda c: (np.isnan(c[1]), c[1])), "near": near}
