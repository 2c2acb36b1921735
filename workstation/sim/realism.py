"""How a walk looks to the pipeline, measured the same way on simulated and real walks (issue
#12's table): gait regularity, stops, turns, yaw sway, compass, pressure noise and drift, APs,
and how RSS drifts while the walker stands still.

Each quantity is one function of the session and the pipeline's own stages (steps, heading,
landmark detections) at the default parameters, so a simulated walk and a real logfile are
measured by the same code. :data:`REAL_RANGES` holds the ranges measured on the 10 IPIN museum
walks (tests/sim/test_realism.py checks them against the data when ../shared/data is
there); a realistic simulated walk must land inside them.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from workstation.params import Params
from workstation.pipeline.heading import estimate_heading
from workstation.pipeline.landmarks import detect_gyro
from workstation.pipeline.steps import detect_steps
from workstation.session import Session

# quantity → (low, high) over the 10 IPIN museum walks in ../shared/data, measured by
# :func:`measure` (tests/sim/test_realism.py checks these against the data when it is there)
REAL_RANGES: dict[str, tuple[float, float]] = {
    "step_period_cv": (0.1271, 0.2204),  # 10 walks
    "step_change": (0.0983, 0.1592),  # 10 walks
    "period_sd_per_bout_s": (0.0308, 0.0773),  # 10 walks
    "step_amplitude_cv": (0.6359, 1.2092),  # 10 walks
    "still_fraction": (0.2902, 0.5261),  # 10 walks
    "still_acc_var_median": (0.006, 0.1044),  # 10 walks
    "still_acc_var_p90": (0.1362, 0.3622),  # 10 walks
    "stops_per_min": (0.5697, 2.088),  # 10 walks
    "stop_median_s": (1.661, 33.35),  # 10 walks
    "stop_max_s": (19.99, 39.32),  # 10 walks
    "turn_rate_median": (2.972, 5.188),  # 10 walks
    "turn_rate_p10": (1.411, 3.275),  # 10 walks
    "turn_angle_p10_deg": (51.66, 70.96),  # 10 walks
    "turn_angle_p90_deg": (107.5, 144.4),  # 10 walks
    "yaw_rate_rms_straight": (0.1578, 0.4003),  # 10 walks
    "compass_bias_deg": (-5.892, 21.74),  # 4 walks
    "compass_leg_error_median_deg": (2.103, 18.18),  # 4 walks
    "compass_leg_error_p90_deg": (6.478, 30.77),  # 4 walks
    "pressure_noise_hpa": (0.0125, 0.0166),  # 10 walks
    "pressure_drift_hpa_min": (-0.0644, 0.0402),  # 10 walks
    "rss_still_rms_short_db": (2.362, 4.521),  # 10 walks
    "rss_still_rms_long_db": (3.58, 6.57),  # 9 walks
    "distinct_aps": (45, 85),  # 10 walks
}


def _runs(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    d = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return np.flatnonzero(d == 1), np.flatnonzero(d == -1)


def measure(session: Session, params: Params | None = None) -> dict[str, float]:
    """The table's quantities for one walk (NaN where the walk has nothing to measure)."""

    p = params or Params()
    st = detect_steps(session.accelerometer, p.steps)
    hd = estimate_heading(session, p.heading)
    out: dict[str, float] = {}
    out.update(_gait(st))
    out.update(_stillness(st))

    turns = detect_gyro(hd, replace(p.gyro, wiggle_deg=0.0))  # every swing, as measured
    out.update(_turns(hd, st, turns))
    out.update(_compass(session, hd, st))
    out.update(_pressure(session, st))
    out.update(_rss_drift(session, st))
    out["distinct_aps"] = float(np.unique(session.wifi.bssid).size) if len(session.wifi.t) else 0.0
    return {k: round(float(v), 4) for k, v in out.items()}


def _second_means(pr, t0: float, t1: float) -> tuple[np.ndarray, int]:
    """The pressure's means over the seconds of [t0, t1] (from t0), and how many samples."""
    if pr is None or not len(pr.t):
        return np.empty(0), 0
    m = (pr.t >= t0) & (pr.t <= t1)
    idx = np.digitize(pr.t[m], np.arange(t0, t1, 1.0))
    _, inv, cnt = np.unique(idx, return_inverse=True, return_counts=True)
    return np.bincount(inv.ravel(), weights=pr.value[m]) / cnt, int(m.sum())


def _one_level(pr, t0: float, t1: float) -> bool:
    """The pressure's 1-s means over [t0, t1] stay within 0.1 hPa: no lift ride (raw samples
    alone spread that much)."""
    means, _ = _second_means(pr, t0, t1)
    return bool(means.size == 0 or np.ptp(means) <= 0.1)


# scan pairs taken in one stop, by time apart (s): a few seconds, and tens of seconds
RSS_SHORT_S, RSS_LONG_S = (0.0, 4.0), (15.0, 40.0)


