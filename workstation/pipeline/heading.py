"""Heading (§III-B step 4): gyro integrated about gravity, and a tilt-compensated compass.

Gravity ("up" in the phone frame) is the low-passed accelerometer. The vertical rate is the gyro
rate about that axis (positive = turning left, counter-clockwise from above). The compass heading
of the phone's forward axis (+y) comes from the magnetometer's horizontal part: east = m × up,
north = up × east. Headings are radians counter-clockwise from +x (east), as the graph's edges.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workstation.params import GYRO_HEADING, HeadingParams
from workstation.pipeline.filters import cumulative_trapezoid, lowpass
from workstation.session import Session


@dataclass(frozen=True)
class Heading:
    t: np.ndarray  # gyro times
    vertical_rate: np.ndarray  # rad/s about gravity
    gyro: np.ndarray  # integrated vertical rate, unwrapped, 0 at the start (relative)
    compass: np.ndarray  # tilt-compensated magnetometer heading at the same times (wrapped)
    # |ω| (rad/s, all three axes) at the same times: the phone turned in the hand (calibration
    # figure-eights) against carried while walking (start.py); None when not measured
    rotation_rate: np.ndarray | None = None

    def at(self, t: np.ndarray, which: str = GYRO_HEADING) -> np.ndarray:
        if which == GYRO_HEADING:
            return np.interp(t, self.t, self.gyro)
        c = np.unwrap(self.compass)
        return np.interp(t, self.t, c)


def _lowpass(x: np.ndarray, fs: float, hz: float) -> np.ndarray:
    if x.shape[0] < 16:
        return x
    return lowpass(x, fs, hz)


def estimate_heading(session: Session, p: HeadingParams) -> Heading:
    acc, gyro, mag = session.accelerometer, session.gyroscope, session.magnetometer
    base = gyro if len(gyro) else acc
    t = base.t
    if len(acc) < 2:
        z = np.zeros(t.size)
        return Heading(t, z, z, z, z)
    g_acc = _lowpass(acc.xyz, acc.rate_hz, p.gravity_lowpass_hz)
    up = np.column_stack([np.interp(t, acc.t, g_acc[:, i]) for i in range(3)])
    up /= np.maximum(np.linalg.norm(up, axis=1, keepdims=True), 1e-9)
    if len(gyro):
        rate = np.einsum("ij,ij->i", gyro.xyz, up)
        integ = cumulative_trapezoid(rate, t)
    else:
        rate = np.zeros(t.size)
        integ = np.zeros(t.size)
    if len(mag):
        m0, m1, m2 = (np.interp(t, mag.t, mag.xyz[:, i]) for i in range(3))
        u0, u1, u2 = up.T
        # east = m × up, north = up × east; the forward axis (+y) in each: arctan2 needs only
        # their y components, and neither normalisation (a positive factor on both)
        e0, e1, e2 = m1 * u2 - m2 * u1, m2 * u0 - m0 * u2, m0 * u1 - m1 * u0
        compass = np.arctan2(u2 * e0 - u0 * e2, e1)
    else:
        compass = np.full(t.size, np.nan)
    norm = np.linalg.norm(gyro.xyz, axis=1) if len(gyro) else np.zeros(t.size)
    return Heading(t, rate, integ, compass, norm)
