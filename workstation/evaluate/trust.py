"""What the walks' verdicts are worth against their own truth (issue #49), and the building's
walks checking each other inside ``evaluate --walks`` as ``merge`` and a campaign do
(:mod:`workstation.walks.crosscheck`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from workstation.walks.crosscheck import check_walks, disagreeing

#: a walk "placed wrong" and "placed well" (issue #49: by the mean distance of its points to
#: its own tapped truth)
WRONG_M, GOOD_M = 5.0, 2.0


def keep_out_disagreeing(maps: dict, per_walk: dict, asks: set, tau: float, align: bool,
                         same_walks: dict) -> None:  # fmt: skip
    """Check the map walks (``maps``: walk → kind → its map; the query walks ``asks`` of a
    split left out) against each other; a walk that disagrees loses its maps of ours (and of
    the baselines built from the walks in our map, ``same_walks``) and gets ``disagrees`` among
    its quarantine reasons in ``per_walk``, with the figures; every checked walk its
    ``crosscheck_m``."""
    checked = check_walks({n: m["ours"] for n, m in maps.items() if n not in asks}, tau, align)
    for n, d in checked.items():
        per_walk[n]["crosscheck_m"] = round(d.offset_m, 2)
    for n, d in disagreeing(checked).items():
        per_walk[n]["quarantine"] = [*per_walk[n]["quarantine"], "disagrees"]
        per_walk[n]["disagrees"] = d.to_dict()
        empty = maps[n]["ours"].subset(slice(0, 0))
        maps[n] |= {"ours": empty, "ours_unfiltered": empty}
        maps[n] |= {k: empty for k in same_walks}


def held_by_run(w: dict) -> bool:
    """Held by its own run's verdict (not by the cross-check, which comes after)."""
    return bool([q for q in w["quarantine"] if q != "disagrees"])


def map_points(sig_map: list[np.ndarray], per_walk: dict) -> np.ndarray:
    """(σ, error) of the points our map holds: ``sig_map`` has one array per walk its own run
    did not hold (in ``per_walk``'s order); those the cross-check kept out are dropped too."""
    runs = [w for w in per_walk.values() if not held_by_run(w)]
    keep = [a for a, w in zip(sig_map, runs) if not w["quarantine"]]
    return np.vstack(keep) if keep else np.empty((0, 2))


def verdicts(per_walk: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """How the walks' verdicts match the truth: walks in the map whose points are placed more
    than ``WRONG_M`` off, walks kept out though placed within ``GOOD_M`` (every row, as they
    would have been placed), the reasons."""
    kept = {n: w for n, w in per_walk.items() if not w["quarantine"] and w["reference_points"]}
    held = {n: w for n, w in per_walk.items() if w["quarantine"]}
    wrong = sorted(n for n, w in kept.items() if (w.get("placed_m") or 0) > WRONG_M)
    good = sorted(n for n, w in held.items()
                  if w.get("placed_every_row_m") is not None and w["placed_every_row_m"] <= GOOD_M)
    return {
        "walks": len(per_walk), "in_map": len(kept), "held": len(held),
        "in_map_placed_over_5m": wrong, "held_placed_within_2m": good,
        "held_by_reason": {r: sum(r in w["quarantine"] for w in held.values())
                           for r in sorted({r for w in held.values() for r in w["quarantine"]})},
    }  # fmt: skip
