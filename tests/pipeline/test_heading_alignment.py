"""The gyro re-aligned at a match along several edges (tracker.Tracker.advance): the walked
displacement is turned onto the true one only when it is long enough for its direction to be
known better than the heading term's own σ (confidence.direction_known_m)."""

import math
from dataclasses import replace

import numpy as np
import pytest

from tests.pipeline.test_association import walk
from workstation.graph import LandmarkGraph
from workstation.params import Params
from workstation.pipeline.confidence import direction_known_m
from workstation.pipeline.reach import Reach
from workstation.pipeline.tracking.candidates import Candidate
from workstation.pipeline.tracking.tracker import Tracker


def test_the_direction_is_known_from_the_tolerance_over_half_the_heading_threshold():
    p = Params().pdr
    eps = math.radians(p.heading_threshold_deg)
    d = direction_known_m(eps, p.confidence_threshold)
    assert d == pytest.approx(2.0 / math.tan(math.radians(15.0)))  # 7.46 m with the defaults
    assert direction_known_m(eps, 2 * p.confidence_threshold) == pytest.approx(d / 2)
    assert direction_known_m(eps / 2, p.confidence_threshold) > d


def _offset_after(scale: float, gyro_error_deg: float) -> float:
    """A → B → C: east, then a right-angle turn north, each leg ``scale`` × 3 m; B has no rule,
    so C is matched along a two-edge route. The gyro is ``gyro_error_deg`` off. The chain's
    gyro offset after the match at C."""
    g = LandmarkGraph.from_dict(
        {
            "nodes": [
                {"id": "A", "x": 0, "y": 0, "floor": 0, "rules": ["gyro"]},
                {"id": "B", "x": 3 * scale, "y": 0, "floor": 0, "rules": []},
                {"id": "C", "x": 3 * scale, "y": 3 * scale, "floor": 0, "rules": ["gyro"]},
                {"id": "D", "x": 3 * scale, "y": 6 * scale, "floor": 0, "rules": ["gyro"]},
            ],
            "edges": [{"from": a, "to": b} for a, b in ("AB", "BC", "CD")],
        }
    )
    steps, heading, det = walk(
        [(0.0, 3.0 * scale), (np.pi / 2, 3.0 * scale), (np.pi / 2, 3.0 * scale)],
        np.random.default_rng(0),
        sway=0.0,
    )
    p = Params().updated(**{"pdr.snap_heading": False}).pdr  # the gyro's error left whole
    reach = Reach(g, p.max_hops)
    trk = Tracker(steps, heading, det, reach, None, p, 0.0)
    st = replace(trk.start("A"), offset=math.radians(gyro_error_deg))
    k = 1  # the detections: the turn at B (no rule: nothing to match), then C
    route = next(r for r in reach.routes_from("A") if r.node == "C")
    assert route.edges == 2
    w = trk.walk_to_detection(st, k)
    return trk.advance(st, k, Candidate("C", route, 1.0, 0.0), w).offset


def test_a_long_displacement_turns_the_gyro_back_a_short_one_leaves_it():
    """Legs of 3 × 3 m: the displacement from A to C (12.7 m) is longer than
    direction_known_m, and the gyro's error is taken out — what is left (a part of a step where
    the detection falls) is the same whatever the error was; legs of 3 × 1 m (4.2 m): too short
    to say more than the heading, and the offset is left as it was."""
    errors = (-12.0, 10.0)
    long_ = [math.degrees(_offset_after(3.0, e)) for e in errors]
    assert long_[0] == pytest.approx(long_[1], abs=0.1) and abs(long_[0]) < 3.0
    for e in errors:
        assert math.degrees(_offset_after(1.0, e)) == pytest.approx(e)
