"""The radio-map kinds of ``evaluate --walks`` and how one kind is scored: each query walk
localized (1-NN, or kNN as the parameters say) on the map merged from every other walk of that
kind, errors pooled over all queries and over the *covered* ones (another walk's ground truth
passed within ``COVERED_M`` on the query's floor). :mod:`.walks` runs the walks and builds
the maps."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from workstation.fingerprints.devices import ap_means, fit_offsets
from workstation.fingerprints.kinds import KINDS as BUILT
from workstation.fingerprints.kinds import build
from workstation.fingerprints.localize import Fingerprints, RadioMapIndex, localize
from workstation.fingerprints.matchers import METHODS, Matcher, of_params
from workstation.fingerprints.standby import JOIN_M, floor_points, joins_without_one
from workstation.params import LocalizeParams
from workstation.pipeline.tracking.map_prior import MapPrior, scan_queries, span_m2
from workstation.session import WifiScans
from workstation.stats import error_stats

KINDS = {
    "ours": "Ours",
    "ours_unfiltered": "Ours, every scan kept (no filter)",
    "tap_oracle": "Tap interpolation (oracle)",
    "waypoint_pdr": "Waypoint-anchored PDR (organizers', needs taps)",
    "pdr_i": "PDR I",
    "tap_oracle_in_map": "Tap oracle, walks in our map only",
    "waypoint_pdr_in_map": "Waypoint PDR, walks in our map only",
}
SAME_WALKS = {"tap_oracle_in_map": "tap_oracle", "waypoint_pdr_in_map": "waypoint_pdr"}


@dataclass(frozen=True)
class MapKindResult:
    """One kind of radio map, every walk localized on the map of the others."""

    kind: str
    label: str
    queries: int
    reference_points_per_map: float
    floor_accuracy: float
    error_floor_right: dict[str, float]  # mean_m, median_m, p75_m, p90_m
    mean_with_floor_penalty_m: float
    evaal_p75_m: float
    query_device_offsets_db: dict[str, float]  # per walk, removed before matching
    # the same over the covered queries only (COVERED_M, module doc)
    covered_queries: int = 0
    covered_floor_accuracy: float = float("nan")
    covered_mean_with_floor_penalty_m: float = float("nan")
    # share of queries with a point of the map within COVERED_M of where they were taken
    near_map: float = float("nan")


COVERED_M = 5.0


@dataclass(frozen=True)
class Penalized:
    """A map's mean error with the floor penalty (m) under one matcher: over every query and over
    the covered ones (None: none covered) — one cell of results.json's ``matchers`` and
    ``built_kinds`` (the names are its keys)."""

    mean_with_floor_penalty_m: float
    covered_mean_with_floor_penalty_m: float | None


def covered_by_others(q: Fingerprints, others: list[Fingerprints]) -> np.ndarray:
    """Per query: another walk's ground truth passed within COVERED_M on its floor."""
    out = np.zeros(len(q), bool)
    for o in others:
        for f in np.unique(q.floor):
            mq, mo = q.floor == f, o.floor == f
            if mo.any() and mq.any():
                d = np.hypot(q.x[mq, None] - o.x[None, mo], q.y[mq, None] - o.y[None, mo])
                out[mq] |= d.min(axis=1) <= COVERED_M
    return out


