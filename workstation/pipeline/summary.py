"""What a run says of a walk (``summary.json``), typed: :class:`Summary`, with the start
inference (:class:`StartInference`), the end's closure (:class:`EndClosure`) and the quarantine
(:class:`Quarantine`, reasons in :mod:`.verdict`) as records of their own. One writer
(:meth:`Summary.to_json`) and one reader (:meth:`Summary.from_json`): every command, the
campaign, the editor, the panel and ``evaluate`` read a walk's verdict through them.

summary.json, schema 1 (a file without ``schema`` is the same keys, written before it was
versioned). Keys, in the order written:

- the walk: ``steps``, ``steps_before_start``, ``start_node``, ``start_time_s``,
  ``start_time_how``, ``landmarks_detected``, ``landmarks_detected_by_kind`` (rule → count),
  ``landmarks_matched``, ``step_length_m`` (null: no step), ``segments``;
- its end (:class:`EndClosure`): ``end_node`` (null: open), ``end_how``, ``end_margin``,
  ``end_sigma_m``;
- what the building's map did: ``chain_by_map`` (:class:`~.tracking.state.Reranked` as a
  mapping; null without a map), ``open_by_map`` (:class:`~.tracking.state.OpenFit`; null when
  not tried);
- the radio map: ``segments_accepted``, ``scans``, ``reference_points``,
  ``reference_points_at_landmarks``, ``reference_points_gap_fill``, ``scans_not_points``
  (reason → count), ``input_warnings``;
- an inferred start only (:class:`StartInference`): ``start_alternative``, ``start_margin``
  (null: no alternative), ``start_ambiguous``, ``start_candidates`` ([landmark, log-likelihood
  below the best]);
- a walk from a given start that matched nothing: ``off_graph_m``;
- a hole in the inertial streams longer than :data:`.verdict.MAX_HOLE_S`: ``sensor_hole_s``
  (its length) and ``sensor_hole_at_s`` (where it begins, from the recording's first sample);
- a second recording on the walk's clock (:mod:`workstation.session.clocks`): ``clock_jump_at_s``
  (where it begins, counted alike) and ``clock_jump`` (the evidence);
- the compass turning where the gyroscope did not (:mod:`.continuity`): ``facing_jump_at_s``
  (counted alike) and ``facing_jump_deg``;
- the verdict: ``quarantined``, ``quarantine`` ([{reason, detail, what_to_do}]);
- where the walk's start was searched: ``start_within`` ([x, y, floor, r], ``run
  --start-within``), ``start_after`` (the hand-over from the walk before, in a campaign);
- against ground truth, when the session has it: the figures of :func:`.metrics.summarize`
  (``trajectory_error_mean_m``, ``fix_error_mean_m``, ``landmark_node_accuracy``, …), each a
  number, a count or null, and ``ground_truth`` ("dense" or "N fixes");
- ``schema``: 1.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Literal, cast, get_args

from workstation.pipeline.start import HandedStart, StartTimeHow
from workstation.pipeline.tracking.state import EndHow, OpenFit, Reranked

SCHEMA = 1

#: a figure against ground truth: a number, a count, "dense" / "N fixes", or null
Figure = float | int | str | None


#: why a walk's points stay out of merged maps: :mod:`.verdict`'s rules, in the order a walk's
#: reasons are said (``verdict.RULES``), each with what to do (``verdict.REMEDY``)
Reason = Literal["start_ambiguous", "no_walking", "nothing_matched", "off_graph", "end_far",
                 "sensor_hole", "two_clocks", "facing_jump", "no_reference_point"]  # fmt: skip


@dataclass(frozen=True)
class Quarantine:
    """One reason a walk's points stay out of merged maps (:mod:`.verdict`)."""

    reason: Reason
    detail: str  # what was seen, in words
    what_to_do: str = ""

    def to_json(self) -> dict[str, str]:
        return {"reason": self.reason, "detail": self.detail, "what_to_do": self.what_to_do}


@dataclass(frozen=True)
class StartInference:
    """An inferred start: the best start elsewhere, how much less likely it is (log-likelihood;
    None: no other place survived), whether that is too close to call, and every distinct
    start that survived (landmark, log-likelihood below the best)."""

    alternative: str | None
    margin: float | None
    ambiguous: bool
    candidates: tuple[tuple[str, float], ...] = ()


@dataclass(frozen=True)
class EndClosure:
    """Where the walk's end closed (:mod:`.tracking.walk_end`): the landmark (None: the end
    stays open), how it was taken, how much likelier than any landmark elsewhere, and σ (m)."""

    node: str | None = None
    how: EndHow = "off"
    margin: float | None = None
    sigma_m: float | None = None


