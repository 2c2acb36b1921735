"""The pipeline's numpy signal kernels against the SciPy functions they replace (issue #17)."""

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid as sp_cumtrapz
from scipy.ndimage import uniform_filter1d
from scipy.signal import butter, sosfiltfilt
from scipy.signal import find_peaks as sp_find_peaks

from workstation.pipeline.filters import cumulative_trapezoid, find_peaks, lowpass, moving_mean


def _walk_like(seed: int, n: int = 3000, fs: float = 50.0) -> np.ndarray:
    """|acc|-like: a 1.8 Hz gait with jitter, noise and a stop."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    x = 9.8 + 2.0 * np.sin(2 * np.pi * 1.8 * t + rng.normal(0, 0.3, n).cumsum() * 0.05)
    x += rng.normal(0, 0.6, n)
    x[n // 3 : n // 3 + 200] = 9.8 + rng.normal(0, 0.05, 200)
    return x


@pytest.mark.parametrize("window", [1, 2, 5, 10, 51])
def test_moving_mean_is_uniform_filter_nearest(window):
    x = _walk_like(0, 500)
    assert np.allclose(moving_mean(x, window), uniform_filter1d(x, window, mode="nearest"),
                       rtol=0, atol=1e-9)  # fmt: skip


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("cutoff", [3.0, 0.5])
@pytest.mark.parametrize("n", [3000, 60000])  # one overlap-save block, and many
def test_lowpass_is_butterworth_filtfilt(seed, cutoff, n):
    fs = 50.0
    x = _walk_like(seed, n)
    ref = sosfiltfilt(butter(2, cutoff / (fs / 2), output="sos"), x)
    y = lowpass(x, fs, cutoff)
    assert np.max(np.abs(y - ref)) < 1e-9 * np.ptp(x)  # to rounding, ends included
    xyz = np.column_stack([x, -x, 2 * x])  # along axis 0 for a (n, 3) stream
    assert np.allclose(lowpass(xyz, fs, cutoff)[:, 2], 2 * y)


@pytest.mark.parametrize("seed", range(6))
def test_find_peaks_is_scipy_with_height_and_distance(seed):
    x = sosfiltfilt(butter(2, 3.0 / 25, output="sos"), _walk_like(seed))
    x[100:110] = x[100:110].max() + 1.0  # a flat peak: reported at its middle
    for height, distance in [(9.8, 1), (10.3, 15), (9.0, 40)]:
        ref, _ = sp_find_peaks(x, height=height, distance=distance)
        assert np.array_equal(find_peaks(x, height, distance), ref)


def test_cumulative_trapezoid():
    t = np.cumsum(np.random.default_rng(3).uniform(0.01, 0.03, 400))
    y = np.sin(t * 5)
    assert np.allclose(cumulative_trapezoid(y, t), sp_cumtrapz(y, t, initial=0.0))