def _rss_drift(session: Session, st) -> dict[str, float]:
    """How much two scans taken standing on one spot differ, RMS over the APs either hears
    above −80 dBm (pairs sharing at least 3): pairs at most 4 s apart, and 15–40 s apart. The
    spot is a still run of the step detector (1 s in from either end) where the pressure
    moves less than 0.1 hPa (not a lift ride)."""
    out = {"rss_still_rms_short_db": np.nan, "rss_still_rms_long_db": np.nan}
    if not len(session.wifi.t):
        return out
    times, _, rss = session.wifi.matrix()
    a, b = _runs(~st.walking)
    t = st.state_t
    pr = session.pressure
    sq: dict[str, list[np.ndarray]] = {"short": [], "long": []}
    for i, j in zip(a, b):
        t0, t1 = t[i] + 1.0, t[min(j, t.size - 1)] - 1.0
        k = np.flatnonzero((times >= t0) & (times <= t1))
        if k.size < 2:
            continue
        if not _one_level(pr, t0, t1):
            continue
        for u, v in zip(*np.triu_indices(k.size, 1)):  # the scans of one stop: a handful
            dt = times[k[v]] - times[k[u]]
            for name, (lo, hi) in (("short", RSS_SHORT_S), ("long", RSS_LONG_S)):
                if lo <= dt <= hi:
                    r1, r2 = rss[k[u]], rss[k[v]]
                    both = np.isfinite(r1) & np.isfinite(r2) & (np.fmax(r1, r2) > -80)
                    if both.sum() >= 3:
                        sq[name].append((r1[both] - r2[both]) ** 2)
    for name, parts in sq.items():
        if parts:
            out[f"rss_still_rms_{name}_db"] = float(np.sqrt(np.concatenate(parts).mean()))
    return out


def _gait(st) -> dict[str, float]:
    """Step-period CV and step-to-step change over walking periods (0.3–1.2 s); σ of the valid
    periods (0.4–1.0 s) per walking bout, median over bouts of 8 valid periods or more."""
    per = st.period
    ok = np.isfinite(per) & (per > 0.3) & (per < 1.2)
    v = per[ok]
    cv = float(np.std(v) / np.mean(v)) if v.size > 5 else np.nan
    both = ok[1:] & ok[:-1]
    ch = np.abs(np.diff(per))[both] / per[:-1][both]
    # bouts: consecutive steps without a gap longer than 1.2 s
    bout = np.cumsum(~ok)
    sds = []
    for b in np.unique(bout[ok]):
        x = per[ok & (bout == b)]
        x = x[(x >= 0.4) & (x <= 1.0)]
        if x.size >= 8:
            sds.append(np.std(x))
    return {
        "step_period_cv": cv,
        "step_change": float(np.mean(ch)) if ch.size else np.nan,
        "period_sd_per_bout_s": float(np.median(sds)) if sds else np.nan,
        "step_amplitude_cv": _amp_cv(st, ok),
    }


def _amp_cv(st, ok) -> float:
    """CV of the step peak height (m/s² above gravity) within bouts: a proxy for step-length
    variation (Weinberg: length ∝ amplitude^¼)."""
    a = st.peak[ok] - st.gravity
    a = a[a > 0]
    return float(np.std(a) / np.mean(a)) if a.size > 5 else np.nan


def _stillness(st) -> dict[str, float]:
    still = ~st.walking
    t = st.state_t
    out = {"still_fraction": float(still.mean()) if still.size else np.nan}
    v = st.variance[still]
    out["still_acc_var_median"] = float(np.median(v)) if v.size else np.nan
    out["still_acc_var_p90"] = float(np.percentile(v, 90)) if v.size else np.nan
    a, b = _runs(still)
    dur = t[np.minimum(b, t.size - 1)] - t[a] if a.size else np.empty(0)
    inner = dur[(a > 0) & (b < t.size)]
    inner = inner[inner >= 1.0]
    minutes = (t[-1] - t[0]) / 60.0 if t.size else np.nan
    out["stops_per_min"] = float(inner.size / minutes) if minutes else np.nan
    out["stop_median_s"] = float(np.median(inner)) if inner.size else np.nan
    out["stop_max_s"] = float(inner.max()) if inner.size else np.nan
    return out


def _turns(hd, st, turns) -> dict[str, float]:
    """Peak vertical rate (smoothed as the detector does) and angle of each gyro detection of
    45–150°; RMS yaw rate walking straight (walking, more than 2 s from any detected turn)."""
    from scipy.ndimage import uniform_filter1d

    t = hd.t
    rate = hd.vertical_rate
    smooth = uniform_filter1d(rate, Params().gyro.window, mode="nearest") if t.size else rate
    out = {}
    all_turns = turns
    ang = np.abs(np.array([x[3] for x in turns])) if turns else np.empty(0)
    big = (ang >= np.radians(45)) & (ang < np.radians(150))  # corners, not U-turns or wiggles
    turns = [x for x, b in zip(turns, big) if b]
    if turns:
        tt = np.array([x[0] for x in turns])
        ang = ang[big]
        k = np.clip(np.searchsorted(t, tt), 0, t.size - 1)
        peak = np.abs(smooth[k])
        out["turn_rate_median"] = float(np.median(peak))
        out["turn_rate_p10"] = float(np.percentile(peak, 10))
        out["turn_angle_p10_deg"] = (
            float(np.degrees(np.percentile(ang, 10))) if ang.size else np.nan
        )
        out["turn_angle_p90_deg"] = (
            float(np.degrees(np.percentile(ang, 90))) if ang.size else np.nan
        )
    else:
        tt = np.empty(0)
        out.update(
            turn_rate_median=np.nan, turn_rate_p10=np.nan,
            turn_angle_p10_deg=np.nan, turn_angle_p90_deg=np.nan,
        )  # fmt: skip
    walking = np.interp(t, st.state_t, st.walking.astype(float)) > 0.5
    far = np.ones(t.size, bool)
    for x in all_turns:
        far &= (t < x[4] - 2.0) | (t > x[2] + 2.0)
    m = walking & far
    out["yaw_rate_rms_straight"] = float(np.sqrt(np.mean(rate[m] ** 2))) if m.sum() > 50 else np.nan
    return out


