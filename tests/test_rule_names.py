"""Rule behaviour is read from the rule table, never from a rule's name spelled out (issue #52):
a module testing ``kind == "gyro"`` silently stops working for a renamed or added rule."""

import ast
from pathlib import Path

from workstation.rules import (
    BARO,
    BY_NAME,
    FLOOR_CHANGE,
    FLOOR_ENTRY,
    FLOOR_EXIT,
    NAMES,
    STOP,
    TURN,
)

PKG = Path(__file__).resolve().parents[1] / "workstation"
SPELLED = set(NAMES) | {BARO}


def _heading_sources(node: ast.AST) -> bool:
    """The one other vocabulary that shares a word with the rules: where the heading comes from
    (``params.schema.HeadingSource``, its words ``GYRO_HEADING``…), defined once."""
    return isinstance(node, ast.Assign) and any(
        isinstance(e, ast.Name) and e.id in ("GYRO_HEADING", "HeadingSource")
        for t in node.targets
        for e in (t.elts if isinstance(t, ast.Tuple) else [t])
    )


def spelled_rule_names(root: Path = PKG) -> list[str]:
    found = []
    for path in sorted(root.rglob("*.py")):
        if path.name == "rules.py" and path.parent == root:
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        allowed = {id(c) for n in ast.walk(tree) if _heading_sources(n) for c in ast.walk(n)}
        for node in ast.walk(tree):
            if isinstance(node, ast.Constant) and node.value in SPELLED and id(node) not in allowed:
                found.append(f"{path.relative_to(root.parent)}:{node.lineno} {node.value!r}")
    return found


def test_no_module_spells_a_rule_name():
    assert not spelled_rule_names(), "spell the rule from workstation.rules: " + "; ".join(
        spelled_rule_names()[:10]
    )


def test_the_check_finds_a_spelled_name(tmp_path):
    pkg = tmp_path / "workstation"
    pkg.mkdir()
    (pkg / "rules.py").write_text('TURN = "gyro"\n')  # the table itself may
    (pkg / "a.py").write_text('def f(kind):\n    return kind == "gyro"\n')
    (pkg / "b.py").write_text('GYRO_HEADING, COMPASS_HEADING = "gyro", "compass"\n')
    (pkg / "c.py").write_text('"""A docstring naming gyro and baro_exit is prose."""\n')
    assert spelled_rule_names(pkg) == ["workstation/a.py:2 'gyro'"]


def test_the_table_says_what_each_rule_is():
    assert BY_NAME[TURN].is_turn and not BY_NAME[TURN].is_stop and not BY_NAME[TURN].floor_change
    assert BY_NAME[STOP].is_stop and not BY_NAME[STOP].is_turn
    assert BY_NAME[FLOOR_ENTRY].enters_floor_change and not BY_NAME[FLOOR_ENTRY].exits_floor_change
    assert BY_NAME[FLOOR_EXIT].exits_floor_change and not BY_NAME[FLOOR_EXIT].enters_floor_change
    assert FLOOR_CHANGE == {FLOOR_ENTRY, FLOOR_EXIT}
    assert {BY_NAME[n].params for n in FLOOR_CHANGE} == {BARO}
