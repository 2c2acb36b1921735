"""Between packages, results are typed (issue #52): no function of the pipeline, the layer over
many walks, the campaign, the editor or evaluate that another package imports takes or returns
a bare ``dict`` or ``dict[str, Any]`` — except the JSON writers and readers themselves
(``to_json``/``from_json`` and the like), which turn a typed record into its file and back.
Issue #65: no public function of those packages and ``session`` at all, imported elsewhere or
not, takes or returns ``dict``/``Mapping`` of anything or ``Any`` (a mapping of typed values,
``dict[str, float]``, is typed)."""

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
#: issue #65's stricter reading: ``Any`` anywhere, a ``Mapping`` of anything
UNTYPED = re.compile(r"\bdict\b(?!\[)|\bMapping\b(?!\[)|\bAny\b")
PUBLIC = CHECKED | {"session"}


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


def _public_functions(path: Path):
    """Each public function of a module, and each public method of its public classes."""
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.FunctionDef) and not node.name.startswith("_"):
            yield node
        elif isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
            yield from (f for f in node.body if isinstance(f, ast.FunctionDef)
                        and not f.name.startswith("_"))  # fmt: skip


def untyped(root: Path = PKG) -> list[str]:
    """Public functions of the packages in ``PUBLIC`` (private modules aside) whose signature
    has a dict or mapping of anything, or ``Any`` — the JSON readers and writers aside."""
    found = []
    for p in sorted(root.rglob("*.py")):
        rel = p.relative_to(root)
        if rel.parts[0].removesuffix(".py") not in PUBLIC:
            continue
        if any(part.startswith("_") and part != "__init__.py" for part in rel.parts):
            continue
        for f in _public_functions(p):
            if f.name in JSON:
                continue
            sig = ast.unparse(f.args) + " -> " + (ast.unparse(f.returns) if f.returns else "")
            if UNTYPED.search(sig):
                found.append(f"{rel}:{f.lineno} {f.name}({sig})")
    return found


def test_no_public_function_is_loosely_typed():
    assert not untyped(), "records, not dicts (issue #65): " + "; ".join(untyped()[:8])


def test_the_stricter_check_finds_any_and_a_bare_mapping(tmp_path):
    pkg = tmp_path / "workstation"
    (pkg / "session").mkdir(parents=True)
    (pkg / "session" / "_private.py").write_text("def loose(x: Any) -> None: ...\n")
    (pkg / "session" / "m.py").write_text(
        "def a(x: Any) -> int: ...\n"
        "def b(x: Mapping) -> int: ...\n"
        "def c(x: Mapping[str, float]) -> dict[str, int]: ...\n"
        "def _d(x: Any) -> None: ...\n"
        "def to_json() -> dict[str, Any]: ...\n"
        "class R:\n    def e(self, **kw: Any) -> None: ...\n"
    )
    assert [f.split(" ")[1].split("(")[0] for f in untyped(pkg)] == ["a", "b", "e"]


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
