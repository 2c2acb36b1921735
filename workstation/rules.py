"""The landmark rules, in one table (issue #31): what each one is, the parameter section that
tunes its detector (:mod:`.pipeline.landmarks` holds the detectors, one per rule), and whether
it marks a floor change. The graph's valid rules, the detections' kinds, the floor-change
logic of the association, the simulator and the survey plan, and the colours
(:mod:`.viz.colours`, keyed by these names) all read it. Adding a rule is one entry here, its
detector, and its colour."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Rule:
    name: str  # as written in the graph YAML, and the kind of its detections
    what: str  # what the phone shows where the rule fires (the paper's §III-A)
    params: str  # the parameter section (params.py) that tunes its detector
    floor_change: bool  # the start or end of stairs or a lift


TABLE: tuple[Rule, ...] = (
    Rule("acc", "a stop: walking, still for 1–8 s, walking again (eq. 2; a door)", "acc", False),
    Rule("gyro", "a turn: the vertical rotation rate beyond ε_gyro (eq. 3)", "gyro", False),
    Rule(
        "baro_entry", "a floor change begins: the pressure leaves a level (eq. 4–6)", "baro", True
    ),  # fmt: skip
    Rule("baro_exit", "a floor change ends: the pressure levels out (eq. 4–6)", "baro", True),
)
BY_NAME: dict[str, Rule] = {r.name: r for r in TABLE}
NAMES: tuple[str, ...] = tuple(r.name for r in TABLE)
FLOOR_CHANGE: frozenset[str] = frozenset(r.name for r in TABLE if r.floor_change)
