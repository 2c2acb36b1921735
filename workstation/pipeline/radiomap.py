"""Radio map (§IV-B, eq. 19–20, Algorithm 1).

Each WiFi scan's position is interpolated in time between the steps around it; its segment is
the one that holds that time; the scan becomes a reference point (RP) when the segment's belief
passes ε_S. Switchable, beyond the paper: positions from the backward-corrected trajectory.
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
            self.bssids,
            self.rss[m],
            self.corrected,
        )


def build_radiomap(wifi: WifiScans, track: Track, belief: Belief, p: RadioMapParams) -> RadioMap:
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
    return RadioMap(times, x, y, f, seg, bel, ok, bssids, rss, p.backward_correction)
