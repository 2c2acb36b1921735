"""Each walk's ``summary.json`` in a campaign's output, as the passes of one run read it.

A run reads every walk's summary four times — the shared starts, the map pass, the handed-over
starts, the report — and from a bucket each read took three requests (is it a file, how long,
the bytes), one after another in the client: 12 a walk, 12,000 at 1,000 walks (issue #66: the
campaign in a store took 2 × its time on disk). Here what this run wrote is kept as it was
written, and the rest is read once, in one request."""

from __future__ import annotations

import json

from workstation.campaign.jobs import file_digest
from workstation.campaign.walk_result import WalkResult
from workstation.io.store import get_bytes, listed, put_text


class Records:
    """The walks' results of the campaign output ``out`` (their ``summary.json``), by walk key."""

    def __init__(self, out) -> None:
        self.out = out
        self._known: dict[str, WalkResult] = {}

    def path(self, key: str):
        return self.out / "walks" / key / "summary.json"

    def get(self, key: str) -> WalkResult:
        """The walk's result (``missing`` when it has none yet)."""
        if key not in self._known:
            data = get_bytes(self.path(key))
            self._known[key] = WalkResult.from_json(json.loads(data) if data is not None else {},
                                                    key)  # fmt: skip
        return self._known[key]

    def keep(self, key: str, text: str) -> None:
        """What was just written for the walk (its ``summary.json``'s text), as a read of the
        file gives it back."""
        self._known[key] = WalkResult.from_json(json.loads(text), key)

    def write(self, res: WalkResult) -> None:
        text = summary_text(res)
        put_text(self.path(res.key), text)
        self.keep(res.key, text)


def summary_text(res: WalkResult) -> str:
    """A walk's ``summary.json`` as the campaign writes it."""
    return json.dumps(res.to_json(), indent=1, default=str)


class WalkFiles:
    """Which files a building's walks have in the campaign output ``out``: in a store, one
    listing of its ``walks/BUILDING/`` (a few requests where asking for each walk's file was a
    request apiece, twice a walk); on disk each file is asked."""

    def __init__(self, out, building: str) -> None:
        self.out, self.building = out, building
        self._tags = listed(out / "walks" / building)

    def path(self, key: str, name: str):
        return self.out / "walks" / key / name

    def _rel(self, key: str, name: str) -> str:
        return f"{key[len(self.building) + 1:]}/{name}"

    def has(self, key: str, name: str) -> bool:
        if self._tags is None:
            return self.path(key, name).is_file()
        return self._rel(key, name) in self._tags

    def digest(self, key: str, name: str) -> str:
        """The file's :func:`~workstation.campaign.jobs.file_digest`."""
        tag = None if self._tags is None else self._tags.get(self._rel(key, name), "missing")
        return file_digest(self.path(key, name), tag)
