"""The tracker keeps the walker on the simulated office when the graph is drawn imprecisely and
when the gait varies, on the realistic model (issue #10's robustness bars, on a few seeds; lost =
mean error > 5 m)."""

import numpy as np
import pytest

from workstation.params import Params
from workstation.pipeline import Pipeline
from workstation.sim import simulate
from workstation.sim.building import office2f

LOST_M = 5.0


def _displaced(graph, sd, rng):
    for n in graph.nodes:
        x, y = n.x + rng.normal(0, sd), n.y + rng.normal(0, sd)
        graph = graph.with_node(n.__class__(n.id, x, y, n.floor, n.rules, n.name))
    return graph


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_nodes_displaced_by_1_5_m(seed):
    sim = simulate("office2f", "normal", seed)
    g = _displaced(office2f().graph, 1.5, np.random.default_rng(100 + seed))
    p = Params().updated(**{"pdr.start_node": "W0"})
    m = Pipeline(sim.session, g, p).run().summary(sim.session, g)
    assert m["trajectory_error_mean_m"] < LOST_M


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_varied_walk_not_lost(seed):
    sim = simulate("office2f", "varied", seed)
    g = office2f().graph
    m = (
        Pipeline(sim.session, g, Params().updated(**{"pdr.start_node": "W0"}))
        .run()
        .summary(sim.session, g)
    )
    assert m["trajectory_error_mean_m"] < LOST_M
