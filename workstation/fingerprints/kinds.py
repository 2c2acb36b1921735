"""Kinds of radio map (issue #63): what ``merge --kind`` builds from the walks' merged points.

A kind is one module with one :class:`MapKind` — a name, a line of words and ``build``: the
merged map of the walks' placed scans (kind ``points``, each row with its σ) and the building's
landmark graph when there is one, to the reference points of the new map (positions, floors,
readings in dBm, a σ per row). A map of any kind is then saved, read, merged into a campaign's
report, exported and queried as every radio map is (:class:`.localize.Fingerprints`, its
``kind`` in the file: ``# kind: NAME`` / the metadata's ``kind``), so a new kind is its module
and one line of :data:`KINDS`.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from workstation.errors import InputError, WorkstationError

# a map is a :class:`.localize.Fingerprints` (which reads this registry: not imported here)
Fingerprints = Any


@dataclass(frozen=True)
class MapKind:
    """A kind of radio map: its name, what it is in a line, and how it is built."""

    name: str
    words: str
    build: Callable[[Fingerprints, Any], Fingerprints]  # (merged points, graph or None) → map


def _points(merged: Fingerprints, graph: Any = None) -> Fingerprints:
    return merged


POINTS = MapKind("points", "the walks' scans where the walks placed them (each with its σ)",
                 _points)  # fmt: skip

#: every kind, by name: "module:attribute" of its :class:`MapKind` (imported when used)
KINDS: dict[str, str] = {
    "points": "workstation.fingerprints.kinds:POINTS",
    "interpolated": "workstation.fingerprints.kind_interpolated:KIND",
    "densified": "workstation.fingerprints.quality:KIND",
}
DEFAULT_KIND = "points"


def kind_of(name: str) -> MapKind:
    """The kind registered as ``name``."""
    if name not in KINDS:
        raise WorkstationError(f"no map kind '{name}': the kinds are {', '.join(KINDS)}")
    module, attr = KINDS[name].split(":")
    return getattr(importlib.import_module(module), attr)


def known_kind(path: str | Path, name: str) -> None:
    """A map file's kind is one of :data:`KINDS`, else the file is named with what is wrong."""
    if name not in KINDS:
        raise InputError(path, f"its kind '{name}' is none of {', '.join(KINDS)}")


def build(name: str, merged: Fingerprints, graph: Any = None) -> Fingerprints:
    """The map of kind ``name`` built from the walks' merged points ``merged`` (settled, on
    standby none), its ``kind`` set; ``graph``: the building's landmark graph, when known."""
    if merged.kind != "points":
        raise WorkstationError(f"a {name} map is built from a map of points, not of {merged.kind}")
    kind = kind_of(name)
    out = kind.build(merged.settled(), graph)
    if not len(out):
        raise WorkstationError(f"the {name} map has no reference points")
    return replace(out, kind=kind.name, offsets_db=merged.offsets_db)
