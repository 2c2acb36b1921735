"""Survey plans on the real buildings (../shared/data): the museum's predicted durations, and
the route against its matching bound on the museum graph."""

import pytest

from tests.conftest import SHARED_DATA, need
from workstation.evaluate.walks import ipin_museum
from workstation.params import Params
from workstation.pipeline import Pipeline
from workstation.pipeline.start import resolve_start
from workstation.session import load_session
from workstation.survey_plan.check import durations
from workstation.survey_plan.plan import plan_survey

pytestmark = pytest.mark.shared_data


@pytest.fixture(scope="module")
def museum():
    need(SHARED_DATA / "ipin2023-track3")
    logs, graph = ipin_museum(SHARED_DATA)
    sessions = [load_session(p).in_frame(graph.frame) for p in logs]
    results = [
        Pipeline(s, graph, Params().updated(**{"pdr.start_node": resolve_start("first-fix", s, graph)})).run()
        for s in sessions
    ]  # fmt: skip
    return graph, sessions, results


def test_predicted_duration_of_each_museum_walk_is_within_20_percent(museum):
    """Each walk's route from its fixes, priced with the pace of the other nine walks."""
    rows = durations(*museum)
    assert len(rows) == 10
    assert all(abs(r["error"]) <= 0.20 for r in rows), rows


def test_museum_route_meets_its_matching_bound(museum):
    graph = museum[0]
    plan = plan_survey(graph)
    assert plan.bound_s - 1e-6 <= plan.route_s <= 1.01 * plan.bound_s
