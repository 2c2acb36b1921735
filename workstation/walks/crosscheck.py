"""The building's walks check each other (issue #49): a walk whose reference points the other
walks' WiFi puts systematically elsewhere is kept out of the merged map.

Each walk's reference points (not those on standby) are localized (kNN, ``K``) on the map
merged from the *other* walks; where they overlap, the displacement from the placed position to
the estimate is kept. A scan overlaps where another walk has a point within ``COVER_M`` of
where this walk placed it (on its floor): a walk displaced to where nobody else walked is not
checked (recognising its fingerprints by their signal distance instead was measured and
dropped: how close a fingerprint matches depends on the place, and a threshold that caught the
displaced walk condemned good walks in places only they walked — docs/decisions.md). One fingerprint's estimate is metres off (1-NN on the mall
F1: 6–7 m), in any direction; a walk placed wrong is off the *same* way at every scan. So the
statistic is the length of the median displacement vector (per axis) over the walk's covered
rows (at least ``MIN_ROWS``): a walk disagrees when it reaches ``DISAGREE_M`` *and* at most
``AGREE_SHARE`` of those scans have their estimate within ``AGREE_M`` of where the walk put
them — a displaced walk, not a few scans the others' map answers from afar (a good mall walk's
last five scans were all answered 70–80 m away: stale or moved APs). The report says where it
is worse when one half of the rows (in time) is clearly worse than the other.

Robust to APs that moved: the median, and each walk's device offset removed (merge's
alignment). One bad walk must not condemn a good one near where it was put: the flagged walks are
explained away one at a time (:func:`check_walks`); of two walks that only overlap each other
and disagree, nothing tells which is wrong: both are left out, and say so.

What it can see, measured (first-fix starts, first runs, docs/decisions.md): on mall F1 the
walk placed 18 m off shows 18 m with none of its 15 scans within 8 m — flagged; the next
lowest agreement is 20 % (a walk placed 2.5 m off); a walk placed 10 m off shows 11 m but 36 %
agreement — not flagged. The museum's walks: at most 7 m. A walk a few metres off hides in
the fingerprints' own noise: this check catches gross errors (a wrong start, a wrong chain).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from workstation.fingerprints.localize import Fingerprints, localize
from workstation.fingerprints.standby import COVER_M, floor_points

K = 3  # neighbours averaged per scan: steadier than 1-NN, still local
MIN_ROWS = 5  # covered rows a statistic needs (the median's spread ~ 1.25 · 5 m / √5 ≈ 2.8 m)
DISAGREE_M = 10.0  # the median displacement that flags a walk (≈ 3.5 × that spread) …
AGREE_M = 8.0  # … when hardly any of its scans is placed within this of its estimate:
AGREE_SHARE = 0.15  # at most this share (one scan in seven)
MAX_CANDIDATES = 6  # flagged walks tried per round of explaining away (check_walks)

WHAT_TO_DO = (
    "open it in the panel (workstation edit) on the building's map: check its start and the "
    "landmarks it matched where its track leaves the others; fix the start, the end or the "
    "graph and run it again, or walk it again"
)


@dataclass(frozen=True)
class Disagreement:
    """How far one walk's points lie from where the other walks' WiFi puts them."""

    name: str
    offset_m: float  # the length of the median displacement over its covered rows
    where: str  # "the whole walk", "its first half", "its second half"
    rows: int  # covered rows it was measured on
    agree: float  # share of those whose estimate lies within AGREE_M of where it was placed
    dx: float = 0.0  # the median displacement (m, east / north)
    dy: float = 0.0
    # walks it disagrees with where nothing says which is right: left out together
    unsure_with: tuple[str, ...] = ()

    @property
    def flagged(self) -> bool:
        return self.offset_m >= DISAGREE_M and self.agree <= AGREE_SHARE

    def words(self) -> str:
        return (
            f"{self.name}: disagrees with the building's other walks by {self.offset_m:.0f} m "
            f"along {self.where} ({self.rows} scans where they overlap, "
            f"{100 * self.agree:.0f} % of them within {AGREE_M:g} m)"
            + (f"; it and {', '.join(self.unsure_with)} disagree with each other and no other "
               "walk says which is right: both are left out" if self.unsure_with else "")
        )  # fmt: skip

    def to_dict(self) -> dict:
        return {"walk": self.name, "offset_m": round(self.offset_m, 2), "where": self.where,
                "rows": self.rows, "agree": round(self.agree, 3),
                "unsure_with": list(self.unsure_with), "dx_m": round(self.dx, 2), "dy_m": round(self.dy, 2),
                "what_to_do": WHAT_TO_DO}  # fmt: skip


def _displacement(
    walk: Fingerprints, others: list[Fingerprints], tau: float, align: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per row of ``walk``: estimate − placed (dx, dy) on the others' map, and whether another
    walk's point lies within COVER_M of it on its floor."""
    from scipy.spatial import cKDTree

    ref = Fingerprints.merge(others, align_devices=align)
    est = localize(ref, walk, "euclidean", k=K, tau=tau, align_device=align)
    d, _ = cKDTree(floor_points(ref.x, ref.y, ref.floor)).query(
        floor_points(walk.x, walk.y, walk.floor), distance_upper_bound=COVER_M
    )
    covered = (d <= COVER_M) & (est.floor == walk.floor)
    return est.x - walk.x, est.y - walk.y, covered


