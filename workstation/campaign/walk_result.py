"""One walk's result in a campaign: what its run gave (:func:`.jobs.run_walk`) and what the
passes after it add — a record, not a dict (issue #65). It is the walk's ``summary.json`` in
the campaign's output (:meth:`WalkResult.to_json`, read back by :meth:`WalkResult.from_json`,
which reads the files earlier versions wrote), and it carries the walk's maps as Parquet bytes
from the worker to the client (``maps``; never in the file).

- the run: ``status`` (:data:`Status`), its ``error`` and ``trace``, ``retry`` (its input
  could not be read: tried again on the next run), ``seconds``;
- the figures of its run summary a campaign keeps (``figures``: :data:`SUMMARY_KEYS`, as the
  file holds them; :attr:`WalkResult.summary` reads them as a :class:`Summary`);
- what the building's passes need: the phone (``device``), when it was recorded (``clock``),
  where it ended (``ended``: x, y, floor, σ), the floor's name, an inferred start's candidates
  and stand fingerprint (:class:`InferredStart`), the start decided with walks that stood
  together (:class:`GroupStart`) or searched where the walk before ended
  (:class:`~workstation.pipeline.start.HandedStart`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Any, Literal

from workstation.pipeline.start import HandedStart
from workstation.pipeline.summary import Summary

#: a walk's state in the campaign: run, failed (its file or its run), or never run
Status = Literal["ok", "failed", "missing"]

#: the figures of a walk's run summary a campaign keeps (summary.json's keys)
SUMMARY_KEYS = (
    "steps", "landmarks_detected", "landmarks_matched", "end_node", "end_how", "end_sigma_m", "segments",
    "segments_accepted", "scans", "reference_points", "start_node", "landmark_node_accuracy",
    "landmark_fix_match_rate", "floor_accuracy", "fix_error_mean_m", "trajectory_error_mean_m",
    "start_time_s", "start_time_how", "quarantine", "chain_by_map", "open_by_map", "start_after",
    "sensor_hole_at_s", "sensor_hole_s", "clock_jump_at_s", "clock_jump",
    "facing_jump_at_s", "facing_jump_deg",
)  # fmt: skip

#: the walk's Parquet files a run gives: its map, its queries (scans at the ground truth) and
#: its first run's map (what the building's other walks' second runs read)
MAP_FILES = ("map", "queries", "first")


def _kept(summary: Summary) -> dict[str, Any]:
    """The figures of a walk's run summary a campaign keeps (``SUMMARY_KEYS``; null: absent)."""
    figures = summary.to_json()
    return {k: figures.get(k) for k in SUMMARY_KEYS}


@dataclass(frozen=True)
class InferredStart:
    """What a walk whose start was inferred gives the building's shared-start pass
    (:mod:`.shared_pass`): its candidate starts (landmark, log-likelihood below the best; best
    first), the fingerprint of where it stood before setting off (access points, dBm; None:
    no scan there) and the threshold it was read with."""

    candidates: tuple[tuple[str, float], ...]
    stand: tuple[tuple[str, ...], tuple[float, ...]] | None
    tau_dbm: float

    def to_json(self) -> dict[str, Any]:
        return {"candidates": [[n, m] for n, m in self.candidates],
                "stand": None if self.stand is None else [list(self.stand[0]), list(self.stand[1])],
                "tau_dbm": self.tau_dbm}  # fmt: skip

    @classmethod
    def from_json(cls, d: Mapping[str, Any]) -> InferredStart:
        stand = d.get("stand")
        return cls(tuple((str(n), float(m)) for n, m in d.get("candidates") or ()),
                   None if stand is None else (tuple(map(str, stand[0])), tuple(stand[1])),
                   float(d["tau_dbm"]))  # fmt: skip


@dataclass(frozen=True)
class GroupStart:
    """The start a group of walks that stood at one place chose together
    (:func:`workstation.walks.shared_start.decide_shared`): the landmark, the group's other
    walks, each candidate's summed log-likelihood; ``kept``: it was the walk's own best."""

    start: str
    walks: tuple[str, ...]
    totals: Mapping[str, float]
    kept: bool = False

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {"start": self.start, "with": list(self.walks),
                               "totals": dict(self.totals)}  # fmt: skip
        if self.kept:
            out["kept"] = True
        return out

    @classmethod
    def from_json(cls, d: Mapping[str, Any]) -> GroupStart:
        return cls(str(d["start"]), tuple(d.get("with") or ()), dict(d.get("totals") or {}),
                   bool(d.get("kept")))  # fmt: skip


