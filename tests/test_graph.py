import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.conftest import IPIN, need
from workstation.errors import GraphError, InputError
from workstation.graph import LandmarkGraph
from workstation.graph.importers import graph_from_tra

GOOD = """
nodes:
  - {id: A, x: 0, y: 0, floor: 0, rules: [acc]}
  - {id: B, x: 10, y: 0, floor: 0, rules: [gyro, baro_entry, baro_exit], name: stairs bottom}
  - {id: C, x: 10, y: 5, floor: 1, rules: [baro_entry, baro_exit]}
  - {id: D, x: 0, y: 10, floor: 0, rules: []}
edges:
  - {from: A, to: B}
  - {from: B, to: C}
  - {from: A, to: D, oneway: true}
"""


def test_loads_directed_edges_with_heading_and_length():
    g = LandmarkGraph.from_yaml(GOOD)
    assert set(g.digraph.edges) == {("A", "B"), ("B", "A"), ("B", "C"), ("C", "B"), ("A", "D")}
    ab, ba = g.edge("A", "B"), g.edge("B", "A")
    assert ab["length"] == pytest.approx(10) and ab["heading"] == pytest.approx(0)
    assert abs(ba["heading"]) == pytest.approx(math.pi)
    assert g.edge("A", "D")["heading"] == pytest.approx(math.pi / 2)
    assert g.edge("B", "C")["floor_change"] == 1
    assert g.node("B").name == "stairs bottom" and g.node("B").rules == {
        "gyro",
        "baro_entry",
        "baro_exit",
    }
    assert sorted(g.successors("A")) == ["B", "D"] and g.successors("D") == []


def test_yaml_round_trip(tmp_path):
    g = LandmarkGraph.from_yaml(GOOD)
    p = tmp_path / "g.yaml"
    assert g.save(p) is None
    g2 = LandmarkGraph.load(p)
    assert g2.nodes == g.nodes and set(g2.edges) == set(g.edges)
    # saving again keeps the previous file as a backup
    g3 = g2.with_node(g2.node("D").__class__("E", 5, 5, 0))
    bak = g3.save(p)
    assert bak.name == "g.yaml.bak" and LandmarkGraph.load(bak).nodes == g.nodes
    assert "E" in LandmarkGraph.load(p).ids


@pytest.mark.parametrize(
    "patch, message",
    [
        ("  - {id: A, x: 1, y: 1, floor: 0}\n", "node A: duplicate id"),
        ("  - {id: E, x: 1, y: 1, floor: 0, rules: [door]}\n", "node E .*unknown rule 'door'"),
        ("  - {id: E, x: 1, y: q, floor: 0}\n", "node E .*y must be a finite number"),
    ],
)
def test_node_errors_name_the_node(patch, message):
    text = GOOD.replace("edges:", patch + "edges:")
    with pytest.raises(GraphError, match=message):
        LandmarkGraph.from_yaml(text)


@pytest.mark.parametrize(
    "edge, message",
    [
        ("  - {from: A, to: Z}\n", "edge A -> Z: unknown node Z"),
        ("  - {from: A, to: E}\n", "edge A -> E: zero length"),
        (
            "  - {from: A, to: C}\n",
            "edge A -> C: joins floors 0 and 1 but node A has no barometer rule",
        ),
        ("  - {from: A, to: A}\n", "edge A -> A: an edge from a node to itself"),
        ("  - {from: A, to: B}\n", "edge A -> B: listed twice"),
    ],
)
def test_edge_errors_name_the_edge(edge, message):
    text = GOOD.replace("edges:", "  - {id: E, x: 0.01, y: 0, floor: 0}\nedges:") + edge
    with pytest.raises(GraphError, match=message):
        LandmarkGraph.from_yaml(text)


def test_schema_errors_give_line_numbers():
    with pytest.raises(GraphError, match=r"nodes\[1\] \(line 4\): unknown key\(s\) colour"):
        LandmarkGraph.from_yaml(
            "nodes:\n  - {id: A, x: 0, y: 0, floor: 0}\n\n  - {id: B, x: 0, y: 0, floor: 0, colour: red}\n"
        )
    with pytest.raises(InputError, match="g.yaml:3: not valid YAML"):
        LandmarkGraph.from_yaml(
            "nodes:\n  - {id: A, x: 0, y: 0, floor: 0}\n  - {id: B, x: 1: 2}\n", source="g.yaml"
        )


