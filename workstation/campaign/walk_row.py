"""One walk's row of a campaign's report (``campaign.json``'s ``per_walk``, campaign.md's table
of walks): a record, not a dict (issue #65).

What the walk's run left (its status, error, time, phone model and the figures of its run
summary a campaign keeps, :data:`.walk_result.SUMMARY_KEYS` — read as a :class:`Summary`) and what the
report adds to it: the walks its start was decided with, an ambiguous start's candidates, what
the joint estimate did (:class:`..walks.joint.WalkCorrection`), how many of a held walk's scans
lie where the merged map has nothing, the command that opens it in the panel and what the
building's map says of its candidate starts. :meth:`WalkRow.to_json` writes the row as
campaign.json has always held it; :meth:`WalkRow.from_json` reads it back.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

from workstation.campaign.walk_result import SUMMARY_KEYS, Status, WalkResult
from workstation.pipeline.summary import Quarantine, Summary
from workstation.walks.correction import UNRECONCILED, WHAT_TO_DO, WalkCorrection
from workstation.walks.start_by_map import MapRanking


@dataclass(frozen=True)
class WalkRow:
    """A walk's row of the report (module docstring)."""

    key: str  # building/walk
    building: str
    status: Status  # as the campaign's records say
    error: str | None = None
    seconds: float | None = None
    retry: bool = False  # failed for its input (store, disk): tried again on the next run
    device: str = ""
    #: the run summary's figures a campaign keeps (SUMMARY_KEYS), as summary.json has them
    figures: Mapping[str, Any] = field(default_factory=dict)
    start_shared_with: tuple[str, ...] = ()  # walks whose start was decided with it
    candidates: tuple[str, ...] | None = None  # an ambiguous start's candidate landmarks
    joint: WalkCorrection | None = None  # what the joint estimate did to it
    map_lacks: int | None = None  # a held walk's scans where the merged map has no point
    edit_command: str | None = None  # opens it in the panel, set up to fix it
    start_by_map: MapRanking | None = None  # the building's map on its candidate starts
    start_by_map_error: str | None = None  # why the map could not rank them

    @cached_property
    def summary(self) -> Summary:
        """The kept figures read back (a failed walk's: every figure absent)."""
        return Summary.from_json(self.figures)

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def quarantine(self) -> tuple[Quarantine, ...]:
        """Why its points stay out of the merged map: its run's reasons, or the joint
        estimate's when it left the walk out."""
        if self.joint is not None and self.joint.left_out:
            return (Quarantine(UNRECONCILED, self.joint.words(), WHAT_TO_DO),)  # type: ignore[arg-type]
        return self.summary.quarantine

    @property
    def quarantined(self) -> bool:
        return bool(self.quarantine)

    @property
    def name(self) -> str:
        """The walk's name within its building (the key's second part)."""
        return self.key.split("/", 1)[1]

    @classmethod
    def of(cls, res: WalkResult) -> WalkRow:
        """A walk's row as its run left it (what the report adds comes after)."""
        shared = res.start_shared
        ambiguous = "start_ambiguous" in res.summary.reasons
        cands = res.start_inference.candidates if res.start_inference is not None else ()
        return cls(res.key, res.building, res.status, res.error, res.seconds, res.retry,
                   res.device or "", res.figures, shared.walks if shared else (),
                   tuple(n for n, _ in cands) if ambiguous else None)  # fmt: skip

    def to_json(self) -> dict[str, Any]:
        """campaign.json's row: the run's part, its kept figures, then what the report added."""
        out: dict[str, Any] = {"key": self.key, "building": self.building,
                               "status": self.status, "error": self.error,
                               "seconds": self.seconds}  # fmt: skip
        if self.retry:
            out["retry"] = True
        out["device"] = self.device
        out.update(self.figures)
        if "quarantine" in self.figures or self.joint is not None and self.joint.left_out:
            out["quarantine"] = [q.to_json() for q in self.quarantine]
        if self.start_shared_with:
            out["start_shared_with"] = list(self.start_shared_with)
        if self.candidates is not None:
            out["candidates"] = list(self.candidates)
        if self.joint is not None:
            out["joint"] = self.joint.to_dict()
        if self.map_lacks is not None:
            out["map_lacks"] = self.map_lacks
        if self.edit_command is not None:
            out["edit_command"] = self.edit_command
        if self.start_by_map is not None:
            out |= self.start_by_map.to_json()
        if self.start_by_map_error is not None:
            out["start_by_map_error"] = self.start_by_map_error
        return out

    @classmethod
    def from_json(cls, d: Mapping[str, Any]) -> WalkRow:
        """A row of campaign.json read back."""
        joint = d.get("joint")
        figures = {k: d[k] for k in SUMMARY_KEYS if k in d}
        if joint and joint.get("left_out"):  # its quarantine is the joint estimate's
            figures["quarantine"] = [q for q in figures.get("quarantine") or ()
                                     if q.get("reason") != UNRECONCILED]  # fmt: skip
        ranked = d.get("start_by_map")
        return cls(
            key=str(d["key"]), building=str(d["building"]), status=d["status"],
            error=d.get("error"), seconds=d.get("seconds"), retry=bool(d.get("retry")),
            device=str(d.get("device") or ""), figures=figures,
            start_shared_with=tuple(d.get("start_shared_with") or ()),
            candidates=None if d.get("candidates") is None else tuple(d["candidates"]),
            joint=None if not joint else WalkCorrection.from_dict(joint),
            map_lacks=d.get("map_lacks"), edit_command=d.get("edit_command"),
            start_by_map=None if ranked is None else MapRanking.from_json(d),
            start_by_map_error=d.get("start_by_map_error"),
        )  # fmt: skip
