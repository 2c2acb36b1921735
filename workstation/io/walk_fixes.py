"""A surveyor's fix of one campaign walk, written where the campaign reads it (beyond the paper).

A campaign lists the walks that need the surveyor (an ambiguous start, nothing matched) and
reads their fixes from the building's ``starts.yaml`` and ``ends.yaml`` (``walk: landmark``,
:mod:`.campaign.layout`). Its report gives each such walk the command that opens it in the
panel with ``--campaign-walk NAME`` and those files (``--starts-file``, ``--ends-file``): then
"Start here" and "End here" (and finding the start or end again) also write the walk's entry
there, so the next campaign run takes it — no walk name typed by hand. The file is rewritten
whole (its comments are not kept; the previous file stays beside it as ``.bak``), atomically;
in a store (a campaign there, issue #54) as one object, the previous one copied to ``.bak``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from workstation.errors import InputError
from workstation.io.store import put_text, read_via_local
from workstation.io.yamlio import dump_yaml, load_yaml


@dataclass(frozen=True)
class WalkFixes:
    """Where one campaign walk's start and end are given: its name in the campaign (the key of
    its entries) and the building's files (None: not written)."""

    name: str
    starts: Path | None = None
    ends: Path | None = None

    def record(self, what: str, node: str | None) -> str:
        """Write (``node``) or drop (None) this walk's entry in the file for ``what`` ("start"
        or "end"); what was done, in words for the panel ("" when there is no such file)."""
        path = self.starts if what == "start" else self.ends
        if path is None:
            return ""
        try:
            data = (read_via_local(path, lambda p: load_yaml(p, f"walk {what}s"))
                    if path.is_file() else None)  # fmt: skip
            data = {} if data is None else data
            if not isinstance(data, dict):
                raise InputError(path, f"walk {what}s are a mapping 'walk name: landmark id'")
        except InputError as e:
            return f"; NOT updated: {e}"
        if node:
            data[self.name] = node
        elif self.name in data:
            del data[self.name]
        else:
            return ""
        try:
            text = dump_yaml({str(k): str(v) for k, v in data.items()})
            put_text(path, text, backup=True)
        except (OSError, InputError) as e:  # a full disk, a store that refused
            return f"; {path} NOT updated: {getattr(e, 'strerror', None) or e}"
        said = f"{self.name}: {node}" if node else f"{self.name} taken out"
        return f"; written to {path} ({said}): the next campaign run takes it"
