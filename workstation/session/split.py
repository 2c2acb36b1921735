"""A walk cut in two at a moment (beyond the paper): what a surveyor does with a file that holds
two recordings joined, or a walk whose inertial sensors paused (``sensor_hole``,
:mod:`workstation.pipeline.verdict`) — each part then runs with its own start.

Every stream is cut at the same instant ``t``: samples before it go to the first part, the rest
to the second (a WiFi reading by its own time); the ground truth likewise. The parts keep the
walk's metadata, with ``split_from`` saying which walk and where. Times are kept as they were.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import TypeVar

import numpy as np

from workstation.errors import InputError
from workstation.session.clocks import SAID
from workstation.session.metadata import SplitFrom
from workstation.session.model import GroundTruth, Scalar, Session, Vector3, WifiScans

R = TypeVar("R", Vector3, Scalar, WifiScans, GroundTruth)


def inertial_start(s: Session) -> float:
    """Where the times of ``sensor_hole`` count from: the first accelerometer or gyroscope
    sample."""
    ts = [float(t[0]) for t in (s.accelerometer.t, s.gyroscope.t) if t.size]
    return min(ts) if ts else s.start


def split_at(s: Session, t: float, source: str = "") -> tuple[Session, Session]:
    """The walk before ``t`` and from ``t`` on (``t`` on the session's own clock). Raises
    :class:`InputError` when either part would hold no inertial sample."""
    parts = [_part(s, lambda x: x < t), _part(s, lambda x: x >= t)]
    for i, p in enumerate(parts, 1):
        if p.accelerometer.t.size < 2 or p.gyroscope.t.size < 2:
            raise InputError(source or s.metadata.path,
                             f"a cut at {t - inertial_start(s):.2f} s leaves part {i} without "
                             "accelerometer or gyroscope samples")  # fmt: skip
        meta = p.metadata
        jump = meta.clock_jump  # a second recording begins inside it, or not
        end = max(float(p.accelerometer.t[-1]), float(p.gyroscope.t[-1]))
        if jump is not None and not inertial_start(p) < jump.t - 1e-6 <= end:
            meta = dataclasses.replace(
                meta,
                clock_jump=None,
                warnings=tuple(w for w in meta.warnings if not w.startswith(SAID)),
            )
        split = SplitFrom(source or s.metadata.path, i, round(t - inertial_start(s), 3))
        parts[i - 1] = dataclasses.replace(p, metadata=dataclasses.replace(meta, split_from=split))
    return parts[0], parts[1]


def _part(s: Session, keep: Callable[[np.ndarray], np.ndarray]) -> Session:
    return dataclasses.replace(
        s,
        accelerometer=_cut(s.accelerometer, keep),
        gyroscope=_cut(s.gyroscope, keep),
        magnetometer=_cut(s.magnetometer, keep),
        pressure=None if s.pressure is None else _cut(s.pressure, keep),
        wifi=_cut(s.wifi, keep),
        ground_truth=None if s.ground_truth is None else _cut(s.ground_truth, keep),
    )


def _cut(record: R, keep: Callable[[np.ndarray], np.ndarray]) -> R:
    """``record`` (a dataclass of arrays along ``t``) with the rows ``keep(t)`` says."""
    mask = keep(np.asarray(record.t))
    n = mask.size
    changes = {
        f.name: getattr(record, f.name)[mask]
        for f in dataclasses.fields(record)
        if isinstance(getattr(record, f.name), np.ndarray) and len(getattr(record, f.name)) == n
    }
    return dataclasses.replace(record, **changes)
