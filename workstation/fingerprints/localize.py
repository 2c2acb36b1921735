"""Fingerprint localization (§V-C): positive-values representation (eq. 21), 1-NN / kNN with
Euclidean or Sørensen distance, floor recognition; and radio-map files (read, merge).

Fingerprints are RSS matrices (fingerprints × APs, dBm, NaN where unheard). The positive
representation maps RSS ≥ τ to RSS − min and everything else to 0, where min is the lowest RSS
of the radio map minus 1. The nearest reference points, Euclidean or Sørensen (Bray–Curtis), are
found exactly over an index by access point (:mod:`.nn`) that a :class:`RadioMapIndex` builds
once per map.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from workstation.errors import WorkstationError
from workstation.fingerprints.blocks import row_blocks, weakest
from workstation.fingerprints.devices import ap_means, offset_against
from workstation.fingerprints.kinds import known_kind
from workstation.fingerprints.matchers import Matcher, powed, weighted_mean
from workstation.fingerprints.standby import JOIN_M, joins
from workstation.fingerprints.union import ApUnion
from workstation.geo import LocalFrame
from workstation.io.map_read import read_map
from workstation.stats import error_stats

if TYPE_CHECKING:
    import pandas as pd


class Metric(str, enum.Enum):
    EUCLIDEAN = "euclidean"
    SORENSEN = "sorensen"


@dataclass(frozen=True)
class Fingerprints:
    """Reference points (or queries): positions, floors and an RSS matrix over ``bssids``."""

    x: np.ndarray
    y: np.ndarray
    floor: np.ndarray
    bssids: np.ndarray
    rss: np.ndarray  # (N, A) dBm, NaN = unheard
    frame: LocalFrame | None = None
    offsets_db: tuple[float, ...] = ()  # device offset removed from each map merged here
    quarantined: str = ""  # the walk's quarantine reasons (a run's radiomap.csv), "" if none
    device: str = ""  # the phone model of its walk(s): "" unknown, or several
    # per row: held back for its σ, joins where no other point covers it (standby.py); None: none
    standby: np.ndarray | None = None
    # per row, when known (a walk's radiomap.csv): the scan's time (s) and its placement σ (m,
    # pipeline/sigma.py, or the joint estimate's marginal: walks/joint.py); None: not carried
    t: np.ndarray | None = None
    sigma: np.ndarray | None = None
    # the kind of map (fingerprints/kinds.py): "points", the walks' placed scans; another kind
    # is built from them by ``merge --kind``
    kind: str = "points"

    def shifted(self, db: float) -> Fingerprints:
        """The same fingerprints with ``db`` added to every RSS."""
        return replace(self, rss=self.rss + db) if db else self

    def __len__(self) -> int:
        return int(self.x.size)

    def subset(self, rows) -> Fingerprints:
        """The fingerprints at ``rows`` (an index, slice or mask)."""
        def cut(a):
            return None if a is None else a[rows]

        return replace(self, x=self.x[rows], y=self.y[rows], floor=self.floor[rows],
                       rss=self.rss[rows], standby=cut(self.standby), t=cut(self.t),
                       sigma=cut(self.sigma))  # fmt: skip

    @property
    def on_standby(self) -> np.ndarray:
        """Per row, whether it is on standby (all False when none is)."""
        return np.zeros(len(self), bool) if self.standby is None else np.asarray(self.standby, bool)

    def without_standby(self) -> Fingerprints:
        """Only the rows not on standby (the walk's reference points)."""
        if self.standby is None:
            return self
        return replace(self.subset(~self.on_standby), standby=None)

    def settled(self, cover_m: float = JOIN_M) -> Fingerprints:
        """The map as it is used: each row on standby joins where no other row covers it within
        ``cover_m`` (:func:`.standby.joins`; 0, the default: none needed) and its σ is at most
        ``standby.JOIN_MAX_SIGMA_M``, or leaves; none is on standby after."""
        if self.standby is None:
            return self
        return replace(self.subset(self._settles(cover_m)), standby=None)

    def _settles(self, cover_m: float = JOIN_M) -> np.ndarray:
        """The rows :meth:`settled` keeps: not on standby, or on standby and joining."""
        return ~self.on_standby | joins(self.x, self.y, self.floor, self.on_standby, cover_m,
                                        self.sigma)  # fmt: skip

    def aligned(self, bssids: np.ndarray) -> np.ndarray:
        """RSS over another AP list (columns for unknown APs are NaN)."""
        if bssids is self.bssids or (
            bssids.shape == self.bssids.shape and np.array_equal(bssids, self.bssids)
        ):
            return self.rss  # already over that list (read-only use: callers make new arrays)
        out = np.full((len(self), bssids.size), np.nan)
        if not len(self) or not bssids.size or not self.bssids.size:
            return out
        # vectorized lookup: each wanted AP's column in this map (sorted search, not a dict)
        order = np.argsort(self.bssids, kind="stable")
        mine = self.bssids[order]
        at = np.minimum(np.searchsorted(mine, bssids), mine.size - 1)
        ok = mine[at] == bssids
        out[:, ok] = self.rss[:, order[at[ok]]]
        return out

    @classmethod
    def merge(
        cls, maps: list[Fingerprints], align_devices: bool = False, settle: bool = True
    ) -> Fingerprints:
        """One radio map from several (e.g. several walks of one building): the union of APs.
        ``align_devices``: each map is one walk (one phone); its RSS offset is estimated (on
        its rows not on standby) and removed first (:mod:`.devices`), the offsets kept in
        ``offsets_db`` — unless every map was recorded with the same phone model
        (:func:`.devices.one_model`). ``settle``: the rows on standby join or leave
        (:meth:`settled`); else they stay on standby."""
        frames = _mergeable(maps)
        union = ApUnion.of(maps, align_devices)
        off, bssids = union.offsets, union.bssids
        wait = (np.concatenate([m.on_standby for m in maps])
                if any(m.standby is not None for m in maps) else None)  # fmt: skip
        def joined(attr: str) -> np.ndarray | None:  # a per-row column every map carries
            cols = [getattr(m, attr) for m in maps]
            return None if any(c is None for c in cols) else np.concatenate(cols)

        rows = cls(  # every row, no reading yet: which rows stay is known before the readings
            np.concatenate([m.x for m in maps]),
            np.concatenate([m.y for m in maps]),
            np.concatenate([m.floor for m in maps]),
            bssids[:0],
            np.empty((sum(len(m) for m in maps), 0)),
            next(iter(frames)) if frames else None,
            tuple(round(float(o), 2) for o in off) if union.aligned else (),
            device=union.device,
            standby=wait,
            t=joined("t"),
            sigma=joined("sigma"),
        )
        keep = rows._settles() if settle and wait is not None else np.ones(len(rows), bool)
        rss = np.full((int(keep.sum()), bssids.size), np.nan)
        at = kept = 0
        for i, m in enumerate(maps):
            mine = np.flatnonzero(keep[at : at + len(m)])
            rss[kept : kept + mine.size] = union.readings(maps, i, mine)
            at, kept = at + len(m), kept + mine.size
        out = replace(rows.subset(keep), bssids=bssids, rss=rss)
        return replace(out, standby=None) if settle and wait is not None else out

    @classmethod
    def from_radiomap(
        cls,
        rm,
        frame: LocalFrame | None = None,
        accepted_only: bool = True,
        device: str = "",
        standby: bool = False,
    ) -> Fingerprints:
        """A walk's reference points (``accepted_only``; else every scan once the walk started);
        ``standby``: with the scans held back for their σ on standby (standby.py)."""
        sig = rm.sigma if rm.sigma is not None else np.full(len(rm), np.inf)
        if not accepted_only:
            m = rm.segment >= 0
            return cls(rm.x[m], rm.y[m], rm.floor[m], rm.bssids, rm.rss[m], frame, device=device,
                       t=rm.t[m], sigma=sig[m])  # fmt: skip
        wait = rm.held_for_sigma if standby else np.zeros(len(rm), bool)
        m = rm.accepted | wait
        return cls(rm.x[m], rm.y[m], rm.floor[m], rm.bssids, rm.rss[m], frame, device=device,
                   standby=wait[m] if wait.any() else None, t=rm.t[m], sigma=sig[m])  # fmt: skip

    @classmethod
    def of_walk(cls, rm, frame: LocalFrame | None = None, device: str = "") -> Fingerprints:
        """A walk's radio map as it is used alone: its reference points and the scans on
        standby that none of them covers (standby.py)."""
        return cls.from_radiomap(rm, frame, device=device, standby=True).settled()

    @classmethod
    def from_session(cls, session) -> Fingerprints:
        """Every WiFi scan of a session at its ground-truth position (queries, or a manual
        survey's reference points). Real walks: interpolated between the fixes."""
        gt = session.ground_truth
        if gt is None or not len(gt):
            raise WorkstationError(
                f"{session.metadata.path}: the session has no ground truth"
            )
        times, bssids, rss = session.wifi.matrix()
        inside = (times >= gt.t[0]) & (times <= gt.t[-1])
        x, y, f = gt.at(times[inside])
        return cls(
            x, y, f, bssids, rss[inside], session.frame, device=session.metadata.device
        )

    # ---- files ------------------------------------------------------------------------------
    def to_frame(self) -> pd.DataFrame:
        import pandas as pd

        df = pd.DataFrame({"x": self.x, "y": self.y, "floor": self.floor})
        if self.sigma is not None:
            df["sigma"] = np.round(self.sigma, 3)
        if self.standby is not None:
            df["standby"] = self.on_standby
        return pd.concat(
            [df, pd.DataFrame(self.rss, columns=[str(b) for b in self.bssids])], axis=1
        )

    @classmethod
    def read(cls, path: str | Path) -> Fingerprints:
        """A radio map written by ``workstation run``/export (CSV with an optional
        ``# frame origin_lat=.. origin_lon=..`` first line, or Parquet), or a campaign's merged
        map of one building (the folder ``radiomap/building=NAME``, partitioned by floor):
        :func:`workstation.io.map_read.read_map`."""
        fields = read_map(path)
        known_kind(path, fields["kind"])
        return cls(**fields)


def positive(rss: np.ndarray, tau: float, rss_min: float) -> np.ndarray:
    """Eq. 21: RSS − min where heard and RSS ≥ τ, else 0."""
    out = rss - rss_min
    return np.where(np.isfinite(rss) & (rss >= tau), out, 0.0)


@dataclass(frozen=True)
class Estimate:
    x: np.ndarray
    y: np.ndarray
    floor: np.ndarray
    distance: np.ndarray  # to the nearest reference point
    index: np.ndarray  # of the nearest reference point
    device_offset_db: float = 0.0  # removed from the queries before matching


def nearest(
    ref: np.ndarray, qry: np.ndarray, metric: Metric, k: int
) -> tuple[np.ndarray, np.ndarray]:
    """Indices (Q, k) and distances (Q, k) of the k nearest rows of ``ref`` to each row of
    ``qry`` (both in the positive representation), nearest first; ties to the lower index."""
    from workstation.fingerprints.nn import InvertedIndex

    return InvertedIndex.build(ref).search(qry, Metric(metric).value, k)


class RadioMapIndex:
    """A radio map ready for queries, built once and kept: its positive representation (eq. 21)
    under one τ and RSS minimum, indexed by access point (:mod:`.nn`), and its per-AP means
    for the device offset. ``rss_min`` defaults to the map's weakest reading minus 1 dB; a
    query reading weaker than that counts as unheard."""

    def __init__(self, radio_map: Fingerprints, tau: float = -90.0, rss_min: float | None = None,
                 representation: str = "positive"):  # fmt: skip
        from workstation.fingerprints.nn import InvertedIndex

        radio_map = radio_map.settled()  # rows on standby join or leave (standby.py)
        if not len(radio_map):
            raise WorkstationError("the radio map has no reference points")
        self.map, self.tau = radio_map, float(tau)
        if rss_min is None:
            rss_min = weakest(radio_map.rss) - 1.0
        self.rss_min = float(rss_min)
        self._means: np.ndarray | None = None  # per-AP means, when a device offset is asked for
        self.representation = representation
        self._index = InvertedIndex.from_blocks(self._values(b) for b in row_blocks(radio_map.rss))

    def _values(self, rss: np.ndarray) -> np.ndarray:
        """RSS in the index's representation: eq. 21's positive values, or powed (matchers.py)."""
        pos = np.maximum(positive(rss, self.tau, self.rss_min), 0.0)
        return powed(pos, self.rss_min) if self.representation == "powed" else pos

    def localize(
        self,
        queries: Fingerprints,
        metric: Metric | str = Metric.EUCLIDEAN,
        k: int = 1,
        align_device: bool = True,
        weights: str = "equal",
    ) -> Estimate:
        """1-NN (k = 1) or kNN: position = mean of the k neighbours (``weights``: plain or by
        inverse distance, :mod:`.matchers`), floor = the nearest one's. ``align_device``: the
        queries are one walk (one phone); its RSS offset against the map is estimated and
        removed first (:mod:`.devices`)."""
        m = self.map
        q = queries.aligned(m.bssids)
        offset = 0.0
        if align_device:
            if self._means is None:
                self._means = ap_means(m.rss)
            offset = offset_against(self._means, ap_means(q))
        qry = self._values(q - offset)
        idx, dist = self._index.search(qry, Metric(metric).value, k)
        return self._estimate(idx, dist, offset, weights)

    def localize_without(self, queries: Fingerprints, k: int, lo: int, hi: int,
                         metric: Metric | str = Metric.EUCLIDEAN, weights: str = "equal",
                         columns: np.ndarray | None = None) -> Estimate:  # fmt: skip
        """:meth:`localize` (no device offset) on the map without its reference points
        ``lo:hi`` — what an index of the others gives when their weakest reading is this map's
        (the same ``rss_min``): one index serves every walk left out in turn. ``columns``: the
        APs the others' map lists; the query's readings of the rest are dropped, as that map
        would (else they add the same to every Euclidean distance, which leaves 1-NN alone but
        not a Sørensen distance or a weight)."""
        q = queries.aligned(self.map.bssids)
        if columns is not None:
            q = np.where(columns[None, :], q, np.nan)
        idx, dist = self._index.search_without(self._values(q), k, lo, hi, Metric(metric).value)
        return self._estimate(idx, dist, 0.0, weights)

    def _estimate(self, idx: np.ndarray, dist: np.ndarray, offset: float,
                  weights: str = "equal") -> Estimate:  # fmt: skip
        m = self.map
        x = weighted_mean(m.x[idx], dist, weights)
        y = weighted_mean(m.y[idx], dist, weights)
        return Estimate(x, y, m.floor[idx[:, 0]], dist[:, 0], idx[:, 0], round(offset, 2))


def localize(
    radio_map: Fingerprints,
    queries: Fingerprints,
    metric: Metric | str = Metric.EUCLIDEAN,
    k: int = 1,
    tau: float = -90.0,
    rss_min: float | None = None,
    align_device: bool = True,
    matcher: Matcher | None = None,
) -> Estimate:
    """Localize ``queries`` on ``radio_map`` once (:class:`RadioMapIndex` keeps the index for
    repeated queries); ``matcher`` (:mod:`.matchers`), when given, instead of ``metric``/``k``."""
    if matcher is None:
        return RadioMapIndex(radio_map, tau, rss_min).localize(queries, metric, k, align_device)
    index = RadioMapIndex(radio_map, tau, rss_min, matcher.representation)
    return index.localize(queries, matcher.metric, matcher.k, align_device, matcher.weights)


def errors(est: Estimate, truth: Fingerprints) -> dict[str, float | None]:
    """Floor accuracy; position error where the floor is right (as the paper: ``mean_m`` …);
    over all queries with 15 m per floor of error (``mean_with_floor_penalty_m``) and the
    EvAAL score (``evaal_p75_m``) — a map that gets floors wrong cannot hide its hardest scans."""
    right = est.floor == truth.floor
    e = np.hypot(est.x - truth.x, est.y - truth.y)
    out: dict[str, float | None] = {"queries": int(truth.x.size)}
    if not right.size:
        out["floor_accuracy"] = None
        return out
    out["floor_accuracy"] = round(float(right.mean()), 4)
    out.update(error_stats(e[right]))
    allq = error_stats(e, est.floor - truth.floor)
    out["mean_with_floor_penalty_m"] = allq["mean_with_floor_penalty_m"]
    out["evaal_p75_m"] = allq["evaal_p75_m"]
    return out


def _mergeable(maps: list[Fingerprints]) -> set:
    """The frames of maps that may be merged (at most one); refused: none, a map of a built
    kind (merge the walks' points and build it from them), maps in different frames."""
    if not maps:
        raise WorkstationError("no radio maps to merge")
    built = sorted({m.kind for m in maps} - {"points"})
    if built:  # a kind is built from the walks' points, not from another kind's map
        raise WorkstationError(
            f"a map of kind {', '.join(built)} cannot be merged: merge the walks' maps "
            "(kind points) and pass --kind to build it from them"
        )
    frames = {m.frame for m in maps if m.frame is not None}
    if len(frames) > 1:
        raise WorkstationError("radio maps in different frames cannot be merged")
    return frames