def test_elevator_edge_between_floors_may_have_zero_length():
    g = LandmarkGraph.from_yaml(
        "nodes:\n"
        "  - {id: E0, x: 3, y: 3, floor: 0, rules: [baro_entry, baro_exit]}\n"
        "  - {id: E1, x: 3, y: 3, floor: 1, rules: [baro_entry, baro_exit]}\n"
        "edges:\n  - {from: E0, to: E1}\n"
    )
    assert g.edge("E0", "E1")["length"] == 0


def test_edits_are_validated():
    g = LandmarkGraph.from_yaml(GOOD)
    g2 = g.without_node("B")
    assert "B" not in g2.ids and all("B" not in e for e in g2.edges)
    assert ("D", "A") in g.with_edge("D", "A").edges
    with pytest.raises(GraphError, match="unknown node Q"):
        g.with_edge("A", "Q")
    assert ("A", "B") not in g.without_edge("B", "A").edges


def test_from_tra_infers_rules(tmp_path):
    # a route: east 10 m, turn north (90°) 10 m, then down a stair to floor -1, back the same way
    lat0, lon0 = 49.0, 11.0
    dlat, dlon = 10 / 111_200, 10 / (111_320 * math.cos(math.radians(49)))
    pts = [
        (lat0, lon0, 0),
        (lat0, lon0 + dlon, 0),
        (lat0 + dlat, lon0 + dlon, 0),
        (lat0 + dlat, lon0 + dlon, 0),
        (lat0 + dlat, lon0 + 1.5 * dlon, -1),
    ]
    text = "\n\nPoint_Index  Latitude Longitude Floor_ID Building_ID\n" + "".join(
        f"{i + 1} {a:.12f} {b:.12f} {f} 100\n" for i, (a, b, f) in enumerate(pts)
    )
    p = tmp_path / "IPIN2023_T3_TrainingTrial99_repetition01.tra"
    p.write_text(text)
    g = graph_from_tra([p])
    assert len(g.nodes) == 4  # the repeated landmark is one node
    assert g.nodes[0].rules == frozenset() and g.nodes[0].name == "T99#1"
    assert g.nodes[1].rules == {"gyro"}  # 90° turn
    assert g.nodes[2].rules == {"baro_entry", "baro_exit", "gyro"}
    assert g.nodes[3].rules == {"baro_entry", "baro_exit"}
    assert g.edge(g.ids[0], g.ids[1])["length"] == pytest.approx(10, abs=0.05)
    assert len(g.undirected_pairs()) == 3


def test_from_tra_bad_line(tmp_path):
    p = tmp_path / "r.tra"
    p.write_text(
        "Point_Index Latitude Longitude Floor_ID\n1 49.0 11.0 0 100\n2 49.0 eleven 0 100\n"
    )
    with pytest.raises(InputError, match=r"r.tra:3: non-numeric"):
        graph_from_tra([p])


@pytest.mark.shared_data
def test_museum_graph_from_all_tra_files_validates(tmp_path):
    files = sorted(need(IPIN / "supplementary" / "trajectories").glob("*.tra"))
    g = graph_from_tra(files)
    assert len(g.nodes) == 77 and g.floors == [-2.0, -1.0, 0.0]
    stairs = [n for n in g.nodes if n.rules & {"baro_entry"}]
    assert len(stairs) >= 4
    p = tmp_path / "museum.yaml"
    g.save(p)
    assert LandmarkGraph.load(p).ids == g.ids


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    pos=st.integers(min_value=0, max_value=len(GOOD) - 1),
    junk=st.text(alphabet=st.characters(codec="utf-8", exclude_categories=("Cs",)), max_size=8),
    cut=st.booleans(),
)
def test_mutated_graph_yaml_gives_only_typed_errors(pos, junk, cut):
    text = GOOD[:pos] + junk + ("" if cut else GOOD[pos:])
    try:
        g = LandmarkGraph.from_yaml(text, source="g.yaml")
    except (GraphError, InputError) as e:
        assert "g.yaml" in str(e)
        return
    assert all(math.isfinite(n.x) for n in g.nodes)


