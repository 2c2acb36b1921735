"""Where the walk starts, ends and which way it went (issue #50 item 3), held against the
simulator's dense ground truth over several seeds: the arrows point the way the walker walked."""

from dataclasses import replace

import numpy as np
import pytest

from workstation.pipeline import Pipeline
from workstation.sim import simulate
from workstation.viz.walk_marks import ARROW_EVERY_M, walk_marks


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_arrows_point_the_way_the_walker_went(seed):
    sim = simulate("office2f", "normal", seed)
    tr = Pipeline(sim.session, sim.graph).run().track
    marks = walk_marks(tr, corrected=True)
    assert marks is not None
    gt = sim.session.ground_truth
    walking = tr.steps.segment >= 0
    t = tr.steps.t[walking]
    assert marks.start_label == f"start {tr.start.node} · {t[0]:.1f} s"
    assert marks.end_label.endswith(f" · {t[-1]:.1f} s")
    a = marks.arrows
    walked = np.hypot(np.diff(tr.steps.x_bc[walking]), np.diff(tr.steps.y_bc[walking])).sum()
    assert 0.7 * walked / ARROW_EVERY_M <= len(a) <= walked / ARROW_EVERY_M + 2
    # at each arrow, the walker's true direction (the ground truth around the nearest step)
    i = np.argmin(np.hypot(tr.steps.x_bc[walking][:, None] - a[:, 0], tr.steps.y_bc[walking][:, None] - a[:, 1]),
                  axis=0)  # fmt: skip
    gx0, gy0, _ = gt.at(t[i] - 1.0)
    gx1, gy1, _ = gt.at(t[i] + 1.0)
    d = np.column_stack([gx1 - gx0, gy1 - gy0])
    cos = (d * a[:, 3:5]).sum(axis=1) / np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-9)
    assert np.mean(cos > 0.7) >= 0.85, np.round(cos, 2)  # along the way walked, not against it


def test_a_walk_that_never_set_off_has_no_marks():
    sim = simulate("office2f", "normal", 1)
    tr = Pipeline(sim.session, sim.graph).run().track
    still = replace(tr, steps=replace(tr.steps, segment=np.full(tr.steps.t.size, -1)))
    assert walk_marks(still) is None
