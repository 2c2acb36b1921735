"""Shared text-log parsing: typed errors with line numbers, time ordering and duplicates."""

from __future__ import annotations

import os
import zlib
from collections.abc import Callable
from pathlib import Path
from typing import Protocol

import numpy as np

from workstation.errors import InputError


def read_text_lines(path: Path) -> list[str]:
    """The file's lines (undecodable bytes replaced); an error if it is missing or empty."""
    return text_lines(read_bytes(path))


def text_lines(data: bytes | bytearray) -> list[str]:
    return data.decode("utf-8", errors="replace").replace("\r", "").split("\n")


GZIP_MAGIC = b"\x1f\x8b"
#: the most a compressed walk may unpack to (a decompression bomb is refused, not read)
MAX_UNPACKED_BYTES = 1 << 30


#: the byte-order mark an editor may put before UTF-8 text; read past, like any reader does
UTF8_BOM = b"\xef\xbb\xbf"


def read_bytes(path: Path) -> bytearray:
    """The file's bytes (read into one buffer: no copy); an error if it is missing, unreadable
    or empty. A gzipped file (recognised by its magic bytes, whatever its name) is unpacked,
    up to :data:`MAX_UNPACKED_BYTES`."""
    try:
        with open(path, "rb") as f:
            data = bytearray(os.fstat(f.fileno()).st_size)
            if data:
                del data[f.readinto(data) :]  # in place
            else:  # no size known (a pipe, /proc)
                data = bytearray(f.read())
        if data[:2] == GZIP_MAGIC:
            data = _gunzip(path, data)
        if data[:3] == UTF8_BOM:  # an editor or spreadsheet saved it (issue #51)
            del data[:3]
    except FileNotFoundError:
        raise InputError(path, "no such file") from None
    except IsADirectoryError:
        raise InputError(path, "is a folder, not a logfile") from None
    except OSError as e:
        raise InputError(path, f"cannot read: {e.strerror}") from None
    if not data or data.isspace():
        raise InputError(path, "file is empty")
    return data


def _gunzip(path: Path, packed: bytearray) -> bytearray:
    out = bytearray()
    d = zlib.decompressobj(wbits=47)  # gzip header, concatenated members handled below
    data = bytes(packed)
    try:
        while data:
            out += d.decompress(data, MAX_UNPACKED_BYTES + 1 - len(out))
            if len(out) > MAX_UNPACKED_BYTES:
                raise InputError(
                    path, f"unpacks to more than {MAX_UNPACKED_BYTES >> 20} MiB: not read"
                )
            if d.unconsumed_tail:
                data = d.unconsumed_tail
                continue
            data = d.unused_data  # a next gzip member (``cat a.gz b.gz``)
            if data:
                if data[:2] != GZIP_MAGIC:
                    break  # trailing garbage after the last member: ignored, as gzip does
                d = zlib.decompressobj(wbits=47)
        if not d.eof and not d.unconsumed_tail:
            raise InputError(path, "gzip stream is truncated (the file was cut short)")
    except zlib.error as e:
        raise InputError(path, f"not a readable gzip file: {e}") from None
    return out


def head_text(path: Path, n_bytes: int = 8192) -> str:
    """The first ``n_bytes`` of the file as text (unpacked when it is gzipped)."""
    with open(path, "rb") as f:
        head = f.read(n_bytes)
        if head[:2] == GZIP_MAGIC:
            # text packs ~5-10x: 64 packed bytes per wanted byte is ample for a header
            packed = head + f.read(n_bytes * 63)
            try:
                head = zlib.decompressobj(wbits=47).decompress(packed, n_bytes)
            except zlib.error as e:
                raise InputError(path, f"not a readable gzip file: {e}") from None
    return head.removeprefix(UTF8_BOM).decode("utf-8", errors="replace")


class Records:
    """Lines of one record type: their 1-based line numbers and their split fields."""

    def __init__(self, kind: str):
        self.kind = kind
        self.lines: list[int] = []
        self.fields: list[list[str]] = []

    def add(self, lineno: int, fields: list[str]) -> None:
        self.lines.append(lineno)
        self.fields.append(fields)

    def __len__(self) -> int:
        return len(self.lines)

    def require_fields(self, path: Path, n: int, layout: str) -> None:
        """Every line has at least ``n`` fields (record type included)."""
        if not self.fields:
            return
        lens = np.fromiter(map(len, self.fields), dtype=np.int64, count=len(self.fields))
        refuse_first(
            path, lens < n, self.lines,
            lambda i: f"{self.kind} record has {lens[i] - 1} fields, expected {n - 1} ({layout})",
        )  # fmt: skip

    def column(self, k: int) -> list[str]:
        return [f[k] for f in self.fields]

    def numbers(self, path: Path, cols: dict[int, str]) -> dict[str, np.ndarray]:
        """Parse columns {index: name} as finite float64; the first bad value is reported."""
        out = {}
        for k, name in cols.items():
            raw = self.column(k)
            try:
                v = np.array(raw, dtype=np.float64)
                ok = np.isfinite(v)
                if ok.all():
                    out[name] = v
                    continue
                i = int(np.flatnonzero(~ok)[0])
            except ValueError:
                i = next(j for j, s in enumerate(raw) if not _is_float(s))
            raise InputError(
                path,
                f"{self.kind} {name}: {raw[i].strip()[:40]!r} is not a finite number",
                self.lines[i],
            )
        return out


