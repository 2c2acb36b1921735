"""Points on standby: a scan held back for its placement σ joins a radio map where the map has
no reference point near it (beyond the paper: docs/decisions.md, issue #29).

The σ cut (``radiomap.max_sigma_m``) keeps a scan out because a better-placed point is
expected near it. Where no walk of the map left one within ``COVER_M`` — a corridor only a
walk's loosely placed stretch went through — the cut leaves a hole, and a query there takes
its nearest fingerprint 20–30 m away (mall F1: the tap oracle places those queries 2 m off).
So a held-back scan stays with its walk's map *on standby* (``Fingerprints.standby``) and is
settled when a map is merged or used: it joins when no point that is not on standby lies within
the join radius on its floor, else it is dropped — ``COVER_M`` for 1-NN, where an accepted
point should win where walks overlap (#29 item 1). With the default matcher (weighted 5-NN,
issue #63) the radius is ``JOIN_M`` = 0: every row joins, its σ with it.
"""

from __future__ import annotations

import numpy as np

# horizontal radius (m) within which a reference point covers a held-back scan: the radius at
# which the evaluation calls a query covered by a walk (evaluate/map_kinds.COVERED_M)
COVER_M = 5.0
# the radius a merged map settles its rows on standby with: 0, every one joins. The rule above
# was chosen for 1-NN, where one loosely placed point beside a better one can be the answer;
# the default matcher averages 5 neighbours weighted by signal distance (matchers.py), and
# with it a map of every row beats the map the rule leaves on every building (mall F1–B1 and
# the museum: docs/experiments.md, "Matchers"). ``COVER_M`` gives the rule back.
JOIN_M = 0.0


def floor_points(x: np.ndarray, y: np.ndarray, floor: np.ndarray) -> np.ndarray:
    """Points for a KD-tree in which floors lie far apart (a point on another floor never
    covers)."""
    f = np.nan_to_num(np.asarray(floor, float), nan=-1e4)
    return np.column_stack([x, y, f * 1e6])


def joins(x, y, floor, standby: np.ndarray, cover_m: float = JOIN_M) -> np.ndarray:
    """Per row, whether a row on standby joins: no row that is not on standby lies within
    ``cover_m`` on its floor (0: every one joins). False for the rows not on standby."""
    from scipy.spatial import cKDTree

    standby = np.asarray(standby, bool)
    out = np.zeros(standby.size, bool)
    if not standby.any():
        return out
    if cover_m <= 0:
        return standby.copy()
    pts = floor_points(x, y, floor)
    if standby.all():
        out[:] = True
        return out
    d, _ = cKDTree(pts[~standby]).query(pts[standby], distance_upper_bound=cover_m)
    out[standby] = ~(d <= cover_m)
    return out


def joins_without_one(x, y, floor, standby, owner, cover_m: float = JOIN_M):
    """For maps merged from several walks (``owner``: per row, its walk's index) where each walk
    is left out in turn: per row on standby, whether it joins whichever walk is left out
    (``always``), and the walk whose leaving out alone makes it join (``only_without``: its
    index, -1 for none). A row joins without walk w when no row that is not on standby lies
    within ``cover_m`` once w's rows are gone."""
    from scipy.spatial import cKDTree

    standby, owner = np.asarray(standby, bool), np.asarray(owner)
    always = np.zeros(standby.size, bool)
    only = np.full(standby.size, -1)
    if not standby.any():
        return always, only
    pts = floor_points(x, y, floor)
    if standby.all() or cover_m <= 0:
        always[:] = standby
        return always, only
    anchors = np.flatnonzero(~standby)
    tree = cKDTree(pts[anchors])
    rows = np.flatnonzero(standby)
    near = tree.query_ball_point(pts[rows], cover_m)
    for r, hits in zip(rows.tolist(), near):
        walks = np.unique(owner[anchors[hits]]) if hits else np.empty(0, int)
        if walks.size == 0:
            always[r] = True
        elif walks.size == 1 and walks[0] != owner[r]:  # (its own walk out, it is out too)
            only[r] = int(walks[0])
    return always, only
