"""Single walks' starts and ends in a campaign: the surveyor's fix for a walk whose inferred
start was ambiguous (what the building's map says of its candidate starts:
:mod:`..start_by_map`), or that matched nothing (where it ended).
"""

from __future__ import annotations

import difflib

from workstation.errors import InputError
from workstation.graph import LandmarkGraph
from workstation.io.store import read_via_local


def check_starts(spec, keys: list[str], what: str = "starts") -> dict[str, str]:
    """The building's single-walk starts (or ``what`` = "ends": ends) as {walk key: landmark},
    checked: every walk named is one of the building's (``keys``: their names in the output),
    every landmark is in its graph. Raises :class:`InputError` naming the file and the entry."""
    pairs, src = getattr(spec, what), getattr(spec, f"{what}_source")
    if not pairs:
        return {}
    ids = set(read_via_local(spec.graph, LandmarkGraph.load).ids)
    out = {}
    for walk, node in pairs:
        if walk not in keys:
            close = difflib.get_close_matches(walk, keys, n=1)
            raise InputError(src, f"{what}: {walk!r} is no walk of building {spec.name}"
                             + (f" — did you mean {close[0]!r}?" if close else "")
                             + f" (its walks: {', '.join(keys[:8])}{' …' if len(keys) > 8 else ''})")  # fmt: skip
        if node not in ids:
            close = difflib.get_close_matches(node, sorted(ids), n=1)
            raise InputError(src, f"{what}: {walk}: {node!r} is no landmark of {spec.graph}"
                             + (f" — did you mean {close[0]}?" if close else ""))  # fmt: skip
        out[walk] = node
    return out
