"""Every session that loads is sane (issue #18): one bad value must not crash the pipeline, eat
memory sized by a timestamp, or silently turn a walk into nothing.

- Times: every stream within ``MAX_SPAN_S`` of the others (a walk is hours at most; one pressure
  stamp at +1e9 s made ``run`` ask for 16 GB) — otherwise refused, naming the stream.
- Values: samples with a non-finite sensor value are dropped, and the warning says how many (ten
  NaN accelerometer samples used to leave a walk with no steps at all); ground-truth rows with a
  non-finite position are dropped likewise.
- Missing streams (issue #33): a walk without an accelerometer, gyroscope, magnetometer or WiFi
  loads, with a warning that says what it costs (no gyroscope gave 0 landmarks and 39 m with
  nothing said).
- Glitches (issues #55, #67): a sample beyond what any phone measures (``PHYSICAL``, one table:
  accelerometer 16 g, gyroscope 4000 °/s, magnetometer 5000 µT; WiFi RSS outside
  ``RSS_DBM``) is dropped with a warning; more than 5 % of a stream's samples beyond is a
  broken sensor or another unit, refused. The gyroscope's unit is judged on its samples as
  recorded, before its spikes are dropped (a walk in °/s must not pass as one in rad/s with
  its turns dropped).
- Pressure (issue #51): a barometer sample off its neighbours by more than any climb makes is a
  glitch, dropped with a warning; a jump that stays (a 50-hPa step gave floor accuracy 0.33 and
  exit 0) is no staircase or lift — two recordings joined, or the barometer re-zeroed — refused
  naming its time. The fastest lifts climb 20 m/s, ``MAX_CLIMB_HPA_S`` = 2.4 hPa/s near the
  ground (0.12 hPa a metre); ``PRESSURE_NOISE_HPA`` is ten times the largest step between two
  samples of the museum's real walks (0.03 hPa).
- Units (issue #33): an accelerometer whose median magnitude is not near gravity (9.81 m/s²;
  in g it reads 1) or a gyroscope beyond what phones measure (about 35 rad/s = 2000 °/s; in
  degrees per second a walk reads hundreds) is refused — a gyroscope in °/s gave 28 m at the
  fixes and exit 0.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from workstation.errors import InputError
from workstation.physical import PHYSICAL, RSS_DBM
from workstation.session.model import GroundTruth, Scalar, Session, Vector3, WifiScans

MAX_SPAN_S = 2 * 86400.0
GRAVITY_RANGE = (5.0, 15.0)  # m/s²: the median accelerometer magnitude of a phone carried
MAX_GYRO_RAD_S = 35.0  # phones saturate at 2000 °/s
MIN_SAMPLES = 100  # fewer: too few to judge the unit
# a sample beyond what phones measure (physical.PHYSICAL) is a glitch, dropped with a warning
# (issue #55 item 6: 1 % of accelerometer samples at 1000 m/s² gave 21 points 21.5 m off, exit 0;
# issue #67 item 1: 0.5 % of gyroscope samples at 1e6 rad/s, 31.9 m) — more than MAX_WILD_SHARE
# of them is a broken sensor or another unit: refused
MAX_WILD_SHARE = 0.05
MAX_CLIMB_HPA_S = 2.4  # 20 m/s, the fastest lifts, at 0.12 hPa a metre
PRESSURE_NOISE_HPA = 0.3
EXCURSION_S = 10.0  # a stretch off and back within this is a glitch, not a change of floor
MAX_EXCURSIONS = 20  # more of them: a broken barometer (refused at the next)
_SPIKE_WINDOW = 9  # samples of the running median a glitch is judged against (≤ 4 in a row)
MISSING = {  # a stream a walk lacks, and what it costs: said by `run`, kept in summary.json
    "accelerometer": "no steps can be detected (the walk is quarantined)",
    "gyroscope": "no turn can be detected and the heading between landmarks is the compass's",
    "magnetometer": "no compass: the heading is known only relative to where the walk set off",
    "wifi": "no scan can become a reference point",
}


def sanitize(session: Session, path: Path) -> Session:
    warnings = list(session.metadata.warnings)
    changes: dict[str, Any] = {}  # stream name → the stream without its bad samples
    for name in ("accelerometer", "gyroscope", "magnetometer"):
        kept = _inertial(name, getattr(session, name), path, warnings)
        if kept is not None:
            changes[name] = kept
    wifi = _wifi_in_range(session.wifi, path, warnings)
    if wifi is not None:
        changes["wifi"] = wifi
    changed, pressure = _pressure(session.pressure, path, warnings)
    if changed:
        changes["pressure"] = pressure
    gt = _ground_truth(session.ground_truth, warnings)
    if gt is not None:
        changes["ground_truth"] = gt
    for name, what in MISSING.items():
        stream = changes.get(name, getattr(session, name))
        if not len(stream) and not any(w.startswith(f"no {name}") for w in warnings):
            warnings.append(f"no {name}: {what}")
    if changes or warnings != list(session.metadata.warnings):
        meta = replace(session.metadata, warnings=tuple(warnings))
        session = replace(session, **changes, metadata=meta)
    _check_span(session, path)
    _check_units(session, path)
    return session


def _inertial(name: str, s: Vector3, path: Path, warnings: list[str]) -> Vector3 | None:
    """An inertial stream without its non-finite samples and those beyond what any phone
    measures (``PHYSICAL``; refused when more than ``MAX_WILD_SHARE`` are); None: unchanged.
    The gyroscope's unit is checked on what was recorded, spikes and all."""
    ok = np.isfinite(s.xyz).all(axis=1)
    if not ok.all():
        warnings.append(f"{name}: {int((~ok).sum())} samples with non-finite values dropped")
    if name == "gyroscope":
        _check_gyro_unit(s.xyz[ok], path)
    cap = PHYSICAL.get(name)
    if cap is not None and len(s):
        size = np.linalg.norm(np.where(ok[:, None], s.xyz, 0.0), axis=1)
        wild = ok & (size > cap[0])
        if wild.mean() > MAX_WILD_SHARE:  # a broken sensor or another unit, not glitches
            raise InputError(
                path,
                f"{name}: {100 * wild.mean():.1f} % of the samples beyond {cap[0]:g} "
                f"{cap[1]}, more than any phone measures: a broken sensor or another unit",
            )
        if wild.any():
            warnings.append(
                f"{name}: {int(wild.sum())} samples beyond {cap[0]:g} {cap[1]} (more than "
                "any phone measures) dropped"
            )
            ok &= ~wild
    return None if ok.all() else Vector3(s.t[ok], s.xyz[ok])


