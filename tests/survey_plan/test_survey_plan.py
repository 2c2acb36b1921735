"""Survey plans: what they tell the walker, that the simulator walking them gives a tracked walk
and a covering map, that a re-walk plans exactly the thin edges, and the command's files."""

import json

import numpy as np
import pytest

from tests.conftest import REPO
from workstation.cli import main
from workstation.fingerprints.quality import thin_edges
from workstation.params import Params
from workstation.pipeline import Pipeline
from workstation.sim import simulate
from workstation.sim.building import BUILDINGS
from workstation.survey_plan.check import edge_cover, track_error
from workstation.survey_plan.pace import default_pace
from workstation.survey_plan.plan import level_edges, plan_survey

OFFICE = REPO / "sample_sessions" / "office2f" / "normal"


def _walked(plan) -> set:
    return {frozenset((leg.frm, leg.to)) for w in plan.walks for leg in w.legs}


@pytest.mark.parametrize("building", ["office2f", "office3f"])
def test_plan_walks_every_level_edge_in_walks_that_end_on_rule_landmarks(building):
    g = BUILDINGS[building]().graph
    p = Params()
    plan = plan_survey(g, default_pace(p), max_minutes=4)
    assert {frozenset(e) for e in level_edges(g)} <= _walked(plan)
    assert len(plan.walks) >= 2
    for a, b in zip(plan.walks[:-1], plan.walks[1:]):
        assert a.end == b.start  # the next recording starts where the last ended
    for w in plan.walks:
        assert g.node(w.start).rules and g.node(w.end).rules
        assert w.duration_s <= 4 * 60
        for v in w.visits[1:-1]:
            rules = g.node(v.node).rules
            if "acc" in rules:  # a stop the acc rule sees
                assert p.acc.still_min_s < v.stop_s < p.acc.still_max_s and v.seen
            if rules == {"gyro"}:  # a turn is seen; a straight pass says it is not
                assert v.seen == (abs(v.turn_deg) >= 45)
                assert ("not seen" in v.action) != v.seen


@pytest.mark.parametrize("building", ["office2f", "office3f"])
def test_the_simulated_walker_walking_the_plan_covers_the_edges_and_is_tracked(building):
    """3 seeds here (`benchmarks/bench_plan.py` prints 10): every edge carries accepted points
    (≥ 95 %) and the plan's walk is tracked as well as the bundled route is (mean error within
    0.25 m of it: the per-seed spread is about 0.15 m)."""
    b = BUILDINGS[building]()
    route = tuple(v.node for v in plan_survey(b.graph).walks[0].visits)
    plan_err, base_err = [], []
    for seed in (1, 2, 3):
        sim = simulate(building, "normal", seed, route=route)
        r = Pipeline(sim.session, sim.graph, Params().updated(**{"pdr.start_node": route[0]})).run()
        assert edge_cover(b.graph, r.radiomap) >= 0.95
        plan_err.append(track_error(sim.session, r))
        base = simulate(building, "normal", seed)
        start = b.routes["survey"][0]
        rb = Pipeline(base.session, base.graph, Params().updated(**{"pdr.start_node": start})).run()
        base_err.append(track_error(base.session, rb))
    assert np.mean(plan_err) <= np.mean(base_err) + 0.25


