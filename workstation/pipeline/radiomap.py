"""Radio map (§IV-B, eq. 19–20, Algorithm 1).

Each WiFi scan's position is interpolated in time between the steps around it; its segment is
the one that holds that time; the scan becomes a reference point (RP) when the segment's belief
passes ε_S. Switchable, beyond the paper: positions from the backward-corrected trajectory, and
scans taken while the walker stands still at a matched landmark placed at the landmark and
trusted (the position is known there whatever the belief of the segments around it) — while
the pressure stays at its level there: a stop in a lift goes on through the ride, and those
scans are on no floor; and scans of untrusted closed segments kept where the trusted ones leave
a gap (``fill_gaps_m``).

A scan taken while the track changes floor (the steps before and after it are on different
floors: a lift ride, or the step where the barometer's floor flips on a flight) is on neither
floor and is never a reference point, unless it was taken standing at a matched landmark. On
the simulated office such a scan, labelled with the floor left, drew the queries of the other
floor to it (9 of 139 queries on the wrong floor, one seed).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workstation.fingerprints.standby import JOIN_M, JOIN_MAX_SIGMA_M
from workstation.params import RadioMapParams
from workstation.pipeline.belief import Belief
from workstation.pipeline.heading import Heading
from workstation.pipeline.landmarks import window_means
from workstation.pipeline.sigma import COMPASS_GATE_DEG, sigma_and_compass
from workstation.pipeline.tracking.state import END_CHECK_M, Track
from workstation.session import Scalar, WifiScans

# why a scan is no reference point (RadioMap.why_not; summary.json "scans_not_points")
WHY_NOT = {
    "before_start": "before the walk started",
    "between_floors": "taken between two floors",
    "sigma": "placed too uncertainly (sigma above radiomap.max_sigma_m), on standby: a merged "
    + (f"map takes such a scan where no point lies within {JOIN_M:g} m" if JOIN_M > 0
       else f"map takes it, with its sigma, unless that is over {JOIN_MAX_SIGMA_M:g} m"),
    "belief": "its segment's belief is below eps_S",
    # over the σ cut only for the compass's part of σ (sigma.compass_drift), on standby alike:
    # the surveyor checks the landmark matched before it, where the track turned and the phone
    # did not
    "compass": f"placed along a stretch the phone's compass denies (over {COMPASS_GATE_DEG:g} "
    "degrees off it: check the landmark matched before it), on standby as a scan placed too "
    "uncertainly",
}

# a scan of a stop at a landmark is placed on it when the pressure (1-s means) is within this
# of its level when the landmark was matched: above door drafts (0.05 hPa) and a minute's
# weather drift, a third of the lowest storey seen (0.28 hPa, the museum)
STOP_LEVEL_HPA = 0.1


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
    filled: np.ndarray  # bool: from an untrusted closed segment, kept where the map had a gap
    bssids: np.ndarray
    rss: np.ndarray
    corrected: bool = True  # placed on the backward-corrected trajectory
    sigma: np.ndarray | None = None  # placement uncertainty per scan (m, sigma.py; inf: none)
    why_not: np.ndarray | None = None  # per scan: why it is no reference point (WHY_NOT; "")

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def reference_points(self) -> int:
        return int(self.accepted.sum())

    def accepted_only(self) -> RadioMap:
        return self.rows(self.accepted)

    def rows(self, m: np.ndarray) -> RadioMap:
        """The scans at mask ``m``."""
        return RadioMap(
            self.t[m],
            self.x[m],
            self.y[m],
            self.floor[m],
            self.segment[m],
            self.belief[m],
            self.accepted[m],
            self.at_landmark[m],
            self.filled[m],
            self.bssids,
            self.rss[m],
            self.corrected,
            None if self.sigma is None else self.sigma[m],
            None if self.why_not is None else self.why_not[m],
        )

    @property
    def held_for_sigma(self) -> np.ndarray:
        """Per scan, held back for its σ alone (``radiomap.max_sigma_m``; the compass's part of
        it too): on standby in the walk's map, it joins a merged map as standby.py says."""
        if self.why_not is None:
            return np.zeros(len(self), bool)
        return np.isin(self.why_not, [WHY_NOT["sigma"], WHY_NOT["compass"]])

    def not_points(self) -> dict[str, int]:
        """How many scans did not become reference points, by reason (WHY_NOT)."""
        if self.why_not is None:
            return {}
        keys, n = np.unique(self.why_not[self.why_not != ""], return_counts=True)
        return {str(k): int(c) for k, c in zip(keys, n)}


