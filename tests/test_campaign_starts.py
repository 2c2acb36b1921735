"""A surveyor fixes a campaign walk whose inferred start was ambiguous by giving its start
(``starts.yaml`` beside the graph, or ``starts:`` in the campaign file), helped by what the
building's map says of its candidate starts (workstation/campaign/starts.py)."""

from __future__ import annotations

import json
import math
import shlex
import sys

import numpy as np
import pytest

from tests.conftest import REPO
from workstation.campaign import run_campaign
from workstation.errors import InputError
from workstation.fingerprints.localize import Fingerprints
from workstation.graph import LandmarkGraph
from workstation.pipeline.start import resolve_start
from workstation.session import load_session

MALL = REPO / "tests" / "data" / "msilc"


def _mall_campaign(tmp_path, given: int):
    """The ten bundled mall walks (MIT), starts inferred, the first ``given`` of them given
    their start (the landmark at their first tap) in a folder's starts.yaml."""
    b = tmp_path / "c" / "buildings" / "mall"
    (b / "walks").mkdir(parents=True)
    g = LandmarkGraph.load(MALL / "site1_f1_graph.yaml")
    (b / "graph.yaml").write_text((MALL / "site1_f1_graph.yaml").read_text())
    walks = sorted(MALL.glob("*.gz"))
    truth = {}
    for w in walks:
        (b / "walks" / w.name).write_bytes(w.read_bytes())
        truth[w.name.split(".")[0]] = resolve_start("first-fix", load_session(w), g)
    (b / "params.yaml").write_text("pdr:\n  start_node: null\n")
    return tmp_path / "c", b, truth, walks


def test_a_walk_given_its_start_in_starts_yaml_runs_from_it(tmp_path, monkeypatch):
    """In a folder campaign whose walks start at their first tap (the default), a starts.yaml
    entry moves one walk's start: that walk alone is run again, from the landmark given."""
    monkeypatch.setitem(sys.modules, "distributed", None)  # the process pool: quicker here
    root, b, truth, _ = _mall_campaign(tmp_path, 0)
    (b / "params.yaml").unlink()
    out = tmp_path / "out"
    rep = run_campaign(root, out, workers=1, say=lambda s: None)
    by = {w["key"]: w for w in rep.per_walk}
    name = sorted(truth)[3]
    assert by[f"mall/{name}"]["start_node"] == truth[name]
    other = next(n for n in LandmarkGraph.load(b / "graph.yaml").ids if n != truth[name])
    (b / "starts.yaml").write_text(f"{name}: {other}\n")
    again = run_campaign(root, out, workers=1, say=lambda s: None)
    assert again.run_now == 1
    assert {w["key"]: w["start_node"] for w in again.per_walk}[f"mall/{name}"] == other


@pytest.mark.parametrize(
    "file, text, said",
    [
        ("starts", "no_such_walk: L10\n", "'no_such_walk' is no walk of building mall"),
        ("starts", "5dd9e7aac5b77e0006b1732c: L10\n", "did you mean '5dd9e7aac5b77e0006b1732b'"),
        ("starts", "5dd9e7aac5b77e0006b1732b: L1000\n", "'L1000' is no landmark of"),
        ("starts", "- 5dd9e7aac5b77e0006b1732b\n", "walk starts are a mapping"),
        ("ends", "no_such_walk: L10\n", "ends: 'no_such_walk' is no walk of building mall"),
        ("ends", "5dd9e7aac5b77e0006b1732b: L1000\n", "'L1000' is no landmark of"),
        ("ends", "- 5dd9e7aac5b77e0006b1732b\n", "walk ends are a mapping"),
    ],
)
def test_a_bad_starts_or_ends_file_is_refused_naming_it(tmp_path, file, text, said):
    root, b, _, _ = _mall_campaign(tmp_path, 0)
    (b / f"{file}.yaml").write_text(text)
    with pytest.raises(InputError) as e:
        run_campaign(root, tmp_path / "out", workers=1, say=lambda s: None)
    assert str(b / f"{file}.yaml") in str(e.value) and said in str(e.value)
    assert not (tmp_path / "out" / "walks").exists()  # refused before anything ran


