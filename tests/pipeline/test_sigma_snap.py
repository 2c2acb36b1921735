"""σ after a match that made the track jump (pipeline/sigma.py, ``snap_spread``): the walker
turns after 10 m of dead reckoning at a corner the graph puts 7 m farther on; the match snaps the
track to it. Within what dead reckoning drifts over 10 m (``SNAP_GATES`` × σ's drift) the next
segment's σ is as before; beyond it, σ there is at least as wide as the jump (the anchor may
be wrong), over several seeds of the walker's sway."""

import numpy as np
import pytest

from tests.pipeline.test_association import walk
from workstation.graph import LandmarkGraph
from workstation.params import Params
from workstation.pipeline.sigma import (
    BASE_M,
    DRIFT,
    SCALE,
    SNAP_GATES,
    placement_sigma,
    snap_spread,
)
from workstation.pipeline.tracking.run import track


def _corner(at: float) -> LandmarkGraph:
    """A corridor east from A, a turn landmark B ``at`` m on, north 40 m to C (the walk ends
    10 m on, its last segment open)."""
    return LandmarkGraph.from_dict(
        {
            "nodes": [
                {"id": "A", "x": 0, "y": 0, "floor": 0, "rules": ["gyro"]},
                {"id": "B", "x": at, "y": 0, "floor": 0, "rules": ["gyro"]},
                {"id": "C", "x": at, "y": 40, "floor": 0},
            ],
            "edges": [{"from": "A", "to": "B"}, {"from": "B", "to": "C"}],
        }
    )


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_sigma_after_a_match_is_as_wide_as_a_jump_dead_reckoning_cannot_make(seed):
    rng = np.random.default_rng(seed)
    steps, hd, det = walk([(0.0, 10.0), (np.pi / 2, 10.0)], rng)
    p = Params().pdr.__class__(start_node="A")
    gate = np.hypot(BASE_M, DRIFT * 10.0)
    t = np.array([det.t[0] + 3.0])  # a scan a few steps after the turn
    near = track(steps, hd, det, _corner(10.5), None, p, start_time=0.0)
    far = track(steps, hd, det, _corner(17.0), None, p, start_time=0.0)
    assert list(near.detections.node) == ["B"] and list(far.detections.node) == ["B"]
    assert snap_spread(near, SNAP_GATES)[1] == 0.0  # within the gate: nothing added
    jump = snap_spread(far, SNAP_GATES)[1]
    assert 7.0 - 1.5 <= jump <= 7.0 + 2.5 and jump > SNAP_GATES * gate  # (the offset, a step)
    s_near = placement_sigma(near, t, np.array([1]), np.zeros(1, bool))[0]
    s_far = placement_sigma(far, t, np.array([1]), np.zeros(1, bool))[0]
    assert s_near < 1.5 and s_far >= SCALE * jump
