"""WiFi: log-distance path loss with per-wall and per-floor attenuation and shadowing.

RSS = P(1 m) − 10 n log10(d) − walls · L_wall − |Δfloor| · L_floor + shadowing(x, y) + drift(t)
+ fading. Shadowing is a fixed, spatially smooth field per access point (from the building's
seed, so every walk and the manual survey see the same building); fading is drawn per scan.
APs weaker than −100 dBm are not heard, and a heard AP is missed from a scan now and then.

Realistic radio (:data:`REALISTIC`): the neighbours' access points around the building (real
walks hear ≈50–85 APs, the office has 24 of its own), each walk's phone reads all APs
``offset_db`` higher or lower (phone makes differ by several dB), and each AP's reading drifts
in time (people passing, doors, the walker turning): an Ornstein–Uhlenbeck process per AP and
walk, σ ``drift_sd_db``, correlation time ``drift_tau_s``, beside a smaller per-scan fading.
Measured on the museum walks, scans taken standing on one spot differ by 3.3 dB RMS 0–4 s apart,
3.9 dB at 8–15 s, 4.4 dB at 15–25 s and ≈ 5 dB beyond (docs/decisions.md): per-scan noise alone
(2.5 dB, 3.5 dB RMS apart at any interval) made the manual survey's five scans per point five
independent draws, where a real surveyor's five agree with each other more than with a walk
minutes later.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workstation.building.floorplan import count_crossings
from workstation.sim.building import AccessPoint, Building


@dataclass(frozen=True)
class RadioSpec:
    path_loss_exp: float = 2.6
    wall_db: float = 3.5
    floor_db: float = 16.0
    shadow_sd_db: float = 4.0
    fading_sd_db: float = 2.5
    floor_noise_dbm: float = -100.0
    miss_prob: float = 0.06
    weak_miss_prob: float = 0.25  # below -88 dBm
    neighbour_aps: int = 0  # APs of the neighbours, outside the building's walls
    device_offset_sd_db: float = 0.0  # σ of each walk's phone offset
    drift_sd_db: float = 0.0  # σ of each AP's slow drift in time (0: none)
    drift_tau_s: float = 20.0  # its correlation time


REALISTIC = RadioSpec(
    neighbour_aps=36, device_offset_sd_db=3.5, fading_sd_db=2.0, drift_sd_db=2.6, drift_tau_s=20.0
)


class RadioModel:
    """Mean RSS of every AP of ``building`` anywhere in it."""

    def __init__(self, building: Building, spec: RadioSpec = RadioSpec()):
        self.b = building
        self.spec = spec
        rng = np.random.default_rng(building.seed + 1000)
        ap = list(building.access_points)
        if spec.neighbour_aps:
            ap += _neighbours(building, spec.neighbour_aps)
        self.aps = tuple(ap)
        n = len(ap)
        k = 8
        # shadowing: per AP, a sum of k plane waves with 5-20 m wavelengths, normalised to sd
        wl = rng.uniform(5, 20, (n, k))
        ang = rng.uniform(0, 2 * np.pi, (n, k))
        self._kx = 2 * np.pi / wl * np.cos(ang)
        self._ky = 2 * np.pi / wl * np.sin(ang)
        self._ph = rng.uniform(0, 2 * np.pi, (n, k))
        self._sh_amp = spec.shadow_sd_db * np.sqrt(2.0 / k)
        self.ap_xy = np.array([[a.x, a.y] for a in ap])
        self.ap_floor = np.array([a.floor for a in ap])
        self.ap_tx = np.array([a.tx_dbm for a in ap])

    def mean_rss(self, x: np.ndarray, y: np.ndarray, floor: np.ndarray) -> np.ndarray:
        """(N, n_ap) mean RSS (dBm) at points (x, y, floor)."""
        x, y, floor = (np.atleast_1d(np.asarray(v, float)) for v in (x, y, floor))
        s = self.spec
        dx = x[:, None] - self.ap_xy[None, :, 0]
        dy = y[:, None] - self.ap_xy[None, :, 1]
        dfl = np.abs(floor[:, None] - self.ap_floor[None, :])
        d = np.sqrt(dx**2 + dy**2 + (dfl * self.b.floor_height_m) ** 2)
        rss = (
            self.ap_tx[None, :]
            - 10 * s.path_loss_exp * np.log10(np.maximum(d, 1.0))
            - s.floor_db * dfl
        )
        walls = np.zeros_like(rss)
        pts = np.column_stack([x, y])
        for f in np.unique(floor):
            m = floor == f
            p = np.repeat(pts[m], len(self.ap_xy), axis=0)
            q = np.tile(self.ap_xy, (int(m.sum()), 1))
            walls[m] = count_crossings(self.b.plan.walls(f), p, q).reshape(int(m.sum()), -1)
        rss -= s.wall_db * walls
        phase = (
            x[:, None, None] * self._kx[None] + y[:, None, None] * self._ky[None] + self._ph[None]
        )
        rss += self._sh_amp * np.cos(phase).sum(axis=2)
        return rss

    def scans(self, t: np.ndarray, x, y, floor, rng: np.random.Generator, offset_db: float = 0.0):
        """Long-form readings (t, bssid, ssid, freq, rss) for one scan at each time, by a phone
        that reads ``offset_db`` high."""
        s = self.spec
        mean = self.mean_rss(x, y, floor) + offset_db
        noise = s.fading_sd_db * rng.standard_normal(mean.shape)
        if s.drift_sd_db > 0:
            t = np.asarray(t, float)
            order = np.argsort(t, kind="stable")
            noise[order] += drift(t[order], len(self.aps), s, rng)
        rss = np.round(mean + noise)
        p_miss = np.where(rss < -88, s.weak_miss_prob, s.miss_prob)
        heard = (rss >= s.floor_noise_dbm) & (rng.random(rss.shape) >= p_miss)
        i, j = np.nonzero(heard)
        ap = self.aps
        bssid = np.array([a.bssid for a in ap])[j]
        ssid = np.array([a.ssid for a in ap])[j]
        freq = np.array([a.freq_mhz for a in ap])[j]
        return np.asarray(t, float)[i], bssid, ssid, freq, rss[i, j]


def drift(t: np.ndarray, n_ap: int, spec: RadioSpec, rng: np.random.Generator) -> np.ndarray:
    """(len(t), n_ap) slow drift of each AP at times ``t`` (increasing): an Ornstein–Uhlenbeck
    process, stationary σ ``drift_sd_db``, correlation exp(−Δt / τ), τ = ``drift_tau_s``.

    Exact at any spacing: x_k = a_k x_{k−1} + σ √(1 − a_k²) ε_k, a_k = exp(−(t_k − t_{k−1})/τ).
    Unrolled, with s_k = (t_k − t_0)/τ: x_k = e^{−s_k} (x_0 + Σ_{j≤k} e^{s_j} σ √(1 − a_j²) ε_j)
    — a cumulative sum, restarted every ``DRIFT_BLOCK`` τ so that e^{s} stays finite."""
    tau, sd = spec.drift_tau_s, spec.drift_sd_db
    e = rng.standard_normal((t.size, n_ap))
    out = np.empty((t.size, n_ap))
    if not t.size:
        return out
    b = sd * np.sqrt(1.0 - np.exp(-2.0 * np.diff(t) / tau))  # σ √(1 − a²) per step
    out[0] = sd * e[0]
    i = 0
    while i < t.size - 1:
        j = max(int(np.searchsorted(t, t[i] + DRIFT_BLOCK * tau, side="right")) - 1, i + 1)
        s = (t[i : j + 1] - t[i]) / tau
        cum = np.cumsum((b[i:j] * np.exp(s[1:]))[:, None] * e[i + 1 : j + 1], axis=0)
        out[i + 1 : j + 1] = np.exp(-s[1:])[:, None] * (out[i] + cum)
        i = j
    return out


DRIFT_BLOCK = 300.0  # e^300 ≈ 2e130: far from overflow


def scan_times(
    duration: float, rng: np.random.Generator, lo: float = 2.0, hi: float = 4.0
) -> np.ndarray:
    """A scan every 2-4 s."""
    n = int(duration / lo) + 2
    t = rng.uniform(0.5, 2.0) + np.concatenate([[0], np.cumsum(rng.uniform(lo, hi, n))])
    return t[t < duration - 0.5]


def _neighbours(building: Building, n: int) -> list:
    """``n`` APs 3–15 m outside the building's outline, on its floors (fixed per building)."""
    rng = np.random.default_rng(building.seed + 4000)
    floors = sorted(building.plan.floors)
    xy = np.vstack([f.outline for f in building.plan.floors.values()])
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    out = []
    for i in range(n):
        side = rng.integers(4)
        u = rng.uniform(0, 1)
        d = rng.uniform(3, 15)
        x = lo[0] + u * (hi[0] - lo[0]) if side < 2 else (lo[0] - d if side == 2 else hi[0] + d)
        y = lo[1] + u * (hi[1] - lo[1]) if side >= 2 else (lo[1] - d if side == 0 else hi[1] + d)
        out.append(
            AccessPoint(
                bssid=f"02:0e:{i // 256:02x}:{i % 256:02x}:00:01",
                ssid=f"neighbour-{i % 7}",
                x=float(x),
                y=float(y),
                floor=float(floors[rng.integers(len(floors))]),
                freq_mhz=float((2412, 2437, 2462, 5180, 5500)[i % 5]),
                tx_dbm=float(rng.uniform(-42, -32)),
            )
        )
    return out
