"""What ``workstation info`` says of a walk (:meth:`Session.info`): its duration, each sensor's
samples and rate, its WiFi scans, its ground truth, what the reader skipped or warned of — a
record; ``info --json`` prints :meth:`SessionInfo.to_json`."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class StreamInfo:
    """One inertial or pressure stream: its samples and rate (Hz; None without samples)."""

    samples: int
    rate_hz: float | None


@dataclass(frozen=True)
class SessionInfo:
    source: str | None
    path: str | None
    device: str | None  # None: the file does not say
    duration_s: float
    streams: Mapping[str, StreamInfo]  # accelerometer, gyroscope, magnetometer, pressure
    scans: int
    readings: int
    access_points: int
    median_scan_interval_s: float | None  # None: fewer than two scans
    truth_points: int | None  # None: no ground truth
    truth_floors: tuple[float, ...]
    skipped_records: Mapping[str, int]
    warnings: tuple[str, ...]

    @property
    def floors(self) -> list[int | float]:
        """The ground truth's floors, whole ones as integers."""
        return [float(f) if f % 1 else int(f) for f in self.truth_floors]

    def to_json(self) -> dict[str, Any]:
        return {
            "source": self.source, "path": self.path, "device": self.device,
            "duration_s": self.duration_s,
            "streams": {k: {"samples": s.samples, "rate_hz": s.rate_hz}
                        for k, s in self.streams.items()},
            "wifi": {"scans": self.scans, "readings": self.readings,
                     "access_points": self.access_points,
                     "median_scan_interval_s": self.median_scan_interval_s},
            "ground_truth": None if self.truth_points is None else {
                "points": self.truth_points,
                "floors": self.floors},
            "skipped_records": dict(self.skipped_records),
            "warnings": list(self.warnings),
        }  # fmt: skip
