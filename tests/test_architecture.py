"""docs/architecture.md against the code (issue #52): every package of ours sits in one layer of
its table, and every import between packages — under ``TYPE_CHECKING`` and inside functions
included — goes to a layer below."""

import re
import sys
from pathlib import Path

import networkx as nx

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_imports import PKG, import_graph  # noqa: E402

DOC = PKG.parent / "docs" / "architecture.md"


def layers(text: str) -> dict[str, int]:
    """Package or root module → its layer, from the page's table (the first, above any
    ``##`` section)."""
    out = {}
    for m in re.finditer(r"^\| (\d+) \| ([^|]+) \|", text.split("\n## ")[0], flags=re.M):
        for name in re.findall(r"`([\w]+)`", m.group(2)):
            out[name] = int(m.group(1))
    return out


def package_of(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else parts[0]


def package_arrows(g: nx.DiGraph) -> set[tuple[str, str]]:
    return {(package_of(a), package_of(b)) for a, b in g.edges} - {
        (p, p) for p in map(package_of, g)
    }


def wrong_arrows(layer: dict[str, int], arrows) -> list[str]:
    return sorted(f"{a} → {b}" for a, b in arrows if layer[a] <= layer[b])


def test_every_package_is_on_the_page():
    layer = layers(DOC.read_text(encoding="utf-8"))
    code = {package_of(m) for m in import_graph(every=True)}
    assert code - layer.keys() == set(), "packages the page does not place"
    assert layer.keys() - code == set(), "the page places packages that are gone"


def test_every_import_between_packages_goes_down():
    layer = layers(DOC.read_text(encoding="utf-8"))
    arrows = package_arrows(import_graph(every=True))
    assert len(arrows) > 50  # the walk found the imports
    assert not wrong_arrows(layer, arrows), "imports that go up or sideways"


def test_the_figure_names_each_package_in_its_layer():
    text = DOC.read_text(encoding="utf-8")
    figure = {int(n): label for n, label in re.findall(r'L(\d)\["(.*?)"\]', text)}
    for name, n in layers(text).items():
        if name not in ("_heavy", "workstation"):  # the face and the heavy list: not drawn
            assert re.search(rf"\b{re.escape(name)}\b", figure[n]), (name, n)


def test_the_check_sees_an_arrow_up():
    layer = {"pipeline": 3, "walks": 4, "errors": 0}
    assert wrong_arrows(layer, {("walks", "pipeline"), ("pipeline", "errors")}) == []
    assert wrong_arrows(layer, {("pipeline", "walks")}) == ["pipeline → walks"]
    assert wrong_arrows(layer, {("pipeline", "pipeline")}) == ["pipeline → pipeline"]


def test_decisions_say_what_the_product_does_in_under_600_lines():
    """docs/decisions.md states today's choices, each with its measurement; the measurements in
    full and what was not adopted live in docs/experiments.md, dated (issue #52)."""
    text = (PKG.parent / "docs" / "decisions.md").read_text(encoding="utf-8")
    assert len(text.splitlines()) < 600
    assert not re.search(r"\bsession \d+", text), "experiments.md dates; decisions.md says what is"
    assert (PKG.parent / "docs" / "experiments.md").is_file() and "experiments.md#" in text


def child_arrows(g: nx.DiGraph, package: str) -> set[tuple[str, str]]:
    """Inside ``package`` (dotted), the import arrows between its children — a module, its
    ``__init__``, or a sub-package drawn as one (as ``farm-studio look`` draws a folder)."""
    depth = package.count(".") + 1

    def child(module: str) -> str | None:
        parts = module.split(".")
        if parts[:depth] != package.split("."):
            return None
        return parts[depth] if len(parts) > depth else "__init__"

    out = set()
    for a, b in g.edges:
        ca, cb = child(a), child(b)
        if ca is not None and cb is not None and ca != cb:
            out.add((ca, cb))
    return out


def test_no_import_runs_back_up_inside_any_package():
    """Issue #65 item 3: in every package, its modules and sub-packages (each drawn as one room)
    stand in floors — no loop of imports between them, e.g. ``pipeline/start.py`` taking a name
    from ``pipeline/tracking/`` while ``tracking/run.py`` imports ``start``."""
    g = import_graph(every=True)
    packages = sorted({m.rsplit(".", 1)[0] for m in g} | {"workstation"})
    assert "workstation.pipeline.tracking" in packages
    loops = []
    for pkg in packages:
        h = nx.DiGraph(child_arrows(g, pkg))
        h.remove_edges_from([(a, b) for a, b in list(h.edges) if a == "__init__"])  # the face
        loops += [f"{pkg}: " + " → ".join(c + c[:1]) for c in nx.simple_cycles(h)]
    assert not loops, "imports that run back up: " + "; ".join(loops[:5])


def test_the_package_check_sees_a_loop_through_a_sub_package():
    g = nx.DiGraph([("workstation.pipeline.start", "workstation.pipeline.tracking.state"),
                    ("workstation.pipeline.tracking.run", "workstation.pipeline.start")])  # fmt: skip
    assert child_arrows(g, "workstation.pipeline") == {("start", "tracking"), ("tracking", "start")}
    assert child_arrows(g, "workstation.pipeline.tracking") == set()
