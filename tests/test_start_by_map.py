"""The building's map ranks an ambiguous walk's candidate starts: the right start agrees best
with it, `run --map` and the panel say the ranking and ring the likeliest places, and the wider
search keeps distinct starts (workstation/walks/start_by_map.py, pipeline/start.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import REPO
from workstation.fingerprints.localize import Fingerprints
from workstation.graph import LandmarkGraph
from workstation.session import load_session

MALL = REPO / "tests" / "data" / "msilc"


@pytest.mark.parametrize("seed", range(1, 6))
def test_the_right_start_agrees_best_with_the_map(seed):
    """Simulated office: the map of one walk started at its start; another walk's candidate
    starts ranked by it — the true start (the simulator's) first, ahead of the landmark on its
    floor farthest from it, and the map puts the walk's first scans within a landmark spacing
    (~15 m) of the truth."""
    from workstation.fingerprints.localize import Fingerprints, RadioMapIndex
    from workstation.params import Params
    from workstation.pipeline import Pipeline
    from workstation.sim import simulate
    from workstation.sim.building import office2f
    from workstation.walks.start_by_map import rank_by_map

    b = office2f()
    m = simulate(b, "normal", seed)
    r = Pipeline(
        m.session, m.graph, Params().updated(**{"pdr.start_node": b.routes["survey"][0]})
    ).run()
    index = RadioMapIndex(Fingerprints.from_radiomap(r.radiomap, m.graph.frame))
    q = simulate(b, "heldout", seed)
    true = b.routes["reverse"][0]
    pos = {n.id: (n.x, n.y, n.floor) for n in q.graph.nodes}
    far = max((n for n in pos if pos[n][2] == pos[true][2]),
              key=lambda n: np.hypot(pos[n][0] - pos[true][0], pos[n][1] - pos[true][1]))  # fmt: skip
    got = rank_by_map(q.session, q.graph, Params(), [far, true], index)
    ll = {c[0]: c[2] for c in got.ranked}
    assert got.ranked[0][0] == true and ll[true] > ll[far]
    near = pos[got.near]
    assert np.hypot(near[0] - pos[true][0], near[1] - pos[true][1]) <= 20.0


@pytest.fixture(scope="module")
def mall_maps(tmp_path_factory):
    """radiomap.csv of the bundled mall walks but the last, each run from its first tap's
    landmark, those in the map only: the building's map an ambiguous walk is ranked by."""
    from workstation.cli import main

    tmp = tmp_path_factory.mktemp("maps")
    g = MALL / "site1_f1_graph.yaml"
    maps = []
    for w in sorted(MALL.glob("*.gz"))[:-1]:
        out = tmp / w.name.split(".")[0]
        main(["run", str(w), "--graph", str(g), "--start", "first-fix", "--out", str(out)])
        if '"quarantined": false' in (out / "summary.json").read_text():
            maps.append(str(out / "radiomap.csv"))
    assert len(maps) >= 5
    return maps


def test_run_ranks_an_ambiguous_start_by_a_given_map(tmp_path, capsys, mall_maps):
    """`run --map`: a walk whose inferred start is ambiguous gets its candidate starts ranked by
    the building's map (the other bundled walks run from their first tap); a map that cannot be
    read is refused before anything runs or is written."""
    from workstation.cli import main

    g, walk = MALL / "site1_f1_graph.yaml", sorted(MALL.glob("*.gz"))[-1]
    capsys.readouterr()
    code = main(["run", str(walk), "--graph", str(g), "--out", str(tmp_path / "q"),
                 "--map", *mall_maps])  # fmt: skip
    said = capsys.readouterr().out
    assert code == 3 and "start_ambiguous" in said
    line = next(
        ln for ln in said.splitlines() if "the building's map on its candidate starts" in ln
    )
    assert " m, " in line and "nearest to L" in line and "give --start" in line
    code = main(["run", str(walk), "--graph", str(g), "--out", str(tmp_path / "bad"),
                 "--map", str(tmp_path / "nothing.csv")])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and "nothing.csv" in err and not (tmp_path / "bad").exists()


def _ambiguous_mall_editor(tmp_path, maps):
    """The last bundled mall walk (its inferred start ambiguous) in the editor, on the map of
    the others (``maps``: their radiomap.csv)."""
    from workstation.editor import SurveyEditor

    g = LandmarkGraph.load(MALL / "site1_f1_graph.yaml")
    walk = load_session(sorted(MALL.glob("*.gz"))[-1])
    ref = Fingerprints.merge([Fingerprints.read(m) for m in maps])
    return g, walk, SurveyEditor(walk, g, graph_path=tmp_path / "g.yaml",
                                 out_dir=tmp_path / "o", building_map=ref)  # fmt: skip


def test_the_panel_start_line_carries_the_maps_ranking(tmp_path, mall_maps):
    """`edit --map`: the editor's start line, ambiguous, ends with the candidates ranked by the
    building's map; a given start, or no map, says nothing of it."""
    from workstation.editor import SurveyEditor
    from workstation.walks.start_by_map import SHOWN

    g, walk, ed = _ambiguous_mall_editor(tmp_path, mall_maps)
    note = ed.start_note()
    assert "ambiguous" in note and "by the building's map" in note
    cands = [n for n, _ in ed.result.track.start.candidates]
    ranked = note.split("where the map's WiFi does: ")[1].split(";")[0].split(", ")
    # the likeliest SHOWN of its candidates and the wider search's, numbered, each with its
    # median distance (m), the rest counted
    assert [r.split(" ")[0] for r in ranked[:SHOWN]] == [f"#{k}" for k in range(1, len(ranked[:SHOWN]) + 1)]
    named = [r.split(" ")[1] for r in ranked]
    metres = [float(r.split(" ")[2]) for r in ranked]
    assert 1 <= len(named) <= SHOWN and set(named) <= set(g.ids) and all(m >= 0 for m in metres)
    assert "less likely)" in ranked[-1]
    assert ed.start_note() == note  # kept, not computed again
    assert (
        "building's map"
        not in SurveyEditor(
            walk, g, graph_path=tmp_path / "g2.yaml", out_dir=tmp_path / "o2"
        ).start_note()
    )
    ed.set_start(cands[0])
    assert "building's map" not in ed.start_note()


def test_the_panel_rings_the_maps_likeliest_starts_on_the_plan(tmp_path, mall_maps):
    """`edit --map` on an ambiguous walk: the panel rings the map's likeliest candidates (at
    most SHOWN, "start? #1 L… · likeliest" first) on the floor on view, as the start line names them;
    once the start is given, none."""
    from workstation.editor import SurveyEditor
    from workstation.pipeline.confidence import odds
    from workstation.viz.panel import SurveyPanel
    from workstation.walks.start_by_map import SHOWN

    g, walk, ed = _ambiguous_mall_editor(tmp_path, mall_maps)
    hints = ed.start_hints()
    ranked, near = hints[:-1], hints[-1]  # and where the map puts its first scans
    assert 1 <= len(ranked) <= SHOWN and all(n in g.ids and (m.endswith("less likely") or m in ("likeliest", "as likely")) for n, m in ranked)
    assert near == (ed._by_map[1].near, "the map's WiFi")
    named = ed.start_note().split("where the map's WiFi does: ")[1].split(",")[0]
    assert named.startswith(f"#1 {hints[0][0]} ") and hints[0][1] == "likeliest"
    pan = SurveyPanel(ed, None, port=0)
    try:
        on_view = [n for n, _ in hints if g.node(n).floor == pan.floor]
        assert len(pan.scene.hint_rings) == len(pan.scene.hint_labels) == len(on_view) >= 1
        assert pan.scene.hint_labels[0].text == f"start? #1 {hints[0][0]} · likeliest"
        ed.set_start(hints[0][0])
        pan.after_edit()
        assert ed.start_hints() == [] and not pan.scene.hint_rings and not pan.scene.hint_labels
    finally:
        pan.stop()
    # without a map: the sensors' own candidate starts, best first, with how much less likely
    alone = SurveyEditor(walk, g, graph_path=tmp_path / "g3.yaml", out_dir=tmp_path / "o3")
    own = alone.result.track.start.candidates
    assert alone.start_hints() == [(n, odds(d)) for n, d in own][:SHOWN]
    assert alone.start_hints()[0] == (alone.result.track.start.node, "likeliest")
    assert "ringed on the plan (start? #1 …), by the sensors." in alone.start_note()


@pytest.mark.parametrize("seed", range(1, 4))
def test_the_wider_search_keeps_distinct_starts_and_leaves_the_run_alone(seed):
    """Simulated office, start inferred: the wider search (start_by_map's hint) returns up to
    ``most`` starts at distinct places (another floor or more than ALTERNATIVE_START_M apart),
    the true start (the simulator's) among them; the pipeline's own result is untouched."""
    from workstation.params import Params
    from workstation.pipeline import Pipeline
    from workstation.pipeline.confidence import ALTERNATIVE_START_M
    from workstation.sim import simulate
    from workstation.sim.building import office2f

    b = office2f()
    q = simulate(b, "heldout", seed)
    pipe = Pipeline(q.session, q.graph, Params())
    before = pipe.run()
    wide = pipe.start_candidates(64, 12)
    assert pipe.result is before and 1 <= len(wide) <= 12 and len(set(wide)) == len(wide)
    pos = {n.id: (n.x, n.y, n.floor) for n in q.graph.nodes}
    for i, a in enumerate(wide):
        for c in wide[:i]:
            same_floor = pos[a][2] == pos[c][2]
            assert (
                not same_floor
                or np.hypot(pos[a][0] - pos[c][0], pos[a][1] - pos[c][1]) > ALTERNATIVE_START_M
            )
    true = pos[b.routes["reverse"][0]]
    assert any(
        pos[a][2] == true[2]
        and np.hypot(pos[a][0] - true[0], pos[a][1] - true[1]) <= ALTERNATIVE_START_M
        for a in wide
    )


def test_the_hint_says_how_much_less_likely_the_next_place_is():
    """The margin of the map's first candidate: its log-likelihood minus that of the best
    candidate at another place (another floor, or more than ALTERNATIVE_START_M away); a
    neighbour within that distance is the same place; none without another place."""
    from workstation.graph import Landmark
    from workstation.walks.start_by_map import MapRanking, _margin, describe

    g = LandmarkGraph(
        nodes=(Landmark("A", 0, 0, 0), Landmark("B", 3, 0, 0), Landmark("C", 20, 0, 0),
               Landmark("D", 0, 0, 1)),
        edges=(),
    )  # fmt: skip
    ranked = [("A", 2.0, -10.0), ("B", 2.5, -11.0), ("C", 9.0, -30.0)]
    assert _margin(g, ranked) == 20.0  # B is the same place as A
    assert _margin(g, [("A", 2.0, -10.0), ("D", 4.0, -12.5), ("C", 9.0, -30.0)]) == 2.5
    assert _margin(g, [("A", 2.0, -10.0), ("B", 3.0, -11.0)]) is None
    assert _margin(g, [("A", float("nan"), -math.inf)]) is None and _margin(g, []) is None
    said = describe(MapRanking(ranked=(("A", 2.0, -10.0), ("C", 9.0, -30.0)), margin_ll=20.0))
    assert said == "#1 A 2 m, #2 C 9 m (over 1000× less likely); the best start elsewhere: over 1000× less likely"
    ranked = (("A", 2.0, -10.0), ("B", 4.0, -11.06), ("C", 9.0, -11.06), ("D", 5.0, -13.3))
    said = describe(MapRanking(ranked=ranked))  # how much less likely said where it changes
    assert said == "#1 A 2 m, #2 B 4 m (2.9× less likely), #3 C 9 m, #4 D 5 m (27× less likely)"
