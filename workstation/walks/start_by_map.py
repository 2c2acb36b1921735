"""What a building's radio map says of a walk's start (a hint for the surveyor, beyond the paper).

A walk whose inferred start is ambiguous is quarantined until a surveyor gives its start. To
help choose, its candidate starts (the association's distinct surviving starts,
``start_candidates``) are ranked by how well each agrees with the building's map: the walk run
from that start places its scans; 1-NN on the map of the walks already in it places them too;
the candidate's figure is the median distance between the two (m), and the candidates are
ordered by the map's log-likelihood of the placement (the equation with which the map re-ranks
a walk's chains, :mod:`.pipeline.map_prior`). Where the map covers the
walk, the right start's scans land a few metres from where the map puts them and a wrong
start's tens of metres away (mall F1, session 18: with every other walk's scans at their true
positions the smallest distance was the right start's on 54 of the 56 walks whose right start
was a candidate). It is evidence for the surveyor, not a decision: chosen automatically it let
wrong walks into the map (docs/decisions.md), so no start is ever taken from it. Used by the
campaign report and ``workstation run --map``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from workstation.fingerprints.localize import Fingerprints, RadioMapIndex
from workstation.graph import LandmarkGraph
from workstation.params import Params
from workstation.pipeline import Pipeline
from workstation.pipeline.confidence import ALTERNATIVE_START_M, odds
from workstation.pipeline.start import Region
from workstation.pipeline.tracking.map_prior import MapPrior, loglik, scan_queries, span_m2
from workstation.session import Session

#: the first seconds of a walk whose scans say where it began (1-NN on the building's map)
FIRST_S = 10.0
#: the wider search whose starts are ranked beside the walk's own candidates: chains kept, and
#: distinct starts ranked (mall F1, half of the walks' starts given, the other half ranked on
#: their map: the right start among them on 36 of 53 walks, against 26 with the walk's own six;
#: docs/decisions.md)
WIDE_BEAM = 64
WIDE_CANDIDATES = 30
#: the likeliest candidates named in words and ringed in the panel (the rest counted)
SHOWN = 6


@dataclass(frozen=True)
class MapRanking:
    """What the building's map says of a walk's candidate starts (:func:`rank_by_map`)."""

    #: (landmark, median distance m, log-likelihood), likeliest first (NaN, −inf: no scan)
    ranked: tuple[tuple[str, float, float], ...] = ()
    near: str = ""  # the landmark nearest to where the map puts the first scans ("": none)
    near_floor: float = float("nan")
    margin_ll: float | None = None  # how much less likely the best other place is

    def to_json(self) -> dict[str, Any]:
        """As a campaign report's row keeps it (campaign.json)."""
        return {"start_by_map": [list(c) for c in self.ranked], "start_near_by_map": self.near,
                "start_near_floor_by_map": self.near_floor,
                "start_by_map_margin_ll": self.margin_ll}  # fmt: skip

    @classmethod
    def from_json(cls, d: Mapping[str, Any]) -> MapRanking:
        """From what a campaign report's row kept (:meth:`to_json`; JSON: lists, nulls)."""
        near, near_floor, margin_ll = (d.get(k) for k in (
            "start_near_by_map", "start_near_floor_by_map", "start_by_map_margin_ll"))  # fmt: skip
        return cls(
            tuple((str(c[0]), float(c[1]), float(c[2])) for c in d.get("start_by_map") or ()),
            str(near or ""),
            float("nan") if near_floor is None else float(near_floor),
            None if margin_ll is None else float(margin_ll),
        )


