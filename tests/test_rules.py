"""One table of landmark rules (issue #31): every place that knows the rules reads
workstation/rules.py — the graph, the detectors, the association's floor changes, the
parameters, the colours, the panel."""

import numpy as np

from workstation import rules
from workstation.graph import BARO_RULES, RULES, LandmarkGraph
from workstation.params import Params
from workstation.pipeline.heading import estimate_heading
from workstation.pipeline.landmarks import KINDS, detect_landmarks
from workstation.pipeline.steps import detect_steps
from workstation.sim import simulate
from workstation.viz import colours


def test_every_rule_is_known_everywhere_from_one_table():
    assert RULES == KINDS == rules.NAMES
    assert BARO_RULES == rules.FLOOR_CHANGE == {"baro_entry", "baro_exit"}
    p = Params()
    for r in rules.TABLE:
        assert getattr(p, r.params) is not None, r.name  # its detector's parameter section
        assert r.name in colours.KINDS, r.name  # its colour
        g = LandmarkGraph.from_dict({"nodes": [{"id": "A", "x": 0, "y": 0, "floor": 0,
                                               "rules": [r.name]}],
                                     "edges": []})  # fmt: skip
        assert g.node("A").rules == {r.name}


def test_the_detectors_report_only_rules_of_the_table():
    s = simulate("office2f", "normal", 1).session
    p = Params()
    d = detect_landmarks(detect_steps(s.accelerometer, p.steps), estimate_heading(s, p.heading),
                         s.pressure, p)  # fmt: skip
    assert set(np.unique(d.kind)) == set(rules.NAMES)  # the office walk shows all four
