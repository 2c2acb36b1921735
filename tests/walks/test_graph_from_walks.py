"""The graph a surveyor would draw from many walks (graph_walks.py): landmarks where walks turn,
begin, end or meet, checked against the simulated office's own graph (several walks)."""

import numpy as np

from tests.conftest import REPO
from workstation.graph import LandmarkGraph
from workstation.session import load_session
from workstation.walks.graph_from_walks import graph_from_walks, report_markdown

OFFICE = REPO / "sample_sessions" / "office2f"


def test_landmarks_where_the_walks_turn_and_rules_from_the_phones():
    walks = [load_session(OFFICE / w) for w in ("normal", "varied", "heldout")]
    truth = LandmarkGraph.load(OFFICE / "normal" / "graph.yaml")
    g, reports = graph_from_walks(walks)
    taps = sum(len(w.ground_truth) for w in walks)
    assert len(g.nodes) < 0.02 * taps  # not one landmark per ground-truth point
    xyf = g.xyf()
    # every true landmark where the walks turn has a built landmark near it, on its floor
    turned = [n for n in truth.nodes if "gyro" in n.rules]
    near = [
        np.min(np.where(xyf[:, 2] == n.floor, np.hypot(xyf[:, 0] - n.x, xyf[:, 1] - n.y), np.inf))
        for n in turned
    ]
    walked = [d for d in near if np.isfinite(d)]
    assert np.mean(np.array(walked) <= 2.0) >= 0.8, sorted(near)
    # rules come from the sensors: most built turn landmarks were seen by the gyroscope
    gyro = [r for n, r in zip(g.nodes, reports) if "gyro" in n.rules]
    assert gyro and all(2 * r.turns_seen >= r.turns > 0 for r in gyro)
    # floor changes give barometer rules; edges join landmarks walked one after the other
    assert any(n.rules & {"baro_entry", "baro_exit"} for n in g.nodes)
    assert g.undirected_pairs()
    md = report_markdown(g, reports, ["normal", "varied", "heldout"])
    assert md.count("\n| L") == len(g.nodes)


def test_the_graph_round_trips_through_yaml(tmp_path):
    walks = [load_session(OFFICE / w) for w in ("normal", "heldout")]
    g, _ = graph_from_walks(walks)
    g.save(tmp_path / "g.yaml")
    back = LandmarkGraph.load(tmp_path / "g.yaml")
    assert [n.id for n in back.nodes] == [n.id for n in g.nodes]
