"""The building's walks correct each other (issue #62): one joint estimate per floor instead of
a keep-or-drop vote per walk.

Each walk is placed by its own run (PDR between the landmarks it matched, σ per point:
:mod:`workstation.pipeline.sigma`). What its own run cannot see — a landmark matched to the
wrong one of two alike, a start one corridor off — shows against the other walks: scans of two
walks that heard the same APs alike stood near each other. So every walk gets a *correction*
c_w(t) ∈ ℝ², piecewise linear in time between knots ``KNOT_S`` apart, and all corrections of a
floor are estimated together by least squares over three kinds of evidence:

- **its own placement** (a prior per knot): c_w(t_k) ~ N(0, s_k²), s_k the walk's σ near the
  knot as a per-axis spread (σ holds ~68 % of the points: s = σ / ``SIGMA_TO_AXIS``);
- **its PDR chain** (between consecutive knots): c_w(t_{k+1}) − c_w(t_k) ~ N(0, σ_c²),
  σ_c = ``CHAIN_M`` + ``CHAIN_DRIFT`` · the distance walked between them — the track bends
  only as much as dead reckoning drifts;
- **links** between a scan i and its ``LINK_K`` nearest fingerprints j of *other* walks on its
  floor (Euclidean on eq. 21's positive values, device offsets removed as merge removes them):
  (p_i + c(i)) − (p_j + c(j)) ~ N(0, ``LINK_M``²) per axis, with the robust weight of
  :func:`robust_weight` — one fingerprint's nearest neighbour is metres off in any direction
  and sometimes 100 m away (an AP moved, a stale reading), so a link far from agreeing costs
  little; a walk placed wrong is off the *same* way at every scan, and its links together
  move it.

Every residual is linear in the corrections, so the estimate is iteratively reweighted least
squares: the normal equations H c = g (one sparse matrix for both axes) solved, the links'
weights taken again from their residuals, ``ITERATIONS`` times. A point's σ after the
estimate is its own σ narrowed by the others' evidence — its marginal with the links over
its marginal without, sqrt(wᵢᵀ H⁻¹ wᵢ), wᵢ the interpolation weights of its knots — and
widened by what the estimate could not explain: where the links near a point still disagree
the same way, by b beyond what their median wanders by chance (:func:`.joint_solve.bias`),
σ_i ← hypot(σ_i, ``BIAS_GAIN`` · b). A walk its own σ held where the others' WiFi says it is
not keeps its place but not its confidence (the four mall floors: 1σ / 2σ shares 59 / 86 % →
64 / 88 % on the one whose walks drift most, docs/experiments.md).

A walk the others cannot reconcile — whose links still disagree, after the estimate, by more
than ``UNRECONCILED_M`` the same way — is named with where and by how much; it is left out of
the map only when other walks' points cover where it went (``COVER_M``), so coverage is never
traded for a doubt (:func:`_covered`). The same bars are put to each half of a walk in time:
two walks joined into one file with every clock re-timed run on from where the first ended, so
one half agrees and the other is off by tens of metres — too few of the whole walk's links to
name it, all of the half's. Only that half's points leave the map, where others cover it
(:meth:`JointResult.placed`; issue #67 item 2: 9 of the 16 joins the compass let into the
four mall floors' maps named, no real walk; docs/experiments.md). The record and the bars
live in :mod:`.correction`, with what a doubt resting on one other walk says.
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass, field, replace

import numpy as np

from workstation.fingerprints.localize import Fingerprints, positive
from workstation.fingerprints.standby import COVER_M, floor_points
from workstation.fingerprints.union import ApUnion
from workstation.walks.correction import (  # noqa: F401 - UNRECONCILED_M: its home before
    UNRECONCILED_M,
    WalkCorrection,
    agreement,
    alone,
    doubt,
    resting,
)
from workstation.walks.joint_solve import (  # noqa: F401 - robust_weight: its home before
    BIAS_GAIN,
    LINK_M,
    Design,
    bias,
    narrowed,
    robust_weight,
    solve,
)

MUTUAL = True  # a link only where each scan is among the other's nearest (module doc)
LINK_K = 3  # nearest fingerprints of other walks linked per scan
MAX_LINK_WALKS = 200  # a floor's walks searched for links at most (every n-th: :func:`_links`)


@dataclass(frozen=True)
class JointResult:
    """The walks' maps as the joint estimate placed them (σ its marginals), and per walk what
    it did; ``links``: (row a, row b, weight) over the rows of ``order``'s maps concatenated."""

    maps: dict[str, Fingerprints]
    walks: dict[str, WalkCorrection]
    links: np.ndarray = field(default_factory=lambda: np.empty((0, 3)))

    def kept(self) -> dict[str, Fingerprints]:
        """The maps that go into the merged map (those left out dropped, a half left out on
        standby with no σ to join by: :meth:`placed`)."""
        return {n: self.placed(n) for n in self.maps if not self.walks[n].left_out}

    def placed(self, name: str) -> Fingerprints:
        """A walk's map as the estimate placed it, the half of it left out (``part_out``) on
        standby with no σ to join by (:func:`~workstation.fingerprints.standby.may_join`):
        its rows stay with the walk, out of every map made of it."""
        m, w = self.maps[name], self.walks[name]
        if not w.part_out:
            return m
        part = _in_part(m, w)
        sigma = m.sigma if m.sigma is not None else np.zeros(len(m))
        return replace(m, standby=m.on_standby | part, sigma=np.where(part, np.inf, sigma))

    def left_out(self) -> list[WalkCorrection]:
        return [w for w in self.walks.values() if w.left_out]