def _compass(session: Session, hd, st) -> dict[str, float]:
    """Per leg between consecutive ground-truth points ≥ 5 m apart (walking all the way): the
    compass's circular mean against the leg's direction. The per-walk bias is the median
    difference; the per-leg error is |difference − bias|."""
    gt = session.ground_truth
    out = {"compass_bias_deg": np.nan, "compass_leg_error_median_deg": np.nan,
           "compass_leg_error_p90_deg": np.nan}  # fmt: skip
    if gt is None or len(gt) < 2 or not np.isfinite(hd.compass).any():
        return out
    gt_t, gx, gy = _gt_points(gt)
    diffs = []
    i = 0
    while i < gt_t.size - 1:
        j = i + 1
        while j < gt_t.size and np.hypot(gx[j] - gx[i], gy[j] - gy[i]) < 5.0:
            j += 1
        if j >= gt_t.size:
            break
        seg = (hd.t >= gt_t[i]) & (hd.t <= gt_t[j])
        walk = (st.state_t >= gt_t[i]) & (st.state_t <= gt_t[j])
        straight = np.abs(np.diff(np.interp([gt_t[i], gt_t[j]], hd.t, hd.gyro)))[0] < 0.35
        if seg.sum() > 10 and st.walking[walk].mean() > 0.7 and straight:
            c = hd.compass[seg]
            cm = np.arctan2(np.sin(c).mean(), np.cos(c).mean())
            leg = np.arctan2(gy[j] - gy[i], gx[j] - gx[i])
            diffs.append(np.angle(np.exp(1j * (cm - leg))))
        i = j
    if len(diffs) < 3:
        return out
    d = np.array(diffs)
    bias = float(np.angle(np.mean(np.exp(1j * d))))
    err = np.abs(np.angle(np.exp(1j * (d - bias))))
    out["compass_bias_deg"] = float(np.degrees(bias))
    out["compass_leg_error_median_deg"] = float(np.degrees(np.median(err)))
    out["compass_leg_error_p90_deg"] = float(np.degrees(np.percentile(err, 90)))
    return out


def _gt_points(gt, spacing_s: float = 2.0):
    """Ground-truth points no closer than ``spacing_s`` in time (dense simulated truth thinned
    to about what real fixes give)."""
    t = np.asarray(gt.t, float)
    keep = [0]  # greedy: the next point at least spacing_s after the last kept (a loop over
    while True:  # the kept points, not over every sample)
        i = int(np.searchsorted(t, t[keep[-1]] + spacing_s, side="left"))
        if i >= t.size:
            break
        keep.append(i)
    k = np.array(keep)
    return t[k], np.asarray(gt.x)[k], np.asarray(gt.y)[k]


def _pressure(session: Session, st) -> dict[str, float]:
    """Noise: σ of the 1-s means about a straight line over still runs ≥ 8 s (median over runs).
    Drift: the lines' slopes averaged with weights T³ (a slope over T seconds is known to
    ∝ T^-3/2), hPa/min. Runs where the pressure moves more than 0.1 hPa (an elevator ride) are
    left out."""
    pr = session.pressure
    out = {"pressure_noise_hpa": np.nan, "pressure_drift_hpa_min": np.nan}
    if pr is None or len(pr.t) < 10:
        return out
    a, b = _runs(~st.walking)
    t = st.state_t
    sds, slopes, lens = [], [], []
    for i, j in zip(a, b):
        t0, t1 = t[i], t[min(j, t.size - 1)]
        if t1 - t0 < 8.0:
            continue
        means, n = _second_means(pr, t0 + 0.5, t1 - 0.5)
        if n < 8 or means.size < 6 or np.ptp(means) > 0.1:
            continue
        x = np.arange(means.size, dtype=float)
        coef = np.polyfit(x, means, 1)
        sds.append(np.std(means - np.polyval(coef, x)))
        slopes.append(coef[0] * 60.0)
        lens.append(t1 - t0)
    if sds:
        out["pressure_noise_hpa"] = float(np.median(sds))
        w = np.asarray(lens) ** 3
        out["pressure_drift_hpa_min"] = float(np.sum(w * np.asarray(slopes)) / w.sum())
    return out
