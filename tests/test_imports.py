"""The layering (issue #31): no import circle among workstation's modules — a test walks the
graph of module-level imports (imports inside functions and under TYPE_CHECKING are not edges:
they run after both modules are loaded)."""

import ast
import sys
from pathlib import Path

import networkx as nx

PKG = Path(__file__).resolve().parents[1] / "workstation"


def _module(path: Path) -> str:
    parts = list(path.relative_to(PKG.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _top_level_imports(tree: ast.Module):
    """Import nodes run when the module loads: at its top level and in its top-level if/try
    blocks, except under ``if TYPE_CHECKING``."""
    todo = list(tree.body)
    while todo:
        node = todo.pop()
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node
        elif isinstance(node, ast.If):
            if "TYPE_CHECKING" not in ast.unparse(node.test):
                todo += node.body + node.orelse
        elif isinstance(node, ast.Try):
            todo += node.body + node.orelse + node.finalbody
            for h in node.handlers:
                todo += h.body


def import_graph() -> nx.DiGraph:
    g = nx.DiGraph()
    modules = {_module(p): p for p in PKG.rglob("*.py")}
    for name, path in modules.items():
        g.add_node(name)
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        for node in _top_level_imports(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            else:
                base = node.module or ""
                if node.level:
                    up = package.split(".")[: len(package.split(".")) - node.level + 1]
                    base = ".".join(up + ([base] if base else []))
                targets = [base] + [f"{base}.{a.name}" for a in node.names]
            for t in targets:
                while t and t not in modules:  # a name inside a module: the module
                    t = t.rpartition(".")[0]
                if t and t != name:
                    g.add_edge(name, t)
    return g


def test_the_import_graph_has_no_circle():
    g = import_graph()
    assert g.number_of_nodes() > 100 and g.number_of_edges() > 200  # the walk found the graph
    cycles = list(nx.simple_cycles(g))
    assert not cycles, "import circles: " + "; ".join(" → ".join(c + c[:1]) for c in cycles[:5])


def test_the_walk_sees_a_circle_when_there_is_one(tmp_path, monkeypatch):
    """The check itself: two modules importing each other at load are found."""
    pkg = tmp_path / "workstation"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from .b import x\n")
    (pkg / "b.py").write_text("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    pass\n"
                              "from . import a\nx = 1\n")  # fmt: skip
    (pkg / "c.py").write_text("def f():\n    from . import a\n")  # inside a function: no edge
    monkeypatch.setattr(sys.modules[__name__], "PKG", pkg)
    g = import_graph()
    assert sorted(map(sorted, nx.simple_cycles(g))) == [["workstation.a", "workstation.b"]]
    assert not g.has_edge("workstation.c", "workstation.a")
