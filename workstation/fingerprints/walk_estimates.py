"""A walk nobody measured, localized on a radio map (issue #64 item 2): one estimate per WiFi
scan — where (1-NN / kNN, §V-C), how well it matched, how many of its APs the map knows —
with its errors when the walk has ground truth; every scan not localized or not scored counted
with why. ``workstation localize --map M --session WALK -o estimates.csv|parquet|geojson``."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from workstation.fingerprints.localize import Estimate, Fingerprints, RadioMapIndex
from workstation.fingerprints.matchers import Matcher

#: why a scan has no estimate, or no error
NO_AP_KNOWN = "no AP the map knows: not localized"
OUTSIDE_TRUTH = "outside the ground truth's span (before its first fix or after its last): localized, not scored"


@dataclass(frozen=True)
class WalkEstimates:
    """Per scan of the walk (``columns``: t, x, y, floor, match_distance, aps_heard, aps_known,
    localized; with ground truth also true_x, true_y, true_floor, error_m — NaN where not
    scored), the scans not localized or not scored by reason, and the walk's phone offset
    removed against the map."""

    columns: dict[str, np.ndarray]
    not_used: dict[str, int] = field(default_factory=dict)
    device_offset_db: float = 0.0

    @property
    def scans(self) -> int:
        return int(self.columns["t"].size)

    @property
    def localized(self) -> np.ndarray:
        return self.columns["localized"]

    def scored(self) -> tuple[Estimate, Fingerprints] | None:
        """The localized scans with ground truth, as (estimate, truth) for ``errors``; None
        without ground truth."""
        c = self.columns
        if "true_x" not in c:
            return None
        m = np.isfinite(c["true_x"]) & self.localized
        n = int(m.sum())
        est = Estimate(c["x"][m], c["y"][m], c["floor"][m], c["match_distance"][m],
                       np.zeros(n, int), self.device_offset_db)  # fmt: skip
        truth = Fingerprints(c["true_x"][m], c["true_y"][m], c["true_floor"][m],
                             np.array([], str), np.empty((n, 0)))  # fmt: skip
        return est, truth


def estimate_walk(
    index: RadioMapIndex, session, matcher: Matcher | None = None, align_device: bool = True,
) -> WalkEstimates:  # fmt: skip
    """Every scan of ``session`` localized on ``index``'s map (module doc) with ``matcher``
    (:mod:`.matchers`; the paper's 1-NN when None; ``index`` built in its representation)."""
    matcher = matcher or Matcher()
    times, bssids, rss = session.wifi.matrix()
    m = index.map
    heard = np.isfinite(rss)
    known = np.isin(bssids, m.bssids)
    aps_known = (heard & known[None, :]).sum(axis=1)
    ok = aps_known > 0
    n = times.size
    x, y, f, dist = (np.full(n, np.nan) for _ in range(4))
    offset = 0.0
    if ok.any():
        q = Fingerprints(np.zeros(int(ok.sum())), np.zeros(int(ok.sum())),
                         np.zeros(int(ok.sum())), bssids, rss[ok])  # fmt: skip
        est = index.localize(q, matcher.metric, k=matcher.k, align_device=align_device,
                             weights=matcher.weights)  # fmt: skip
        x[ok], y[ok], f[ok], dist[ok] = est.x, est.y, est.floor, est.distance
        offset = est.device_offset_db
    cols = {"t": times, "x": x, "y": y, "floor": f, "match_distance": dist,
            "aps_heard": heard.sum(axis=1), "aps_known": aps_known, "localized": ok}  # fmt: skip
    not_used = {NO_AP_KNOWN: int((~ok).sum())} if (~ok).any() else {}
    gt = session.ground_truth
    if gt is not None and len(gt):
        inside = (times >= gt.t[0]) & (times <= gt.t[-1])
        tx, ty, tf = (np.full(n, np.nan) for _ in range(3))
        if inside.any():
            tx[inside], ty[inside], tf[inside] = gt.at(times[inside])
        cols |= {"true_x": tx, "true_y": ty, "true_floor": tf,
                 "error_m": np.where(inside & ok, np.hypot(x - tx, y - ty), np.nan)}  # fmt: skip
        if (~inside & ok).any():
            not_used[OUTSIDE_TRUTH] = int((~inside & ok).sum())
    if m.frame is not None:
        lat, lon = m.frame.to_latlon(np.nan_to_num(x), np.nan_to_num(y))
        cols |= {"lat": np.where(ok, lat, np.nan), "lon": np.where(ok, lon, np.nan)}
    return WalkEstimates(cols, not_used, offset)