def test_rewalk_plans_exactly_the_edges_whose_points_were_removed():
    from workstation.fingerprints.localize import Fingerprints

    b = BUILDINGS["office2f"]()
    g = b.graph
    route = tuple(v.node for v in plan_survey(g).walks[0].visits)
    sim = simulate("office2f", "normal", 1, route=route)
    r = Pipeline(sim.session, g, Params().updated(**{"pdr.start_node": route[0]})).run()
    rm, tr = r.radiomap, r.track
    fp = Fingerprints.from_radiomap(rm, g.frame)
    assert thin_edges(fp, g) == ()
    # two long level edges walked once, and the segments that walked them
    pairs = [frozenset((a, c)) for a, c in zip(tr.segments.from_node, tr.segments.to_node) if c]
    once = [
        e for e in map(frozenset, level_edges(g))
        if pairs.count(e) == 1 and g.edge(*sorted(e))["length"] >= 15
    ]  # fmt: skip
    assert len(once) >= 2
    gone = once[:2]
    segs = [s for s, e in enumerate(pairs) if e in gone]
    keep = ~np.isin(rm.segment[rm.accepted], segs)
    thin = thin_edges(fp.subset(keep), g)
    assert {frozenset(e) for e in thin} == set(gone)
    plan = plan_survey(g, required=list(thin))
    assert plan.rewalk and {frozenset(e) for e in plan.required} == set(gone)
    walked = _walked(plan)
    assert set(gone) <= walked
    # the way between them and nothing else: no more than a shortest closed tour
    assert plan.route_s <= plan.bound_s + 1e-6


def test_plan_command_writes_the_checklist_the_json_and_the_geojson(tmp_path, capsys):
    out = tmp_path / "plan"
    rc = main(["plan", "--graph", str(OFFICE / "graph.yaml"), "--max-minutes", "4",
               "--out", str(out)])  # fmt: skip
    assert rc == 0
    text = capsys.readouterr().out
    assert "walk(s)" in text and "lower bound" in text
    plan = json.loads((out / "plan.json").read_text())
    md = (out / "plan.md").read_text()
    geo = json.loads((out / "plan.geojson").read_text())
    assert plan["totals"]["walks"] == len(plan["walks"]) >= 2
    assert all(w["duration_s"] <= 240 for w in plan["walks"])
    assert len(geo["features"]) == sum(len(w["legs"]) for w in plan["walks"])
    assert md.count("## Walk ") == len(plan["walks"])
    assert "stand still" in md and "- [ ]" in md
    # the simulator walks a plan's walk, from where the plan starts it
    sim_out = tmp_path / "sim"
    assert main(["simulate", "--plan", str(out / "plan.json"), "--plan-walk", "2",
                 "--out", str(sim_out)]) == 0  # fmt: skip
    from workstation.session import load_session

    meta = load_session(sim_out).metadata.extra
    assert meta["planned"] and meta["route"][0] == plan["walks"][1]["start"]


def test_plan_command_names_what_is_wrong(tmp_path, capsys):
    g = str(OFFICE / "graph.yaml")
    assert main(["plan", "--graph", g, "--start", "NOPE", "--out", str(tmp_path)]) == 2
    assert "--start NOPE: no such landmark" in capsys.readouterr().err
    bad = tmp_path / "q"
    bad.mkdir()
    (bad / "quality.json").write_text('{"floors": [{"edges_to_rewalk": ["X-Y"]}]}')
    assert main(["plan", "--graph", g, "--quality", str(bad), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "quality.json" in err and "X-Y" in err
    assert (
        main(["simulate", "--plan", str(bad / "quality.json"), "--out", str(tmp_path / "s")]) == 2
    )
    assert "not a plan.json" in capsys.readouterr().err


def test_rewalk_from_a_quality_folder_plans_its_edges(tmp_path, capsys):
    from workstation.graph import LandmarkGraph

    g = LandmarkGraph.load(OFFICE / "graph.yaml")
    a, b = sorted(level_edges(g)[3])
    q = tmp_path / "quality"
    q.mkdir()
    (q / "quality.json").write_text(json.dumps({"floors": [{"edges_to_rewalk": [f"{a}-{b}"]}]}))
    out = tmp_path / "plan"
    assert main(["plan", "--graph", str(OFFICE / "graph.yaml"), "--quality", str(q),
                 "--out", str(out)]) == 0  # fmt: skip
    plan = json.loads((out / "plan.json").read_text())
    assert plan["kind"] == "re-walk" and plan["required_edges"] == [f"{a}-{b}"]
    legs = [{leg["from"], leg["to"]} for w in plan["walks"] for leg in w["legs"]]
    assert {a, b} in legs and "1 edge to walk" in capsys.readouterr().out
