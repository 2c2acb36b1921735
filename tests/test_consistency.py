"""Walk, graph and building that do not belong together are refused (issue #13)."""

from dataclasses import replace

from tests.conftest import REPO
from workstation.cli import main
from workstation.graph import LandmarkGraph

WALK = REPO / "sample_sessions" / "office2f" / "normal"
MS = REPO / "sample_sessions" / "msilc-site1-f1-walk"


def _moved(tmp_path, dx=0.0, df=0.0):
    g = LandmarkGraph.load(WALK / "graph.yaml")
    nodes = tuple(replace(n, x=n.x + dx, floor=n.floor + df) for n in g.nodes)
    path = tmp_path / "other.yaml"
    replace(g, nodes=nodes).save(path)
    return path


def test_a_graph_of_another_building_is_refused(tmp_path, capsys):
    far = _moved(tmp_path, dx=400.0)
    assert main(["run", str(WALK), "--graph", str(far), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "do not belong together" in err and "outside the graph's extent" in err
    assert main(["run", str(WALK), "--graph", str(far), "--out", str(tmp_path / "o"),
                 "--force"]) == 0  # fmt: skip
    assert "warning" in capsys.readouterr().out + capsys.readouterr().err


def test_floors_the_graph_lacks_are_named(tmp_path, capsys):
    other = _moved(tmp_path, df=5.0)
    assert main(["view", str(WALK), "--graph", str(other), "--save", str(tmp_path / "x.rrd")]) == 2
    assert "floor(s) 0, 1, which the graph lacks" in capsys.readouterr().err


def test_the_ms_walk_on_the_office_graph_is_refused(tmp_path, capsys):
    rc = main(["run", str(MS), "--graph", str(WALK / "graph.yaml"), "--out", str(tmp_path)])
    assert rc == 2 and "do not belong together" in capsys.readouterr().err


def test_an_image_given_as_wall_plan_says_what_to_do(tmp_path, capsys):
    rc = main(["view", str(MS), "--graph", str(MS / "graph.yaml"),
               "--plan", str(MS / "floor_image.png"), "--save", str(tmp_path / "x.rrd")])  # fmt: skip
    assert rc == 2 and "building file" in capsys.readouterr().err


def test_view_logs_the_plan_image_of_the_building_beside_the_graph(tmp_path):
    from rerun.chunk import RrdReader

    rrd = tmp_path / "ms.rrd"
    assert main(["view", str(MS), "--graph", str(MS / "graph.yaml"), "--save", str(rrd)]) == 0
    chunks = [c for c in RrdReader(rrd).stream() if c.entity_path == "/map/floor_0/plan/image"]
    names = {n for c in chunks for n in c.to_record_batch().schema.names}
    assert any(n.endswith("Blob") or "blob" in n.lower() for n in names), names
    assert any("mat3x3" in n.lower() for n in names), names


def test_a_walk_off_the_graphs_corridors_is_refused(tmp_path, capsys):
    """The graph overlaps the walk's extent but not its corridors (the museum walk on the office
    graph was accepted this way): refused, unless --force."""
    shifted = _moved(tmp_path, dx=12.0)  # inside the 50 m margin, off the corridors
    assert main(["run", str(WALK), "--graph", str(shifted), "--out", str(tmp_path / "o")]) == 2
    assert "from every corridor" in capsys.readouterr().err


def _map(tmp_path, walk, name):
    out = tmp_path / name
    assert main(["run", str(walk), "--graph", str(walk / "graph.yaml"), "--out", str(out)]) in (
        0,
        3,
    )
    return out / "radiomap.csv"


def test_a_walk_on_another_buildings_radio_map_is_refused(tmp_path, capsys):
    """The mall's map and an office walk share no access point: no scan can match anything,
    so localize refuses (it printed 'floor accuracy 0.0 %' and exit 0); the office's own map
    serves it without a word; --force localizes anyway, with the warning."""
    mall, office = _map(tmp_path, MS, "ms"), _map(tmp_path, WALK, "office")
    heldout = str(REPO / "sample_sessions" / "office2f" / "heldout")
    capsys.readouterr()
    assert main(["localize", "--map", str(mall), "--session", heldout]) == 2
    err = capsys.readouterr().err
    assert "do not belong together" in err and "share 0" in err and str(mall) in err
    assert main(["localize", "--map", str(office), "--session", heldout]) == 0
    assert "warning" not in capsys.readouterr().out
    assert main(["localize", "--map", str(mall), "--session", heldout, "--force"]) == 0
    assert "warning" in capsys.readouterr().out


def test_merging_maps_that_share_no_access_point_says_so(tmp_path, capsys):
    """Another building, or parts of one no other walk reached (merging those is right): said
    for each map, not refused."""
    mall, office = _map(tmp_path, MS, "ms"), _map(tmp_path, WALK, "office")
    capsys.readouterr()
    assert main(["merge", str(mall), str(office), "-o", str(tmp_path / "m.csv")]) == 0
    out = capsys.readouterr().out
    assert f"{mall} shares 0 of its" in out and f"{office} shares 0 of its" in out


def test_a_georeferenced_map_and_one_that_is_not_do_not_merge_without_force(tmp_path, capsys):
    """Issue #50 item 4: maps of different sites merged silently when one was placed on the globe
    and the other not (the museum's with the mall's). Refused, naming both, unless --force."""
    office = _map(tmp_path, WALK, "office")
    placed = tmp_path / "placed.csv"
    placed.write_text("# frame origin_lat=49.461 origin_lon=11.111\n" + office.read_text())
    capsys.readouterr()
    args = ["merge", str(office), str(placed), "-o", str(tmp_path / "m.csv")]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "is georeferenced (49.46100, 11.11100)" in err and str(placed) in err
    assert "--force" in err and not (tmp_path / "m.csv").exists()
    assert main([*args, "--force"]) == 0 and (tmp_path / "m.csv").exists()


def test_quality_refuses_a_map_on_another_buildings_plans(tmp_path, capsys):
    """Issue #50 item 4: the simulated office's two-floor map drawn on the mall's one-floor plan
    (it said "100 % covered", exit 0). Refused naming the floor the plans lack, unless --force."""
    office = _map(tmp_path, WALK, "office")
    capsys.readouterr()
    args = ["quality", "--map", str(office), "--building", str(MS / "building.yaml"),
            "--out", str(tmp_path / "q")]  # fmt: skip
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "floor(s) 1, which the building file lacks (it has 0)" in err and "--force" in err
    assert main([*args, "--force"]) == 0