def _pos(fps: list[Fingerprints], union: ApUnion, i: int, rows: np.ndarray, tau: float,
         rss_min: float) -> np.ndarray:  # fmt: skip
    """Walk ``i``'s ``rows`` over the union in eq. 21's positive values."""
    return np.maximum(positive(union.readings(fps, i, rows), tau, rss_min), 0.0)


def _links(fps: list[Fingerprints], union: ApUnion, tau: float) -> np.ndarray:
    """(i, j) pairs of rows (numbered across the walks, in order): each row's ``LINK_K``
    nearest rows of other walks on its floor, where each is among the other's nearest
    (``MUTUAL``). Each walk's readings over the union are made when its block is needed: the
    floor's whole matrix never is. A floor of more than ``MAX_LINK_WALKS`` walks is searched
    against every n-th of them only, so that a crowd's floor costs in proportion to its walks,
    not their square (issue #66): a walk outside that set keeps a link to a row of the set
    where it would be among that row's nearest (within its ``LINK_K``-th distance)."""
    from workstation.fingerprints.nn import InvertedIndex

    pairs, extra = [], []
    rss_min = union.weakest(fps) - 1.0
    first = np.concatenate([[0], np.cumsum([len(m) for m in fps])])
    kth = np.full(int(first[-1]), np.inf)  # each searched row's LINK_K-th distance
    for f in np.unique(np.concatenate([m.floor for m in fps])):
        on = [np.flatnonzero(m.floor == f) for m in fps]
        walks = [i for i, r in enumerate(on) if r.size]
        if len(walks) < 2:
            continue
        ref = walks[:: max(1, -(-len(walks) // MAX_LINK_WALKS))]
        rows = np.concatenate([first[i] + on[i] for i in ref])  # the searched rows, in order
        index = InvertedIndex.from_blocks(_pos(fps, union, i, on[i], tau, rss_min) for i in ref)
        lo = 0
        for i in ref:
            hi = lo + on[i].size
            idx, d = index.search_without(_pos(fps, union, i, on[i], tau, rss_min), LINK_K, lo, hi)
            pairs.append(np.column_stack([np.repeat(rows[lo:hi], idx.shape[1]),
                                          rows[idx.ravel()]]))  # fmt: skip
            kth[rows[lo:hi]] = d[:, -1]
            lo = hi
        for i in sorted(set(walks) - set(ref)):  # a crowd's floor: the rest against the set
            idx, d = index.search(_pos(fps, union, i, on[i], tau, rss_min), "euclidean", LINK_K)
            extra.append((np.repeat(first[i] + on[i], idx.shape[1]), rows[idx.ravel()], d.ravel()))
    p = np.vstack(pairs) if pairs else np.empty((0, 2), int)
    if MUTUAL:  # keep i → j only when j → i too: a match at the edge of another walk's coverage
        code = p[:, 0].astype(np.int64) * first[-1] + p[:, 1]  # pulls one way only
        back = p[:, 1].astype(np.int64) * first[-1] + p[:, 0]
        p = p[np.isin(code, back)]
    if extra:
        a, b, d = (np.concatenate([e[k] for e in extra]) for k in range(3))
        keep = d <= kth[b] if MUTUAL else np.ones(a.size, bool)
        p = np.vstack([p, np.column_stack([a[keep], b[keep]]), np.column_stack([b[keep], a[keep]])])
    return p


def correct(
    maps: dict[str, Fingerprints], tau: float = -90.0, align: bool = True,
    fixed: Collection[str] = (),
) -> JointResult:  # fmt: skip
    """The joint estimate over every walk's map (module doc). ``maps``: walk name → its map
    (rows on standby included: they are moved and given σ too; whether they join is settled
    after, where the corrected map is used). A map without times (``t``) is one knot: moved
    as a whole. ``fixed``: maps that do not move (a building's merged map, against which one
    walk is placed: the panel)."""
    import scipy.sparse as sp

    names = [n for n, m in maps.items() if len(m)]
    empty = {n: m for n, m in maps.items() if not len(m)}
    if len(names) < 2:
        return JointResult(dict(maps), {n: _still(n, m) for n, m in maps.items()})
    fps = [maps[n] for n in names]
    union = ApUnion.of(fps, align)
    d = Design.of(names, fps, fixed)
    x0, y0 = np.concatenate([m.x for m in fps]), np.concatenate([m.y for m in fps])
    pairs = _links(fps, union, tau)
    L = (d.C[pairs[:, 0]] - d.C[pairs[:, 1]]) if len(pairs) else sp.csr_matrix((0, d.n_k))
    bx, by = x0[pairs[:, 1]] - x0[pairs[:, 0]], y0[pairs[:, 1]] - y0[pairs[:, 0]]
    cx, cy, w = solve(d.H0, L, bx, by)
    sigma = d.own_sigma * narrowed(d, L, w)
    dx, dy = d.C @ cx, d.C @ cy
    a_, b_ = pairs[:, 0], pairs[:, 1]  # the links' residuals after the estimate
    rx, ry = (dx[a_] - dx[b_]) + (x0[a_] - x0[b_]), (dy[a_] - dy[b_]) + (y0[a_] - y0[b_])
    near_k = np.where(d.wa >= 0.5, d.ka, d.kb)  # each row's nearest knot
    sigma = np.hypot(sigma, BIAS_GAIN * bias(near_k[a_], rx, ry, d.knot_start, d.n_k)[near_k])
    sizes = np.diff(d.row_start)
    owner = np.repeat(np.arange(len(fps)), sizes)
    out: dict[str, Fingerprints] = {}
    walks: dict[str, WalkCorrection] = {}
    start = np.concatenate([[0], np.cumsum(sizes)])
    for i, (name, m) in enumerate(zip(names, fps)):
        a, z = start[i], start[i + 1]
        out[name] = replace(m, x=m.x + dx[a:z], y=m.y + dy[a:z], sigma=sigma[a:z])
        mine = owner[pairs[:, 0]] == i if len(pairs) else np.zeros(0, bool)
        tl = m.t[pairs[mine, 0] - a] if m.t is not None else None  # each link's scan time
        walks[name] = _report(name, m, dx[a:z], dy[a:z], rx[mine], ry[mine], tl,
                              np.asarray(names)[owner[pairs[mine, 1]]])  # fmt: skip
    for name, m in empty.items():
        out[name], walks[name] = m, _still(name, m)
    links = np.column_stack([pairs, w]) if len(pairs) else np.empty((0, 3))
    return JointResult(out, _covered(out, resting(walks)), links)


def _still(name: str, m: Fingerprints) -> WalkCorrection:
    return WalkCorrection(name, len(m), 0, 0.0, 0.0, "the whole walk", 0.0, 0.0)


def _report(name: str, m: Fingerprints, dx: np.ndarray, dy: np.ndarray, rx: np.ndarray,
            ry: np.ndarray, tl: np.ndarray | None = None,
            partner: np.ndarray | None = None) -> WalkCorrection:  # fmt: skip
    """What the estimate did to one walk: its shift (``dx``, ``dy`` per row), how its links
    agree after it (residuals ``rx``, ``ry``; per link its scan's time ``tl`` and the other
    walk, ``partner``) — over the whole walk, or the half of it in time the others cannot
    reconcile while the rest agrees."""
    shift = np.hypot(dx, dy)
    partner = np.zeros(rx.size, str) if partner is None else partner
    where = "the whole walk"
    if m.t is not None and shift.size >= 4:
        order = np.argsort(m.t, kind="stable")
        half = order.size // 2
        a, b = shift[order[:half]].mean(), shift[order[half:]].mean()
        if max(a, b) >= 1.5 * min(a, b) + 0.5:
            where = "its first half" if a > b else "its second half"
    n, dis, agree = agreement(rx, ry)
    out = WalkCorrection(name, len(m), n, float(shift.mean()) if shift.size else 0.0,
                         float(shift.max()) if shift.size else 0.0, where, dis, 0.0,
                         agree, only_against=alone(rx, ry, partner))  # fmt: skip
    if doubt(n, dis, agree) or tl is None or m.t is None or not rx.size:
        return out
    # one half of it the others cannot reconcile, the other agreeing: two walks joined into one
    # file (the track runs on from where the first ended), or a wrong landmark half-way
    t0, t1 = float(m.t.min()), float(m.t.max())
    mid = 0.5 * (t0 + t1)
    for part, sel, span in (("its first half", tl < mid, (t0, mid)),
                            ("its second half", tl >= mid, (mid, t1))):  # fmt: skip
        n, dis, agree = agreement(rx[sel], ry[sel])
        cut = replace(out, links=n, disagree_m=dis, agree=agree, part=part, part_s=span,
                      only_against=alone(rx[sel], ry[sel], partner[sel]))  # fmt: skip
        if doubt(n, dis, agree):
            return cut
    return out


def _in_part(m: Fingerprints, w: WalkCorrection) -> np.ndarray:
    """Per row of ``m``, whether it lies in the half ``w`` is named for."""
    if m.t is None or w.part_s is None:
        return np.zeros(len(m), bool)
    return m.t < w.part_s[1] if w.part == "its first half" else m.t >= w.part_s[0]


def _covered(
    maps: dict[str, Fingerprints], walks: dict[str, WalkCorrection]
) -> dict[str, WalkCorrection]:
    """Each walk's share of rows another walk's (corrected) point covers; an unreconciled walk
    is left out when that share is at least ``LEAVE_COVERED``."""
    from scipy.spatial import cKDTree

    names = [n for n in maps if len(maps[n])]
    if len(names) < 2:
        return walks
    pts = np.vstack([floor_points(maps[n].x, maps[n].y, maps[n].floor) for n in names])
    owner = np.repeat(np.arange(len(names)), [len(maps[n]) for n in names])
    tree = cKDTree(pts)
    out = dict(walks)
    for i, n in enumerate(names):
        mine = owner == i
        hits = tree.query_ball_point(pts[mine], COVER_M)
        cov = np.array([bool(np.any(owner[h] != i)) for h in hits])
        w = walks[n]
        if w.part_s is not None:  # the half it is named for
            cov = cov[_in_part(maps[n], w)]
        out[n] = replace(w, covered=float(cov.mean()) if cov.size else 0.0)
    for n in names:
        if out[n].unreconciled and out[n].covered >= LEAVE_COVERED:
            whole = out[n].part_s is None
            out[n] = replace(out[n], left_out=whole, part_out=not whole)
    return out


LEAVE_COVERED = 0.8  # an unreconciled walk is left out when others cover this share of it
