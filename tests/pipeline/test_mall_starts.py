"""Never a wrong walk in the map, on real walks in CI: ten walks of the Microsoft mall floor
(tests/data/msilc, MIT) with the start inferred on the graph of the floor's 106 walks. A walk
whose inferred start is not the landmark of its first fix must be quarantined. With the
turn-exit term on (``pdr.turn_exits``, off by default) two of them were not: their wrong starts
(40 and 124 m off) won by 3.07 and 3.69, past the ambiguity margin."""

from pathlib import Path

import pytest

from tests.conftest import REPO
from workstation.graph import LandmarkGraph
from workstation.params import Params
from workstation.pipeline import Pipeline
from workstation.pipeline.start import resolve_start
from workstation.session import load_session

DATA = REPO / "tests" / "data" / "msilc"
ESCAPED = ("5dd9e7c4c5b77e0006b17335", "5dda0225c5b77e0006b17412")


@pytest.fixture(scope="module")
def floor():
    g = LandmarkGraph.load(DATA / "site1_f1_graph.yaml")
    walks = []
    for f in sorted(DATA.glob("*.txt.gz")):
        s = load_session(f)
        s = s.in_frame(g.frame)
        walks.append((Path(f.name).stem.split(".")[0], s, resolve_start("first-fix", s, g)))
    assert len(walks) == 10
    return g, walks


def _escaped(g, walks, **params) -> list[str]:
    """Walks in the map (not quarantined) whose inferred start is not their first fix's."""
    p = Params().updated(**{"pdr.start_node": None, **params})
    out = []
    for name, s, truth in walks:
        summary = Pipeline(s, g, p).run().summary(s, g)
        if not summary["quarantined"] and summary["start_node"] != truth:
            out.append(name)
    return out


def test_no_walk_with_a_wrong_inferred_start_escapes_the_quarantine(floor):
    g, walks = floor
    assert _escaped(g, walks) == []


def test_the_check_catches_the_walks_the_turn_exit_term_let_through(floor):
    """Measured when the term was on (session 13); the two escape with today's defaults too."""
    g, walks = floor
    assert sorted(_escaped(g, walks, **{"pdr.turn_exits": True})) == sorted(ESCAPED)
