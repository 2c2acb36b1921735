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
# a row on standby whose σ (after the building's walks corrected each other, walks/joint.py) is
# over this never joins: it says the scan may lie more than the matcher's own error away (the
# default matcher is 5–6 m off on the mall). 3 × radiomap.max_sigma_m's default; measured on
# the four mall floors and the museum (docs/experiments.md, "Rows on standby join, up to a σ")
JOIN_MAX_SIGMA_M = 7.5


def floor_points(x: np.ndarray, y: np.ndarray, floor: np.ndarray) -> np.ndarray:
    """Points for a KD-tree in which floors lie far apart (a point on another floor never
    covers)."""
    f = np.nan_to_num(np.asarray(floor, float), nan=-1e4)
    return np.column_stack([x, y, f * 1e6])


def may_join(standby: np.ndarray, sigma: np.ndarray | None) -> np.ndarray:
    """Per row, on standby with a σ that lets it join (at most ``JOIN_MAX_SIGMA_M``; no σ: all)."""
    standby = np.asarray(standby, bool)
    if sigma is None:
        return standby.copy()
    return standby & ~(np.asarray(sigma, float) > JOIN_MAX_SIGMA_M)


def joins(x, y, floor, standby: np.ndarray, cover_m: float = JOIN_M,
          sigma: np.ndarray | None = None) -> np.ndarray:  # fmt: skip
    """Per row, whether a row on standby joins: its σ (when given) at most ``JOIN_MAX_SIGMA_M``
    and no row that is not on standby within ``cover_m`` on its floor (0: none needed). False
    for the rows not on standby."""
    from scipy.spatial import cKDTree

    standby = np.asarray(standby, bool)
    out = may_join(standby, sigma)
    if not out.any() or cover_m <= 0 or standby.all():
        return out
    pts = floor_points(x, y, floor)
    d, _ = cKDTree(pts[~standby]).query(pts[out], distance_upper_bound=cover_m)
    out[out] = ~(d <= cover_m)
    return out


def joins_without_one(x, y, floor, standby, owner, cover_m: float = JOIN_M, sigma=None):
    """For maps merged from several walks (``owner``: per row, its walk's index) where each walk
    is left out in turn: per row on standby, whether it joins whichever walk is left out
    (``always``), and the walk whose leaving out alone makes it join (``only_without``: its
    index, -1 for none). A row joins without walk w when no row that is not on standby lies
    within ``cover_m`` once w's rows are gone (and its σ lets it: :func:`may_join`)."""
    from scipy.spatial import cKDTree

    standby, owner = np.asarray(standby, bool), np.asarray(owner)
    eligible = may_join(standby, sigma)
    always = np.zeros(standby.size, bool)
    only = np.full(standby.size, -1)
    if not eligible.any():
        return always, only
    pts = floor_points(x, y, floor)
    if standby.all() or cover_m <= 0:
        always[:] = eligible
        return always, only
    anchors = np.flatnonzero(~standby)
    tree = cKDTree(pts[anchors])
    rows = np.flatnonzero(eligible)
    near = tree.query_ball_point(pts[rows], cover_m)
    for r, hits in zip(rows.tolist(), near):
        walks = np.unique(owner[anchors[hits]]) if hits else np.empty(0, int)
        if walks.size == 0:
            always[r] = True
        elif walks.size == 1 and walks[0] != owner[r]:  # (its own walk out, it is out too)
            only[r] = int(walks[0])
    return always, only