def _pressure(p: Scalar | None, path: Path, warnings: list[str]) -> tuple[bool, Scalar | None]:
    """Whether the barometer changed, and what is left of it without samples that are no
    pressure and without glitches (None: none)."""
    if p is None:
        return False, None
    changed = False
    q: Scalar | None = p
    ok = np.isfinite(p.value) & (p.value > 100.0) & (p.value < 1200.0)
    if not ok.all():
        changed, q = True, (Scalar(p.t[ok], p.value[ok]) if ok.any() else None)
        warnings.append(
            f"pressure: {int((~ok).sum())} samples not a plausible pressure (hPa) dropped"
        )
    if q is not None and len(q) >= _SPIKE_WINDOW:
        kept = _pressure_glitches(q, path, warnings)
        if kept is not None:
            changed, q = True, Scalar(q.t[kept], q.value[kept])
    return changed, q


def _ground_truth(gt: GroundTruth | None, warnings: list[str]) -> GroundTruth | None:
    """The ground truth without rows that have no position; None: unchanged."""
    if gt is None or not len(gt):
        return None
    ok = np.isfinite(gt.x) & np.isfinite(gt.y) & np.isfinite(gt.floor)
    if ok.all():
        return None
    kw: dict[str, Any] = {k: (getattr(gt, k)[ok] if getattr(gt, k) is not None else None)
                          for k in ("t", "x", "y", "floor", *GroundTruth.OPTIONAL)}  # fmt: skip
    warnings.append(f"ground truth: {int((~ok).sum())} rows without a position dropped")
    return GroundTruth(**kw)


def _pressure_glitches(p: Scalar, path: Path, warnings: list[str]) -> np.ndarray | None:
    """The samples to keep when some are glitches (None: all), or an error for a jump that stays.

    A glitch is a sample off the running median of its ``_SPIKE_WINDOW`` neighbours by more than
    the noise and the fastest climb over the window allow (the median follows a lift's ramp and
    keeps a step, so neither is taken for a glitch)."""
    half = _SPIKE_WINDOW // 2
    padded = np.pad(p.value, half, mode="edge")
    med = np.median(sliding_window_view(padded, _SPIKE_WINDOW), axis=1)
    span = np.pad(p.t, half, mode="edge")
    window_s = span[_SPIKE_WINDOW - 1 :] - span[: -_SPIKE_WINDOW + 1]
    glitch = np.abs(p.value - med) > PRESSURE_NOISE_HPA + MAX_CLIMB_HPA_S * window_s
    if glitch.mean() > MAX_WILD_SHARE:
        raise InputError(
            path,
            f"pressure: {100 * glitch.mean():.1f} % of the samples jump off their neighbours by "
            "more than any staircase or lift climbs: a broken barometer",
        )
    keep = np.flatnonzero(~glitch)
    excursions = 0
    while True:
        t, v = p.t[keep], p.value[keep]
        dv, dt = np.abs(np.diff(v)), np.diff(t)
        jump = np.flatnonzero(dv > PRESSURE_NOISE_HPA + MAX_CLIMB_HPA_S * dt)
        if not jump.size:
            break
        i = int(jump[0])
        back = _comes_back(t, v, i)
        if back is not None and excursions < MAX_EXCURSIONS:  # off, then back: a glitch
            keep = np.delete(keep, np.arange(i + 1, back))
            excursions += 1
            continue
        raise InputError(
            path,
            f"pressure: jumps {dv[i]:.2f} hPa in {dt[i]:.2f} s at {t[i + 1]:.3f} s and stays — no "
            f"staircase or lift climbs that fast (at most {MAX_CLIMB_HPA_S:g} hPa/s): two "
            "recordings joined, or the barometer re-zeroed? Split the file there",
        )
    if keep.size == len(p):
        return None
    warnings.append(
        f"pressure: {len(p) - keep.size} samples off their neighbours by more than any climb "
        "(glitches) dropped"
        + (f", {excursions} stretch(es) of up to {EXCURSION_S:g} s that jumped off and came back "
           "among them" if excursions else "")
    )
    return keep


