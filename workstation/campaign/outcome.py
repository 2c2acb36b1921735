"""What a campaign run says (``campaign.json``), typed: :class:`CampaignReport` with one
:class:`BuildingReport` per building. One writer (:meth:`CampaignReport.to_json`) and one reader
(:meth:`CampaignReport.from_json`).

campaign.json: ``walks``, ``walks_ok``, ``run_now`` (walks run this time), ``run_again_with_map``
(second runs with the building's map), ``walks_quarantined`` (quarantined or disagreeing: they
need the surveyor), ``wall_seconds``, ``buildings`` ({name: ``walks``, ``walks_ok``,
``walks_quarantined``, and with a merged map ``reference_points``, ``access_points``,
``leave_one_out`` — the error statistics of each walk's scans localized on the others' map}),
``per_walk`` (one row per walk: key, building, status, error, seconds, device, the figures the
campaign keeps of its run summary — :data:`.walk_row.SUMMARY_KEYS` — and what the report adds:
``candidates``, ``start_by_map``, ``disagrees``, ``map_lacks``, ``edit``), ``starts_files`` and
``ends_files`` ({building: where its given starts and ends are read}), ``pass_seconds`` (wall
seconds of each pass).
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from workstation.campaign.walk_row import WalkRow


class PassClock:
    """Wall seconds per pass (``CampaignReport.pass_seconds``): :meth:`lap` adds the time since
    the last lap to ``name`` (a pass run per building adds up)."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = {}
        self._t = time.perf_counter()

    def lap(self, name: str) -> None:
        now = time.perf_counter()
        self.seconds[name] = round(self.seconds.get(name, 0.0) + now - self._t, 3)
        self._t = now


@dataclass(frozen=True)
class BuildingReport:
    walks: int
    walks_ok: int
    walks_quarantined: int
    reference_points: int = 0  # in the building's merged map (0: no map)
    access_points: int = 0
    leave_one_out: Mapping[str, float] | None = None  # error statistics (stats.error_stats)

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "walks": self.walks,
            "walks_ok": self.walks_ok,
            "walks_quarantined": self.walks_quarantined,
        }
        if self.reference_points:
            out["reference_points"] = self.reference_points
            out["access_points"] = self.access_points
        if self.leave_one_out is not None:
            out["leave_one_out"] = dict(self.leave_one_out)
        return out

    @classmethod
    def from_json(cls, d: Mapping[str, Any]) -> BuildingReport:
        return cls(
            int(d["walks"]),
            int(d["walks_ok"]),
            int(d["walks_quarantined"]),
            int(d.get("reference_points") or 0),
            int(d.get("access_points") or 0),
            d.get("leave_one_out"),
        )


@dataclass(frozen=True)
class CampaignReport:
    walks: int
    walks_ok: int
    run_now: int
    run_again_with_map: int
    walks_quarantined: int
    wall_seconds: float
    buildings: Mapping[str, BuildingReport] = field(default_factory=dict)
    #: one row per walk (module doc): the campaign's table, as campaign.json and campaign.md show
    per_walk: tuple[WalkRow, ...] = ()
    starts_files: Mapping[str, str] = field(default_factory=dict)
    ends_files: Mapping[str, str] = field(default_factory=dict)
    #: walk runs this campaign run made (a walk runs again in later passes) and their own time
    #: summed: ``wall_seconds`` × workers beyond it is what scheduling and passing cost
    runs: int = 0
    busy_seconds: float = 0.0
    #: wall seconds of each pass (the walks' first runs, the passes that run walks again, the
    #: report's steps: the joint estimate, the merged maps, the leave-one-out), in order
    pass_seconds: Mapping[str, float] = field(default_factory=dict)

    @property
    def failed(self) -> int:
        return self.walks - self.walks_ok

    def to_json(self) -> dict[str, Any]:
        return {
            "walks": self.walks, "walks_ok": self.walks_ok, "run_now": self.run_now,
            "run_again_with_map": self.run_again_with_map,
            "walks_quarantined": self.walks_quarantined, "wall_seconds": self.wall_seconds,
            "buildings": {k: b.to_json() for k, b in self.buildings.items()},
            "per_walk": [w.to_json() for w in self.per_walk],
            "starts_files": dict(self.starts_files), "ends_files": dict(self.ends_files),
            "runs": self.runs, "busy_seconds": self.busy_seconds,
            "pass_seconds": dict(self.pass_seconds),
        }  # fmt: skip

    @classmethod
    def from_json(cls, d: Mapping[str, Any]) -> CampaignReport:
        return cls(
            int(d["walks"]), int(d["walks_ok"]), int(d["run_now"]),
            int(d.get("run_again_with_map") or 0), int(d["walks_quarantined"]),
            float(d["wall_seconds"]),
            {k: BuildingReport.from_json(b) for k, b in (d.get("buildings") or {}).items()},
            tuple(WalkRow.from_json(w) for w in d.get("per_walk") or ()),
            dict(d.get("starts_files") or {}), dict(d.get("ends_files") or {}),
            int(d.get("runs") or 0), float(d.get("busy_seconds") or 0.0),
            dict(d.get("pass_seconds") or {}),
        )  # fmt: skip
