"""What a building's radio map says of a walk's start (a hint for the surveyor, beyond the paper).

A walk whose inferred start is ambiguous is quarantined until a surveyor gives its start. To
help choose, its candidate starts (the association's distinct surviving starts,
``start_candidates``) are ranked by how well each agrees with the building's map: the walk run
from that start places its scans; 1-NN on the map of the walks already in it places them too;
the candidate's figure is the median distance between the two (m). Where the map covers the
walk, the right start's scans land a few metres from where the map puts them and a wrong
start's tens of metres away (mall F1, session 18: with every other walk's scans at their true
positions the smallest distance was the right start's on 54 of the 56 walks whose right start
was a candidate). It is evidence for the surveyor, not a decision: chosen automatically it let
wrong walks into the map (docs/decisions.md), so no start is ever taken from it. Used by the
campaign report and ``workstation run --map``.
"""

from __future__ import annotations

import numpy as np

from .localize import Fingerprints, RadioMapIndex
from .pipeline.confidence import ALTERNATIVE_START_M

#: the first seconds of a walk whose scans say where it began (1-NN on the building's map)
FIRST_S = 10.0
#: the wider search whose starts are ranked beside the walk's own candidates: chains kept, and
#: distinct starts ranked (mall F1, half of the walks' starts given, the other half ranked on
#: their map: the right start among them on 36 of 53 walks and ranked first on 30, against 26
#: and 24 with the walk's own six; docs/decisions.md)
WIDE_BEAM = 64
WIDE_CANDIDATES = 30
#: the nearest candidates named in words (the rest counted)
SHOWN = 6


def rank_by_map(session, graph, params, candidates: list[str], index) -> dict:
    """What the building's map (``index``, a :class:`..localize.RadioMapIndex`) says of a walk's
    start: ``ranked``, each candidate start (``candidates``, then those of a wider search,
    ``WIDE_BEAM`` and ``WIDE_CANDIDATES``) with the median distance (m) between where the walk
    run from it places its scans and where 1-NN puts them, nearest first (NaN: no scan); and
    ``near``, the landmark nearest to where 1-NN puts the scans of its first ``FIRST_S`` seconds
    (the median position; "" without such scans) — where to look on the plan when no candidate
    agrees."""
    from .pipeline import Pipeline

    pipe = Pipeline(session, graph, params)  # steps, heading, detections once for every start
    if candidates:  # an ambiguous start: its candidates, then the wider search's
        candidates = list(
            dict.fromkeys([*candidates, *pipe.start_candidates(WIDE_BEAM, WIDE_CANDIDATES)])
        )
    ranked, first = [], None
    for node in candidates:
        r = pipe.run(params.updated(**{"pdr.start_node": node}))
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
            if m.any():  # the median position, on the floor most of them are given
                fl, n = np.unique(est.floor[m], return_counts=True)
                first = (float(np.median(est.x[m])), float(np.median(est.y[m])),
                         float(fl[np.argmax(n)]))  # fmt: skip
    near, near_floor = "", float("nan")
    if first is not None:
        on = [n for n in graph.nodes if n.floor == first[2]] or list(graph.nodes)
        best = min(on, key=lambda n: (n.x - first[0]) ** 2 + (n.y - first[1]) ** 2)
        near, near_floor = best.id, float(best.floor)
    ranked.sort(key=lambda c: (np.isnan(c[1]), c[1]))
    return {"ranked": ranked, "near": near, "near_floor": near_floor,
            "margin_m": _margin(graph, ranked)}  # fmt: skip


def _margin(graph, ranked: list[tuple[str, float]]) -> float | None:
    """How much farther (m) the best candidate at another place than the first is — another
    floor, or more than ``ALTERNATIVE_START_M`` away, as the start inference counts places;
    None when no other place was ranked."""
    ok = [(n, m) for n, m in ranked if m == m]
    if not ok:
        return None
    pos = {n.id: (n.x, n.y, n.floor) for n in graph.nodes}
    bx, by, bf = pos[ok[0][0]]
    other = [m for n, m in ok[1:]
             if pos[n][2] != bf or np.hypot(pos[n][0] - bx, pos[n][1] - by) > ALTERNATIVE_START_M]  # fmt: skip
    return round(other[0] - ok[0][1], 1) if other else None


def hint(session, graph, params, candidates: list[str], building_map: Fingerprints) -> str:
    """:func:`rank_by_map` on the building's map itself, in words (:func:`describe`)."""
    index = RadioMapIndex(building_map, params.localize.tau_dbm)
    return describe(rank_by_map(session, graph, params, candidates, index))


def describe(got: dict) -> str:
    """The ranking in words: "L70 2.2 m, L72 12.3 m …; the map puts its first scans nearest to L69"."""
    ranked = [f"{n} {m:g} m" for n, m in got.get("ranked") or [] if m == m]
    out = ", ".join(ranked[:SHOWN]) + (f" (+{len(ranked) - SHOWN} farther away)"
                                       if len(ranked) > SHOWN else "")  # fmt: skip
    if got.get("margin_m") is not None:
        out += f"; the next place is {got['margin_m']:g} m farther"
    if got.get("near"):
        fl = got.get("near_floor")
        on = f" on floor {fl:g}" if fl is not None and fl == fl else ""
        out += (("; " if out else "") + f"the map puts its first scans nearest to {got['near']}"
                f"{on} (1-NN, metres and perhaps a floor off: look around it when no candidate "
                "agrees)")  # fmt: skip
    return out
