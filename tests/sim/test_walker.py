"""The simulated walker (sim.walker.walk): it passes every landmark of its route, in order, where
the landmark is, and its steps add up to the route's length."""

import numpy as np
import pytest

from workstation.sim.building import office3f
from workstation.sim.styles import STYLES, realistic
from workstation.sim.walker import walk


@pytest.mark.parametrize("style", ["normal", "varied"])
def test_the_walker_passes_its_route_where_the_landmarks_are(style):
    b = office3f()
    route = b.routes["survey"]
    g = b.graph
    for seed in (1, 2, 3):
        m = walk(b, route, realistic(STYLES[style]), np.random.default_rng(seed))
        t = np.array([tt for tt, _ in m.landmark_passes])
        assert [n for _, n in m.landmark_passes] == list(route)
        assert np.all(np.diff(t) >= 0)
        at = m.at(t)
        for k, (_, n) in enumerate(m.landmark_passes):
            node = g.node(n)
            assert np.hypot(at["x"][k] - node.x, at["y"][k] - node.y) < 0.5
            assert at["floor"][k] == node.floor
        legs = [(g.node(u), g.node(v)) for u, v in zip(route[:-1], route[1:])]
        level = sum(np.hypot(v.x - u.x, v.y - u.y) for u, v in legs if u.floor == v.floor)
        walked = np.sum(np.hypot(np.diff(m.x), np.diff(m.y))[np.diff(m.alt) == 0])
        assert walked == pytest.approx(level, rel=0.05)
