"""The pipeline on real IPIN walks with the museum graph built from the .tra files."""

import pytest

from tests.conftest import IPIN, REPO, need
from workstation.cli import resolve_start
from workstation.graph import graph_from_tra
from workstation.params import Params
from workstation.pipeline import Pipeline
from workstation.session import load_session

pytestmark = pytest.mark.shared_data


@pytest.fixture(scope="module")
def museum():
    return graph_from_tra(sorted(need(IPIN / "supplementary" / "trajectories").glob("*.tra")))


@pytest.mark.parametrize(
    "walk, min_node_accuracy, beats_raw_pdr",
    [
        ("IPIN2023_T3_TrainingTrial51_repetition02.txt", 0.55, False),
        ("IPIN2023_T3_TrainingTrial01_repetition01.txt", 0.9, True),
    ],
)
def test_real_walk(museum, walk, min_node_accuracy, beats_raw_pdr):
    s = load_session(need(IPIN / "logfiles" / walk))
    p = Params.load(REPO / "sample_sessions" / "ipin-museum.params.yaml")
    p = p.updated(**{"pdr.start_node": resolve_start("first-fix", s, museum)})
    pipe = Pipeline(s, museum, p)
    m = pipe.run().summary(pipe.session, museum)
    assert m["floor_accuracy"] >= 0.95  # Trial51 crosses three floors by the stairs
    assert m["landmark_node_accuracy"] >= min_node_accuracy
    if beats_raw_pdr:
        assert m["trajectory_error_mean_m"] < m["raw_pdr_error_mean_m"]
    assert m["trajectory_error_mean_m"] < 15.0


def test_all_museum_walks_pooled(museum):
    """The issue's bar: the right landmark at ≥ 90 % of POSI fixes, the right floor at ≥ 95 %."""
    logs = sorted(need(IPIN / "logfiles").glob("*.txt"))
    p = Params.load(REPO / "sample_sessions" / "ipin-museum.params.yaml")
    right = floor = total = 0.0
    for f in logs:
        s = load_session(f)
        pipe = Pipeline(
            s, museum, p.updated(**{"pdr.start_node": resolve_start("first-fix", s, museum)})
        )
        m = pipe.run().summary(pipe.session, museum)
        total += m["landmark_fixes"]
        right += m["landmark_node_accuracy"] * m["landmark_fixes"]
        floor += m["floor_accuracy"] * m["landmark_fixes"]
    assert total >= 130
    assert right / total >= 0.90
    assert floor / total >= 0.95
