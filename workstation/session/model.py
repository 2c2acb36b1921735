"""The in-memory session: one walk's sensor streams, WiFi scans and optional ground truth.

Times are float64 seconds from the session start; every stream is sorted by time with no
duplicated timestamps (the readers guarantee it and say so in ``metadata.warnings``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

from workstation.geo import LocalFrame
from workstation.session.info import SessionInfo, StreamInfo
from workstation.session.metadata import Metadata

#: times (s) to sample at: an array, a list, or one time
Times = np.ndarray | Sequence[float] | float


def _f64(a: Times) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(a, dtype=np.float64))


def _check_times(name: str, t: np.ndarray) -> None:
    if t.ndim != 1:
        raise ValueError(f"{name}: times must be 1-D, got shape {t.shape}")
    if t.size and not np.all(np.isfinite(t)):
        raise ValueError(f"{name}: non-finite time")
    if t.size > 1 and np.any(np.diff(t) <= 0):
        raise ValueError(f"{name}: times must be strictly increasing")


def sample_path(
    t_src: np.ndarray, x: np.ndarray, y: np.ndarray, floor: np.ndarray, t: Times
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """x, y interpolated in time along a path (eq. 19–20); floor of the nearest earlier point."""
    t = _f64(t)
    if t_src.size == 0:
        z = np.zeros(t.size)
        return z, z, z
    idx = np.clip(np.searchsorted(t_src, t, side="right") - 1, 0, t_src.size - 1)
    return np.interp(t, t_src, x), np.interp(t, t_src, y), floor[idx]


def median_rate(t: np.ndarray) -> float:
    if t.size < 2:
        return float("nan")
    return float(1.0 / np.median(np.diff(t)))


@dataclass(frozen=True)
class Vector3:
    """A 3-axis stream: ``t`` (N,) and ``xyz`` (N, 3) in the phone's frame."""

    t: np.ndarray
    xyz: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "t", _f64(self.t))
        object.__setattr__(self, "xyz", _f64(self.xyz).reshape(-1, 3))
        _check_times("vector stream", self.t)
        if self.xyz.shape[0] != self.t.shape[0]:
            raise ValueError(f"{self.t.size} times but {self.xyz.shape[0]} samples")

    @classmethod
    def empty(cls) -> Vector3:
        return cls(np.empty(0), np.empty((0, 3)))

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def rate_hz(self) -> float:
        return median_rate(self.t)


@dataclass(frozen=True)
class Scalar:
    """A scalar stream (e.g. pressure in hPa)."""

    t: np.ndarray
    value: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "t", _f64(self.t))
        object.__setattr__(self, "value", _f64(self.value))
        _check_times("scalar stream", self.t)
        if self.value.shape != self.t.shape:
            raise ValueError(f"{self.t.size} times but {self.value.size} values")

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def rate_hz(self) -> float:
        return median_rate(self.t)


