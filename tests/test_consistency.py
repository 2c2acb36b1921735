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
