"""The landmark rules, in one table (issue #31): what each one is, the parameter section that
tunes its detector (:mod:`.pipeline.landmarks` holds the detectors, one per rule), and whether
it marks a floor change. The graph's valid rules, the detections' kinds, the floor-change
logic of the association, the simulator and the survey plan, and the colours
(:mod:`.viz.colours`, keyed by these names) all read it. Adding a rule is one entry here and
its detector — ``detect_<params>`` in :mod:`.pipeline.landmarks`, whose first argument names
what it reads (``steps``, ``heading`` or ``pressure``) and whose second is the section's
parameters (None without one): the graph's files, the association, the panel's rule menu and
both legends take it from there, drawn in the colour of rules without one of their own until
:mod:`.viz.colours` gives it one (``tests/test_toy_rule.py`` adds a rule so). No other module
spells a rule's name: they use the names below (``tests/test_rules.py`` greps for it)."""

from __future__ import annotations

from dataclasses import dataclass

#: the rules' names, as the graph YAML writes them and the detections' kinds
STOP, TURN, FLOOR_ENTRY, FLOOR_EXIT = "acc", "gyro", "baro_entry", "baro_exit"
#: the parameter section tuning the two barometer rules' detector (one detector finds both)
BARO = "baro"


@dataclass(frozen=True)
class Rule:
    name: str  # as written in the graph YAML, and the kind of its detections
    what: str  # what the phone shows where the rule fires (the paper's §III-A)
    params: str  # the parameter section (params/model.py) tuning its detector, detect_<params>
    floor_change: bool  # the start or end of stairs or a lift

    @property
    def is_stop(self) -> bool:
        return self.name == STOP

    @property
    def is_turn(self) -> bool:
        return self.name == TURN

    @property
    def enters_floor_change(self) -> bool:
        """The pressure leaves a level: stairs or a lift begin."""
        return self.name == FLOOR_ENTRY

    @property
    def exits_floor_change(self) -> bool:
        """The pressure levels out: stairs or a lift end."""
        return self.name == FLOOR_EXIT


TABLE: tuple[Rule, ...] = (
    Rule(STOP, "a stop: walking, still for 1–8 s, walking again (eq. 2; a door)", STOP, False),
    Rule(TURN, "a turn: the vertical rotation rate beyond ε_gyro (eq. 3)", TURN, False),
    Rule(FLOOR_ENTRY, "a floor change begins: the pressure leaves a level (eq. 4–6)", BARO, True),
    Rule(FLOOR_EXIT, "a floor change ends: the pressure levels out (eq. 4–6)", BARO, True),
)
BY_NAME: dict[str, Rule] = {r.name: r for r in TABLE}
NAMES: tuple[str, ...] = tuple(r.name for r in TABLE)
FLOOR_CHANGE: frozenset[str] = frozenset(r.name for r in TABLE if r.floor_change)
