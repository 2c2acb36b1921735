"""Walks on disk for the evaluation: a walk's name from its file, the IPIN museum's walks and
graph in ../shared/data."""

from __future__ import annotations

from pathlib import Path

from workstation.graph import LandmarkGraph
from workstation.graph.importers import graph_from_tra


def walk_name(path) -> str:
    """A walk's name: its file name without ``.txt``/``.gz``-like suffixes."""
    name = Path(path).name
    for suffix in (".gz", ".txt", ".csv", ".log"):
        name = name[: -len(suffix)] if name.lower().endswith(suffix) else name
    return name


def ipin_museum(data: Path) -> tuple[list[Path], LandmarkGraph] | None:
    """The IPIN 2023 museum walks in ../shared/data and the graph from all their .tra files."""
    root = Path(data) / "ipin2023-track3"
    logs = sorted((root / "logfiles").glob("*.txt"))
    tra = sorted((root / "supplementary" / "trajectories").glob("*.tra"))
    if not logs or not tra:
        return None
    return logs, graph_from_tra(list(tra))