class _Pool:
    """Every walk's map of one kind merged once: the map of all walks but one is then a row and
    column selection of it, equal to merging the others (:meth:`Fingerprints.merge`: the union
    of their APs; each one's device offset fitted on the others' per-AP means) without
    re-aligning every map's columns for every query. Rows on standby (:mod:`..standby`) are
    settled once for every walk left out: those that join whichever walk is out are rows of
    ``all``; those that join only while one walk is out wait in ``extra`` under its name."""

    def __init__(self, maps: dict[str, Fingerprints], cover_m: float = JOIN_M):
        self.names = list(maps)
        fps = list(maps.values())
        merged = Fingerprints.merge(fps, settle=False)
        owner = np.repeat(np.arange(len(fps)), [len(m) for m in fps])
        self.extra: dict[str, tuple[Fingerprints, np.ndarray]] = {}
        if merged.standby is not None:
            always, only = joins_without_one(
                merged.x, merged.y, merged.floor, merged.on_standby, owner, cover_m, merged.sigma
            )
            for w in np.unique(only[only >= 0]).tolist():
                r = only == w
                self.extra[self.names[w]] = (replace(merged.subset(r), standby=None), owner[r])
            keep = ~merged.on_standby | always
            waits = merged.on_standby[keep]
            merged, owner = replace(merged.subset(keep), standby=None), owner[keep]
        else:
            waits = np.zeros(len(merged), bool)
        self.all = merged
        b = self.all.bssids
        self.member = np.zeros((len(fps), b.size), bool)  # the APs each map lists
        for i, m in enumerate(fps):
            self.member[i, np.searchsorted(b, m.bssids)] = True
        self.count = self.member.sum(axis=0)
        self.stop = np.cumsum(np.bincount(owner, minlength=len(fps)))
        self.start = self.stop - np.bincount(owner, minlength=len(fps))
        # each map's device offset is fitted on its rows not on standby, as merging fits it
        self.means = np.vstack([ap_means(self.all.rss[a:z][~waits[a:z]])
                                for a, z in zip(self.start, self.stop)])  # fmt: skip
        # each map's weakest reading: the others' weakest is the map without it's (its rss_min)
        self.weakest = np.array(
            [_weakest(self.all.rss[a:z]) for a, z in zip(self.start, self.stop)]
        )

    def rows(self, name: str) -> tuple[int, int]:
        """The rows of walk ``name`` in the merged map (0, 0 when it gave none)."""
        if name not in self.names:
            return 0, 0
        i = self.names.index(name)
        return int(self.start[i]), int(self.stop[i])

    def index(self, tau: float, representation: str = "positive") -> RadioMapIndex:
        """The index of every walk's map merged, with its RSS minimum."""
        w = self.weakest[np.isfinite(self.weakest)]
        return RadioMapIndex(self.all, tau, (float(w.min()) if w.size else -100.0) - 1.0,
                             representation)  # fmt: skip

    def rss_min(self, name: str, align: bool) -> float | None:
        """The RSS minimum :class:`..localize.RadioMapIndex` takes for the map without ``name``
        (its weakest reading − 1 dB), from each map's weakest; None when aligned (the offsets
        move the readings: the index computes it)."""
        if align:
            return None
        w = self.weakest[[n != name for n in self.names]]
        if name in self.extra:
            w = np.append(w, _weakest(self.extra[name][0].rss))
        w = w[np.isfinite(w)]
        return (float(w.min()) if w.size else -100.0) - 1.0

    def columns(self, name: str) -> np.ndarray:
        """The APs the map without walk ``name`` lists."""
        keep = np.array([n != name for n in self.names])
        return self.count - (self.member[~keep].sum(axis=0)) > 0

    def without(self, name: str, align: bool) -> Fingerprints | None:
        keep = np.array([n != name for n in self.names])
        if not keep.any():
            return None
        rows = np.repeat(keep, self.stop - self.start)
        cols = self.columns(name)
        a = self.all
        rss = a.rss[np.ix_(np.flatnonzero(rows), np.flatnonzero(cols))]
        off: tuple[float, ...] = ()
        if align:
            fitted = np.zeros(int(keep.sum()))
            if keep.sum() > 1:
                fitted, _ = fit_offsets(self.means[keep][:, cols])
                rss -= np.repeat(fitted, (self.stop - self.start)[keep])[:, None]
            off = tuple(round(float(o), 2) for o in fitted)
        x, y, f = a.x[rows], a.y[rows], a.floor[rows]
        sig = None if a.sigma is None else a.sigma[rows]
        if name in self.extra:  # rows on standby that join while this walk is out
            ex, own = self.extra[name]
            more = ex.rss[:, cols]
            if align:
                more = more - np.asarray(fitted)[(np.cumsum(keep) - 1)[own]][:, None]
            x, y, f = np.append(x, ex.x), np.append(y, ex.y), np.append(f, ex.floor)
            rss = np.vstack([rss, more])
            sig = None if sig is None or ex.sigma is None else np.append(sig, ex.sigma)
        return Fingerprints(x, y, f, a.bssids[cols], rss, a.frame, off, sigma=sig)


def _weakest(rss: np.ndarray) -> float:
    heard = rss[np.isfinite(rss)]
    return float(heard.min()) if heard.size else np.inf


def map_priors(
    maps: dict[str, Fingerprints], wifi: dict[str, WifiScans], lp: LocalizeParams, align: bool
) -> dict[str, MapPrior]:
    """Per walk of ``wifi`` (name → its :class:`..session.WifiScans`): where the map merged from
    the other walks of ``maps`` (name → its first-pass map "ours") puts its scans — the
    evidence :mod:`..pipeline.map_prior` weighs in choosing the walk's chain of matches. A
    walk is never in its own map. The paper's 1-NN, as :func:`..map_prior.prior_from_map`."""
    given = {k: m for k, m in maps.items() if len(m)}
    if not given:
        return {}
    pool = _Pool(given)
    shared = pool.index(lp.tau_dbm) if not align else None
    out: dict[str, MapPrior] = {}
    for name, wifi_scans in wifi.items():
        times, q = scan_queries(wifi_scans)
        if not times.size:
            continue
        lo, hi = pool.rows(name)
        if hi - lo >= len(pool.all):
            continue  # no other walk's map
        if (shared is not None and name not in pool.extra
                and pool.rss_min(name, False) == shared.rss_min):  # fmt: skip
            est = shared.localize_without(q, 1, lo, hi)
            keep = np.ones(len(pool.all), bool)
            keep[lo:hi] = False
            area = span_m2(pool.all.subset(keep))
        else:
            m = pool.without(name, align)
            if m is None:
                continue
            est = localize(m, q, "euclidean", k=1, tau=lp.tau_dbm,
                           rss_min=pool.rss_min(name, align), align_device=align)  # fmt: skip
            area = span_m2(m)
        out[name] = MapPrior(times, est.x, est.y, est.floor, area, "the other walks' map")
    return out


