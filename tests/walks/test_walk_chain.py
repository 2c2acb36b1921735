"""A walk recorded right after another begins within walking reach of where that one ended
(workstation/walks/chain.py): which walks follow which, the reach, and two real mall
walks recorded 4 s apart."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from tests.conftest import REPO
from workstation.graph import Landmark, LandmarkGraph
from workstation.params import Params
from workstation.pipeline import Pipeline
from workstation.pipeline.start import resolve_start
from workstation.session import load_session
from workstation.session.getsensordata import created_ms
from workstation.walks.chain import (
    MAX_GAP_S,
    SLACK_M,
    WALK_SPEED_MS,
    follows,
    handover,
    wall_clock,
)
from workstation.walks.shared_start import run_inferring_starts

DATA = REPO / "tests" / "data"
BEFORE = DATA / "msilc_more" / "5dd9efa79191710006b5708e.txt.gz"  # ends 4.1 s before …
AFTER = DATA / "msilc" / "5dd9efa7c5b77e0006b17367.txt.gz"  # … this one starts
GRAPH = DATA / "msilc" / "site1_f1_graph.yaml"


def test_walks_follow_each_other_in_time_only_when_nothing_else_was_recorded_between():
    clocks = [(0.0, 30.0), (35.0, 60.0), (60.5, 90.0), None, (90.0 + MAX_GAP_S + 1, 400.0)]
    assert follows(clocks) == {1: (0, 5.0), 2: (1, 0.5)}
    # listed in any order: the clock orders them
    assert follows([clocks[2], clocks[0], clocks[1]]) == {2: (1, 5.0), 0: (2, 0.5)}
    # another phone model: another surveyor
    assert follows(clocks[:3], ["a", "b", "b"]) == {2: (1, 0.5)}
    assert follows(clocks[:3], ["a", "", "a"]) == {1: (0, 5.0), 2: (1, 0.5)}
    # a walk recorded meanwhile (two surveyors at once): no walk follows another across it
    assert follows([(0.0, 30.0), (35.0, 60.0), (20.0, 50.0)]) == {}
    assert follows([(0.0, 100.0), (10.0, 30.0), (35.0, 60.0)]) == {}  # one begun before
    assert follows([(10.0, 30.0), (35.0, 60.0), (50.0, 70.0)]) == {}  # one begun meanwhile
    assert follows([(10.0, 30.0), (35.0, 60.0), (61.0, 70.0)]) == {1: (0, 5.0), 2: (1, 1.0)}
    # overlapping recordings are not one after the other
    assert follows([(0.0, 30.0), (29.0, 60.0)]) == {}


def test_the_reach_is_a_walking_pace_over_the_gap_three_sigma_and_a_landmark():
    g = LandmarkGraph(
        nodes=(Landmark("A", 0, 0, 0), Landmark("B", 9, 0, 0), Landmark("C", 12, 0, 0),
               Landmark("D", 0, 5, 1)),
        edges=(),
    )  # fmt: skip
    h = handover((0.0, 0.0, 0.0, 1.0), 4.0, g, "w0")
    assert h.radius_m == pytest.approx(WALK_SPEED_MS * 4.0 + 3.0 + SLACK_M)
    assert h.among == tuple(n for n, x in (("A", 0), ("B", 9), ("C", 12)) if x <= h.radius_m)
    assert h.among == ("A", "B")
    # floors: only the one it ended on when both recordings name the same floor
    assert handover((0.0, 0.0, 0.0, 1.0), 4.0, g, same_floor=False).among == ("A", "B", "D")
    assert h.handed().walk_before == "w0" and h.handed().landmarks_in_reach == 2


def test_a_getsensordata_header_dates_the_walk():
    assert created_ms("Wed Jun 14 10:00:58 GMT+02:00 2023") == 1686729658000.0
    assert created_ms("14/06/2023") is None and created_ms(None) is None


def _pair():
    g = LandmarkGraph.load(GRAPH)
    return g, [load_session(p).in_frame(g.frame) for p in (BEFORE, AFTER)]


def _run(g, sessions, given=frozenset({0})):
    alone = []
    for i, s in enumerate(sessions):
        start = resolve_start("first-fix", s, g) if i in given else None
        alone.append(Pipeline(s, g, Params().updated(**{"pdr.start_node": start})).run())
    return run_inferring_starts(sessions, g, Params(), alone, given, ["before", "after"])


def test_a_real_walk_takes_its_start_within_reach_of_where_the_walk_before_ended():
    """Two mall walks (MIT) one surveyor recorded 4.1 s apart: the first given its start, the
    second inferred. Alone, the second's start is ambiguous; searched within reach of where the
    first ended, it is the landmark at its first tap, beyond doubt."""
    g, (s0, s1) = _pair()
    c0, c1 = wall_clock(s0), wall_clock(s1)
    assert c0 is not None and c1 is not None and 0 < c1[0] - c0[1] < 5
    truth = g.node(resolve_start("first-fix", s1, g))
    own = Pipeline(s1, g, Params().updated(**{"pdr.start_node": None})).run()
    assert own.summary().to_json()["start_ambiguous"]
    results, _, handed = _run(g, [s0, s1])
    assert set(handed) == {1} and handed[1].before == "before"
    got = results[1].track
    assert not results[1].summary().to_json()["start_ambiguous"]
    st = g.node(got.start.node)
    assert st.floor == truth.floor and math.hypot(st.x - truth.x, st.y - truth.y) <= 5.0
    assert got.start.node in handed[1].among and len(handed[1].among) > 1


def test_no_start_is_handed_over_a_long_gap_or_from_an_uncertain_walk():
    g, (s0, s1) = _pair()
    late = replace(
        s1,
        metadata=replace(s1.metadata, start_time_ms=s1.metadata.start_time_ms + 1e3 * MAX_GAP_S),
    )
    _, _, handed = _run(g, [s0, late])
    assert handed == {}
    results, _, handed = _run(g, [s0, s1], given=frozenset())
    assert results[0].summary().to_json()["start_ambiguous"]  # the walk before is ambiguous itself
    assert handed == {}


def test_the_panel_searches_the_start_where_the_campaign_did(tmp_path):
    """``edit --start-within`` (campaign.md's command for such a walk): the editor infers the
    start among the landmarks in reach, says so, and searches there again on "Infer again"."""
    from workstation.editor import SurveyEditor
    from workstation.walks.chain import where_ended

    g, (s0, s1) = _pair()
    first = Pipeline(
        s0, g, Params().updated(**{"pdr.start_node": resolve_start("first-fix", s0, g)})
    )
    gap = wall_clock(s1)[0] - wall_clock(s0)[1]
    h = handover(where_ended(first.run().track), gap, g, "before")
    ed = SurveyEditor(s1, g, out_dir=tmp_path, start_within=(h.x, h.y, h.floor, h.radius_m))
    truth = g.node(resolve_start("first-fix", s1, g))
    st = g.node(ed.result.track.start.node)
    assert math.hypot(st.x - truth.x, st.y - truth.y) <= 5.0
    note = ed.start_note()
    assert "within reach of where the walk before ended" in note and "ambiguous" not in note
    ed.infer_start()
    assert ed.result.track.start.node in h.among
    alone = SurveyEditor(s1, g, out_dir=tmp_path)
    assert "ambiguous" in alone.start_note()


def test_run_takes_the_reach_as_the_campaign_gives_it(tmp_path):
    import json

    from workstation.cli import main
    from workstation.walks.chain import where_ended

    g, (s0, s1) = _pair()
    first = Pipeline(
        s0, g, Params().updated(**{"pdr.start_node": resolve_start("first-fix", s0, g)})
    )
    h = handover(where_ended(first.run().track), wall_clock(s1)[0] - wall_clock(s0)[1], g)
    reach = f"{h.x:g},{h.y:g},{h.floor:g},{h.radius_m:g}"
    assert main(["run", str(AFTER), "--graph", str(GRAPH), "--out", str(tmp_path),
                 "--start-within", reach]) == 0  # fmt: skip
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s["start_within"] == [float(v) for v in reach.split(",")]
    assert s["start_node"] in h.among and not s["quarantine"]