def test_a_walk_that_matched_nothing_is_fixed_by_its_end_in_ends_yaml(tmp_path, monkeypatch):
    """The campaign walk that matched nothing, given its start (the first tap, the default), is
    in the map (issue #49); given an end in ends.yaml its sensors disagree with, it is held for
    that and listed with where its end goes; given its real end (the landmark at its last tap),
    that walk alone runs again and joins the map."""
    from workstation.pipeline.start import resolve_end

    monkeypatch.setitem(sys.modules, "distributed", None)
    root, b, _, walks = _mall_campaign(tmp_path, 0)
    (b / "params.yaml").unlink()  # starts at the first tap (the default)
    out = tmp_path / "out"
    name = "5dd9e7b7c5b77e0006b1732f"
    first = run_campaign(root, out, workers=1, say=lambda s: None)
    w = {w["key"]: w for w in first.per_walk}[f"mall/{name}"]
    assert w["landmarks_matched"] == 0 and not w.get("quarantine")
    g = LandmarkGraph.load(b / "graph.yaml")
    s = load_session(b / "walks" / f"{name}.txt.gz")
    end = resolve_end("last-fix", s, g)
    far = max(g.nodes, key=lambda n: np.hypot(n.x - g.node(end).x, n.y - g.node(end).y)).id
    (b / "ends.yaml").write_text(f"{name}: {far}\n")
    said = []
    rep = run_campaign(root, out, workers=1, say=lambda s: None,
                       progress=lambda i, n, text, phase="": said.append(text))  # fmt: skip
    held = {w["key"]: w for w in rep.per_walk if w.get("quarantine")}
    assert f"mall/{name}" in held
    assert [q["reason"] for q in held[f"mall/{name}"]["quarantine"]] == ["end_far"]
    # its progress says so, not "ok" (issue #64 item 7)
    assert f"mall/{name}: quarantined (end_far)" in said and f"mall/{name}: ok" not in said
    md = (out / "campaign.md").read_text()
    assert f"{b / 'ends.yaml'} ({name}: LANDMARK)" in md
    # listed by what fixing each adds: its scans with no point of the merged map within 5 m
    import pandas as pd

    from workstation.campaign.jobs import load_map

    merged = pd.read_parquet(out / "radiomap")
    m = load_map(out / "walks" / "mall" / name / "map.parquet")
    d = np.hypot(
        m.x[:, None] - merged["x"].to_numpy()[None], m.y[:, None] - merged["y"].to_numpy()[None]
    )
    assert held[f"mall/{name}"]["map_lacks"] == int((d.min(axis=1) > 5.0).sum())
    # a walk's map.parquet says its phone model as a merged map does (issue #64 item 7: merge
    # of two of them removed "offsets" between walks of one phone); merging them removes none
    from workstation.cli import main as cli
    from workstation.fingerprints.localize import Fingerprints

    walk_maps = sorted((out / "walks" / "mall").glob("*/map.parquet"))
    assert Fingerprints.read(walk_maps[0]).device == s.metadata["device"]
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        assert cli(["merge", *map(str, walk_maps[:3]), "-o", str(tmp_path / "m.csv")]) == 0
    said = buf.getvalue()
    assert "dB removed" not in said and f"one phone model ({s.metadata['device']})" in said
    listed = md.split("## Needs the surveyor")[1]
    order = sorted(held, key=lambda k: listed.index(f"| {k} |"))
    assert [held[k]["map_lacks"] for k in order] == sorted(
        (held[k]["map_lacks"] for k in held), reverse=True
    )
    (b / "ends.yaml").write_text(f"{name}: {end}\n")
    again = run_campaign(root, out, workers=1, say=lambda s: None)
    assert again.run_now == 1
    w = {w["key"]: w for w in again.per_walk}[f"mall/{name}"]
    assert not w.get("quarantine") and w["end_how"] == "given" and w["end_node"] == end
    assert again.walks_quarantined == rep.walks_quarantined - 1


