"""A PNG plan read a strip of rows at a time (issue #55 item 4: memory bounded by what is drawn,
not by the image): a 20,000 × 20,000 plan of 438 KB is 400 MB as stored, 1.2 GB in RGB.

The file's chunks are read in order and its image data inflated as it comes; each strip of rows
is handed to Pillow as a PNG of its own — the last row before it (unfiltered, as the next row's
filter needs it) then the strip's rows as stored, behind the same header, palette and
transparency — so the rows are unfiltered and converted to RGBA by the same code, to the same
bytes, as the whole image would be. Interlaced images and 16 bits a sample are not read so
(:func:`header` says None): the caller decodes those whole, and refuses them beyond 64 Mpixel.
"""

from __future__ import annotations

import io
import struct
import zlib
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

SIGNATURE = b"\x89PNG\r\n\x1a\n"
CHANNELS = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}  # by colour type
PIECE = 1 << 20  # bytes read (and inflated) at a time


@dataclass(frozen=True)
class Header:
    width: int
    height: int
    depth: int
    colour: int

    @property
    def stride(self) -> int:
        """Bytes of one row as stored, its filter byte left out."""
        return (self.width * self.depth * CHANNELS[self.colour] + 7) // 8


def header(path: Path) -> Header | None:
    """The PNG's header when it can be read in strips; None for anything else (not a PNG, an
    interlaced one, 16 bits a sample, a header that does not parse: decoded whole, where
    Pillow says what is wrong)."""
    try:
        with open(path, "rb") as f:
            if f.read(8) != SIGNATURE:
                return None
            kind, data = _chunk(f)
            if kind != b"IHDR" or len(data) != 13:
                return None
            w, h, depth, colour, comp, filt, interlace = struct.unpack(">IIBBBBB", data)
    except (OSError, ValueError, struct.error):
        return None
    ok = (colour in CHANNELS and depth in (1, 2, 4, 8) and (depth == 8 or colour in (0, 3))
          and comp == 0 and filt == 0 and interlace == 0 and w > 0 and h > 0)  # fmt: skip
    return Header(w, h, depth, colour) if ok else None


def strips(path: Path, rows: int) -> Iterator[np.ndarray]:
    """RGBA uint8 strips of ``rows`` rows (the last one shorter), top to bottom. Raises
    ValueError (or OSError) on a broken file, as Pillow's decoder does. At most two strips'
    rows are held inflated: an image that inflates to gigabytes is never inflated at once."""
    head = header(path)
    if head is None:
        raise ValueError("not a PNG read in strips")
    row_bytes = 1 + head.stride
    need = rows * row_bytes
    extra = b""
    inflate = zlib.decompressobj()
    pending = bytearray()
    previous = bytes(head.stride)  # the row above the first: zeros
    done = 0
    with open(path, "rb") as f:
        f.read(8)
        _chunk(f)  # IHDR
        for kind, data in _chunks(f):
            if kind in (b"PLTE", b"tRNS"):
                extra += _pack_chunk(kind, data)
            if kind != b"IDAT":
                continue
            if head.colour == 3 and b"PLTE" not in extra:
                raise ValueError("broken PNG file: a palette image without its palette")
            while data and not inflate.eof:
                pending += inflate.decompress(data, need)
                data = inflate.unconsumed_tail
                while len(pending) >= need and done + rows <= head.height:
                    rgba, previous = _strip(head, extra, previous, bytes(pending[:need]), rows)
                    del pending[:need]
                    done += rows
                    yield rgba
                if len(pending) >= (head.height - done) * row_bytes:
                    break  # every row is here: what follows in the stream is never inflated
            if len(pending) >= (head.height - done) * row_bytes:
                break  # … nor the chunks after it read (Pillow stops there too)
    left = head.height - done
    if left and len(pending) < left * row_bytes:
        raise ValueError("image data cut short (truncated PNG)")
    if left:
        yield _strip(head, extra, previous, bytes(pending[: left * row_bytes]), left)[0]


def _strip(head: Header, extra: bytes, previous: bytes, raw: bytes, n: int):
    """(RGBA of the ``n`` rows in ``raw``, the last row unfiltered) — decoded by Pillow as a
    PNG of ``n + 1`` rows whose first is ``previous``, stored unfiltered."""
    from PIL import Image

    ihdr = struct.pack(">IIBBBBB", head.width, n + 1, head.depth, head.colour, 0, 0, 0)
    data = zlib.compress(b"\x00" + previous + raw, 0)  # stored: nothing to compress again
    png = (SIGNATURE + _pack_chunk(b"IHDR", ihdr) + extra + _pack_chunk(b"IDAT", data)
           + _pack_chunk(b"IEND", b""))  # fmt: skip
    with Image.open(io.BytesIO(png)) as im:
        im.load()
        rgba = np.asarray(im.convert("RGBA"))[1:]
        last = _as_stored(im, head)
    return rgba, last


def _as_stored(im, head: Header) -> bytes:
    """The image's last row as the file stores it, unfiltered (Pillow holds 8-bit samples:
    grey of 2 and 4 bits scaled by 85 and 17, indices and 1-bit grey as they are)."""
    row = np.asarray(im.crop((0, im.height - 1, im.width, im.height)), dtype=np.uint8).reshape(-1)
    if head.depth == 8:
        return row.tobytes()
    if im.mode == "1":
        return np.packbits(row.astype(bool)).tobytes()
    v = row // {2: 85, 4: 17}[head.depth] if head.colour == 0 else row
    per = 8 // head.depth
    groups = np.concatenate([v, np.zeros(-len(v) % per, np.uint8)]).reshape(-1, per)
    shifts = (head.depth * np.arange(per - 1, -1, -1)).astype(np.uint8)
    return np.bitwise_or.reduce(groups << shifts, axis=1).astype(np.uint8).tobytes()


def _chunk(f) -> tuple[bytes, bytes]:
    head = f.read(8)
    if len(head) < 8:
        raise ValueError("PNG cut short: a chunk's header is missing")
    length, kind = struct.unpack(">I4s", head)
    if not kind.isalpha():
        raise ValueError(f"broken PNG file: a chunk type {kind!r} is not four letters")
    if length > 0x7FFFFFFF:
        raise ValueError("PNG chunk longer than the format allows")
    data = f.read(length)
    crc = f.read(4)
    if len(data) < length or len(crc) < 4:
        raise ValueError("PNG cut short inside a chunk")
    if zlib.crc32(kind + data) != struct.unpack(">I", crc)[0]:
        raise ValueError(f"broken PNG file: the checksum of a {kind.decode('latin-1')} chunk")
    return kind, data


def _chunks(f) -> Iterator[tuple[bytes, bytes]]:
    """The chunks after IHDR; an image data chunk in pieces of at most ``PIECE`` bytes (one
    chunk may hold the whole image), its checksum checked at its end."""
    while True:
        head = f.read(8)
        if len(head) < 8:
            raise ValueError("PNG cut short: no IEND")
        length, kind = struct.unpack(">I4s", head)
        if kind != b"IDAT" or length > 0x7FFFFFFF:
            f.seek(-8, 1)
            yield _chunk(f)
            if kind == b"IEND":
                return
            continue
        crc = zlib.crc32(kind)
        while length:
            piece = f.read(min(PIECE, length))
            if not piece:
                raise ValueError("PNG cut short inside image data")
            crc = zlib.crc32(piece, crc)
            length -= len(piece)
            yield kind, piece
        end = f.read(4)
        if len(end) < 4 or struct.unpack(">I", end)[0] != crc:
            raise ValueError("broken PNG file: the checksum of an IDAT chunk")


def _pack_chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
