"""The layering (issues #31, #52): no import circle among workstation's modules — a test walks
the graph of every import, those under ``TYPE_CHECKING`` and inside functions included (a circle
hidden there is still a circle a reader has to hold in mind) — and no import inside a function
except of a heavy library (``workstation._heavy.HEAVY``) or of a module of ours that loads one."""

import ast
import sys
from pathlib import Path

import networkx as nx

PKG = Path(__file__).resolve().parents[1] / "workstation"


def _module(path: Path, root: Path | None = None) -> str:
    """The dotted module name of ``path`` inside the package ``root`` (default: ours)."""
    parts = list(path.relative_to((root or PKG).parent).with_suffix("").parts)
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


def _targets(name: str, path: Path, node, modules) -> tuple[set[str], set[str]]:
    """The modules of ours an import statement in module ``name`` loads, and the top-level
    names of the other libraries it loads."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    if isinstance(node, ast.Import):
        targets = [a.name for a in node.names]
    else:
        base = node.module or ""
        if node.level:
            up = package.split(".")[: len(package.split(".")) - node.level + 1]
            base = ".".join(up + ([base] if base else []))
        targets = [base] + [f"{base}.{a.name}" for a in node.names]
    ours, other = set(), set()
    for t in targets:
        if t.split(".")[0] != "workstation":
            other.add(t.split(".")[0])
            continue
        while t and t not in modules:  # a name inside a module: the module
            t = t.rpartition(".")[0]
        if t and t != name:
            ours.add(t)
        # importing a.b.c first runs the faces of a.b (a package's __init__), unless the
        # importer is inside it (then that face is already loading)
        up = t.rpartition(".")[0]
        while up.count("."):
            if up in modules and not (name + ".").startswith(up + "."):
                ours.add(up)
            up = up.rpartition(".")[0]
    return ours, other


def _every_import(tree: ast.Module):
    """Every import statement of a module: at load, under ``TYPE_CHECKING``, inside functions."""
    return (n for n in ast.walk(tree) if isinstance(n, (ast.Import, ast.ImportFrom)))


def import_graph(every: bool = False) -> nx.DiGraph:
    """Modules of ours → the modules of ours their top level imports (``every``: any import of
    theirs); each node's ``libs``: the other libraries those imports load."""
    g = nx.DiGraph()
    modules = {_module(p): p for p in PKG.rglob("*.py")}
    walk = _every_import if every else _top_level_imports
    for name, path in modules.items():
        g.add_node(name, libs=set())
        for node in walk(ast.parse(path.read_text(encoding="utf-8"))):
            ours, other = _targets(name, path, node, modules)
            g.nodes[name]["libs"] |= other
            for t in ours:
                g.add_edge(name, t)
    return g


def test_the_import_graph_has_no_circle():
    g = import_graph(every=True)
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
    (pkg / "c.py").write_text("def f():\n    from . import d\n")  # inside a function
    (pkg / "d.py").write_text("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n"
                              "    from .c import f\n")  # fmt: skip
    (pkg / "p").mkdir()  # a face that loads a part which needs a module reading the package
    (pkg / "p" / "__init__.py").write_text("from .run import go\n")
    (pkg / "p" / "run.py").write_text("from ..x import y\ngo = y\n")
    (pkg / "p" / "state.py").write_text("S = 1\n")
    (pkg / "x.py").write_text("from .p.state import S\ny = S\n")  # runs p's face first
    monkeypatch.setattr(sys.modules[__name__], "PKG", pkg)
    g = import_graph()
    cycles = sorted(map(sorted, nx.simple_cycles(g)))
    assert ["workstation.p", "workstation.p.run", "workstation.x"] in cycles
    g.remove_nodes_from(["workstation.p", "workstation.p.run", "workstation.p.state", "workstation.x"])
    assert sorted(map(sorted, nx.simple_cycles(g))) == [["workstation.a", "workstation.b"]]
    assert not g.has_edge("workstation.c", "workstation.d")  # not at load
    every = import_graph(every=True)  # the function's and the type checker's imports count
    every.remove_nodes_from(["workstation.p", "workstation.p.run", "workstation.x"])
    assert sorted(map(sorted, nx.simple_cycles(every))) == [
        ["workstation.a", "workstation.b"],
        ["workstation.c", "workstation.d"],
    ]


def test_imports_inside_functions_only_load_heavy_libraries():
    """Every other import is at the top of its module, where the circle check sees it — but
    in the subcommands (``workstation/commands/``, issue #53): each loads its body when it runs,
    so that the parser, ``--help`` and a light command load none of the others' modules (the
    circle check above counts those imports too)."""
    from workstation._heavy import HEAVY, LAZY

    g = import_graph()
    heavy = {
        m for m in g if any(g.nodes[x]["libs"] & set(HEAVY) for x in nx.descendants(g, m) | {m})
    }
    modules = {_module(p): p for p in PKG.rglob("*.py")}
    wrong = []
    for name, path in modules.items():
        if name.startswith(LAZY):
            continue
        for fn in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            for node in ast.walk(fn):
                if isinstance(node, (ast.Import, ast.ImportFrom)):
                    ours, other = _targets(name, path, node, modules)
                    if not (other & set(HEAVY) or ours & heavy):
                        wrong.append(
                            f"{path.relative_to(PKG.parent)}:{node.lineno} {ast.unparse(node)}"
                        )
    assert len(heavy) > 5  # the walk found the modules that load the viewer, panel, figures
    assert not wrong, "imports inside functions of light modules: " + "; ".join(wrong[:10])


def test_the_parser_and_a_walks_summary_load_no_heavy_library():
    """Issue #53: ``workstation --help`` took 0.5 s importing every subcommand's modules
    (networkx, the campaign's, pyarrow…); ``info`` on a path file loaded the same. Both now load
    numpy at most (a fresh interpreter each: what is imported, not how long it takes)."""
    import json
    import subprocess

    from tests.conftest import REPO

    libs = ("networkx", "pandas", "dask", "distributed", "scipy", "pyarrow", "rerun", "viser",
            "matplotlib", "numba", "PIL", "tqdm")  # fmt: skip
    walk = REPO / "tests" / "data" / "msilc" / "5dd9e7aac5b77e0006b1732b.txt.gz"
    probe = (
        "import json, sys\n"
        "from workstation.cli import build_parser, main\n"
        "build_parser()\n"
        "parser = sorted({m.split('.')[0] for m in sys.modules} & set(sys.argv[1:]))\n"
        f"main(['info', {str(walk)!r}])\n"
        "info = sorted({m.split('.')[0] for m in sys.modules} & set(sys.argv[1:]))\n"
        "print(json.dumps([parser, info]))\n"
    )
    out = subprocess.run([sys.executable, "-c", probe, *libs], capture_output=True, text=True,
                         cwd=REPO, check=True)  # fmt: skip
    parser, info = json.loads(out.stdout.strip().splitlines()[-1])
    assert parser == [] and info == []
