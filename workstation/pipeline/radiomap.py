"""Radio map (§IV-B, eq. 19–20, Algorithm 1).

Each WiFi scan's position is interpolated in time between the steps around it; its segment is
the one that holds that time; the scan becomes a reference point (RP) when the segment's belief
passes ε_S. Switchable, beyond the paper: positions from the backward-corrected trajectory, and
scans taken while the walker stands still at a matched landmark placed at the landmark and
trusted (the position is known there whatever the belief of the segments around it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..params import RadioMapParams
from ..session import WifiScans
from .belief import Belief
from .tracking import Track


@dataclass(frozen=True)
class RadioMap:
    """One row per scan (accepted or not); ``rss`` (scans × APs) NaN where unheard."""

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    floor: np.ndarray
    segment: np.ndarray
    belief: np.ndarray
    accepted: np.ndarray
    at_landmark: np.ndarray  # bool: taken standing at a matched landmark, placed on it
    bssids: np.ndarray
    rss: np.ndarray
    corrected: bool = True  # placed on the backward-corrected trajectory

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def reference_points(self) -> int:
        return int(self.accepted.sum())

    def accepted_only(self) -> RadioMap:
        m = self.accepted
        return RadioMap(
            self.t[m],
            self.x[m],
            self.y[m],
            self.floor[m],
            self.segment[m],
            self.belief[m],
            m[m],
            self.at_landmark[m],
            self.bssids,
            self.rss[m],
            self.corrected,
        )


def build_radiomap(
    wifi: WifiScans,
    track: Track,
    belief: Belief,
    p: RadioMapParams,
    landmarks: dict[str, tuple[float, float, float]] | None = None,
) -> RadioMap:
    """``landmarks``: node → (x, y, floor), for scans taken standing at a matched landmark."""
    times, bssids, rss = wifi.matrix()
    x, y, f = track.position_at(times, corrected=p.backward_correction)
    if track.seg_t0.size:
        seg = np.searchsorted(track.seg_t0, times, side="right") - 1
    else:
        seg = np.full(times.size, -1)
    seg = np.where(times < track.start_time, -1, seg)
    bel = (
        np.where(seg >= 0, belief.belief[np.clip(seg, 0, None)], 0.0)
        if belief.belief.size
        else np.zeros(times.size)
    )
    ok = (
        (seg >= 0) & belief.accepted[np.clip(seg, 0, None)]
        if belief.accepted.size
        else np.zeros(times.size, bool)
    )
    at = np.zeros(times.size, bool)
    if p.scans_at_landmark_stops and landmarks:
        for s, node in enumerate(track.seg_from):
            lo, hi = belief.stop_t0[s], belief.stop_t1[s]
            if node not in landmarks or not np.isfinite(lo):
                continue
            m = (times >= lo) & (times <= hi)
            x[m], y[m], f[m] = landmarks[node]
            at |= m
        ok |= at
    return RadioMap(times, x, y, f, seg, bel, ok, at, bssids, rss, p.backward_correction)