def rank_by_map(
    session: Session, graph: LandmarkGraph, params: Params, candidates: list[str],
    index: RadioMapIndex, within: Region | None = None,
) -> MapRanking:  # fmt: skip
    """What the building's map (``index``, a :class:`..localize.RadioMapIndex`) says of a walk's
    start: ``ranked``, each candidate start (``candidates``, then those of a wider search,
    ``WIDE_BEAM`` and ``WIDE_CANDIDATES``) as (landmark, median distance m, log-likelihood),
    likeliest first: the walk run from it places its scans, 1-NN on the map places them too;
    the median distance between the two is what the surveyor reads, and the order is the
    map's log-likelihood of the placement — the equation with which the map re-ranks a walk's
    chains (:func:`.pipeline.map_prior.loglik`; NaN and −inf: no scan). ``near``: the landmark
    nearest to where 1-NN puts the scans of its first ``FIRST_S`` seconds (the median position;
    "" without such scans) — where to look on the plan when no candidate agrees; ``margin_ll``:
    :func:`_margin`. ``within``: the wider search only in that reach (x, y, floor, radius: where
    the walk before ended, :mod:`.chain`)."""

    # steps, heading, detections once for every start
    pipe = Pipeline(session, graph, params, start_within=within)
    if candidates:  # an ambiguous start: its candidates, then the wider search's
        candidates = list(
            dict.fromkeys([*candidates, *pipe.start_candidates(WIDE_BEAM, WIDE_CANDIDATES)])
        )
    times, queries = scan_queries(pipe.session.wifi)  # the same scans from every start
    est = index.localize(queries, align_device=False) if times.size else None
    prior = (MapPrior(times, est.x, est.y, est.floor, span_m2(index.map)) if est is not None
             else None)  # fmt: skip
    ranked, first = [], None
    for node in candidates:
        r = pipe.run(params.updated(**{"pdr.start_node": node}))
        rm = r.radiomap
        on = rm.segment >= 0  # the radio map's rows are the walk's scans, in time order
        if prior is None or not on.any():
            ranked.append((node, float("nan"), -math.inf))
            continue
        d = np.hypot(rm.x[on] - prior.x[on], rm.y[on] - prior.y[on])
        ll = loglik(r.track, prior, params.pdr)
        ranked.append((node, round(float(np.median(d)), 1), round(ll, 2)))
        if first is None:  # where the map puts the first ones
            m = on & (rm.t <= r.track.start.time + FIRST_S)
            if m.any():  # the median position, on the floor most of them are given
                fl, n = np.unique(prior.floor[m], return_counts=True)
                first = (float(np.median(prior.x[m])), float(np.median(prior.y[m])),
                         float(fl[np.argmax(n)]))  # fmt: skip
    near, near_floor = "", float("nan")
    if first is not None:
        at = [n for n in graph.nodes if n.floor == first[2]] or list(graph.nodes)
        best = min(at, key=lambda n: (n.x - first[0]) ** 2 + (n.y - first[1]) ** 2)
        near, near_floor = best.id, float(best.floor)
    # likeliest first; among as likely (the map's likelihood saturates far off), the nearer
    ranked.sort(key=lambda c: (-c[2], c[1] if c[1] == c[1] else math.inf))
    return MapRanking(tuple(ranked), near, near_floor, _margin(graph, ranked))


def _margin(graph: LandmarkGraph, ranked: list[tuple]) -> float | None:
    """How much less likely (log-likelihood) the best candidate at another place than the
    first is — another floor, or more than ``ALTERNATIVE_START_M`` away, as the start inference
    counts places; None when no other place was ranked."""
    ok = [c for c in ranked if c[1] == c[1]]
    if not ok:
        return None
    pos = {n.id: (n.x, n.y, n.floor) for n in graph.nodes}
    bx, by, bf = pos[ok[0][0]]
    other = [c for c in ok[1:]
             if pos[c[0]][2] != bf or np.hypot(pos[c[0]][0] - bx, pos[c[0]][1] - by) > ALTERNATIVE_START_M]  # fmt: skip
    return round(ok[0][2] - other[0][2], 1) if other else None


def rank_on(
    session: Session, graph: LandmarkGraph, params: Params, candidates: list[str],
    building_map: Fingerprints, within: Region | None = None,
) -> MapRanking:  # fmt: skip
    """:func:`rank_by_map` on the building's map itself."""
    index = RadioMapIndex(building_map, params.localize.tau_dbm)
    return rank_by_map(session, graph, params, candidates, index, within)


def hint(
    session: Session, graph: LandmarkGraph, params: Params, candidates: list[str],
    building_map: Fingerprints, within: Region | None = None,
) -> str:  # fmt: skip
    """:func:`rank_on`, in words (:func:`describe`)."""
    return describe(rank_on(session, graph, params, candidates, building_map, within))


def describe(got: MapRanking) -> str:
    """The ranking in words: "#1 L70 2.2 m, #2 L72 12.3 m (3.1× less likely), #3 L80 20.1 m …;
    the best start elsewhere: 60× less likely; the map puts its first scans nearest to L69"
    (how much less likely said where it changes)."""
    placed = [c for c in got.ranked if c[1] == c[1]]
    said = [odds(placed[0][2] - c[2]) for c in placed]  # each said once: where it changes
    ranked = [f"#{k} {c[0]} {c[1]:g} m" + (f" ({w})" if k > 1 and w != said[k - 2] else "")
              for k, (c, w) in enumerate(zip(placed, said), 1)]  # fmt: skip
    out = ", ".join(ranked[:SHOWN]) + (f" (+{len(ranked) - SHOWN} less likely)"
                                       if len(ranked) > SHOWN else "")  # fmt: skip
    if got.margin_ll is not None:
        out += f"; the best start elsewhere: {odds(got.margin_ll)}"
    if got.near:
        fl = got.near_floor
        on = f" on floor {fl:g}" if fl == fl else ""
        out += (("; " if out else "") + f"the map puts its first scans nearest to {got.near}"
                f"{on} (1-NN, metres and perhaps a floor off: look around it when no candidate "
                "agrees)")  # fmt: skip
    return out
