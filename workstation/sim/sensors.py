"""Phone sensor models sampled from a :class:`Motion`.

The phone is held in front, screen up, top pointing the way the walker faces, tilted up by a
pitch that bobs with the steps. Device axes follow Android (x right, y top, z out of screen);
the world frame is east-north-up. Accelerometer = specific force (gravity included) with a step
waveform and noise; gyroscope = body rates with bias and noise; magnetometer = the Earth's field
(north = +y) plus ferromagnetic disturbances in marked zones; barometer = 0.45 hPa a floor,
noise and slow weather drift.

The ``realistic`` spec (:func:`realistic_spec`) adds what real phones show: the phone moving in
the hand (band-limited acceleration and rotation, bursts when the walker taps it at a
landmark), a per-walk compass bias and a building-wide deviation of the magnetic field that
varies over metres, and pressure noise that is correlated over seconds with a per-walk drift.
Floors need not be evenly spaced: the barometer reads the building's own floor levels.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from workstation.sim.building import FLOOR_HPA
from workstation.sim.walker import Motion

G = 9.80665
EARTH_FIELD_UT = np.array([0.0, 20.0, -44.0])  # east, north, up (northern hemisphere: points down)


@dataclass(frozen=True)
class SensorSpec:
    imu_hz: float = 50.0
    baro_hz: float = 10.0
    acc_noise: float = 0.05
    gyro_noise: float = 0.008
    gyro_bias_sd: float = 0.004
    mag_noise: float = 0.35
    baro_noise: float = 0.012
    pitch_deg: float = 28.0
    roll_deg: float = 3.0
    # --- realism (0: the ideal phone) ---
    handling_acc: float = 0.0  # m/s², band-limited 0.3–4 Hz, always (the phone in a hand)
    handling_gyro: float = 0.0  # rad/s, the same
    tap_acc: float = 0.0  # m/s², a 0.6 s burst at each tap
    compass_bias_deg: tuple[float, float] = (0.0, 0.0)  # per walk, drawn uniform in this range
    mag_deviation_deg: float = 0.0  # σ of the building's field deviation, varies over metres
    baro_corr_hpa: float = 0.0  # σ of AR(1) pressure noise, correlation time baro_corr_s
    baro_corr_s: float = 3.0
    baro_drift_hpa_min: tuple[float, float] = (-0.02, 0.02)  # per walk, uniform


def realistic_spec(spec: SensorSpec | None = None) -> SensorSpec:
    """A phone as real phones read (issue #12's table, measured by :mod:`.realism`)."""
    return replace(
        spec or SensorSpec(),
        acc_noise=0.08,
        gyro_noise=0.012,
        handling_acc=0.16,
        handling_gyro=0.03,
        tap_acc=0.65,
        compass_bias_deg=(-4.0, 21.0),
        mag_deviation_deg=9.0,
        baro_noise=0.01,
        baro_corr_hpa=0.018,
        baro_corr_s=1.5,
        baro_drift_hpa_min=(-0.03, 0.03),
    )


@dataclass(frozen=True)
class MagneticZone:
    x: float
    y: float
    floor: float
    radius_m: float
    field_ut: tuple[float, float, float]


def _rotations(yaw, pitch, roll) -> np.ndarray:
    """R (N, 3, 3): device → world, R = Rz(yaw - 90°) · Rx(pitch) · Ry(roll)."""
    cz, sz = np.cos(yaw - np.pi / 2), np.sin(yaw - np.pi / 2)
    cx, sx = np.cos(pitch), np.sin(pitch)
    cy, sy = np.cos(roll), np.sin(roll)
    n = yaw.size
    rz = np.zeros((n, 3, 3))
    rz[:, 0, 0], rz[:, 0, 1], rz[:, 1, 0], rz[:, 1, 1], rz[:, 2, 2] = cz, -sz, sz, cz, 1
    rx = np.zeros((n, 3, 3))
    rx[:, 0, 0], rx[:, 1, 1], rx[:, 1, 2], rx[:, 2, 1], rx[:, 2, 2] = 1, cx, -sx, sx, cx
    ry = np.zeros((n, 3, 3))
    ry[:, 0, 0], ry[:, 0, 2], ry[:, 1, 1], ry[:, 2, 0], ry[:, 2, 2] = cy, sy, 1, -sy, cy
    return rz @ rx @ ry


def _irregular(
    t: np.ndarray, intervals, rng: np.random.Generator, scale: float, dims: int
) -> np.ndarray:
    """Irregular phone motion inside ``intervals`` (sum of random sinusoids, windowed)."""
    out = np.zeros((t.size, dims))
    for t0, t1 in intervals:
        m = (t >= t0) & (t <= t1)
        if not m.any():
            continue
        tt = t[m]
        win = np.clip(np.minimum(tt - t0, t1 - tt) / 0.4, 0, 1)
        for d in range(dims):
            for _ in range(4):
                f = rng.uniform(0.6, 3.8)
                out[m, d] += (
                    scale
                    * rng.uniform(0.4, 1.0)
                    * np.sin(2 * np.pi * f * tt + rng.uniform(0, 2 * np.pi))
                    * win
                )
    return out


def _band_noise(n: int, fs: float, sd: float, rng: np.random.Generator, dims: int = 3):
    """Gaussian noise band-limited to 0.3–4 Hz, scaled to ``sd``."""
    if sd <= 0 or n < 32:
        return np.zeros((n, dims))
    from scipy.signal import butter, sosfiltfilt

    sos = butter(2, [0.3 / (fs / 2), min(4.0 / (fs / 2), 0.99)], btype="band", output="sos")
    x = sosfiltfilt(sos, rng.standard_normal((n, dims)), axis=0)
    return sd * x / max(float(x.std()), 1e-12)


def _deviation(x, y, floor, sd_deg: float, seed: int) -> np.ndarray:
    """The building's magnetic deviation (rad) at (x, y, floor): a fixed smooth field (plane
    waves of 4–15 m), the same for every walk of the building."""
    if sd_deg <= 0:
        return np.zeros(np.size(x))
    r = np.random.default_rng(seed + 3000)
    k = 8
    wl = r.uniform(4, 15, k)
    ang = r.uniform(0, 2 * np.pi, k)
    ph = r.uniform(0, 2 * np.pi, (k, 4))
    fl = np.clip(np.round(floor).astype(int) % 4, 0, 3)
    kx, ky = 2 * np.pi / wl * np.cos(ang), 2 * np.pi / wl * np.sin(ang)
    phase = x[:, None] * kx[None] + y[:, None] * ky[None] + ph.T[fl]
    return np.radians(sd_deg) * np.sqrt(2.0 / k) * np.cos(phase).sum(axis=1)


def imu(
    motion: Motion,
    spec: SensorSpec,
    zones: tuple[MagneticZone, ...],
    rng: np.random.Generator,
    building_seed: int = 0,
):
    """(t, acc (N,3), gyro (N,3), mag (N,3)) at ``spec.imu_hz``."""
    t = np.arange(0.0, motion.duration, 1.0 / spec.imu_hz)
    s = motion.at(t)
    ph2 = 2 * np.pi * s["phase"]
    amp = s["amp"]
    yaw = s["yaw"]
    pitch = np.radians(spec.pitch_deg) + np.radians(2.0) * (amp / max(amp.max(), 1e-9)) * np.sin(
        ph2
    )
    roll = np.full_like(t, np.radians(spec.roll_deg)) + np.radians(1.5) * (
        amp / max(amp.max(), 1e-9)
    ) * np.sin(ph2 / 2)
    fw = _irregular(t, motion.false_walking, rng, 1.1, 3)
    fw_rot = _irregular(t, motion.false_walking, rng, 0.35, 3)
    pitch = pitch + 0.25 * fw_rot[:, 0]
    roll = roll + 0.25 * fw_rot[:, 1]
    yaw = yaw + 0.25 * fw_rot[:, 2]
    r = _rotations(yaw, pitch, roll)

    a_v = amp * np.cos(ph2)
    a_f = 0.35 * amp * np.sin(ph2)
    a_l = 0.25 * amp * np.sin(ph2 / 2)
    h = s["heading"]
    f_world = np.column_stack(
        [
            a_f * np.cos(h) - a_l * np.sin(h),
            a_f * np.sin(h) + a_l * np.cos(h),
            G + a_v,
        ]
    )
    f_world += fw
    fs = spec.imu_hz
    f_world += _band_noise(t.size, fs, spec.handling_acc, rng)
    if spec.tap_acc and motion.taps:
        for t0 in motion.taps:  # a burst as the walker taps the screen
            m = (t >= t0) & (t < t0 + 0.6)
            f_world[m] += spec.tap_acc * rng.standard_normal((int(m.sum()), 3))
    acc = np.einsum("nji,nj->ni", r, f_world) + spec.acc_noise * rng.standard_normal((t.size, 3))

    # body rates: R^T ω_world (yaw rate) + tilt rates about device x/y, numerically
    dt = 1.0 / spec.imu_hz
    yaw_rate = np.gradient(yaw, dt)
    w_world = np.column_stack([np.zeros_like(t), np.zeros_like(t), yaw_rate])
    gyro = np.einsum("nji,nj->ni", r, w_world)
    gyro[:, 0] += np.gradient(pitch, dt)
    gyro[:, 1] += np.gradient(roll, dt)
    gyro += spec.gyro_bias_sd * rng.standard_normal(3) + spec.gyro_noise * rng.standard_normal(
        (t.size, 3)
    )
    gyro += _band_noise(t.size, fs, spec.handling_gyro, rng)

    b = np.broadcast_to(EARTH_FIELD_UT, (t.size, 3)).copy()
    lo, hi = spec.compass_bias_deg
    bias = np.radians(rng.uniform(lo, hi)) if hi > lo else np.radians(lo)
    dev = bias + _deviation(s["x"], s["y"], s["alt"], spec.mag_deviation_deg, building_seed)
    if np.any(dev):  # the horizontal field turned so that the compass reads dev too high
        c, si = np.cos(-dev), np.sin(-dev)
        bx, by = b[:, 0].copy(), b[:, 1].copy()
        b[:, 0], b[:, 1] = c * bx - si * by, si * bx + c * by
    for z in zones:
        d2 = (s["x"] - z.x) ** 2 + (s["y"] - z.y) ** 2
        on = np.abs(s["alt"] - z.floor) < 0.5
        b += (np.exp(-d2 / (2 * z.radius_m**2)) * on)[:, None] * np.asarray(z.field_ut)[None, :]
    mag = np.einsum("nji,nj->ni", r, b) + spec.mag_noise * rng.standard_normal((t.size, 3))
    return t, np.round(acc, 5), np.round(gyro, 5), np.round(mag, 3)


def barometer(motion: Motion, spec: SensorSpec, rng: np.random.Generator, levels_hpa=None):
    """(t, hPa) at ``spec.baro_hz``: the building's floor levels (``levels_hpa[f]``: pressure
    drop of floor f from floor 0; default 0.45 hPa a floor), noise, weather drift."""
    t = np.arange(0.0, motion.duration, 1.0 / spec.baro_hz)
    alt = np.interp(t, motion.t, motion.alt)
    p0 = 1008.0 + rng.uniform(-6, 6)
    slope = rng.uniform(*spec.baro_drift_hpa_min) / 60.0  # hPa/s
    drift = slope * t + 0.02 * np.sin(2 * np.pi * t / 900.0 + rng.uniform(0, 2 * np.pi))
    if levels_hpa:
        fl = np.array(sorted(levels_hpa))
        drop = np.interp(alt, fl, [levels_hpa[f] for f in fl])
    else:
        drop = FLOOR_HPA * alt
    p = p0 - drop + drift + spec.baro_noise * rng.standard_normal(t.size)
    if spec.baro_corr_hpa:
        a = np.exp(-1.0 / (spec.baro_hz * spec.baro_corr_s))
        from scipy.signal import lfilter

        z = lfilter([np.sqrt(1 - a * a)], [1, -a], rng.standard_normal(t.size))
        p += spec.baro_corr_hpa * z
    return t, np.round(p, 4)
