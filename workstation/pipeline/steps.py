"""Steps (§III-B step 2): acceleration-magnitude peaks that pass the variance rule.

The motion state is walking where the variance of the acceleration magnitude over a window
(Table I: 50 samples, i.e. 1 s of a 50-Hz phone; ``filters.samples_at``) exceeds 0.5 (m/s²)²,
still elsewhere. A peak of the low-passed magnitude is a step if the walker is walking there. Step period T_i = time since the previous step.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workstation.params import StepParams
from workstation.pipeline.filters import find_peaks, lowpass, moving_mean, samples_at
from workstation.session import Vector3


@dataclass(frozen=True)
class Steps:
    t: np.ndarray  # step (peak) times
    period: np.ndarray  # T_i: time since the previous step (NaN for the first)
    peak: np.ndarray  # low-passed magnitude at the peak (m/s²)
    state_t: np.ndarray  # accelerometer times
    variance: np.ndarray  # moving variance of |a| at each accelerometer sample
    walking: np.ndarray  # bool motion state at each accelerometer sample
    gravity: float  # median |a| (m/s²)

    def __len__(self) -> int:
        return int(self.t.size)


def moving_variance(x: np.ndarray, window: int) -> np.ndarray:
    m = moving_mean(x, window)
    m2 = moving_mean(x * x, window)
    return np.maximum(m2 - m * m, 0.0)


def close_gaps(mask: np.ndarray, n: int) -> np.ndarray:
    """Fill False runs shorter than ``n`` samples that lie between True runs."""
    if n <= 0 or mask.size == 0:
        return mask
    m = mask.astype(np.int8)
    d = np.diff(np.concatenate([[1], m, [1]]))
    starts, ends = np.flatnonzero(d == -1), np.flatnonzero(d == 1)
    out = mask.copy()
    for s, e in zip(starts, ends):
        if e - s < n and s > 0 and e < mask.size:
            out[s:e] = True
    return out


def detect_steps(acc: Vector3, p: StepParams) -> Steps:
    t = acc.t
    mag = np.linalg.norm(acc.xyz, axis=1)
    fs = acc.rate_hz  # NaN for fewer than two samples: samples_at keeps Table I's count
    window = samples_at(p.variance_window, fs)
    if t.size < max(window, 16):
        e = np.empty(0)
        return Steps(
            e,
            e,
            e,
            t,
            np.zeros(t.size),
            np.zeros(t.size, bool),
            float(np.median(mag)) if mag.size else 9.81,
        )
    var = moving_variance(mag, window)
    walking = close_gaps(var > p.variance_threshold, int(round(p.still_gap_s * fs)))
    g = float(np.median(mag))
    smooth = lowpass(mag, fs, p.lowpass_hz)
    peaks = find_peaks(smooth, g + p.min_peak_ms2, max(1, int(p.min_period_s * fs)))
    peaks = peaks[var[peaks] > p.variance_threshold]
    ts = t[peaks]
    period = np.concatenate([[np.nan], np.diff(ts)])
    return Steps(ts, period, smooth[peaks], t, var, walking, g)