def test_graph_from_waypoints_of_a_bundled_real_walk(tmp_path, capsys):
    from tests.conftest import REPO
    from workstation.cli import main
    from workstation.graph.importers import graph_from_waypoints
    from workstation.session import load_session

    walk = REPO / "sample_sessions" / "msilc-site1-f1-walk"
    s = load_session(walk)
    g = graph_from_waypoints([s])
    assert len(g.nodes) == len(s.ground_truth) == 13 and len(g.undirected_pairs()) == 12
    assert g.nodes[0].name == "W1#1"
    # merging: the same walk twice gives the same landmarks
    assert len(graph_from_waypoints([s, s]).nodes) == 13
    out = tmp_path / "g.yaml"
    assert main(["graph", "from-waypoints", str(walk), "-o", str(out), "--per-tap"]) == 0
    assert "13 landmarks" in capsys.readouterr().out
    # the default: where the walk turns, begins and ends, with a report beside the graph
    assert main(["graph", "from-waypoints", str(walk), "-o", str(out)]) == 0
    assert "from 13 taps of 1 walk (" in capsys.readouterr().out
    assert out.with_suffix(".report.md").is_file()
    assert (
        main(
            [
                "run",
                str(walk),
                "--graph",
                str(out),
                "--start",
                "first-fix",
                "--out",
                str(tmp_path / "run"),
            ]
        )
        == 0
    )


def test_graph_from_waypoints_leaves_out_walks_without_two_taps(tmp_path, capsys):
    """A floor's folder may hold a walk with no tap or one: it draws nothing, so it is left out
    and named (on the console and in the report); with no walk of two taps it is an error that
    names the file."""
    import gzip

    from tests.conftest import REPO
    from workstation.cli import main

    walk = REPO / "tests" / "data" / "msilc" / "5dd9e7aac5b77e0006b1732b.txt.gz"
    lines = gzip.decompress(walk.read_bytes()).decode().splitlines(keepends=True)
    untapped = tmp_path / "untapped.txt"
    untapped.write_text("".join(ln for ln in lines if "\tTYPE_WAYPOINT\t" not in ln))
    out = tmp_path / "g.yaml"
    assert main(["graph", "from-waypoints", str(walk), str(untapped), "-o", str(out)]) == 0
    said = capsys.readouterr()
    printed = said.out
    # reading the walks is said walk by walk (issue #50 item 9: 36 s without a word)
    assert "[2/2] untapped.txt" in said.err and "[1/1] walk 1" in said.err
    assert (
        "of 1 walk (" in printed
        and f"left out 1 walk with fewer than two taps: {untapped}" in printed
    )
    assert (
        f"fewer than two taps (nothing to draw): {untapped}"
        in out.with_suffix(".report.md").read_text()
    )
    assert main(["graph", "from-waypoints", str(untapped), "-o", str(tmp_path / "h.yaml")]) == 2
    err = capsys.readouterr().err
    assert "untapped.txt" in err and "two ground-truth points" in err


def test_every_output_of_from_waypoints_is_checked_before_any_is_written(tmp_path, capsys):
    """Issue #67 item 5: with G.report.md a folder, `graph from-waypoints -o G.yaml` exited 2
    after writing G.yaml. Each output (and the graph's backup place) is checked first: one line
    naming the one in the way, nothing written."""
    from tests.conftest import REPO
    from workstation.cli import main

    walk = REPO / "sample_sessions" / "msilc-site1-f1-walk"
    out = tmp_path / "g.yaml"
    out.with_suffix(".report.md").mkdir()
    assert main(["graph", "from-waypoints", str(walk), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "g.report.md: is not a regular file" in err and not out.exists()
    out.with_suffix(".report.md").rmdir()
    assert main(["graph", "from-waypoints", str(walk), "-o", str(out)]) == 0
    (tmp_path / "g.yaml.bak").mkdir()  # where the previous graph would be kept
    before = out.read_bytes()
    assert main(["graph", "from-waypoints", str(walk), "-o", str(out), "--per-tap"]) == 2
    err = capsys.readouterr().err
    assert "g.yaml.bak: is not a regular file: the previous g.yaml is kept there" in err
    assert out.read_bytes() == before and ".tmp" not in err
