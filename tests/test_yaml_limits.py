"""YAML inputs that would exhaust memory, recursion or floats are refused with a message naming
the file (issue #18): alias bombs, deep nesting, integers too large for a float."""

import pytest

from workstation.errors import InputError, WorkstationError
from workstation.graph import LandmarkGraph
from workstation.params import Params

BOMB = """a: &a ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]
b: &b [*a,*a,*a,*a,*a,*a,*a,*a,*a]
c: &c [*b,*b,*b,*b,*b,*b,*b,*b,*b]
d: &d [*c,*c,*c,*c,*c,*c,*c,*c,*c]
e: &e [*d,*d,*d,*d,*d,*d,*d,*d,*d]
nodes: [{id: A, x: 0, y: 0, floor: 0, name: *e}]
edges: []
"""


def test_alias_bomb_is_refused_quickly(tmp_path):
    p = tmp_path / "graph.yaml"
    p.write_text(BOMB)
    with pytest.raises(InputError, match="graph.yaml.*aliases"):
        LandmarkGraph.load(p)
    (tmp_path / "params.yaml").write_text("belief: &x {threshold: 20}\nradiomap: *x\n")
    with pytest.raises(InputError, match="aliases"):
        Params.load(tmp_path / "params.yaml")


def test_deep_nesting_is_refused(tmp_path):
    p = tmp_path / "graph.yaml"
    p.write_text("nodes: " + "[" * 5000 + "]" * 5000 + "\n")
    with pytest.raises(InputError, match="nest"):  # ours, or libyaml's "maximum nesting depth"
        LandmarkGraph.load(p)


@pytest.mark.parametrize("value", ["1" + "0" * 400, "1e400", ".nan", "-.inf"])
def test_numbers_that_do_not_fit_are_refused(tmp_path, value):
    p = tmp_path / "graph.yaml"
    p.write_text(f"nodes: [{{id: A, x: {value}, y: 0, floor: 0}}]\nedges: []\n")
    with pytest.raises(WorkstationError, match="x must be a finite number"):
        LandmarkGraph.load(p)
    q = tmp_path / "params.yaml"
    q.write_text(f"belief: {{threshold: {value}}}\n")
    with pytest.raises(WorkstationError):
        Params.load(q)


def test_a_key_given_twice_is_refused_with_its_line(tmp_path):
    """Issue #33: a second `belief:` section silently replaced the first."""
    q = tmp_path / "params.yaml"
    q.write_text("belief:\n  threshold: 20\nradiomap:\n  max_sigma_m: 2\nbelief:\n  threshold: 5\n")
    with pytest.raises(InputError, match="'belief' is given twice") as e:
        Params.load(q)
    assert e.value.line == 5 and str(q) in str(e.value)


def test_a_5000_digit_integer_is_a_message_not_a_traceback(tmp_path):
    p = tmp_path / "graph.yaml"
    p.write_text(f"nodes: [{{id: A, x: {'9' * 5000}, y: 0, floor: 0}}]\nedges: []\n")
    with pytest.raises(InputError, match="graph.yaml"):
        LandmarkGraph.load(p)
    q = tmp_path / "params.yaml"
    q.write_text(f"belief: {{threshold: {'9' * 5000}}}\n")
    with pytest.raises(InputError, match="params.yaml"):
        Params.load(q)


def test_oneway_must_be_a_boolean(tmp_path):
    """Issue #33: `oneway: "false"` (a string, so true) made a directed edge."""
    from workstation.errors import GraphError

    p = tmp_path / "graph.yaml"
    p.write_text(
        "nodes: [{id: A, x: 0, y: 0, floor: 0}, {id: B, x: 5, y: 0, floor: 0}]\n"
        'edges: [{from: A, to: B, oneway: "false"}]\n'
    )
    with pytest.raises(GraphError, match="oneway must be true or false"):
        LandmarkGraph.load(p)
