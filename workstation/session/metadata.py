"""What a reader knew of a walk beside its streams: a record, not a dict (issue #65).

The facts the package reads — which reader, the file, the phone model, the map frame, the floor's
name, when the recording began, what the reader said and skipped, where a second recording
begins (:mod:`.clocks`), which walk a part was cut from (:mod:`.split`) — are typed fields. What
only one reader or the simulator knows (a site's name, the Android version, the simulated
walk's true landmark passes and events …) stays in ``extra``, as it was read.

``to_dict`` / ``from_dict`` are the session header's form (``session.yaml``'s ``metadata``):
the fields under their own names, then the extras. ``from_dict`` checks what the package reads
and raises :class:`ValueError` naming the key (``metadata.skipped: …``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

from workstation.geo import LocalFrame


@dataclass(frozen=True)
class ClockJump:
    """Where a second recording begins on the session's clock (s) and the evidence."""

    t: float
    what: str

    def to_dict(self) -> dict[str, Any]:
        return {"t": self.t, "what": self.what}


@dataclass(frozen=True)
class SplitFrom:
    """A part cut from a walk by ``workstation split``: the walk, which part (1 or 2), and where
    the cut is (s from the walk's first inertial sample)."""

    walk: str | None
    part: int
    at_s: float

    def to_dict(self) -> dict[str, Any]:
        return {"walk": self.walk, "part": self.part, "at_s": self.at_s}


@dataclass(frozen=True)
class Metadata:
    """A walk's facts beside its streams (module docstring)."""

    source: str | None = None  # the reader: "msilc", "getsensordata", "simulator" …
    path: str | None = None  # the file or folder it was read from
    device: str = ""  # the phone model ("" unknown): maps of one model need no alignment
    frame: LocalFrame | None = None  # the ground truth's local frame, when geo-referenced
    floor_name: str | None = None  # the floor the recording says it was on
    start_time_ms: float | None = None  # when it began (Unix ms): walks one after another
    warnings: tuple[str, ...] = ()  # what the reader (and the sanity checks) said
    skipped: Mapping[str, int] = field(default_factory=dict)  # records not read, per type
    clock_jump: ClockJump | None = None  # a second recording begins (session/clocks.py)
    split_from: SplitFrom | None = None  # cut from another walk (session/split.py)
    extra: Mapping[str, Any] = field(default_factory=dict)  # what one reader alone knows

    def said(self, *more: str) -> Metadata:
        """The same facts with ``more`` warnings said after the reader's."""
        return replace(self, warnings=(*self.warnings, *more))

    def to_dict(self) -> dict[str, Any]:
        """The header's form: the typed fields that are set, then the extras."""
        out: dict[str, Any] = {"source": self.source, "path": self.path, "device": self.device}
        if self.frame is not None:
            out["frame"] = self.frame.to_dict()
        if self.floor_name is not None:
            out["floor_name"] = self.floor_name
        if self.start_time_ms is not None:
            out["start_time_ms"] = self.start_time_ms
        out["skipped"] = dict(self.skipped)
        out["warnings"] = list(self.warnings)
        if self.clock_jump is not None:
            out["clock_jump"] = self.clock_jump.to_dict()
        if self.split_from is not None:
            out["split_from"] = self.split_from.to_dict()
        return {**out, **{k: v for k, v in self.extra.items() if k not in out}}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Metadata:
        """The header's form read back, checked; :class:`ValueError` names the key."""
        skipped = {} if d.get("skipped") is None else d["skipped"]
        if not isinstance(skipped, Mapping) or not all(
            isinstance(v, int) and not isinstance(v, bool) for v in skipped.values()
        ):
            raise ValueError("metadata.skipped: expected 'record type: count' pairs")
        warnings = [] if d.get("warnings") is None else d["warnings"]
        if not isinstance(warnings, list):
            raise ValueError("metadata.warnings: expected a list of messages")
        known = set(KNOWN)
        return cls(
            source=_text(d, "source"),
            path=_text(d, "path"),
            device=_text(d, "device") or "",
            frame=_frame(d.get("frame")),
            floor_name=_text(d, "floor_name"),
            start_time_ms=_number(d, "start_time_ms"),
            warnings=tuple(str(w) for w in warnings),
            skipped={str(k): int(v) for k, v in skipped.items()},
            clock_jump=_clock_jump(d.get("clock_jump")),
            split_from=_split_from(d.get("split_from")),
            extra={k: v for k, v in d.items() if k not in known},
        )


#: the keys of the typed fields (``extra`` holds the rest)
KNOWN = ("source", "path", "device", "frame", "floor_name", "start_time_ms", "warnings",
         "skipped", "clock_jump", "split_from")  # fmt: skip


def _text(d: Mapping[str, Any], key: str) -> str | None:
    v = d.get(key)
    return None if v is None else str(v)


def _number(d: Mapping[str, Any], key: str) -> float | None:
    v = d.get(key)
    if v is None:
        return None
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ValueError(f"metadata.{key}: expected a number, got {v!r}")
    return v


def _frame(f: Any) -> LocalFrame | None:
    if not f:
        return None
    try:
        return LocalFrame(float(f["origin_lat"]), float(f["origin_lon"]))
    except (TypeError, KeyError, ValueError):
        raise ValueError("metadata.frame: expected origin_lat and origin_lon (degrees)") from None


def _clock_jump(cj: Any) -> ClockJump | None:
    if cj is None:
        return None
    t = cj.get("t") if isinstance(cj, Mapping) else None
    if (not isinstance(t, (int, float)) or isinstance(t, bool) or not math.isfinite(t)
            or not isinstance(cj.get("what"), str)):  # fmt: skip
        raise ValueError("metadata.clock_jump: expected t (seconds) and what (text)")
    return ClockJump(float(t), cj["what"])


def _split_from(s: Any) -> SplitFrom | None:
    if s is None:
        return None
    try:
        return SplitFrom(None if s.get("walk") is None else str(s["walk"]), int(s["part"]),
                         float(s["at_s"]))  # fmt: skip
    except (AttributeError, KeyError, TypeError, ValueError):
        raise ValueError("metadata.split_from: expected walk, part and at_s") from None