@dataclass(frozen=True)
class WalkResult:
    """A walk's result (module docstring); a walk never run is ``missing``."""

    key: str  # building/walk
    building: str = ""
    walk: str = ""  # its file's name
    digest: str = ""  # of its inputs and the code
    status: Status = "missing"
    figures: Mapping[str, Any] = field(default_factory=dict)  # SUMMARY_KEYS, as the file has them
    start_inference: InferredStart | None = None  # its start was inferred
    device: str | None = None  # the phone's model ("": unknown; None: the walk did not run)
    clock: tuple[float, float] | None = None  # recorded from, to (s since the epoch)
    ended: tuple[float, float, float, float] | None = None  # x, y, floor, σ (m)
    floor_name: str | None = None
    error: str | None = None
    trace: str | None = None
    retry: bool = False  # failed for its input (store, disk): tried again on the next run
    seconds: float | None = None
    start_shared: GroupStart | None = None
    start_after: HandedStart | None = None
    #: its Parquet files by name (MAP_FILES; None: remove the file; a name absent: keep the
    #: file as it is) — from the worker to the client, never in summary.json
    maps: Mapping[str, bytes | None] = field(default_factory=dict, repr=False, compare=False)
    stored: bool = False  # its worker wrote the maps to the store itself

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @cached_property
    def summary(self) -> Summary:
        """The kept figures read back (a failed walk's: every figure absent)."""
        return Summary.from_json(self.figures)

    def with_summary(self, summary: Summary) -> WalkResult:
        return replace(self, figures=_kept(summary))

    def to_json(self) -> dict[str, Any]:
        """summary.json (module docstring)."""
        out: dict[str, Any] = {"key": self.key, "building": self.building, "walk": self.walk,
                               "digest": self.digest}  # fmt: skip
        if self.ok:
            out["summary"] = dict(self.figures)
            if self.start_inference is not None:
                out["start_inference"] = self.start_inference.to_json()
            out |= {"device": self.device, "floor_name": self.floor_name,
                    "clock": None if self.clock is None else list(self.clock),
                    "ended": None if self.ended is None else list(self.ended)}  # fmt: skip
        out["status"] = self.status
        if self.error is not None:
            out |= {"error": self.error, "trace": self.trace}
        if self.retry:
            out["retry"] = True
        out["seconds"] = self.seconds
        if not self.ok and self.start_inference is not None:
            out["start_inference"] = self.start_inference.to_json()
        if self.start_shared is not None:
            out["start_shared"] = self.start_shared.to_json()
        if self.start_after is not None:
            out["start_after"] = self.start_after.to_json()
        return out

    @classmethod
    def from_json(cls, d: Mapping[str, Any], key: str = "") -> WalkResult:
        """A walk's summary.json read back (``{}``: the walk ``key`` never ran)."""
        inf, shared, after = d.get("start_inference"), d.get("start_shared"), d.get("start_after")
        clock, ended = d.get("clock"), d.get("ended")
        status = d.get("status", "missing")
        return cls(
            key=str(d.get("key", key)), building=str(d.get("building") or ""),
            walk=str(d.get("walk") or ""), digest=str(d.get("digest") or ""),
            status=status if status in ("ok", "failed") else "missing",
            figures=dict(d.get("summary") or {}),
            start_inference=InferredStart.from_json(inf) if inf else None,
            device=d.get("device"), clock=None if clock is None else (clock[0], clock[1]),
            ended=None if ended is None else (ended[0], ended[1], ended[2], ended[3]),
            floor_name=d.get("floor_name"), error=d.get("error"), trace=d.get("trace"),
            retry=bool(d.get("retry")), seconds=d.get("seconds"),
            start_shared=GroupStart.from_json(shared) if shared else None,
            start_after=HandedStart.from_json(after) if after else None,
        )  # fmt: skip
