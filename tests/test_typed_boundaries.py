"""Between packages, results are typed (issue #52): no function of the pipeline, the layer over
many walks, the campaign, the editor or evaluate that another package imports takes or returns
a bare ``dict`` or ``dict[str, Any]`` — except the JSON writers and readers themselves
(``to_json``/``from_json`` and the like), which turn a typed record into its file and back."""

import ast
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_imports import _module  # noqa: E402

PKG = Path(__file__).resolve().parents[1] / "workstation"
CHECKED = {"pipeline", "walks", "campaign", "editor", "evaluate"}
JSON = {"to_json", "from_json", "to_dict", "from_dict"}  # a record's file form
LOOSE = re.compile(r"\bdict\[str, Any\]|\bdict\b(?!\[)|Mapping\[str, Any\]")


def _package(path: Path, root: Path) -> str:
    return path.relative_to(root).parts[0].removesuffix(".py")


def loose(root: Path = PKG) -> list[str]:
    """Loosely typed functions of the checked packages that another package imports (methods:
    whose class another package imports)."""
    files = list(root.rglob("*.py"))
    offered: dict[tuple[str, str], list[str]] = {}  # (module, name imported) → what is loose
    for p in files:
        if _package(p, root) not in CHECKED:
            continue
        for node in ast.parse(p.read_text(encoding="utf-8")).body:
            fns = [(node.name, node)] if isinstance(node, ast.FunctionDef) else []
            if isinstance(node, ast.ClassDef):
                fns = [(node.name, f) for f in node.body if isinstance(f, ast.FunctionDef)]
            for owner, f in fns:
                if f.name.startswith("_") or f.name in JSON:
                    continue
                sig = ast.unparse(f.args) + " -> " + (ast.unparse(f.returns) if f.returns else "")
                if LOOSE.search(sig):
                    offered.setdefault((_module(p, root), owner), []).append(
                        f"{p.relative_to(root.parent)}:{f.lineno} {f.name}({sig})"
                    )
    found = []
    for p in files:
        for node in ast.walk(ast.parse(p.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.module:
                for a in node.names:
                    got = offered.get((node.module, a.name))
                    if got and _package(p, root) != node.module.split(".")[1]:
                        found += got
    return sorted(set(found))


def test_what_crosses_a_package_is_typed():
    assert not loose(), "typed records across packages, not dicts: " + "; ".join(loose()[:8])


def test_the_check_finds_a_dict_handed_across(tmp_path):
    pkg = tmp_path / "workstation"
    (pkg / "pipeline").mkdir(parents=True)
    (pkg / "viz").mkdir()
    for d in (pkg, pkg / "pipeline", pkg / "viz"):
        (d / "__init__.py").write_text("")
    (pkg / "pipeline" / "m.py").write_text(
        "def figures(x: int) -> dict[str, Any]:\n    return {}\n"
        "def to_json() -> dict[str, Any]:\n    return {}\n"
        "def typed(x: int) -> int:\n    return x\n"
    )
    (pkg / "viz" / "v.py").write_text("from workstation.pipeline.m import figures, to_json, typed\n")
    assert [f.split(" ")[1].split("(")[0] for f in loose(pkg)] == ["figures"]
