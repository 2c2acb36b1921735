"""The commands campaign.md gives for a campaign in a bucket work on its URLs (issue #54): a
walk, its graph, building (with its plan image) and the campaign's starts file read from the
store; the panel's saves of the graph and of a walk's start written back there, the previous
object kept as ``.bak``, the recovery copy of unsaved edits kept on this disk."""

from __future__ import annotations

import json

import pytest

from tests.conftest import REPO
from tests.s3 import local_s3, need_store
from workstation.cli import build_parser, main

need_store()

MS = REPO / "sample_sessions" / "msilc-site1-f1-walk"  # graph.yaml and building.yaml beside it
URL = "s3://walks/mall"


@pytest.fixture(scope="module")
def s3():
    import fsspec

    with local_s3():
        fs = fsspec.filesystem("s3")
        fs.mkdir("walks")
        fs.put(str(MS) + "/", "walks/mall/", recursive=True)
        yield fs


def _args(*argv):
    return build_parser().parse_args(list(argv))


def test_run_and_info_on_a_walk_in_the_store_give_the_local_results(s3, tmp_path, capsys):
    here = ["run", str(MS), "--graph", str(MS / "graph.yaml"), "--out", str(tmp_path / "here")]
    there = ["run", URL, "--graph", f"{URL}/graph.yaml", "--out", str(tmp_path / "there")]
    assert main(here) == main(there)
    for name in ("radiomap.csv", "trajectory.csv", "landmarks.csv", "segments.csv"):
        assert (tmp_path / "here" / name).read_bytes() == (tmp_path / "there" / name).read_bytes()
    a, b = (json.loads((tmp_path / d / "summary.json").read_text()) for d in ("here", "there"))
    assert a == b
    capsys.readouterr()
    assert main(["info", URL]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[0] == URL  # the URL, not the temporary copy (issue #64 item 7)
    assert main(["info", str(MS)]) == 0
    assert out.split("\n", 1)[1] == capsys.readouterr().out.split("\n", 1)[1]  # but the path


def test_the_building_beside_a_graph_in_the_store_comes_with_its_plan(s3):
    from workstation.commands._inputs import building_for, building_path_for

    args = _args("edit", URL, "--graph", f"{URL}/graph.yaml")
    local = building_path_for(args)
    assert local.is_file() and local.name == "building.yaml"
    b = building_for(args)
    img = next(i.image for i in b.floors.values() if i.image is not None)
    assert img.path.is_file() and img.path.read_bytes() == (MS / "floor_image.png").read_bytes()


def test_the_panel_saves_a_graph_and_a_walks_start_back_to_the_store(s3, tmp_path):
    from workstation.commands._inputs import load_inputs
    from workstation.editor import SurveyEditor
    from workstation.graph import LandmarkGraph
    from workstation.io.store import place
    from workstation.io.walk_fixes import WalkFixes

    s3.put(str(MS / "graph.yaml"), "walks/edit/graph.yaml")
    before = s3.cat("walks/edit/graph.yaml")
    args = _args("edit", URL, "--graph", "s3://walks/edit/graph.yaml", "--out", str(tmp_path))
    session, graph, params = load_inputs(args, new_graph_ok=True)
    ed = SurveyEditor(session, graph, params, graph_path=place(args.graph), out_dir=tmp_path)
    node = graph.nodes[0]
    assert ed.move_node(node.id, node.x + 1.5, node.y)
    rec = ed.recovery_paths()[0]
    assert rec.parent == tmp_path and rec.is_file()  # unsaved work: kept on this disk
    ed.save_graph()
    saved = LandmarkGraph.from_yaml(s3.cat("walks/edit/graph.yaml").decode())
    assert saved.node(node.id).x == pytest.approx(node.x + 1.5)
    assert s3.cat("walks/edit/graph.yaml.bak") == before and not rec.exists()
    # "Start here" in a campaign in the store: the walk's entry in the building's starts.yaml
    fixes = WalkFixes("walk03", place("s3://walks/c/buildings/mall/starts.yaml"))
    said = fixes.record("start", node.id)
    assert "written to s3://walks/c/buildings/mall/starts.yaml" in said
    said = fixes.record("start", graph.nodes[1].id)
    text = s3.cat("walks/c/buildings/mall/starts.yaml").decode()
    assert f"walk03: {graph.nodes[1].id}" in text
    assert f"walk03: {node.id}" in s3.cat("walks/c/buildings/mall/starts.yaml.bak").decode()


def test_a_walk_missing_from_the_store_is_one_line(s3, tmp_path, capsys):
    code = main(["run", f"{URL}-none", "--graph", f"{URL}/graph.yaml", "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith(f"error: {URL}-none") and len(err.splitlines()) == 1