# a text field of a walk (an SSID is 32 bytes, a BSSID 17 characters): one 300,000-character
# SSID made numpy size every SSID of the walk to it (2.4 GB for a 4-MB logfile)
MAX_TEXT_FIELD = 256


class LineIndex(Protocol):
    """The file line of each record (a list, or the bulk reader's index over its blocks)."""

    def __getitem__(self, i: int, /) -> int: ...

    def __len__(self) -> int: ...


class RecordsLike(Protocol):
    """Records of one type read line by line (:class:`Records`) or in bulk (``_bulk``)."""

    @property
    def lines(self) -> LineIndex: ...

    def __len__(self) -> int: ...

    def column(self, k: int) -> list[str]: ...


def text_column(path: Path, r: RecordsLike, k: int, what: str) -> list[str]:
    """Column ``k`` of records ``r`` as text, each at most ``MAX_TEXT_FIELD`` characters; a
    longer one is refused with its line."""
    vals = r.column(k)
    lens = np.fromiter(map(len, vals), dtype=np.int64, count=len(vals))
    refuse_first(
        path, lens > MAX_TEXT_FIELD, r.lines,
        lambda i: f"{what} of {lens[i]:,} characters (at most {MAX_TEXT_FIELD})",
    )  # fmt: skip
    return vals


def refuse_first(path: Path, bad: np.ndarray, lines: LineIndex, say: Callable[[int], str]) -> None:
    """An InputError at the first record where ``bad`` holds, with its line and ``say(i)``."""
    idx = np.flatnonzero(bad)
    if idx.size:
        i = int(idx[0])
        raise InputError(path, say(i), lines[i])


def _is_float(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True


MAX_BACK_S = 2.0  # a stream's time may step back this far (event jitter); further: two recordings


def order_times(
    t: np.ndarray,
    name: str,
    warnings: list[str],
    path: Path | None = None,
    lines: LineIndex | None = None,  # fmt: skip
) -> np.ndarray:
    """Indices that sort ``t`` and drop repeated timestamps (first kept), with warnings. With
    ``path`` and the samples' ``lines``: a step back in time of more than ``MAX_BACK_S`` is
    refused, naming its line — walks concatenated into one file (sorted, they interleave: the
    museum's 224 MB of joined walks gave 129 m at the fixes with exit 0)."""
    if path is not None and lines is not None and t.size > 1:
        back = np.flatnonzero(np.diff(t) < -MAX_BACK_S)
        if back.size:
            i = int(back[0])
            raise InputError(
                path,
                f"{name}: time goes back {t[i] - t[i + 1]:.1f} s here ({t[i]:.3f} → "
                f"{t[i + 1]:.3f} s): two recordings joined in one file? Split it into walks",
                int(lines[i + 1]),
            )
    order = np.argsort(t, kind="stable")
    n_unsorted = int(np.count_nonzero(np.diff(t) < 0))
    if n_unsorted:
        warnings.append(f"{name}: {n_unsorted} samples out of time order, sorted")
    ts = t[order]
    dup = np.zeros(ts.size, bool)
    dup[1:] = ts[1:] == ts[:-1]
    if dup.any():
        warnings.append(f"{name}: {int(dup.sum())} samples with a repeated timestamp dropped")
    return order[~dup]


def order_readings(t: np.ndarray, key: np.ndarray, name: str, warnings: list[str]) -> np.ndarray:
    """Indices that sort readings by time, dropping repeated (time, key) pairs."""
    order = np.lexsort((key, t))  # by t, then key; stable
    n_unsorted = int(np.count_nonzero(np.diff(t) < 0))
    if n_unsorted:
        warnings.append(f"{name}: {n_unsorted} readings out of time order, sorted")
    ts, ks = t[order], key[order]
    dup = np.zeros(ts.size, bool)
    dup[1:] = (ts[1:] == ts[:-1]) & (ks[1:] == ks[:-1])
    if dup.any():
        warnings.append(f"{name}: {int(dup.sum())} repeated readings (same scan and AP) dropped")
    return order[~dup]
