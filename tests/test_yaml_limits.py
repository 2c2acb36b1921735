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
    with pytest.raises(InputError, match="nested"):
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
