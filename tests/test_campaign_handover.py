"""A campaign's walks recorded one after another (workstation/campaign/handover.py): an
ambiguous walk recorded right after a walk whose start the surveyor gave takes its start within
reach of where that one ended, says so in campaign.md, and a second run changes nothing."""

from __future__ import annotations

import json
import sys

from tests.conftest import REPO
from workstation.campaign import run_campaign
from workstation.graph import LandmarkGraph
from workstation.pipeline.start import resolve_start
from workstation.session import load_session

DATA = REPO / "tests" / "data"
BEFORE = DATA / "msilc_more" / "5dd9efa79191710006b5708e.txt.gz"
AFTER = DATA / "msilc" / "5dd9efa7c5b77e0006b17367.txt.gz"
GRAPH = DATA / "msilc" / "site1_f1_graph.yaml"


def test_the_walk_after_a_fixed_one_starts_where_it_ended(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # the process pool: quicker here
    g = LandmarkGraph.load(GRAPH)
    name0, name1 = (p.name.split(".")[0] for p in (BEFORE, AFTER))
    given = resolve_start("first-fix", load_session(BEFORE), g)
    truth = resolve_start("first-fix", load_session(AFTER), g)
    (tmp_path / "c.yaml").write_text(
        f"buildings:\n  mall: {{graph: {GRAPH}, walks: ['{BEFORE}', '{AFTER}'], start: infer, "
        f"starts: {{'{name0}': {given}}}}}\n"
    )
    out = tmp_path / "out"
    said: list[str] = []
    rep = run_campaign(tmp_path / "c.yaml", out, workers=1, say=said.append)
    by = {w.key.split("/")[1]: w for w in rep.per_walk}
    after = by[name1]
    assert after.summary.start_after.walk_before == name0
    assert not after.quarantined, after.quarantined
    a, b = g.node(after.summary.start_node), g.node(truth)
    assert a.floor == b.floor and ((a.x - b.x) ** 2 + (a.y - b.y) ** 2) ** 0.5 <= 5.0
    assert any(f"of where {name0} ended" in s for s in said)
    md = (out / "campaign.md").read_text()
    assert f"of where {name0} ended, 4.1 s before)" in md
    meta = json.loads((out / "walks" / "mall" / name1 / "summary.json").read_text())
    assert meta["start_inference"]["candidates"]  # its own inference is kept beside it
    said.clear()
    again = run_campaign(tmp_path / "c.yaml", out, workers=1, say=said.append)
    assert again.run_now == 0 and not any("ended" in s for s in said)
    assert {w.key: w.summary.start_after for w in again.per_walk}[f"mall/{name1}"]
    # the surveyor takes the first walk's start back: it is ambiguous again, and the walk
    # after it runs on its own again — quarantined, as it is alone
    (tmp_path / "c.yaml").write_text(
        f"buildings:\n  mall: {{graph: {GRAPH}, walks: ['{BEFORE}', '{AFTER}'], start: infer}}\n"
    )
    third = run_campaign(tmp_path / "c.yaml", out, workers=1, say=said.append)
    by = {w.key.split("/")[1]: w for w in third.per_walk}
    assert not by[name1].summary.start_after
    assert "start_ambiguous" in {q.reason for q in by[name1].quarantine}


def test_a_walk_handed_a_reach_opens_in_the_panel_with_it(tmp_path):
    """campaign.md's command for a walk still ambiguous after the handover searches its start
    where the campaign did (``edit --start-within X,Y,FLOOR,R``), and the panel's parser reads
    it back."""
    import shlex
    from dataclasses import replace
    from types import SimpleNamespace

    from workstation.campaign.report import _edit_commands, reach_of
    from workstation.campaign.walk_row import WalkRow
    from workstation.cli import build_parser
    from workstation.pipeline.start import HandedStart

    spec = SimpleNamespace(name="mall", graph=GRAPH, params=None, starts_source=None,
                           ends_source=None, building=GRAPH.with_name("building.yaml"))  # fmt: skip
    jobs = [SimpleNamespace(key=f"mall/{k}", walk=AFTER) for k in ("w", "v")]
    after = {"walk_before": "v", "gap_s": 4.1, "ended_at": [80.5, 95.25, 0.0], "reach_m": 19.2,
             "landmarks_in_reach": 21, "any_floor": False}  # fmt: skip
    walks = [WalkRow("mall/w", "mall", "ok", figures={"start_after": after}),
             WalkRow("mall/v", "mall", "ok")]  # fmt: skip
    cmd = _edit_commands(tmp_path, spec, jobs, walks, mapped=False)
    assert "--start-within 80.5,95.25,0,19.2" in cmd["mall/w"]
    assert "--start-within" not in cmd["mall/v"]
    args = build_parser().parse_args(shlex.split(cmd["mall/w"])[1:])
    assert args.start_within == (80.5, 95.25, 0.0, 19.2)
    assert args.building == spec.building  # the plan under the walk (issue #50 item 9)
    g = LandmarkGraph.load(GRAPH)
    handed = HandedStart.from_json(after)
    assert reach_of(handed, g)
    assert reach_of(replace(handed, any_floor=True), g) == reach_of(handed, g)
    assert reach_of(None, g) is None
