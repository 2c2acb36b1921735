"""What the survey editor writes and says beside its edits: the recovery copy of an unsaved
graph, the note on a landmark placed far from everything, and what the building's map says of
an ambiguous start, and where the walk starts."""

from __future__ import annotations

import json
import re

import numpy as np

from workstation.graph import LandmarkGraph
from workstation.io.yamlio import dump_yaml
from workstation.pipeline.confidence import odds
from workstation.pipeline.summary import Summary
from workstation.walks.start_by_map import SHOWN, MapRanking, describe, rank_on

FAR_M = 50.0  # a landmark this far from every other on its floor and from the walk is said
# a JSON number that YAML 1.1 would read as a string (no dot before the exponent: 1e-05)
_SCI = re.compile(r"[0-9]e[-+]?[0-9]")


def recovery_text(graph: LandmarkGraph) -> str:
    """The graph's recovery copy: JSON, which is YAML (the graph loader reads it), written after
    every edit — PyYAML's representer took 4 s per edit on a 10,000-landmark graph, JSON 30 ms.
    Pretty YAML when a number would need YAML's own float syntax."""
    data = graph.to_dict()
    text = json.dumps(data, allow_nan=False)
    return text + "\n" if not _SCI.search(text) else dump_yaml(data, sort_keys=False)


def far_note(moved, new: LandmarkGraph, tr) -> str:
    """Names a landmark of ``moved`` (added or moved by an edit) that lies far from every other
    landmark on its floor in ``new`` and from the walk's track ``tr``: a click outside the
    building (once placed 100 m off without a word)."""
    for n in moved:
        d = [
            np.hypot(o.x - n.x, o.y - n.y) for o in new.nodes if o.floor == n.floor and o.id != n.id
        ]
        if tr is not None and tr.steps.t.size:
            on = tr.steps.floor == n.floor
            if on.any():
                d.append(float(np.hypot(tr.steps.x_bc[on] - n.x, tr.steps.y_bc[on] - n.y).min()))
        if d and min(d) > FAR_M:
            return (
                f" — {n.id} lies {min(d):.0f} m from every other landmark on floor "
                f"{n.floor:g} and from the walk: outside the building? (Undo takes it back)"
            )
    return ""


def ranked_by_map(ed) -> MapRanking | None:
    """The ambiguous start's candidates ranked by the building's map (``ed.building_map``,
    :func:`.start_by_map.rank_on`), kept on the editor until the candidates or the graph
    change; None without a map."""
    if ed.building_map is None or not len(ed.building_map):
        return None
    tr = ed.result.track
    key = (tuple(tr.start.candidates), ed.graph)
    if ed._by_map is None or ed._by_map[0] != key:
        cands = [n for n, _ in tr.start.candidates]
        got = rank_on(ed.session, ed.graph, ed.params, cands, ed.building_map,
                      ed.pipeline.start_within)  # fmt: skip
        ed._by_map = (key, got)
    return ed._by_map[1]


def map_note(ed) -> str:
    """:func:`ranked_by_map` for the panel's start line: a hint beside "Start here" ("" without
    a map)."""
    said = describe(ranked_by_map(ed) or MapRanking())
    if not said:
        return ""
    return (
        ", by the building's map: how likely it finds the whole walk from each, and how far "
        f"(median) each start puts the walk's scans from where the map's WiFi does: {said}"
    )


def start_hints(ed, s: Summary) -> list[tuple[str, str]]:
    """Where to look for an ambiguous start, likeliest first, at most
    :data:`.start_by_map.SHOWN`: (landmark, what is said of it) — the building's map's
    likeliest candidates with how much less likely each is than the first ("likeliest", "2.9×
    less likely": :func:`.start_by_map.odds`), then the landmark nearest to where the map puts
    the walk's first scans (what helps when no candidate agrees: a walk that detected nothing),
    or without a map the sensors' own distinct candidate starts, said alike; empty when the
    start is given or sure. ``s``: the editor's run summary."""
    if ed.params.pdr.start_node or not s.start_ambiguous:
        return []
    got = ranked_by_map(ed)
    if got is not None:
        placed = [c for c in got.ranked if c[1] == c[1]][:SHOWN]
        out = [(c[0], odds(placed[0][2] - c[2])) for c in placed]
        if got.near and got.near not in {n for n, _ in out}:
            out.append((got.near, "the map's WiFi"))
        return out
    own = ed.result.track.start.candidates
    return [(n, odds(gap)) for n, gap in own][:SHOWN]


def start_note(ed, s: Summary) -> str:
    """Where the walk starts and how sure that is, for the panel (markdown); ``s``: the
    editor's run summary."""
    node = s.start_node or "-"
    if ed.params.pdr.start_node:
        return f'{node} (given; "Infer the start again" to search)'
    alt, margin = (s.start.alternative, s.start.margin) if s.start else (None, None)
    how = "inferred"
    among = ed.pipeline.start_among()  # the reach of where the walk before ended (walks/chain.py)
    if among:
        how += f" among the {len(among)} landmarks within reach of where the walk before ended"
    if not alt:
        return f"{node} ({how})"
    if s.start_ambiguous:  # said once, short (issue #50 item 8: ~25 lines of red and orange)
        return (
            f"<span style='color:#e6781e'>{node} ({how}) — **ambiguous**: from {alt} the "
            f"sensors fit almost as well ({odds(margin or 0.0)}).</span> Select where the walk "
            'began and press "Start here"; the likeliest places are ringed on the plan '
            "(start? #1 …)" + (map_note(ed) or ", by the sensors.")
        )  # fmt: skip
    return f"{node} ({how}; next best {alt}, {margin} less likely in log-likelihood)"