@dataclass(frozen=True)
class WifiScans:
    """WiFi readings in long form: one row per (scan, access point).

    A scan is all readings that share one time ``t``. ``bssid``/``ssid`` are string arrays.
    """

    t: np.ndarray
    bssid: np.ndarray
    ssid: np.ndarray
    freq_mhz: np.ndarray
    rss_dbm: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "t", _f64(self.t))
        object.__setattr__(self, "bssid", np.asarray(self.bssid, dtype=str))
        object.__setattr__(self, "ssid", np.asarray(self.ssid, dtype=str))
        object.__setattr__(self, "freq_mhz", _f64(self.freq_mhz))
        object.__setattr__(self, "rss_dbm", _f64(self.rss_dbm))
        n = self.t.size
        for name in ("bssid", "ssid", "freq_mhz", "rss_dbm"):
            if getattr(self, name).shape != (n,):
                raise ValueError(f"wifi: {name} has {getattr(self, name).size} rows, t has {n}")
        if n > 1 and np.any(np.diff(self.t) < 0):
            raise ValueError("wifi: readings must be sorted by scan time")
        # issue #55 item 5: a NaN scan time ran to a radio-map row with empty x, y, t, and
        # NaN RSS or frequency and an empty BSSID were taken without a word
        for name, v in (("scan time", self.t), ("RSS", self.rss_dbm), ("frequency", self.freq_mhz)):
            bad = np.flatnonzero(~np.isfinite(v))
            if bad.size:
                raise ValueError(f"wifi: the {name} of reading {int(bad[0]) + 1} is not a number")
        empty = np.flatnonzero(np.char.str_len(self.bssid) == 0) if n else np.empty(0, int)
        if empty.size:
            raise ValueError(f"wifi: reading {int(empty[0]) + 1} has no BSSID")

    @classmethod
    def empty(cls) -> WifiScans:
        e = np.empty(0)
        return cls(e, e.astype(str), e.astype(str), e, e)

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def scan_times(self) -> np.ndarray:
        return np.unique(self.t)

    @property
    def n_scans(self) -> int:
        return int(self.scan_times.size)

    @property
    def access_points(self) -> np.ndarray:
        return np.unique(self.bssid)

    @cached_property
    def _matrix(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        times, bssids, r = self._build_matrix(None, np.nan)
        r.setflags(write=False)  # shared by every re-run of the radio map stage
        return times, bssids, r

    def matrix(
        self, bssids: np.ndarray | None = None, missing: float = np.nan
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(scan_times, bssids, R) with R[i, j] the RSS of AP j in scan i, ``missing`` if unheard."""
        if bssids is None and np.isnan(missing):
            return self._matrix
        return self._build_matrix(bssids, missing)

    def _build_matrix(
        self, bssids: np.ndarray | None, missing: float
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        times, scan_idx = np.unique(self.t, return_inverse=True)
        if bssids is None:
            bssids, ap_idx = np.unique(self.bssid, return_inverse=True)
            keep = np.ones(self.t.size, bool)
        else:
            bssids = np.asarray(bssids, dtype=str)
            keep = np.zeros(self.t.size, bool)
            ap_idx = np.zeros(self.t.size, np.intp)
            if bssids.size:
                order = np.argsort(bssids)
                pos = np.clip(np.searchsorted(bssids[order], self.bssid), 0, bssids.size - 1)
                keep = bssids[order][pos] == self.bssid
                ap_idx = order[pos]
        r = np.full((times.size, len(bssids)), missing, dtype=np.float64)
        r[scan_idx[keep], ap_idx[keep]] = self.rss_dbm[keep]
        return times, bssids, r


@dataclass(frozen=True)
class GroundTruth:
    """Known positions: x, y (m, local frame), floor (as given by the source).

    Optional per-point columns: ``heading`` (rad, from +x counter-clockwise), ``walking``
    (1 walking / 0 still), ``lat``/``lon`` (degrees, for re-projection into another frame).
    """

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    floor: np.ndarray
    heading: np.ndarray | None = None
    walking: np.ndarray | None = None
    lat: np.ndarray | None = None
    lon: np.ndarray | None = None

    OPTIONAL = ("heading", "walking", "lat", "lon")

    def __post_init__(self) -> None:
        for name in ("t", "x", "y", "floor", *self.OPTIONAL):
            v = getattr(self, name)
            if v is not None:
                object.__setattr__(self, name, _f64(v))
        _check_times("ground truth", self.t)
        for name in ("x", "y", "floor", *self.OPTIONAL):
            v = getattr(self, name)
            if v is not None and v.shape != self.t.shape:
                raise ValueError(f"ground truth: {name} has {v.size} rows, t has {self.t.size}")

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def floors(self) -> np.ndarray:
        return np.unique(self.floor)

    def at(self, t: Times) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position at times ``t``: x, y interpolated in time; floor of the nearest earlier point."""
        return sample_path(self.t, self.x, self.y, self.floor, t)

    def in_frame(self, frame: LocalFrame) -> GroundTruth:
        if self.lat is None or self.lon is None:
            raise ValueError("ground truth has no lat/lon to re-project")
        x, y = frame.to_xy(self.lat, self.lon)
        return replace(self, x=x, y=y)


@dataclass(frozen=True)
class Session:
    """One walk. ``metadata`` (:class:`.Metadata`) holds device, source, path, frame and reader
    warnings."""

    accelerometer: Vector3
    gyroscope: Vector3
    magnetometer: Vector3
    pressure: Scalar | None
    wifi: WifiScans
    ground_truth: GroundTruth | None = None
    metadata: Metadata = field(default_factory=Metadata)

    @property
    def start(self) -> float:
        return min(self._ends(0)) if self._ends(0) else 0.0

    @property
    def end(self) -> float:
        return max(self._ends(-1)) if self._ends(-1) else 0.0

    @property
    def has_path(self) -> bool:
        """At least two ground-truth fixes: a path to draw a graph from or to score a walk on."""
        return self.ground_truth is not None and len(self.ground_truth) >= 2

    @property
    def duration(self) -> float:
        return self.end - self.start

    def _ends(self, i: int) -> list[float]:
        ts = [self.accelerometer.t, self.gyroscope.t, self.magnetometer.t, self.wifi.t]
        if self.pressure is not None:
            ts.append(self.pressure.t)
        return [float(t[i]) for t in ts if t.size]

    @property
    def warnings(self) -> list[str]:
        return list(self.metadata.warnings)

    @property
    def frame(self) -> LocalFrame | None:
        return self.metadata.frame

    def in_frame(self, frame: LocalFrame | None) -> Session:
        """The same session with its ground truth re-projected into ``frame``; as it is when
        there is nothing to re-project (no frame on either side, no ground truth)."""
        if frame is None or self.frame is None or self.ground_truth is None or self.frame == frame:
            return self
        meta = replace(self.metadata, frame=frame)
        return replace(self, ground_truth=self.ground_truth.in_frame(frame), metadata=meta)

    def info(self) -> SessionInfo:
        """What `workstation info` prints: duration, rates, scans, APs, ground truth, skipped."""
        streams = {}
        for name in ("accelerometer", "gyroscope", "magnetometer", "pressure"):
            s = getattr(self, name)
            ok = s is not None and len(s)
            streams[name] = StreamInfo(len(s) if ok else 0, round(s.rate_hz, 2) if ok else None)
        scans = self.wifi.scan_times
        gt = self.ground_truth
        return SessionInfo(
            self.metadata.source, self.metadata.path, self.metadata.device or None,
            round(self.duration, 2), streams, int(scans.size), len(self.wifi),
            int(self.wifi.access_points.size),
            round(float(np.median(np.diff(scans))), 2) if scans.size > 1 else None,
            None if gt is None else len(gt), () if gt is None else tuple(gt.floors),
            dict(self.metadata.skipped), tuple(self.warnings),
        )  # fmt: skip