def _comes_back(t: np.ndarray, v: np.ndarray, i: int) -> int | None:
    """After the jump between samples i and i + 1, the first sample within ``EXCURSION_S`` that
    is back within the noise of sample i — the pressure left and came
    back, no floor changed (issue #67 item 6: a 3-s excursion was said to "jump and stay") —
    or None."""
    later = np.flatnonzero((t > t[i + 1]) & (t <= t[i + 1] + EXCURSION_S))
    if not later.size:
        return None
    near = np.abs(v[later] - v[i]) <= PRESSURE_NOISE_HPA
    return int(later[np.argmax(near)]) if near.any() else None


def _wifi_in_range(w: WifiScans, path: Path, warnings: list[str]) -> WifiScans | None:
    """The WiFi readings without those outside ``RSS_DBM`` (None: all in range), said in a
    warning; more than ``MAX_WILD_SHARE`` of them is refused."""
    odd = (w.rss_dbm < RSS_DBM[0]) | (w.rss_dbm > RSS_DBM[1])
    if not odd.any():
        return None
    if odd.mean() > MAX_WILD_SHARE:
        raise InputError(path, f"wifi: {100 * odd.mean():.1f} % of the readings outside "
                         f"{RSS_DBM[0]:g} … {RSS_DBM[1]:g} dBm: not signal strengths in dBm")  # fmt: skip
    warnings.append(f"wifi: {int(odd.sum())} readings outside {RSS_DBM[0]:g} … {RSS_DBM[1]:g} "
                    "dBm (no signal strength) dropped")  # fmt: skip
    ok = ~odd
    return WifiScans(w.t[ok], w.bssid[ok], w.ssid[ok], w.freq_mhz[ok], w.rss_dbm[ok])


def _check_gyro_unit(gyr: np.ndarray, path: Path) -> None:
    """A gyroscope whose 1 % fastest samples turn faster than phones measure: another unit."""
    if len(gyr) >= MIN_SAMPLES:
        w = float(np.percentile(np.linalg.norm(gyr, axis=1), 99))
        if w > MAX_GYRO_RAD_S:
            raise InputError(
                path,
                f"gyroscope: 1 % of the samples turn faster than {w:.3g} — beyond what phones "
                f"measure ({MAX_GYRO_RAD_S:g} rad/s): recorded in degrees per second? "
                "(expected rad/s)",
            )


def _check_units(session: Session, path: Path) -> None:
    acc = session.accelerometer.xyz
    if len(acc) >= MIN_SAMPLES:
        g = float(np.median(np.linalg.norm(acc, axis=1)))
        if not GRAVITY_RANGE[0] <= g <= GRAVITY_RANGE[1]:
            raise InputError(
                path,
                f"accelerometer: median magnitude {g:.3g}, where gravity alone is 9.81 m/s² — "
                "recorded in g, or in another unit? (expected m/s²)",
            )


def _check_span(session: Session, path: Path) -> None:
    streams = {
        "accelerometer": session.accelerometer.t,
        "gyroscope": session.gyroscope.t,
        "magnetometer": session.magnetometer.t,
        "wifi": session.wifi.t,
    }
    if session.pressure is not None:
        streams["pressure"] = session.pressure.t
    if session.ground_truth is not None:
        streams["ground truth"] = session.ground_truth.t
    ts = {k: v for k, v in streams.items() if v.size}
    if not ts:
        return
    ref = float(np.median(np.concatenate([[v[0], v[-1]] for v in ts.values()])))
    for name, t in ts.items():
        far = np.abs(t - ref) > MAX_SPAN_S
        if far.any():
            i = int(np.flatnonzero(far)[0])
            raise InputError(
                path,
                f"{name}: time {t[i]:.6g} s is {abs(t[i] - ref) / 3600:.0f} h away from the rest "
                f"of the walk (more than {MAX_SPAN_S / 3600:.0f} h): a corrupt timestamp",
            )
