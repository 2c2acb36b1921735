"""One walk's row of ``evaluate --walks`` (``LooResult.per_walk``): a record, not a dict (issue
#65). What its run said (the figures of its summary the table keeps, :data:`PER_WALK_KEYS`,
read as a :class:`Summary`), how far its points lie from its own truth, whether it started
where its first fix says, why it is held, and what the building's other walks did with it (the
walks its start was decided with or handed over from, the joint estimate, its phone's offset).
:meth:`ScoredWalk.to_json` is the row as ``results.json`` holds it."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

from workstation.fingerprints.localize import Fingerprints
from workstation.pipeline.start import HandedStart
from workstation.pipeline.summary import Summary
from workstation.walks.correction import UNRECONCILED, WalkCorrection

#: the figures of a walk's run summary its row keeps (summary.json's keys)
PER_WALK_KEYS = (
    "landmark_node_accuracy",
    "landmark_fix_match_rate",
    "landmark_fix_match_rate_strict",
    "floor_accuracy",
    "fix_error_mean_m",
    "reference_points",
    "reference_point_error_mean_m",
    "start_time_s",
    "scans",
    "scans_not_points",
    "chain_by_map",
    "open_by_map",
)

#: a split's or leave-one-out's maps: walk → kind of map (ours, the tap oracle …) → its map
KindMaps = dict[str, dict[str, Fingerprints]]


@dataclass(frozen=True)
class ScoredWalk:
    """A walk's row of the per-walk table (module docstring)."""

    figures: Mapping[str, Any] = field(default_factory=dict)  # PER_WALK_KEYS, as summary.json
    placed_m: float | None = None  # mean distance of its points in the map from its truth
    placed_every_row_m: float | None = None  # … of every row, as it would have been placed
    start: str = ""  # the start landmark it ran from
    start_right: bool = False  # the landmark of its first fix
    start_off_m: float | None = None  # how far from that (None: another floor)
    start_same_place: bool = False  # within ALTERNATIVE_START_M of it
    start_time_how: str = "given"
    reasons: tuple[str, ...] = ()  # why its run is held (quarantine reasons)
    start_shared_with: str | None = None  # the walk its start was decided with
    start_after: HandedStart | None = None  # searched where the walk before ended
    joint: WalkCorrection | None = None  # what the joint estimate did to it
    device_offset_db: float | None = None  # its phone's RSS offset against the others

    @cached_property
    def summary(self) -> Summary:
        return Summary.from_json(self.figures)

    @property
    def quarantine(self) -> tuple[str, ...]:
        """Why its points stay out of our maps: its run's reasons, and ``unreconciled`` when the
        joint estimate left it out."""
        left = self.joint is not None and self.joint.left_out
        return (*self.reasons, UNRECONCILED) if left else self.reasons

    @property
    def in_map(self) -> bool:
        """Not held, and with reference points: its points are in our map."""
        return not self.quarantine and bool(self.figures.get("reference_points"))

    def to_json(self) -> dict[str, Any]:
        out = {k: self.figures.get(k) for k in PER_WALK_KEYS} | {
            "placed_m": self.placed_m, "placed_every_row_m": self.placed_every_row_m,
            "start": self.start, "start_right": self.start_right,
            "start_off_m": self.start_off_m, "start_same_place": self.start_same_place,
            "start_time_how": self.start_time_how, "quarantine": list(self.quarantine),
        }  # fmt: skip
        if self.start_shared_with is not None:
            out["start_shared_with"] = self.start_shared_with
        if self.start_after is not None:
            out["start_after"] = self.start_after.to_json()
        if self.joint is not None:
            out["joint"] = self.joint.to_dict()
        out["device_offset_db"] = self.device_offset_db
        return out
