"""The editor's undo history, tab by tab, and what it says to whom (issues #50 item 7, #51).

Every graph edit is kept as the graph before and after it and who made it — a browser tab's
id, or None for the Python API. Undo in a tab takes back *that tab's* last edit (one shared
history let tab B's Undo take back tab A's new landmark, without a word):

- when it is the last edit of all, the graph before it comes back as it was;
- when other tabs edited since, only that edit's own change is taken out of the graph as it is
  now (:func:`carry`): the landmarks and edges it touched go back, every later edit of the
  other tabs stays, and the message says how many were kept;
- when a landmark it touched was changed since by someone else, it cannot be taken back without
  losing that change: refused, naming the landmark and the edit (:class:`Conflict`).

Redo is the same the other way. What the editor says (its ``message``) is kept per tab too: a
tab's status line shows what *its* actions did, and what another tab changed meanwhile — a new
tab opened with another tab's "refused …".
"""

from __future__ import annotations

import itertools
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace

from workstation.graph import LandmarkGraph

HISTORY = 200  # edits kept for undo


@dataclass(frozen=True)
class Edit:
    before: LandmarkGraph
    after: LandmarkGraph
    what: str  # "moved L01 to (3.00, 4.00)"
    origin: int | None  # the tab that made it; None: the Python API
    seq: int = 0  # when (the order of everything said and done)


class Conflict(Exception):
    """An edit cannot be carried onto the graph as it is: ``node`` was changed since."""

    def __init__(self, node: str):
        super().__init__(node)
        self.node = node


def carry(current: LandmarkGraph, frm: LandmarkGraph, to: LandmarkGraph) -> LandmarkGraph:
    """The change ``frm`` → ``to`` made to ``current``: each landmark that differs between them
    becomes as in ``to`` (added, replaced or removed), each edge added or removed between them
    is added or removed; nothing else changes. :class:`Conflict` when a landmark the change
    touches is not in ``current`` as it was in ``frm``."""
    f = {n.id: n for n in frm.nodes}
    t = {n.id: n for n in to.nodes}
    c = {n.id: n for n in current.nodes}
    touched = {i for i in f.keys() | t.keys() if f.get(i) != t.get(i)}
    for i in sorted(touched):
        if c.get(i) != f.get(i):
            raise Conflict(i)
    nodes = [t.get(n.id) if n.id in touched else n for n in current.nodes]
    kept = [n for n in nodes if n is not None]
    for k, n in enumerate(to.nodes):  # the landmarks it brings back, where they stood
        if n.id in touched and n.id not in c:
            kept.insert(min(k, len(kept)), n)
    return replace(current, nodes=tuple(kept), edges=_carried_edges(current, frm, to, kept))


def _carried_edges(current: LandmarkGraph, frm: LandmarkGraph, to: LandmarkGraph,
                   kept: list) -> tuple:  # fmt: skip
    """``current``'s edges with those the change removed gone and those it added added, each
    between two landmarks that are there (``kept``)."""
    ids = {n.id for n in kept}
    gone, new = set(frm.edges) - set(to.edges), set(to.edges) - set(frm.edges)
    edges = [e for e in current.edges if e not in gone and e[0] in ids and e[1] in ids]
    edges += [e for e in to.edges if e in new and e not in edges and e[0] in ids and e[1] in ids]
    return tuple(edges)


class History:
    """The edits to undo and to redo, each with its tab; and what was said to each tab."""

    def __init__(self, size: int = HISTORY):
        self.size = size
        self.done: list[Edit] = []
        self.undone: list[Edit] = []
        self._seq = itertools.count(1)
        self._said: dict[int | None, tuple[int, str]] = {}
        self._last = "ready"
        self._local = threading.local()

    # ---- who is acting -----------------------------------------------------------------------
    @contextmanager
    def by(self, origin: int | None) -> Iterator[None]:
        """What is done and said in this block is ``origin``'s (a tab's id)."""
        before = getattr(self._local, "origin", None)
        self._local.origin = origin
        try:
            yield
        finally:
            self._local.origin = before

    @property
    def origin(self) -> int | None:
        return getattr(self._local, "origin", None)

    def tick(self) -> int:
        return next(self._seq)

    # ---- what is said ----------------------------------------------------------------------
    @property
    def message(self) -> str:
        """To the tab acting now, what it was last told; otherwise the last thing said."""
        o = self.origin
        return self._said[o][1] if o is not None and o in self._said else self._last

    def say(self, text: str) -> None:
        """Tell the acting tab (with no tab acting: every tab)."""
        self._said[self.origin] = (self.tick(), text)
        self._last = text

    def said_to(self, origin: int, since: int = 0) -> str:
        """The status line of tab ``origin`` (opened at ``since``): the last thing it was told,
        or told every tab, and the last edit made elsewhere after that."""
        heard = [m for m in (self._said.get(origin), self._said.get(None)) if m and m[0] > since]
        seq, text = max(heard) if heard else (since, "ready")
        other = next((e for e in reversed(self.done) if e.origin != origin and e.seq > seq), None)
        return text + (f" · meanwhile, elsewhere: {other.what}" if other is not None else "")

    # ---- edits -------------------------------------------------------------------------------
    def record(self, before: LandmarkGraph, after: LandmarkGraph, what: str) -> None:
        """A new edit by the acting tab (which can then no longer redo what it undid)."""
        o = self.origin
        self.done.append(Edit(before, after, what, o, self.tick()))
        del self.done[: -self.size]
        self.undone = [e for e in self.undone if e.origin != o]

    def _last_of(self, edits: list[Edit], origin: int | None, anyone: bool) -> int | None:
        for k in range(len(edits) - 1, -1, -1):
            if anyone or edits[k].origin == origin:
                return k
        return None

    def undo(self, current: LandmarkGraph) -> tuple[LandmarkGraph, Edit, int] | None:
        """The graph without the acting tab's last edit (the Python API: the last edit of all),
        that edit, and how many later edits of others it kept; None: nothing to undo.
        :class:`Conflict` (nothing changed) when a landmark it touched was changed since."""
        o = self.origin
        k = self._last_of(self.done, o, anyone=o is None)
        if k is None:
            return None
        e, later = self.done[k], len(self.done) - 1 - k
        g = e.before if later == 0 else carry(current, e.after, e.before)
        del self.done[k]
        self.undone.append(e)
        return g, e, later

    def redo(self, current: LandmarkGraph) -> tuple[LandmarkGraph, Edit, int] | None:
        """The acting tab's last undone edit made again (see :meth:`undo`)."""
        o = self.origin
        k = self._last_of(self.undone, o, anyone=o is None)
        if k is None:
            return None
        e = self.undone[k]
        later = sum(d.seq > e.seq for d in self.done)
        g = e.after if later == 0 and current == e.before else carry(current, e.before, e.after)
        del self.undone[k]
        self.done.append(replace(e, seq=self.tick()))
        return g, e, later
