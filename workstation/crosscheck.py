"""The building's walks check each other (issue #49): a walk whose reference points the other
walks' WiFi puts systematically elsewhere is kept out of the merged map.

Each walk's reference points (not those on standby) are localized (kNN, ``K``) on the map
merged from the *other* walks; where they overlap, the displacement from the placed position to
the estimate is kept. A scan overlaps where another walk has a point within ``COVER_M`` of
where this walk placed it (on its floor), or where the others' map recognises its fingerprint
as closely as it recognises the closest tenth of the scans of overlapping walks
(:func:`_recognised`) — else a walk displaced to where nobody walked would escape. One fingerprint's estimate is metres off (1-NN on the mall
F1: 6–7 m), in any direction; a walk placed wrong is off the *same* way at every scan. So the
statistic is the length of the median displacement vector (per axis) over the walk's covered
rows (at least ``MIN_ROWS``): a walk disagrees when it reaches ``DISAGREE_M`` *and* at most
``AGREE_SHARE`` of those scans have their estimate within ``AGREE_M`` of where the walk put
them — a displaced walk, not a few scans the others' map answers from afar (a good mall walk's
last five scans were all answered 70–80 m away: stale or moved APs). The report says where it
is worse when one half of the rows (in time) is clearly worse than the other.

Robust to APs that moved: the median, and each walk's device offset removed (merge's
alignment). One round with every other walk as reference, then the flagged walks are checked
again against the walks not flagged, so that one bad walk cannot condemn a good one near it;
a flagged walk that only other flagged walks overlap stays flagged, and says so: of two walks
that only overlap each other and disagree, nothing tells which is wrong.

What it can see, measured (first-fix starts, first runs, docs/decisions.md): on mall F1 the
walk placed 18 m off shows 18 m with none of its 15 scans within 8 m — flagged; the next
lowest agreement is 20 % (a walk placed 2.5 m off); a walk placed 10 m off shows 11 m but 36 %
agreement — not flagged. The museum's walks: at most 7 m. A walk a few metres off hides in
the fingerprints' own noise: this check catches gross errors (a wrong start, a wrong chain).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .localize import Fingerprints, localize
from .standby import COVER_M, _xyz

K = 3  # neighbours averaged per scan: steadier than 1-NN, still local
MIN_ROWS = 5  # covered rows a statistic needs (the median's spread ~ 1.25 · 5 m / √5 ≈ 2.8 m)
DISAGREE_M = 10.0  # the median displacement that flags a walk (≈ 3.5 × that spread) …
AGREE_M = 8.0  # … when hardly any of its scans is placed within this of its estimate:
AGREE_SHARE = 0.15  # at most this share (one scan in seven)
RECOGNISED_Q = 0.1  # … as closely as the closest tenth of the overlapping scans (_recognised)

WHAT_TO_DO = (
    "open it in the panel (workstation edit) on the building's map: check its start and the "
    "landmarks it matched where its track leaves the others; fix the start, the end or the "
    "graph and run it again, or walk it again"
)


@dataclass(frozen=True)
class Disagreement:
    """How far one walk's points lie from where the other walks' WiFi puts them."""

    name: str
    offset_m: float  # the largest median displacement (whole walk or a half)
    where: str  # "the whole walk", "its first half", "its second half"
    rows: int  # covered rows it was measured on
    agree: float  # share of those whose estimate lies within AGREE_M of where it was placed
    dx: float = 0.0  # the median displacement (m, east / north)
    dy: float = 0.0
    # flagged walks that alone overlap it: one of them or this one is wrong, nothing says which
    unsure_with: tuple[str, ...] = ()

    @property
    def flagged(self) -> bool:
        return self.offset_m >= DISAGREE_M and self.agree <= AGREE_SHARE

    def words(self) -> str:
        return (
            f"{self.name}: disagrees with the building's other walks by {self.offset_m:.0f} m "
            f"along {self.where} ({self.rows} scans where they overlap, "
            f"{100 * self.agree:.0f} % of them within {AGREE_M:g} m)"
            + (f"; only {', '.join(self.unsure_with)}, flagged too, overlaps it: one of them "
               "is wrong, nothing here says which" if self.unsure_with else "")
        )  # fmt: skip

    def to_dict(self) -> dict:
        return {"walk": self.name, "offset_m": round(self.offset_m, 2), "where": self.where,
                "rows": self.rows, "agree": round(self.agree, 3),
                "unsure_with": list(self.unsure_with), "dx_m": round(self.dx, 2), "dy_m": round(self.dy, 2),
                "what_to_do": WHAT_TO_DO}  # fmt: skip


def _displacement(walk: Fingerprints, others: list[Fingerprints], tau: float, align: bool):
    """Per row of ``walk``: estimate − placed (dx, dy) on the others' map, whether another
    walk's point lies within COVER_M of it on its floor, and the signal distance of its
    nearest fingerprint there."""
    from scipy.spatial import cKDTree

    ref = Fingerprints.merge(others, align_devices=align)
    est = localize(ref, walk, "euclidean", k=K, tau=tau, align_device=align)
    d, _ = cKDTree(_xyz(ref.x, ref.y, ref.floor)).query(
        _xyz(walk.x, walk.y, walk.floor), distance_upper_bound=COVER_M
    )
    covered = (d <= COVER_M) & (est.floor == walk.floor)
    return est.x - walk.x, est.y - walk.y, covered, est.distance


def _statistic(name: str, dx, dy, covered) -> Disagreement:
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
    result)."""
    own = {n: m.without_standby() for n, m in maps.items()}
    own = {n: m for n, m in own.items() if len(m)}
    if len(own) < 2:
        return {}
    raw = {}
    for name, m in own.items():
        if len(m) >= MIN_ROWS:
            raw[name] = _displacement(m, [o for k, o in own.items() if k != name], tau, align)
    known = _recognised(raw)
    out = {n: _statistic(n, dx, dy, cov | (sd <= known)) for n, (dx, dy, cov, sd) in raw.items()}
    flagged = [n for n, d in out.items() if d.flagged]
    for name in flagged:  # again, against the walks not flagged
        others = [o for k, o in own.items() if k != name and k not in flagged]
        again = None
        if others:
            dx, dy, cov, sd = _displacement(own[name], others, tau, align)
            again = _statistic(name, dx, dy, cov | (sd <= known))
        if again is not None and again.rows >= MIN_ROWS:
            out[name] = again
        else:  # only other flagged walks overlap it: which of them is wrong, none can say
            out[name] = replace(out[name], unsure_with=tuple(k for k in flagged if k != name))
    return out


def _recognised(raw: dict) -> float:
    """The signal distance within which the others' map *recognises* a scan wherever the walk
    placed it: the ``RECOGNISED_Q`` quantile of the nearest-fingerprint distances of the scans
    taken where walks overlap (by their placements). A walk displaced to where nobody else
    walked is checked by the scans the others know as closely as the closest tenth of each
    other's. (The median recognised too much: on a mall F1 split it flagged a walk placed
    0.6 m off that went where no map walk went, answered 12 m away; docs/decisions.md.)"""
    sd = [r[3][r[2]] for r in raw.values() if r[2].any()]
    return float(np.quantile(np.concatenate(sd), RECOGNISED_Q)) if sd else -np.inf


def disagreeing(checks: dict[str, Disagreement]) -> dict[str, Disagreement]:
    """The flagged walks of :func:`check_walks`."""
    return {n: d for n, d in checks.items() if d.flagged}
