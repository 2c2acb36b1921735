"""Vectorized splitting of a ``TYPE;field;field…`` text log by record type (issue #17).

The file's bytes are scanned with numpy, never line by line in Python: newline and ``;``
positions give each line's extent, its record type and its field count; the wanted fields of
each record type are parsed in bulk by Arrow's CSV reader, a block of lines at a time, so memory
stays a small multiple of the file. The result behaves exactly as the line-by-line
:class:`~._parse.Records` it replaces, same checks, same errors: a file with anything the bulk
path does not parse cleanly (a value that is no finite number, a line of a known type with an
odd field count, leading whitespace) goes to the line-by-line reader (``None``), which names
the first bad line. A test holds the two readers equal on mutated files.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from workstation.errors import InputError
from workstation.io.arrow import column_to_numpy

if TYPE_CHECKING:
    import pyarrow as pa

_BLOCK_BYTES = 4 << 20
_SEMI, _NL, _PCT = 59, 10, 37
# the first byte of a line the bulk path handles as the line-by-line reader would
_FIRST_OK = np.zeros(256, bool)
_FIRST_OK[[*range(48, 58), *range(65, 91), *range(97, 123), _PCT, _SEMI]] = True


class Unparsed(Exception):
    """This block needs the line-by-line reader."""


class BulkRecords:
    """Lines of one record type found in bulk: line numbers, field counts, parsed fields — the
    interface of the line-by-line :class:`~._parse.Records`."""

    def __init__(self, kind: str, num: tuple[int, ...], txt: tuple[int, ...]):
        self.kind, self._num, self._txt = kind, num, txt
        self._parts: list[tuple] = []
        self._lines = np.empty(0, np.int32)  # 0-based line indices
        self._nf = np.empty(0, np.int32)  # fields per line, the type included
        self._values = np.empty((0, len(num)))  # the fields ``num``, finite
        self._texts = {k: np.empty(0, object) for k in txt}  # the fields ``txt``
        self.lines = _LineNumbers(self._lines)

    def extend(self, lines: np.ndarray, nf: np.ndarray, values: np.ndarray, texts: list) -> None:
        self._parts.append((lines.astype(np.int32), nf.astype(np.int32), values, texts))

    def finish(self) -> None:
        """Join the blocks."""
        if not self._parts:
            return
        parts, self._parts = self._parts, []
        self._lines, self._nf, self._values = (
            np.concatenate([p[k] for p in parts]) for k in range(3)
        )
        self._texts = {k: np.concatenate([p[3][k] for p in parts]) for k in self._txt}
        self.lines = _LineNumbers(self._lines)

    def __len__(self) -> int:
        return int(self._lines.size)

    def column(self, k: int) -> list[str]:
        return self._texts[k].tolist()

    def require_fields(self, path: Path, n: int, layout: str) -> None:
        bad = np.flatnonzero(self._nf < n)
        if bad.size:
            i = int(bad[0])
            raise InputError(
                path,
                f"{self.kind} record has {self._nf[i] - 1} fields, expected {n - 1} ({layout})",
                int(self._lines[i]) + 1,
            )

    def numbers(self, path: Path, cols: dict[int, str]) -> dict[str, np.ndarray]:
        return {name: self._values[:, self._num.index(k)] for k, name in cols.items()}


class _LineNumbers:
    """1-based line numbers, indexable like the list the line-by-line reader keeps."""

    def __init__(self, idx: np.ndarray):
        self._idx = idx

    def __getitem__(self, i: int) -> int:
        return int(self._idx[i]) + 1

    def __len__(self) -> int:
        return int(self._idx.size)


def split_records(
    path: Path, data: bytearray, kinds: dict[str, tuple[tuple[int, ...], tuple[int, ...]]]
) -> tuple[dict[str, BulkRecords], dict[str, str], dict[str, int]] | None:
    """Records of each kind in ``kinds`` ({type: (numeric fields, text fields)}), the
    ``%``-header and the count of every other record type; ``None`` if the file needs the
    line-by-line reader. Raises the line-by-line reader's error for a line that is no record.
    The file is scanned a block of whole lines at a time: no array the size of the file."""
    if b"\r" in data:
        data = data.replace(b"\r", b"")
    if not data.endswith(b"\n"):
        data = data if isinstance(data, bytearray) else bytearray(data)
        data += b"\n"  # in place
    buf = np.frombuffer(data, np.uint8)

    def text_of(start: np.ndarray, end: np.ndarray) -> list[str]:
        return [
            data[s:e].decode("utf-8", errors="replace").strip()
            for s, e in zip(start.tolist(), end.tolist())
        ]

    recs = {k: BulkRecords(k, *spec) for k, spec in kinds.items()}
    state = _State(kinds, recs, text_of)
    pos = 0
    while pos < buf.size:  # blocks of whole lines
        hi = data.find(b"\n", min(pos + _BLOCK_BYTES, buf.size - 1))
        block = buf[pos : hi + 1]
        ends = np.flatnonzero(block == _NL) + pos
        starts = np.empty_like(ends)
        starts[0] = pos
        starts[1:] = ends[:-1] + 1
        if not state.block(buf, starts, ends):
            return None
        pos = hi + 1
    if state.first_bad is not None:
        line, text = state.first_bad
        raise InputError(path, f"not a GetSensorData record: {text[:60]!r}", line + 1)
    for r in recs.values():
        r.finish()
    return recs, state.header, dict(sorted(state.skipped.items()))


class _State:
    """What the blocks found so far."""

    def __init__(
        self, kinds: dict[str, tuple[tuple[int, ...], tuple[int, ...]]],
        recs: dict[str, BulkRecords], text_of: Callable[[np.ndarray, np.ndarray], list[str]],
    ) -> None:  # fmt: skip
        self.kinds, self.recs, self.text_of = kinds, recs, text_of
        self.codes = {int.from_bytes(k.encode(), "little"): k for k in kinds if len(k) == 4}
        self.header: dict[str, str] = {}
        self.skipped: dict[str, int] = {}
        self.first_bad: tuple[int, str] | None = None  # (line index, text)
        self.base = 0  # index of the block's first line

    def _text(self, starts: np.ndarray, ends: np.ndarray, j: int) -> str:
        return self.text_of(starts[j : j + 1], ends[j : j + 1])[0]

    def _bad(self, starts: np.ndarray, ends: np.ndarray, j: int) -> None:
        if self.first_bad is None or self.base + j < self.first_bad[0]:
            self.first_bad = (self.base + j, self._text(starts, ends, j))

    def block(self, buf: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> bool:
        """Split one block of lines; False if the line-by-line reader must decide."""
        if self.base + starts.size >= 2**31:
            return False  # line numbers beyond int32
        try:
            return self._block(buf, starts, ends)
        except Unparsed:
            return False
        finally:
            self.base += starts.size

    def _block(self, buf: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> bool:
        kinds, codes, recs, base = self.kinds, self.codes, self.recs, self.base
        length = ends - starts
        nonblank = length > 0
        first = np.zeros(starts.size, np.uint8)
        first[nonblank] = buf[starts[nonblank]]
        if not _FIRST_OK[first[nonblank]].all():
            return False  # leading whitespace or odd bytes: the line-by-line reader decides
        lo, hi = int(starts[0]), int(ends[-1])
        semi = np.flatnonzero(buf[lo:hi] == _SEMI) + lo
        a = np.searchsorted(semi, starts)
        nsemi = np.searchsorted(semi, ends) - a
        is_header = nonblank & (first == _PCT)
        for i in np.flatnonzero(is_header).tolist():
            line = self._text(starts, ends, i)
            if ":" in line:
                key, _, val = line[1:].partition(":")
                self.header.setdefault(key.strip(), val.strip())
        rec = nonblank & ~is_header
        fs = ends.copy()  # each line's first ';', or its end
        if semi.size:
            fs = np.where(nsemi > 0, semi[np.minimum(a, semi.size - 1)], ends)
        flen = fs - starts
        code = np.zeros(starts.size, np.int64)
        four = rec & (flen == 4)
        if four.any():
            s4 = starts[four]
            b = buf[s4[:, None] + np.arange(4)].astype(np.int64)
            code[four] = b[:, 0] | b[:, 1] << 8 | b[:, 2] << 16 | b[:, 3] << 24
        kind_of = np.full(starts.size, -1)
        names = list(kinds)
        for c, k in codes.items():
            kind_of[four & (code == c)] = names.index(k)
        # lines of no known kind: other record types (counted, skipped), or no record at all
        other = rec & (kind_of < 0)
        typed = other & four & (nsemi > 0)  # a 4-letter type: one check per distinct type
        if typed.any():
            rows = np.flatnonzero(typed)
            uniq, where, counts = np.unique(code[rows], return_index=True, return_counts=True)
            for u, w, c in zip(uniq.tolist(), where.tolist(), counts.tolist()):
                name = self._text(starts, ends, int(rows[w])).split(";", 1)[0]
                if name.isalnum() and name.isupper():
                    self.skipped[name] = self.skipped.get(name, 0) + c
                else:
                    self._bad(starts, ends, int(rows[code[rows] == u][0]))
        for j in np.flatnonzero(other & ~typed).tolist():  # rare: checked as the line reader does
            name = self._text(starts, ends, j).split(";", 1)[0]
            if name in recs:  # a known type the bulk path did not see
                raise Unparsed
            elif nsemi[j] and name.isalnum() and name.isupper():
                self.skipped[name] = self.skipped.get(name, 0) + 1
            else:
                self._bad(starts, ends, j)
        lines = lines_array(buf, starts, ends)
        for ki, k in enumerate(names):
            rows = np.flatnonzero(kind_of == ki)
            if not rows.size:
                continue
            nf = nsemi[rows] + 1
            recs[k].extend(base + rows, nf, *parse_fields(lines, rows, *kinds[k]))
        return True


def lines_array(buf: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> pa.Array:
    """The block's lines (each with its newline) as one Arrow binary array over the file's
    bytes, without copying them."""
    import pyarrow as pa

    lo = int(starts[0])
    offsets = np.append(starts, ends[-1] + 1) - lo
    return pa.Array.from_buffers(
        pa.large_binary(), starts.size,
        [None, pa.py_buffer(offsets.astype(np.int64)), pa.py_buffer(buf[lo : int(ends[-1]) + 1])],
    )  # fmt: skip


def parse_fields(
    lines: pa.Array, rows: np.ndarray, num: tuple[int, ...], txt: tuple[int, ...], sep: str = ";"
) -> tuple:
    """Fields ``num`` (as float64, one column each) and ``txt`` (as strings) of the lines at
    ``rows`` — fields counted from 0 at the line's start, split at ``sep``; raises
    ``Unparsed`` if any fails. The lines are gathered by Arrow's ``take`` (one copy per line,
    in C++) and parsed by its CSV reader: correctly rounded as ``float``, stricter than it (no
    ``1_0``, no padding, UTF-8 checked), never looser."""
    import pyarrow as pa
    import pyarrow.csv as pacsv

    idx = np.ascontiguousarray(rows, dtype=np.int64)  # pa.array(ndarray) would import pandas
    picked = lines.take(pa.Array.from_buffers(pa.int64(), idx.size, [None, pa.py_buffer(idx)]))
    end = int(np.frombuffer(picked.buffers()[1], np.int64, picked.offset + len(picked) + 1)[-1])
    start = int(np.frombuffer(picked.buffers()[1], np.int64, 1, picked.offset * 8)[0])
    text = picked.buffers()[2].slice(start, end - start)
    types = {f"f{k}": pa.float64() for k in num} | {f"f{k}": pa.string() for k in txt}
    try:
        tab = pacsv.read_csv(
            text,
            read_options=pacsv.ReadOptions(autogenerate_column_names=True, use_threads=False),
            parse_options=pacsv.ParseOptions(delimiter=sep, quote_char=False),
            convert_options=pacsv.ConvertOptions(include_columns=list(types), column_types=types),
        )
    except (pa.ArrowInvalid, pa.ArrowKeyError):
        raise Unparsed from None
    if tab.num_rows != rows.size or any(c.null_count for c in tab.columns):
        raise Unparsed
    values = np.column_stack([column_to_numpy(tab[f"f{k}"]) for k in num] or [np.empty(rows.size)])
    if not np.isfinite(values).all():
        raise Unparsed
    texts = {k: np.array(tab[f"f{k}"].combine_chunks().to_pylist(), object) for k in txt}
    return values, texts
