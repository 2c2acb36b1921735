"""Vectorized splitting of a Microsoft ILC path file (``ms<TAB>TYPE_…<TAB>fields…``) by record
type (issue #53: the line-by-line split took 20–30 ms of a 31-s walk's 30 ms in a campaign).

As :mod:`._bulk` does for GetSensorData: newline and tab positions found with numpy give each
line's extent, field count and record type (grouped exactly, by the type's bytes); the wanted
fields of each type are parsed by Arrow's CSV reader (:func:`._bulk.parse_fields`). Anything
this path does not take exactly as the line-by-line reader would — a line with leading
whitespace, a ``#`` line that is not a header, a line without a type, an unknown type, a type
whose lines differ in field count or hold a value Arrow refuses, a file larger than
``MAX_BYTES`` — returns ``None``: the line reader then reads the file and names the bad line.
A test holds the two equal on mutated files.
"""

from __future__ import annotations

import numpy as np

from workstation.session._bulk import BulkRecords, Unparsed, lines_array, parse_fields

MAX_BYTES = 256 << 20  # one pass over the whole file; a larger one is read line by line
TYPE_WIDTH = 48  # the longest type compared in bulk (TYPE_MAGNETIC_FIELD_UNCALIBRATED: 32)
_TAB, _NL, _HASH = 9, 10, 35
_SPACE = np.zeros(256, bool)
_SPACE[[9, 10, 11, 12, 13, 28, 29, 30, 31, 32]] = True  # what str.strip() removes in ASCII
_WEIGHTS = np.random.default_rng(53).integers(1, 2**40, TYPE_WIDTH)  # a type's bytes → one int


def _layout(data: bytes | bytearray, buf: np.ndarray) -> tuple[np.ndarray, ...] | None:
    """Where each line starts and ends, the tabs (and each line's first tab and count), the
    blank lines and the header lines; None when a line needs the line reader (leading
    whitespace, a "#…" that is not the header's "#<TAB>")."""
    ends = np.flatnonzero(buf == _NL)
    starts = np.empty_like(ends)
    starts[0], starts[1:] = 0, ends[:-1] + 1
    first = buf[np.minimum(starts, buf.size - 1)]
    blank = ends == starts  # empty, or (below) only whitespace: skipped
    for i in np.flatnonzero(_SPACE[first] & ~blank).tolist():
        if data[starts[i] : ends[i]].decode("utf-8", errors="replace").strip():
            return None  # leading whitespace: the line reader decides what the fields are
        blank[i] = True
    tabs = np.flatnonzero(buf == _TAB)
    a = np.searchsorted(tabs, starts)
    ntab = np.searchsorted(tabs, ends) - a
    head = ~blank & (first == _HASH)
    if (head & (ntab > 0) & (tabs[np.minimum(a, tabs.size - 1)] != starts + 1)).any():
        return None  # "#…" that is not the header's "#<TAB>"
    if (head & (ntab == 0) & (ends - starts != 1)).any():
        return None
    return starts, ends, tabs, a, ntab, blank, head


def _header(data: bytes | bytearray, starts: np.ndarray, ends: np.ndarray, head: np.ndarray) -> dict[str, str]:
    """The ``#`` lines' ``key: value`` fields (the first of each key)."""
    header: dict[str, str] = {}
    for i in np.flatnonzero(head).tolist():
        for f in data[starts[i] : ends[i]].decode("utf-8", errors="replace").split("\t")[1:]:
            key, sep, val = f.partition(":")
            if sep:
                header.setdefault(key.strip(), val.strip())
    return header


def _types(buf: np.ndarray, tabs: np.ndarray, a: np.ndarray, ntab: np.ndarray,
           ends: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:  # fmt: skip
    """Each record's type (the field after the time) as one of the distinct types' bytes:
    (the distinct types, each record's index into them); None when the line reader must read
    it (a type too wide, a NUL in one, two types with one hash)."""
    t0 = tabs[a] + 1
    t1 = np.where(ntab >= 2, tabs[np.minimum(a + 1, tabs.size - 1)], ends)
    wide = int((t1 - t0).max(initial=0))
    if wide > TYPE_WIDTH:
        return None
    at = t0[:, None] + np.arange(wide)
    names = buf[np.minimum(at, buf.size - 1)]
    outside = at >= t1[:, None]
    if (names == 0).any() and not (outside | (names != 0)).all():
        return None  # a NUL in a type would read as a shorter one here
    names[outside] = 0
    # grouped by a hash of the bytes, then each line checked against its group's first: exact
    key = names @ _WEIGHTS[:wide]
    _, first_of, which = np.unique(key, return_index=True, return_inverse=True)
    if not (names == names[first_of[which]]).all():
        return None  # two types with one hash (never seen): the line reader sorts them out
    return names[first_of], which


def split_tsv(
    data: bytes | bytearray, kinds: dict[str, tuple[tuple[int, ...], tuple[int, ...]]]
) -> tuple[dict[str, BulkRecords], dict[str, str], dict[str, int]] | None:
    """Records of each kind in ``kinds`` ({type: (numeric fields, text fields)}, fields counted
    from the time as 0), the ``#`` header and the count of each other ``TYPE_…``; ``None`` if
    the file needs the line-by-line reader."""
    if len(data) > MAX_BYTES:
        return None
    if b"\r" in data:
        data = data.replace(b"\r", b"")
    if not data.endswith(b"\n"):
        data = bytes(data) + b"\n"
    buf = np.frombuffer(data, np.uint8)
    got = _layout(data, buf)
    if got is None:
        return None
    starts, ends, tabs, a, ntab, blank, head = got
    header = _header(data, starts, ends, head)
    rec = np.flatnonzero(~blank & ~head)
    if (ntab[rec] == 0).any():
        return None  # no type: the line reader says so, with its line
    typed = _types(buf, tabs, a[rec], ntab[rec], ends[rec])
    if typed is None:
        return None
    uniq, which = typed
    recs = {k: BulkRecords(k, *spec) for k, spec in kinds.items()}
    skipped: dict[str, int] = {}
    kind_of = np.full(rec.size, -1)
    wanted = list(kinds)
    for u, raw in enumerate(uniq):
        name = raw.tobytes().rstrip(b"\0").decode("utf-8", errors="replace")
        if name in recs:
            kind_of[which == u] = wanted.index(name)
        elif name.startswith("TYPE_"):  # (bytes that decode alike count together, as there)
            skipped[name] = skipped.get(name, 0) + int((which == u).sum())
        else:
            return None  # an unknown type: the line reader names its line
    lines = lines_array(buf, starts, ends)
    try:
        for ki, k in enumerate(wanted):
            rows = rec[kind_of == ki]
            if rows.size:
                fields = parse_fields(lines, rows, *kinds[k], sep="\t")
                recs[k].extend(rows, ntab[rows] + 1, *fields)
    except Unparsed:
        return None
    for r in recs.values():
        r.finish()
    return recs, header, dict(sorted(skipped.items()))
