"""The building's radio map as evidence on which chain of matches is right (beyond the paper;
docs/decisions.md, "The building's map re-ranks the chains").

The association (:mod:`.association`) ends with the surviving chains of matches, best first by
what the sensors say. Where landmarks lie a few metres apart and the step length is off by a
sixth, the right chain is often among them but not first (mall F1, first-fix starts: the best
of the 8 best distinct chains is 1.46 m off at the fixes, the first 2.28 m). A radio map of
the building's *other* walks puts each of this walk's WiFi scans somewhere (1-NN, §V-C): the
chain that places the scans where the map does is likelier. Each scan adds

    log( w · N₂(d; σ) + (1 − w) / A )

with d the distance between where the chain places the scan (corrected trajectory) and where
the map puts it, N₂ the isotropic 2-D normal of σ = ``pdr.map_sigma_m`` (1-NN is metres off),
w = ``pdr.map_inlier`` the share of scans the map puts near the truth, and A the area the map
spans: a scan the map puts across the building says nothing but "elsewhere". A scan the map
puts on another floor than the chain is such an outlier. The sum, weighted by
``pdr.map_weight`` (< 1: consecutive scans are not independent, and the map was placed by the
same tracker), is added to each chain's log-likelihood, and the best chain is chosen again.

Compared are the chains the sensors alone cannot tell apart — at most
``state.START_AMBIGUOUS_MARGIN`` less likely than their best, the margin that makes a start
ambiguous — and the map decides only when it is decisive: the chain it prefers must beat the
sensors' best by ``AMBIGUOUS_LOGODDS`` with the map term in. On the mall a chain the sensors
found far less likely was as often worse as better when the map chose it: where no other walk
passed, the map puts a stretch of scans consistently elsewhere. And only chains that start
where the best one does: the start is never chosen by WiFi (a wrong start taken from the map
let wrong walks into it, session 18), so the start's ambiguity margin and the quarantine are
those of the sensors alone.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from workstation.fingerprints.devices import one_model
from workstation.fingerprints.localize import Fingerprints, localize
from workstation.params import LocalizeParams, PDRParams
from workstation.pipeline.confidence import AMBIGUOUS_LOGODDS
from workstation.pipeline.tracking.state import (
    START_AMBIGUOUS_MARGIN,
    Reranked,
    Track,
    TrackerState,
)
from workstation.session import Session, WifiScans

#: distinct chains compared (the association keeps ``beam_width`` = 16 at most)
CHAINS = 8
#: the least area a map is taken to span (m²): a map of one corridor still has walls around it
MIN_AREA_M2 = 100.0


@dataclass(frozen=True)
class MapPrior:
    """Where a map puts each WiFi scan of one walk (scan times, positions and floors)."""

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    floor: np.ndarray
    area_m2: float  # the area the map's reference points span (bounding box)
    source: str = ""  # what map it came from, for the summary
    key: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        h = hashlib.sha1()
        for a in (self.t, self.x, self.y, self.floor):
            h.update(np.ascontiguousarray(a, dtype=np.float64).tobytes())
        object.__setattr__(self, "key", h.hexdigest())


def prior_from_map(
    fingerprints: Fingerprints, wifi: WifiScans, lp: LocalizeParams, align: bool = True,
    source: str = "",
) -> MapPrior:  # fmt: skip
    """Each scan of ``wifi`` (one walk's :class:`..session.WifiScans`) localized on the map
    ``fingerprints`` (a :class:`..localize.Fingerprints`) as ``localize`` would (1-NN, τ;
    ``align``: the walk's device offset removed first, across phone models) — the paper's
    1-NN whatever ``localize``'s matcher: ``pdr.map_sigma_m`` was measured with it."""
    times, q = scan_queries(wifi)
    est = localize(fingerprints, q, "euclidean", k=1, tau=lp.tau_dbm, align_device=align)
    return MapPrior(times, est.x, est.y, est.floor, span_m2(fingerprints), source)


def scan_queries(wifi: WifiScans) -> tuple[np.ndarray, Fingerprints]:
    """A walk's scans (:class:`..session.WifiScans`) as 1-NN queries (positions unknown: 0),
    with their times."""
    times, bssids, rss = wifi.matrix()
    z = np.zeros(times.size)
    return times, Fingerprints(z, z, z, bssids, rss)


def prior_for_walk(
    fingerprints: Fingerprints | None, session: Session, lp: LocalizeParams, source: str
) -> MapPrior | None:
    """:func:`prior_from_map` for one walk (``session``) on the building's map (``run --map``,
    ``edit --map``): its device offset removed only across phone models; None for an empty
    map."""
    if fingerprints is None or not len(fingerprints):
        return None
    models = (fingerprints.device, session.metadata.device)
    align = lp.align_devices and not one_model(models)
    return prior_from_map(fingerprints, session.wifi, lp, align, source)


def span_m2(fp: Fingerprints) -> float:
    """The bounding box of a map's reference points (m², at least ``MIN_AREA_M2``)."""
    if not len(fp):
        return MIN_AREA_M2
    return max(float(np.ptp(fp.x) * np.ptp(fp.y)), MIN_AREA_M2)


def loglik(track: Track, prior: MapPrior, p: PDRParams) -> float:
    """Σ over the scans after the walk started of log(w N₂(d; σ) + (1 − w)/A) (module doc)."""
    inside = prior.t >= track.start.time
    if not inside.any() or not track.steps.t.size:
        return 0.0
    x, y, f = track.position_at(prior.t[inside], corrected=True)
    return float(scan_terms(x, y, f, prior, inside, p).sum())


def scan_terms(
    x: np.ndarray, y: np.ndarray, f: np.ndarray, prior: MapPrior, sel: np.ndarray, p: PDRParams
) -> np.ndarray:
    """log(w N₂(d; σ) + (1 − w)/A) per scan ``prior[sel]`` placed at (x, y) on floor f (arrays
    whose last axis runs over those scans; leading axes broadcast: several placements at
    once)."""
    d2 = (x - prior.x[sel]) ** 2 + (y - prior.y[sel]) ** 2
    s2 = p.map_sigma_m**2
    near = p.map_inlier * np.exp(-d2 / (2 * s2)) / (2 * math.pi * s2)
    near = np.where(np.abs(f - prior.floor[sel]) < 0.5, near, 0.0)
    return np.log(near + (1 - p.map_inlier) / prior.area_m2)


def rerank(
    ranked: list[TrackerState], prior: MapPrior, p: PDRParams,
    finish: Callable[[TrackerState], Track],
) -> tuple[list[TrackerState], Reranked]:  # fmt: skip
    """``ranked`` with the chain that best explains sensors and map first (module doc).
    ``finish``: a chain's :class:`Track` as the tracker would give it (replayed, end closed)."""
    if not ranked or p.map_weight <= 0:
        return ranked, Reranked()
    start, top = ranked[0].matches[0].node, ranked[0].score
    seen: set = set()
    chains: list[TrackerState] = []
    for st in ranked:
        key = tuple((m.k, m.node) for m in st.matches)
        if st.matches[0].node != start or key in seen or top - st.score > START_AMBIGUOUS_MARGIN:
            continue
        seen.add(key)
        chains.append(st)
        if len(chains) == CHAINS:
            break
    if len(chains) < 2:
        return ranked, Reranked(0, len(chains), 0.0)
    score = [st.score + p.map_weight * loglik(finish(st), prior, p) for st in chains]
    j = int(np.argmax(score))
    if score[j] - score[0] < AMBIGUOUS_LOGODDS:
        j = 0  # the map is not decisive: the sensors' best stays
    info = Reranked(j, len(chains), round(float(score[j] - score[0]), 2),
                    round(float(chains[0].score - chains[j].score), 2))  # fmt: skip
    if j == 0:
        return ranked, info
    return [chains[j]] + [st for st in ranked if st is not chains[j]], info