def build_radiomap(
    wifi: WifiScans,
    track: Track,
    belief: Belief,
    p: RadioMapParams,
    landmarks: dict[str, tuple[float, float, float]] | None = None,
    pressure: Scalar | None = None,
    landmark_sigma_m: float | None = None,
    heading: Heading | None = None,
) -> RadioMap:
    """``landmarks``: node → (x, y, floor), for scans taken standing at a matched landmark;
    ``pressure``: to tell a stop from a lift ride; ``landmark_sigma_m``: how well the graph
    places its landmarks (σ's start, sigma.py); ``heading``: the compass σ checks the placed
    track against (sigma.py)."""
    times, bssids, rss = wifi.matrix()
    x, y, f = track.position_at(times, corrected=p.backward_correction)
    transit = _between_floors(track, times)
    if track.segments.t0.size:
        seg = np.searchsorted(track.segments.t0, times, side="right") - 1
    else:
        seg = np.full(times.size, -1)
    seg = np.where(times < track.start.time, -1, seg)
    bel = (
        np.where(seg >= 0, belief.belief[np.clip(seg, 0, None)], 0.0)
        if belief.belief.size
        else np.zeros(times.size)
    )
    at = np.zeros(times.size, bool)
    if p.scans_at_landmark_stops and landmarks:
        level = None
        if pressure is not None and len(pressure) >= 2:
            tc, pm = window_means(pressure, 1.0)
            level = np.interp(times, tc, pm)
        for s, node in enumerate(track.segments.from_node):
            lo, hi = belief.stop_t0[s], belief.stop_t1[s]
            if node not in landmarks or not np.isfinite(lo):
                continue
            m = (times >= lo) & (times <= hi)
            if level is not None:  # at the landmark's level only: not riding a lift to or from it
                m &= np.abs(level - np.interp(track.segments.t0[s], tc, pm)) <= STOP_LEVEL_HPA
            x[m], y[m], f[m] = landmarks[node]
            at |= m
    sigma, from_compass = sigma_and_compass(track, times, seg, at, landmark_sigma_m, heading)
    over = sigma > p.max_sigma_m
    by_compass = (p.acceptance == "sigma") & over & (sigma - from_compass <= p.max_sigma_m)
    if p.acceptance == "sigma":
        closeness, reject = sigma <= p.max_sigma_m, "sigma"
    else:  # the paper: the segment's belief passes ε_S
        closeness = (
            (seg >= 0) & belief.accepted[np.clip(seg, 0, None)]
            if belief.accepted.size
            else np.zeros(times.size, bool)
        )
        reject = "belief"
    # a stop on a landmark that a nearly as likely association put elsewhere is no anchor
    ok = (closeness & ~transit) | (at & (sigma <= p.max_sigma_m))
    filled = np.zeros(times.size, bool)
    if p.fill_gaps_m > 0 and ok.any():
        # within a factor 2 of the acceptance, and not re-found after the track was lost (its
        # path is not known: on the museum such points were 13–21 m off)
        segs, end = track.segments, track.end
        sane = segs.missed[np.clip(seg, 0, None)] >= 0 if segs.missed.size else seg < 0
        if end.how == "closed" and end.sigma > END_CHECK_M and segs.to_node.size:
            # an end placed too loosely to check the walk (verdict.py) closes its segment for
            # the backward correction, not as a matched landmark does: no gap fill there
            sane &= seg != segs.to_node.size - 1
        close = (
            sigma <= 2 * p.max_sigma_m if p.acceptance == "sigma" else bel >= belief.threshold / 2
        )
        near = close & sane & (~transit | at)
        new = _fill_gaps(ok, np.where(near, seg, -1), track, x, y, f, p.fill_gaps_m)
        filled, ok = new & ~ok, new
    why = np.select(
        [ok, seg < 0, transit, at],
        ["", WHY_NOT["before_start"], WHY_NOT["between_floors"], WHY_NOT["sigma"]],
        WHY_NOT[reject],
    )
    why = np.where((why == WHY_NOT["sigma"]) & by_compass, WHY_NOT["compass"], why)
    return RadioMap(
        times, x, y, f, seg, bel, ok, at, filled, bssids, rss, p.backward_correction, sigma, why
    )


def _between_floors(track: Track, times: np.ndarray) -> np.ndarray:
    """True where the track samples before and after a time are on different floors."""
    st = track.steps
    if st.t.size < 2:
        return np.zeros(times.size, bool)
    nxt = np.clip(np.searchsorted(st.t, times, side="left"), 0, st.t.size - 1)
    prev = np.clip(np.searchsorted(st.t, times, side="right") - 1, 0, st.t.size - 1)
    return st.floor[prev] != st.floor[nxt]


def _fill_gaps(
    ok: np.ndarray, seg: np.ndarray, track: Track, x: np.ndarray, y: np.ndarray, f: np.ndarray,
    gap_m: float,
) -> np.ndarray:  # fmt: skip
    """Scans of rejected *closed* segments (both ends on matched landmarks, or on an end that
    checks the walk; the caller passes segment −1 for those whose belief is below ε_S / 2 or
    whose path is not known) farther than ``gap_m`` from every
    trusted scan on their floor become reference points too: a point placed to a metre or two
    beats no point, where 1-NN would answer from metres away."""
    closed = (seg >= 0) & (track.segments.to_node[np.clip(seg, 0, None)] != "")
    cand = np.flatnonzero(closed & ~ok)
    out = ok.copy()
    for fl in np.unique(f[cand]):
        c = cand[f[cand] == fl]
        t = np.flatnonzero(ok & (f == fl))
        if t.size == 0:
            out[c] = True
            continue
        d = np.hypot(x[c, None] - x[None, t], y[c, None] - y[None, t]).min(axis=1)
        out[c[d > gap_m]] = True
    return out
