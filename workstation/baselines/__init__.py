"""The methods the paper compares against, each giving a :class:`Trajectory` (and from it a
radio map: every scan placed on it, :meth:`Trajectory.radio_map`).

- :func:`.pdr.pdr` — PDR I (``COMPASS_HEADING``: step counting, a fixed step length, the
  compass) and PDR II (``GYRO_HEADING``: the gyro, aligned to the compass at the start).
- :func:`.particles.particle_filter` — map filtering (PDR I in a particle filter over the
  floor-plan walls, known start) and Zee (unknown start, backward smoothing).
- :func:`.tap.tap_interpolation` — positions interpolated in time between the tapped fixes (an
  oracle on real data).
- :func:`.waypoints.waypoint_pdr` — the organizers' script: PDR re-anchored at each waypoint.

The manual grid survey's reference points come from the simulator (``sim``, walks ``survey5``
and ``survey10``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workstation.fingerprints.localize import Fingerprints
from workstation.session.model import sample_path


@dataclass(frozen=True)
class Trajectory:
    """Positions per step (t, x, y, floor) from a baseline."""

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    floor: np.ndarray

    def at(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return sample_path(self.t, self.x, self.y, self.floor, t)

    def radio_map(self, session, frame=None) -> Fingerprints:
        """Every scan of the walk placed on this trajectory (eq. 19–20, no quality control)."""
        times, bssids, rss = session.wifi.matrix()
        inside = (
            (times >= self.t[0]) & (times <= self.t[-1])
            if self.t.size
            else np.zeros(times.size, bool)
        )
        x, y, f = self.at(times[inside])
        return Fingerprints(x, y, f, bssids, rss[inside], frame)

    def scan_errors(self, session) -> np.ndarray:
        """How far :meth:`radio_map` places each scan from the ground truth (interpolated in
        time; scans outside the ground truth's span left out)."""
        gt = session.ground_truth
        times = np.unique(session.wifi.t)
        if not self.t.size:
            return np.empty(0)
        lo, hi = max(self.t[0], gt.t[0]), min(self.t[-1], gt.t[-1])
        times = times[(times >= lo) & (times <= hi)]
        x, y, _ = self.at(times)
        gx, gy, _ = gt.at(times)
        return np.hypot(x - gx, y - gy)

    def errors(self, session) -> np.ndarray:
        """Error at each step against the session's ground truth (dense or interpolated)."""
        gt = session.ground_truth
        m = (self.t >= gt.t[0]) & (self.t <= gt.t[-1])
        gx, gy, _ = gt.at(self.t[m])
        return np.hypot(self.x[m] - gx, self.y[m] - gy)
