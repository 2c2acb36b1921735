"""Nothing the surveyor made is lost: the editor's recovery copies of unsaved work beside the
graph (``graph.yaml.recovery``, ``params.yaml.recovery``), and what a killed save left behind."""

from __future__ import annotations

from pathlib import Path

from workstation.editor.notes import recovery_text
from workstation.graph import LandmarkGraph
from workstation.io.atomic import atomic_write_text, sweep_leftovers
from workstation.io.store import is_remote
from workstation.params import Params


def recovery_paths(graph: Path | None, params: Path | None, out_dir: Path) -> tuple[Path, Path]:
    """Where the recovery copies of the graph and the parameters go."""
    base = graph if graph is not None and not is_remote(graph) else (
        out_dir / (graph.name if graph is not None else "graph.yaml")
    )  # fmt: skip (a graph in a store: its recovery copy is kept here, in the output folder)
    pp = params or (out_dir / "params.yaml")
    return base.with_name(base.name + ".recovery"), pp.with_name(pp.name + ".recovery")


def keep_recovery(
    paths: tuple[Path, Path], unsaved: list[str], graph: LandmarkGraph, params: Params
) -> None:
    """Write (or clear) the recovery copies of what is ``unsaved`` ("graph", "parameters"); a
    failure here never blocks editing."""
    g, p = paths
    try:
        if "graph" in unsaved:
            atomic_write_text(g, recovery_text(graph))
        else:
            g.unlink(missing_ok=True)
        if "parameters" in unsaved:
            atomic_write_text(p, params.to_yaml())
        else:
            p.unlink(missing_ok=True)
    except OSError:
        pass


def sweep(graph: Path | None, params: Path | None, out_dir: Path) -> int:
    """Temporary files a killed save left beside the graph, the parameters and in the output
    folder (the saves are atomic: the files themselves are whole)."""
    n = 0
    for p in (graph, params):
        if p is not None and not is_remote(p):
            n += len(sweep_leftovers(p.parent, [p.name]))
    return n + len(sweep_leftovers(out_dir))