@dataclass(frozen=True)
class Summary:
    steps: int
    steps_before_start: int
    start_node: str
    start_time_s: float
    start_time_how: StartTimeHow
    landmarks_detected: int
    landmarks_detected_by_kind: Mapping[str, int]
    landmarks_matched: int
    step_length_m: float | None
    segments: int
    end: EndClosure
    chain_by_map: Reranked | None
    open_by_map: OpenFit | None
    segments_accepted: int
    scans: int
    reference_points: int
    reference_points_at_landmarks: int
    reference_points_gap_fill: int
    scans_not_points: Mapping[str, int]
    input_warnings: tuple[str, ...] = ()
    start: StartInference | None = None  # None: the start was given
    off_graph_m: float | None = None
    sensor_hole: tuple[float, float] | None = None  # (at, length) s: verdict.sensor_hole
    clock_jump: tuple[float, str] | None = None  # (at s, what): session/clocks.py
    facing_jump: tuple[float, float] | None = None  # (at s, degrees): continuity.py
    quarantine: tuple[Quarantine, ...] = ()
    start_within: tuple[float | None, ...] | None = None  # x, y, floor (None: any), r
    start_after: HandedStart | None = None  # searched where the walk before ended
    start_inferred_at_load: bool = False  # the editor keeps the start it inferred at load
    truth: Mapping[str, Figure] = field(default_factory=dict)

    @property
    def quarantined(self) -> bool:
        return bool(self.quarantine)

    @property
    def reasons(self) -> tuple[Reason, ...]:
        """The quarantine's reasons, in order."""
        return tuple(q.reason for q in self.quarantine)

    @property
    def inferred(self) -> bool:
        """The start was inferred (not given)."""
        return self.start is not None

    @property
    def start_ambiguous(self) -> bool:
        return self.start is not None and self.start.ambiguous

    def figure(self, name: str) -> Figure:
        """A figure against ground truth (None: not measured)."""
        return self.truth.get(name)

    # ---- summary.json ---------------------------------------------------------------------
    def to_json(self) -> dict[str, Any]:
        """summary.json's mapping (module doc)."""
        e = self.end
        out: dict[str, Any] = {
            "steps": self.steps,
            "steps_before_start": self.steps_before_start,
            "start_node": self.start_node,
            "start_time_s": self.start_time_s,
            "start_time_how": self.start_time_how,
            "landmarks_detected": self.landmarks_detected,
            "landmarks_detected_by_kind": dict(self.landmarks_detected_by_kind),
            "landmarks_matched": self.landmarks_matched,
            "step_length_m": self.step_length_m,
            "segments": self.segments,
            "end_node": e.node,
            "end_how": e.how,
            "end_margin": e.margin,
            "end_sigma_m": e.sigma_m,
            "chain_by_map": (
                dataclasses.asdict(self.chain_by_map) if self.chain_by_map is not None else None
            ),
            "open_by_map": self.open_by_map._asdict() if self.open_by_map is not None else None,
            "segments_accepted": self.segments_accepted,
            "scans": self.scans,
            "reference_points": self.reference_points,
            "reference_points_at_landmarks": self.reference_points_at_landmarks,
            "reference_points_gap_fill": self.reference_points_gap_fill,
            "scans_not_points": dict(self.scans_not_points),
            "input_warnings": list(self.input_warnings),
        }
        if self.start is not None:
            out["start_alternative"] = self.start.alternative
            out["start_margin"] = self.start.margin
            out["start_ambiguous"] = self.start.ambiguous
            out["start_candidates"] = [[n, m] for n, m in self.start.candidates]
        if self.off_graph_m is not None:
            out["off_graph_m"] = self.off_graph_m
        if self.sensor_hole is not None:
            out["sensor_hole_at_s"], out["sensor_hole_s"] = self.sensor_hole
        if self.clock_jump is not None:
            out["clock_jump_at_s"], out["clock_jump"] = self.clock_jump
        if self.facing_jump is not None:
            out["facing_jump_at_s"], out["facing_jump_deg"] = self.facing_jump
        out["quarantined"] = self.quarantined
        out["quarantine"] = [q.to_json() for q in self.quarantine]
        if self.start_within is not None:
            out["start_within"] = list(self.start_within)
        if self.start_after is not None:
            out["start_after"] = self.start_after.to_json()
        if self.start_inferred_at_load:
            out["start_inferred_at_load"] = True
        out.update(self.truth)
        out["schema"] = SCHEMA
        return out

    @classmethod
    def from_json(cls, d: Mapping[str, Any]) -> Summary:
        """A summary.json mapping (schema 1, or the same keys unversioned) back to a Summary."""
        schema = d.get("schema", SCHEMA)
        if schema != SCHEMA:
            raise ValueError(f"summary.json: schema {schema!r}, this version reads {SCHEMA}")
        cbm, obm = d.get("chain_by_map"), d.get("open_by_map")
        within = d.get("start_within")
        return cls(
            steps=_int(d, "steps"),
            steps_before_start=_int(d, "steps_before_start"),
            start_node=str(d.get("start_node") or ""),
            start_time_s=float(d.get("start_time_s") or 0.0),
            start_time_how=_one_of(d.get("start_time_how"), StartTimeHow, "given"),
            landmarks_detected=_int(d, "landmarks_detected"),
            landmarks_detected_by_kind=dict(d.get("landmarks_detected_by_kind") or {}),
            landmarks_matched=_int(d, "landmarks_matched"),
            step_length_m=d.get("step_length_m"),
            segments=_int(d, "segments"),
            end=EndClosure(
                d.get("end_node"), _one_of(d.get("end_how"), EndHow, "off"), d.get("end_margin"),
                d.get("end_sigma_m"),
            ),  # fmt: skip
            chain_by_map=Reranked(**cbm) if cbm else None,
            open_by_map=OpenFit(**obm) if obm else None,
            segments_accepted=_int(d, "segments_accepted"),
            scans=_int(d, "scans"),
            reference_points=_int(d, "reference_points"),
            reference_points_at_landmarks=_int(d, "reference_points_at_landmarks"),
            reference_points_gap_fill=_int(d, "reference_points_gap_fill"),
            scans_not_points=dict(d.get("scans_not_points") or {}),
            input_warnings=tuple(d.get("input_warnings") or ()),
            start=_start_of(d),
            off_graph_m=d.get("off_graph_m"),
            **_events_of(d),
            quarantine=tuple(
                # (a reason as this package wrote it: summary.json is ours)
                Quarantine(cast(Reason, str(q["reason"])), str(q.get("detail", "")),
                           str(q.get("what_to_do", "")))  # fmt: skip
                for q in d.get("quarantine") or ()
            ),
            start_within=tuple(within) if within is not None else None,
            start_after=HandedStart.from_json(d["start_after"]) if d.get("start_after") else None,
            start_inferred_at_load=bool(d.get("start_inferred_at_load")),
            truth={k: v for k, v in d.items() if k not in _KEYS},
        )


