"""The signal kernels of the pipeline, in numpy: moving mean, zero-phase Butterworth low-pass,
peak picking, cumulative trapezoid. One place for each; vectorized, no loop over samples.

They replace ``scipy.ndimage.uniform_filter1d``, ``scipy.signal.butter`` + ``sosfiltfilt``,
``scipy.signal.find_peaks`` and ``scipy.integrate.cumulative_trapezoid``, whose packages take a
second and a half to import — most of a ``workstation run`` (issue #17). Tests hold each against
the SciPy function it replaces.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

OLS_BLOCK = 8  # FFT length of the low-pass's overlap-save blocks, in impulse-response lengths
TABLE_I_RATE_HZ = 50.0  # Table I's windows count samples of a 50-Hz phone (every real walk we have)


def samples_at(n: int, fs: float) -> int:
    """Table I's window of ``n`` samples as samples of a stream at ``fs`` Hz: the same time
    (n / 50 Hz). Unchanged at 50 Hz; a 500-Hz IMU took 0.1-s variance windows and found 2 steps
    where there were 175 (issue #33)."""
    if not np.isfinite(fs) or fs <= 0:
        return max(int(n), 1)
    return max(int(round(n * fs / TABLE_I_RATE_HZ)), 1)


def moving_mean(x: np.ndarray, window: int) -> np.ndarray:
    """Mean over ``window`` samples around each sample, edges repeated (as
    ``uniform_filter1d(x, window, mode="nearest")``: for an even window one more sample before)."""
    x = np.asarray(x, dtype=np.float64)
    w = max(int(window), 1)
    if x.size == 0 or w == 1:
        return x.copy()
    xp = np.pad(x, (w // 2, w - 1 - w // 2), mode="edge")
    c = np.concatenate(([0.0], np.cumsum(xp)))
    return (c[w:] - c[:-w]) / w


def lowpass(x: np.ndarray, fs: float, cutoff_hz: float) -> np.ndarray:
    """Zero-phase 2nd-order Butterworth low-pass along axis 0, as
    ``sosfiltfilt(butter(2, cutoff), x, axis=0)`` to rounding: the bilinear-transform biquad

        K = tan(ω_c/2),  b = K²·(1, 2, 1) / (1 + √2·K + K²),
        a = (1, 2·(K² − 1), 1 − √2·K + K²) / (1 + √2·K + K²),

    run forward then backward as causal convolutions with its impulse response (truncated
    where it falls below 1e-15 of its peak, done by FFT), the ends extended as filtfilt does:
    a 9-sample odd reflection, and the steady state of the value each pass starts from."""
    x = np.asarray(x, dtype=np.float64)
    n = x.shape[0]
    if n < 10:
        return x.copy()
    h = _impulse_response(min(cutoff_hz / (fs / 2.0), 0.99))
    odd = 9  # filtfilt's pad for one second-order section
    head = 2.0 * x[:1] - x[odd:0:-1]
    tail = 2.0 * x[-1:] - x[-2 : -odd - 2 : -1]
    xp = np.concatenate([head, x, tail], axis=0)
    y = _causal(h, xp)  # forward, from the steady state at xp[0]
    y = _causal(h, y[::-1])[::-1]  # backward, from the steady state at the forward's end
    return y[odd : odd + n]


def _causal(h: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The filter with impulse response h run over x (axis 0) from the steady state at x[0]:
    x is preceded by x[0] held for the whole response (the filter's DC gain is 1).

    Overlap-save in blocks of about ``OLS_BLOCK`` × len(h), all blocks in one batched FFT: the
    cost is linear in the length of x (one FFT over a 90-min walk was twice as slow, out of
    cache); a short x is one block."""
    m = h.size
    n = x.shape[0]
    xe = np.concatenate([np.repeat(x[:1], m, axis=0), x], axis=0)
    nfft = min(_fast_length(OLS_BLOCK * m), _fast_length(n + 2 * m))
    step = nfft - m + 1  # outputs per block
    blocks = -(-n // step)
    need = blocks * step + m  # block b reads xe[1 + b·step :][:nfft]
    if xe.shape[0] < need:
        xe = np.concatenate([xe, np.zeros((need - xe.shape[0],) + x.shape[1:])], axis=0)
    frames = np.lib.stride_tricks.sliding_window_view(xe[1:need], nfft, axis=0)[::step]
    spec = np.fft.rfft(frames, nfft, axis=-1) * np.fft.rfft(h, nfft)
    y = np.fft.irfft(spec, nfft, axis=-1)[..., m - 1 :]  # (blocks, [columns,] step)
    if x.ndim == 1:
        return y.reshape(-1)[:n]
    return np.moveaxis(y, -1, 1).reshape((-1,) + x.shape[1:])[:n]


@lru_cache(maxsize=256)
def _fast_length(m: int) -> int:
    """The smallest 2^a·3^b·5^c ≥ m: an FFT length pocketfft does as fast as a power of two,
    up to 1.6× shorter than the next power of two."""
    best = 1 << max(int(m - 1).bit_length(), 0)
    p5 = 1
    while p5 < best:
        p35 = p5
        while p35 < best:
            v = p35 << max(int(-(-m // p35) - 1).bit_length(), 0)  # × the power of 2 reaching m
            best = min(best, v)
            p35 *= 3
        p5 *= 5
    return best


@lru_cache(maxsize=16)
def _impulse_response(wn: float) -> np.ndarray:
    """Impulse response of the 2nd-order Butterworth low-pass at wn (× Nyquist), to 1e-15."""
    k = np.tan(np.pi * wn / 2.0)
    norm = 1.0 / (1.0 + np.sqrt(2.0) * k + k * k)
    b0, b1, b2 = k * k * norm, 2.0 * k * k * norm, k * k * norm
    a1, a2 = 2.0 * (k * k - 1.0) * norm, (1.0 - np.sqrt(2.0) * k + k * k) * norm
    r = np.sqrt(abs(a2))  # pole radius: the response decays as r^n
    length = int(np.ceil(np.log(1e-15) / np.log(min(max(r, 1e-12), 1.0 - 1e-9)))) + 3
    h = np.zeros(length)
    x1 = x2 = y1 = y2 = 0.0  # the recursion over the response's samples (not the stream)
    for i in range(length):
        xi = 1.0 if i == 0 else 0.0
        yi = b0 * xi + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2
        h[i] = yi
        x2, x1, y2, y1 = x1, xi, y1, yi
    h.setflags(write=False)
    return h


def find_peaks(x: np.ndarray, height: float, distance: int) -> np.ndarray:
    """Indices of local maxima at least ``height`` high and ``distance`` samples apart, the
    higher kept first — as ``scipy.signal.find_peaks(x, height=, distance=)``: a flat peak is
    reported at its middle sample; the first and last samples are never peaks."""
    x = np.asarray(x, dtype=np.float64)
    if x.size < 3:
        return np.empty(0, np.int64)
    # runs of equal values: a peak is a run higher than both neighbouring runs
    start = np.flatnonzero(np.concatenate(([True], x[1:] != x[:-1])))
    end = np.concatenate((start[1:], [x.size])) - 1
    v = x[start]
    inner = np.arange(1, v.size - 1)
    top = inner[(v[inner - 1] < v[inner]) & (v[inner + 1] < v[inner])]
    peaks = (start[top] + end[top]) // 2
    peaks = peaks[x[peaks] >= height]
    d = max(int(np.ceil(distance)), 1)
    if d <= 1 or peaks.size < 2:
        return peaks
    close = np.diff(peaks) < d
    if not close.any():
        return peaks
    keep = np.ones(peaks.size, bool)
    # only peaks in clusters closer than `distance` need choosing, highest first
    crowded = np.flatnonzero(np.concatenate(([False], close)) | np.concatenate((close, [False])))
    for j in crowded[np.argsort(x[peaks[crowded]], kind="stable")[::-1]].tolist():
        if not keep[j]:
            continue
        k = j - 1
        while k >= 0 and peaks[j] - peaks[k] < d:
            keep[k] = False
            k -= 1
        k = j + 1
        while k < peaks.size and peaks[k] - peaks[j] < d:
            keep[k] = False
            k += 1
    return peaks[keep]


def cumulative_trapezoid(y: np.ndarray, t: np.ndarray) -> np.ndarray:
    """∫ y dt from the first sample, by trapezoids (0 at the first sample)."""
    y = np.asarray(y, dtype=np.float64)
    if y.size == 0:
        return y.copy()
    return np.concatenate(([0.0], np.cumsum(np.diff(t) * (y[1:] + y[:-1]) / 2.0)))
