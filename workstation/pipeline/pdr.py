"""Pedestrian dead reckoning (§III-B, eq. 7–8), in one place: positions from step lengths and
headings, and the gyroscope's absolute offset taken from the compass over a walk's first steps.
The tracker (between landmarks), its plain-PDR trace and the PDR I / II baselines use it
(issue #31: the equations had been written four times)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from workstation.pipeline.confidence import circmean

ALIGN_STEPS = 15  # steps over which the gyro heading is aligned to the compass


def dead_reckon(
    x0: float, y0: float, length: ArrayLike, theta: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Eq. 7–8 from (x0, y0): x_i = x0 + Σ_{j ≤ i} l_j cos θ_j, y_i = y0 + Σ_{j ≤ i} l_j sin θ_j;
    ``length`` one step length or one per step."""
    theta = np.asarray(theta, dtype=float)
    length = np.broadcast_to(np.asarray(length, dtype=float), theta.shape)
    return x0 + np.cumsum(length * np.cos(theta)), y0 + np.cumsum(length * np.sin(theta))


def step(
    x: np.ndarray, y: np.ndarray, length: ArrayLike, theta: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """One step of eq. 7–8 for many hypotheses at once (the particle filters): each (x, y)
    moved by its ``length`` along its ``theta``."""
    return x + length * np.cos(theta), y + length * np.sin(theta)


def gyro_offset(compass: np.ndarray, gyro: np.ndarray) -> float:
    """The angle to add to the gyro heading to make it absolute: the circular mean of compass −
    gyro over the first ``ALIGN_STEPS`` steps given (the compass is noisy step by step, the
    gyro drifts slowly: their difference over a few steps is steady)."""
    n = min(ALIGN_STEPS, len(compass), len(gyro))
    return circmean(np.asarray(compass[:n]) - np.asarray(gyro[:n]))