def _statistic(name: str, dx: np.ndarray, dy: np.ndarray, covered: np.ndarray) -> Disagreement:
    rows = np.flatnonzero(covered)
    if rows.size < MIN_ROWS:
        return Disagreement(name, 0.0, "the whole walk", int(rows.size), agree=1.0)
    mx, my = float(np.median(dx[rows])), float(np.median(dy[rows]))
    agree = float(np.mean(np.hypot(dx[rows], dy[rows]) <= AGREE_M))
    where = "the whole walk"
    if rows.size >= 2 * MIN_ROWS:  # where it is worse, when one half is clearly worse
        half = rows.size // 2
        off = [float(np.hypot(np.median(dx[r]), np.median(dy[r])))
               for r in (rows[:half], rows[half:])]  # fmt: skip
        if max(off) >= 1.5 * min(off):
            where = ("its first half", "its second half")[int(np.argmax(off))]
    return Disagreement(name, float(np.hypot(mx, my)), where, int(rows.size), agree, mx, my)


def check_walks(
    maps: dict[str, Fingerprints], tau: float = -90.0, align: bool = True
) -> dict[str, Disagreement]:
    """Each walk's disagreement with the others (module doc); ``maps``: walk name → its map
    (rows on standby are neither checked nor reference). Walks with fewer than ``MIN_ROWS``
    points, or when fewer than two walks have points, are not checked (absent from the
    result).

    One displaced walk makes the good walks near where it was put look displaced too. So the
    flagged walks are explained away one at a time: the one whose leaving out clears most of
    the other flags (then the largest offset) is kept out, and the rest checked again without
    it, until no walk is flagged. Two walks whose leaving out clears each other alike (only
    they overlap) are both kept out, each naming the other (``unsure_with``)."""
    own = {n: m.without_standby() for n, m in maps.items()}
    own = {n: m for n, m in own.items() if len(m)}
    if len(own) < 2:
        return {}
    out = _round(own, tau, align)
    out_of_map: dict[str, Disagreement] = {}
    while flagged := sorted((n for n, d in out.items() if d.flagged),
                            key=lambda n: -out[n].offset_m)[:MAX_CANDIDATES]:  # fmt: skip
        trial = {}
        for c in flagged:
            res = _round({k: v for k, v in own.items() if k != c}, tau, align)
            cleared = {n for n in flagged if n != c and not (n in res and res[n].flagged)}
            trial[c] = (len(cleared), out[c].offset_m, cleared, res)
        best = max(trial, key=lambda c: trial[c][:2])
        twins = [c for c in flagged if c != best and trial[c][0] == trial[best][0]
                 and best in trial[c][2] and c in trial[best][2]]  # fmt: skip
        for c in [best, *twins]:
            out_of_map[c] = replace(out[c], unsure_with=tuple(t for t in [best, *twins] if t != c))
            own.pop(c)
        out = trial[best][3] if not twins else _round(own, tau, align)
        out = {n: d for n, d in out.items() if n in own}
    return {**out, **out_of_map}


def _round(own: dict[str, Fingerprints], tau: float, align: bool) -> dict[str, Disagreement]:
    """Every walk of ``own`` with ``MIN_ROWS`` points or more against all the others."""
    if len(own) < 2:
        return {}
    raw = {}
    for name, m in own.items():
        if len(m) >= MIN_ROWS:
            raw[name] = _displacement(m, [o for k, o in own.items() if k != name], tau, align)
    return {n: _statistic(n, dx, dy, cov) for n, (dx, dy, cov) in raw.items()}


def disagreeing(checks: dict[str, Disagreement]) -> dict[str, Disagreement]:
    """The flagged walks of :func:`check_walks`."""
    return {n: d for n, d in checks.items() if d.flagged}