def test_the_report_ranks_an_ambiguous_walks_starts_by_the_map(tmp_path, monkeypatch):
    """Starts inferred (campaign file), eight walks given theirs: those are in the map; the two
    left are ambiguous and listed under "Needs the surveyor" with where to give the start and
    their candidate starts ranked by the building's map."""
    monkeypatch.setitem(sys.modules, "distributed", None)
    root, b, truth, walks = _mall_campaign(tmp_path, 0)
    names = sorted(truth)
    given = {n: truth[n] for n in names[:8]}
    starts = ", ".join(f"'{n}': {v}" for n, v in given.items())
    listing = [str(b / "walks" / w.name) for w in walks]
    (tmp_path / "c.yaml").write_text(
        f"buildings:\n  mall: {{graph: {b / 'graph.yaml'}, walks: {listing}, start: infer, "
        f"starts: {{{starts}}}}}\n"
    )
    out = tmp_path / "out"
    rep = run_campaign(tmp_path / "c.yaml", out, workers=1, say=lambda s: None)
    by = {w["key"].split("/")[1]: w for w in rep.per_walk}
    for n, v in given.items():
        assert by[n]["start_node"] == v
        assert not any(q["reason"] == "start_ambiguous" for q in by[n].get("quarantine") or [])
    ambiguous = [by[n] for n in names[8:]
                 if any(q["reason"] == "start_ambiguous" for q in by[n]["quarantine"])]  # fmt: skip
    assert ambiguous
    md = (out / "campaign.md").read_text()
    for w in ambiguous:
        ranked = w["start_by_map"]
        # its own candidates, and those of the wider search (start_by_map.WIDE_CANDIDATES)
        assert set(w["candidates"]) <= {c[0] for c in ranked}
        assert len(ranked) > len(w["candidates"])
        # likeliest first; each with the median distance the surveyor reads
        ll = [c[2] for c in ranked]
        assert ll == sorted(ll, reverse=True) and all(np.isfinite([c[1] for c in ranked]))
        assert w["start_by_map_margin_ll"] is None or w["start_by_map_margin_ll"] >= 0
        assert w["start_near_by_map"] in LandmarkGraph.load(b / "graph.yaml").ids
        needs = md.split("## Needs the surveyor")[1]
        row = next(ln for ln in needs.splitlines()
                   if ln.startswith(f"| {w['key']} |") and "inferred as the start" in ln)  # fmt: skip
        assert f"`{w['key'].split('/')[1]}: LANDMARK`" in row and "buildings.mall.starts" in row
        assert f"{ranked[0][0]} {ranked[0][1]:g} m" in row
        # the command that opens it in the panel on the building's merged map, which --map reads
        cmd = shlex.split(w["edit_command"])
        assert f"`{w['edit_command']}`" in row and cmd[:2] == ["workstation", "edit"]
        assert cmd[cmd.index("--map") + 1] == str(out / "radiomap" / "building=mall")
    merged = Fingerprints.read(out / "radiomap" / "building=mall")
    assert len(merged) == rep.buildings["mall"].reference_points
    assert set(np.unique(merged.floor)) == {0.0}
    saved = json.loads((out / "campaign.json").read_text())
    assert saved["per_walk"] == json.loads(json.dumps(rep.per_walk, default=str))


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
    cands = [n for n, _ in ed.result.track.start_candidates]
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
    own = alone.result.track.start_candidates
    assert alone.start_hints() == [(n, odds(d)) for n, d in own][:SHOWN]
    assert alone.start_hints()[0] == (alone.result.track.start_node, "likeliest")
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


def test_a_campaign_output_that_is_a_file_or_a_pipe_is_refused_as_such(tmp_path, capsys):
    """Issue #67 item 5: `campaign run --out` given a file or a FIFO said "free the space and
    run the same command again"; it says the output is no folder, and writes nothing."""
    import os

    from workstation.cli import main

    root, _, _, _ = _mall_campaign(tmp_path, 0)
    f, fifo = tmp_path / "out.txt", tmp_path / "pipe"
    f.write_text("mine")
    os.mkfifo(fifo)
    for out in (f, fifo):
        assert main(["campaign", "run", str(root), "--out", str(out)]) == 2
        err = capsys.readouterr().err
        assert f"{out}: is not a folder" in err and "free the space" not in err
    assert f.read_text() == "mine"
