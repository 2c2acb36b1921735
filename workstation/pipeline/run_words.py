"""A run's summary in a surveyor's words: where the walk ends, what the building's map changed.
Above the tracking package: it reads the summary the tracker's results are written into, and
the tracker reads none of it."""

from __future__ import annotations

from workstation.pipeline.summary import Summary
from workstation.pipeline.tracking.walk_end import HOW


def describe_end(summary: Summary) -> str:
    """Where a run's walk ends, in words, from its summary: "L140 (closed on …)"."""
    return f"{summary.end.node or '—'} ({HOW.get(summary.end.how, '')})"


def what_the_map_did(summary: Summary) -> list[str]:
    """What the building's map changed in a run, in words, from its summary: the chain it chose
    (``chain_by_map``) and how it turned a walk that matched nothing (``open_by_map``, from
    :mod:`.tracking.open_by_map`); empty when it changed nothing."""
    out = []
    by_map = summary.chain_by_map
    if by_map is not None and by_map.rank:
        out.append(
            f"the building's map chose the chain of matches the sensors ranked "
            f"{by_map.rank + 1} of {by_map.chains} (log-likelihood {by_map.gain:+} with "
            f"the map, {-by_map.sensors:+} by the sensors alone)"
        )
    fit = summary.open_by_map
    if fit is not None and (fit.turn_deg or fit.scale != 1.0):
        out.append(
            f"nothing was matched after the start: the building's map turned the walk about its "
            f"start by {fit.turn_deg:+g}° and scaled it by {fit.scale:g} "
            f"({fit.scans} scans) before its end was closed"
        )
    return out