def _int(d: Mapping[str, Any], key: str) -> int:
    return int(d.get(key) or 0)


def _start_of(d: Mapping[str, Any]) -> StartInference | None:
    """An inferred start: only its summary has these (a campaign keeps neither)."""
    if "start_margin" not in d and "start_ambiguous" not in d:
        return None
    return StartInference(
        d.get("start_alternative"),
        d.get("start_margin"),
        bool(d.get("start_ambiguous")),
        tuple((str(n), float(m)) for n, m in d.get("start_candidates") or ()),
    )


def _events_of(d: Mapping[str, Any]) -> dict[str, Any]:
    """The recording's faults a summary names: a sensor hole, a clock jump, a facing jump."""
    hole, clock, facing = d.get("sensor_hole_s"), d.get("clock_jump_at_s"), d.get("facing_jump_at_s")
    return {
        "sensor_hole": None if hole is None else (float(d["sensor_hole_at_s"]), float(hole)),
        "clock_jump": None if clock is None else (float(clock), str(d.get("clock_jump") or "")),
        "facing_jump": None if facing is None else (float(facing),
                                                    float(d.get("facing_jump_deg") or 0.0)),
    }  # fmt: skip


_KEYS = frozenset(
    """steps steps_before_start start_node start_time_s start_time_how landmarks_detected
    landmarks_detected_by_kind landmarks_matched step_length_m segments end_node end_how
    end_margin end_sigma_m chain_by_map open_by_map segments_accepted scans reference_points
    reference_points_at_landmarks reference_points_gap_fill scans_not_points input_warnings
    start_alternative start_margin start_ambiguous start_candidates off_graph_m quarantined
    sensor_hole_at_s sensor_hole_s clock_jump_at_s clock_jump facing_jump_at_s facing_jump_deg
    quarantine start_within start_after start_inferred_at_load schema""".split()
)


def _one_of(value: Any, vocabulary: Any, default: str) -> Any:
    """``value`` when it is a word of the ``Literal`` ``vocabulary``, else ``default`` (a
    summary written before the word existed)."""
    return cast(Any, value if value in get_args(vocabulary) else default)