def score_kind(kind: str, maps, queries, covered, lp, align: bool,
               matcher: Matcher | None = None) -> MapKindResult:  # fmt: skip
    """Every query walk localized on the map of the others of this kind (``maps``: walk →
    kind → its map; ``covered``: walk → which of its queries another walk passed near) with
    ``matcher`` (:mod:`..fingerprints.matchers`; None: the one ``lp`` selects)."""
    m = matcher or of_params(lp)
    err, ferr, cov, sizes, offsets, near = [], [], [], [], {}, []
    given = {k: m[kind] for k, m in maps.items() if len(m[kind])}
    pool = _Pool(given) if given else None  # every walk quarantined: no map of ours at all
    # one index for every walk left out in turn, where that gives what the map of the others
    # would: no device offsets, and the walk left out not the one with the weakest reading
    # (else the others' map has another RSS minimum): identical results, 742 index builds → 7
    # on the mall's 106 walks
    shared = (pool.index(lp.tau_dbm, m.representation)
              if pool is not None and not align else None)  # fmt: skip
    for q, qf in queries.items():
        if pool is None or not len(qf):
            continue
        lo, hi = pool.rows(q)
        got = _on_the_others(pool, shared, q, qf, m, lp, align)
        if got is None:
            continue
        est, n_map = got
        near.append(_near(pool.all, lo, hi, qf) if n_map else np.zeros(len(qf), bool))
        err.append(np.hypot(est.x - qf.x, est.y - qf.y))
        ferr.append(est.floor - qf.floor)
        cov.append(covered[q])
        sizes.append(n_map)
        offsets[q] = est.device_offset_db
    e = np.concatenate(err) if err else np.empty(0)
    fe = np.concatenate(ferr) if ferr else np.empty(0)
    right = np.abs(fe) < 0.5
    allq = error_stats(e, fe)
    c = np.concatenate(cov) if cov else np.zeros(0, bool)
    cq = error_stats(e[c], fe[c])
    return MapKindResult(
        kind=kind,
        label=KINDS[kind],
        queries=int(e.size),
        reference_points_per_map=round(float(np.mean(sizes)), 1) if sizes else 0.0,
        floor_accuracy=allq.get("floor_accuracy", float("nan")),
        error_floor_right=error_stats(e[right]),
        mean_with_floor_penalty_m=allq.get("mean_with_floor_penalty_m", float("nan")),
        evaal_p75_m=allq.get("evaal_p75_m", float("nan")),
        query_device_offsets_db=offsets,
        covered_queries=int(c.sum()),
        covered_floor_accuracy=cq.get("floor_accuracy", float("nan")),
        covered_mean_with_floor_penalty_m=cq.get("mean_with_floor_penalty_m", float("nan")),
        near_map=round(float(np.concatenate(near).mean()), 4) if near else float("nan"),
    )


def _on_the_others(pool: _Pool, shared, q: str, qf: Fingerprints, m: Matcher, lp, align: bool):
    """Query walk ``q`` localized on the map of the others — on the one index of every walk
    with its own rows left out of the search where that gives what the others' map would
    (module doc of :func:`score_kind`), else on that map merged — and the map's size; None
    when there is no other walk's map."""
    lo, hi = pool.rows(q)
    if (
        shared is not None
        and hi - lo < len(pool.all)
        and q not in pool.extra
        and pool.rss_min(q, False) == shared.rss_min
    ):
        est = shared.localize_without(qf, m.k, lo, hi, m.metric, m.weights, pool.columns(q))
        return est, len(pool.all) - (hi - lo)
    rm = pool.without(q, align)
    if rm is None:
        return None
    est = localize(rm, qf, tau=lp.tau_dbm, rss_min=pool.rss_min(q, align), align_device=align,
                   matcher=m)  # fmt: skip
    return est, len(rm)


def _near(m: Fingerprints, lo: int, hi: int, q: Fingerprints) -> np.ndarray:
    """Per query: a row of ``m`` outside ``lo:hi`` within COVERED_M of it, on its floor."""
    from scipy.spatial import cKDTree

    keep = np.ones(len(m), bool)
    keep[lo:hi] = False
    if not keep.any():
        return np.zeros(len(q), bool)
    d, _ = cKDTree(floor_points(m.x[keep], m.y[keep], m.floor[keep])).query(
        floor_points(q.x, q.y, q.floor), distance_upper_bound=COVERED_M
    )
    return d <= COVERED_M


#: the kinds every matcher of the table is scored on: ours, every row, the tap oracle
MATCHER_KINDS = ("ours", "ours_unfiltered", "tap_oracle")


def score_matchers(maps, queries, covered, lp, align: bool,
                   scored: dict[str, MapKindResult]) -> dict[str, dict[str, Penalized]]:  # fmt: skip
    """Every matcher of the table (:data:`..fingerprints.matchers.METHODS`) on the same
    queries, on our map, every row and the tap oracle (issue #63): per matcher, per kind, the
    mean error with the floor penalty, over all and over the covered queries. ``scored``: the
    kinds already scored with the matcher ``lp`` selects (not scored again)."""
    out: dict[str, dict[str, Penalized]] = {}
    for name, m in METHODS.items():
        out[name] = {}
        for kind in MATCHER_KINDS:
            r = (scored[kind] if m == of_params(lp) and kind in scored
                 else score_kind(kind, maps, queries, covered, lp, align, m))  # fmt: skip
            out[name][kind] = Penalized(r.mean_with_floor_penalty_m,
                                        r.covered_mean_with_floor_penalty_m)  # fmt: skip
    return out


def _built_scores(kind: str, source: str, given: dict, queries, covered, lp,
                  align: bool) -> dict[str, Penalized]:  # fmt: skip
    """One kind built from one source's maps (:func:`score_built_kinds`): per matcher ("default",
    "1nn"), the mean error with the floor penalty, all queries and the covered ones."""
    pool = _Pool(given)
    # per map built (a split's one serves every query walk), its index per matcher
    made: dict[tuple[int, int], dict[str, RadioMapIndex] | None] = {}
    errs: dict[str, list] = {"default": [], "1nn": []}
    cov = []
    matchers = (("default", of_params(lp)), ("1nn", METHODS["1nn"]))
    for q, qf in queries.items():
        rows = pool.rows(q)
        if rows not in made:
            rm = pool.without(q, align)
            built = None if rm is None or not len(rm) else build(kind, rm)
            made[rows] = None if built is None else {
                label: RadioMapIndex(built, lp.tau_dbm, representation=m.representation)
                for label, m in matchers}  # fmt: skip
        indexes = made[rows]
        if indexes is None or not len(qf):
            continue
        for label, m in matchers:
            est = indexes[label].localize(qf, m.metric, m.k, align, m.weights)
            errs[label].append((np.hypot(est.x - qf.x, est.y - qf.y), est.floor - qf.floor))
        cov.append(covered[q])
    c = np.concatenate(cov) if cov else np.zeros(0, bool)
    out = {}
    for label, pairs in errs.items():
        if not pairs:
            continue
        e, fe = (np.concatenate(v) for v in zip(*pairs))
        key = "mean_with_floor_penalty_m"
        out[f"{source}/{label}"] = Penalized(
            error_stats(e, fe)[key], error_stats(e[c], fe[c])[key] if c.any() else None
        )
    return out


#: the sources each built kind of map is scored on, and the matchers (the default and 1-NN)
BUILT_SOURCES = ("ours", "tap_oracle")
#: leave one out builds each kind once per walk: beyond this many walks, the kinds are scored
#: only in a split (``--queries-every``), where one map serves every query walk (the mall's
#: 106 walks: 45 s → 456 s)
MAX_LOO_BUILDS = 12


def score_built_kinds(maps, queries, covered, lp, align: bool) -> dict[str, dict[str, Penalized]]:
    """Every kind of map built from the points (:data:`..fingerprints.kinds.KINDS` but
    ``points``, issue #63) on the same queries: each query walk localized on the kind built
    from the map of the others, ours and the tap oracle's, with the selected matcher and the
    paper's 1-NN. Per kind, per "source/matcher", the mean error with the floor penalty (all
    queries and the covered ones). A map built once serves every query walk that is not in it
    (a split's)."""
    out: dict[str, dict[str, Penalized]] = {}
    if sum(q in maps for q in queries) > MAX_LOO_BUILDS:  # a build per walk left out
        return out
    for kind in (k for k in BUILT if k != "points"):
        out[kind] = {}
        for source in BUILT_SOURCES:
            given = {k: m[source] for k, m in maps.items() if len(m[source])}
            if given:
                out[kind] |= _built_scores(kind, source, given, queries, covered, lp, align)
    return out
