"""Plan images read a strip of rows at a time (issue #55 item 4): the same RGBA rows as Pillow's
decode of the whole image — every colour type and bit depth a plan comes in, every row filter,
palettes with transparency — and memory bounded by the strip, not by the image."""

from __future__ import annotations

import struct
import subprocess
import sys
import zlib

import numpy as np
import pytest

from workstation.building import png_strips

CT = {"L": 0, "RGB": 2, "P": 3, "LA": 4, "RGBA": 6}


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def _filtered(rows: np.ndarray, bpp: int, rng) -> bytes:
    """Stored rows (uint8, each row its bytes), each filtered by a random PNG filter."""
    out = bytearray()
    prior = np.zeros(rows.shape[1], np.int16)
    for r in rows.astype(np.int16):
        left = np.concatenate([np.zeros(bpp, np.int16), r[:-bpp]])
        upleft = np.concatenate([np.zeros(bpp, np.int16), prior[:-bpp]])
        kind = int(rng.integers(0, 5))
        if kind == 0:
            f = r
        elif kind == 1:
            f = r - left
        elif kind == 2:
            f = r - prior
        elif kind == 3:
            f = r - (left + prior) // 2
        else:
            p = left + prior - upleft
            pa, pb, pc = np.abs(p - left), np.abs(p - prior), np.abs(p - upleft)
            f = r - np.where((pa <= pb) & (pa <= pc), left, np.where(pb <= pc, prior, upleft))
        out += bytes([kind]) + (f % 256).astype(np.uint8).tobytes()
        prior = r
    return bytes(out)


def write_png(path, mode: str, depth: int, pixels: np.ndarray, rng, palette=None, trns=None,
              idat_piece: int = 997) -> None:  # fmt: skip
    """``pixels`` (h, w[, c]) of samples < 2**depth, rows randomly filtered, the image data
    split into chunks of ``idat_piece`` bytes."""
    h, w = pixels.shape[:2]
    c = 1 if pixels.ndim == 2 else pixels.shape[2]
    flat = pixels.reshape(h, w * c).astype(np.uint8)
    if depth < 8:
        per = 8 // depth
        pad = np.zeros((h, -flat.shape[1] % per), np.uint8)
        g = np.concatenate([flat, pad], axis=1).reshape(h, -1, per)
        shifts = (depth * np.arange(per - 1, -1, -1)).astype(np.uint8)
        flat = np.bitwise_or.reduce(g << shifts, axis=2).astype(np.uint8)
    data = zlib.compress(_filtered(flat, max(1, c * depth // 8), rng), 6)
    out = png_strips.SIGNATURE + _chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, depth, CT[mode],
                                                             0, 0, 0))  # fmt: skip
    if palette is not None:
        out += _chunk(b"PLTE", palette.astype(np.uint8).tobytes())
    if trns is not None:
        out += _chunk(b"tRNS", trns)
    for i in range(0, len(data), idat_piece):
        out += _chunk(b"IDAT", data[i : i + idat_piece])
    path.write_bytes(out + _chunk(b"IEND", b""))


CASES = [("L", 8), ("L", 4), ("L", 2), ("L", 1), ("RGB", 8), ("RGBA", 8), ("LA", 8),
         ("P", 8), ("P", 4), ("P", 2), ("P", 1)]  # fmt: skip


@pytest.mark.parametrize("mode,depth", CASES)
@pytest.mark.parametrize("seed", [0, 1])
def test_strips_are_the_whole_images_rows(tmp_path, mode, depth, seed):
    from PIL import Image

    rng = np.random.default_rng(seed)
    h, w = int(rng.integers(5, 60)), int(rng.integers(1, 70))
    c = {"L": 1, "RGB": 3, "RGBA": 4, "LA": 2, "P": 1}[mode]
    pixels = rng.integers(0, 2**depth, (h, w, c) if c > 1 else (h, w))
    palette = rng.integers(0, 256, (2**depth, 3)) if mode == "P" else None
    trns = None
    if mode == "P" and seed:
        trns = rng.integers(0, 256, 2**depth).astype(np.uint8).tobytes()
    elif mode in ("L", "RGB") and seed:  # one colour transparent
        trns = b"".join(struct.pack(">H", int(v)) for v in pixels.reshape(-1, c)[0])
    write_png(tmp_path / "p.png", mode, depth, pixels, rng, palette, trns)
    with Image.open(tmp_path / "p.png") as im:
        whole = np.asarray(im.convert("RGBA"))
    for rows in (1, 3, 7, h):
        got = np.concatenate(list(png_strips.strips(tmp_path / "p.png", rows)))
        assert np.array_equal(got, whole), (rows, mode, depth)


def test_what_is_not_read_in_strips_is_said_so(tmp_path):
    from PIL import Image

    ihdr = struct.pack(">IIBBBBB", 8, 8, 8, 2, 0, 0, 1)  # Adam7 (Pillow writes none)
    (tmp_path / "i.png").write_bytes(png_strips.SIGNATURE + _chunk(b"IHDR", ihdr))
    Image.new("I;16", (8, 8)).save(tmp_path / "s.png")
    Image.new("RGB", (8, 8)).save(tmp_path / "j.jpg")
    for name in ("i.png", "s.png", "j.jpg", "missing.png"):
        assert png_strips.header(tmp_path / name) is None


@pytest.mark.parametrize("cut", ["short", "crc", "taller"])
def test_a_broken_file_is_an_error_never_rows(tmp_path, cut):
    rng = np.random.default_rng(3)
    write_png(tmp_path / "p.png", "RGB", 8, rng.integers(0, 256, (20, 20, 3)), rng)
    raw = (tmp_path / "p.png").read_bytes()
    if cut == "short":
        raw = raw[: len(raw) // 2]
    elif cut == "crc":
        raw = raw[:60] + bytes([raw[60] ^ 1]) + raw[61:]
    else:  # a header claiming rows the data does not hold (Pillow shows them black)
        raw = _with_crcs_fixed(raw[:20] + struct.pack(">I", 21) + raw[24:])
    (tmp_path / "p.png").write_bytes(raw)
    with pytest.raises(ValueError):
        list(png_strips.strips(tmp_path / "p.png", 4))


# the process's own peak: VmHWM, not getrusage's ru_maxrss — that one carries the peak of the
# process that started it across exec (vfork), the whole test worker's in a full run (301 MB)
BIG = """
import re, sys
from pathlib import Path
sys.path.insert(0, {repo!r})
from workstation.building.raster import downsample as _downsample
shape = _downsample(Path({path!r}), 10).shape
hwm = re.search(r"VmHWM:\\s+(\\d+) kB", Path("/proc/self/status").read_text()).group(1)
print(shape, int(hwm) // 1024)
"""


def test_a_large_plan_is_reduced_in_memory_the_size_of_a_strip(tmp_path):
    """12,000 × 12,000 RGB (432 MB as stored, 576 MB in RGBA; 1 MB in the file): reduced to
    1,200 × 1,200 with the process's peak under 200 MB (86 MB here, 37 of them Python, numpy
    and Pillow; decoded whole, as before: 774 MB)."""
    from tests.conftest import REPO

    w = h = 12_000
    row = np.full(w * 3, 255, np.uint8)
    row[::97] = 0  # a few dark lines
    comp = zlib.compressobj(9)
    data = b"".join(comp.compress(b"\x00" + row.tobytes()) for _ in range(h)) + comp.flush()
    path = tmp_path / "big.png"
    path.write_bytes(png_strips.SIGNATURE + _chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2,
                     0, 0, 0)) + _chunk(b"IDAT", data) + _chunk(b"IEND", b""))  # fmt: skip
    got = subprocess.run([sys.executable, "-c", BIG.format(repo=str(REPO), path=str(path))],
                         capture_output=True, text=True, check=True).stdout.split()  # fmt: skip
    assert got[:2] == ["(1200,", "1200,"] and int(got[-1]) < 200, got


def _with_crcs_fixed(raw: bytes) -> bytes:
    """Every chunk's checksum made right again: corruption reaches the inflater and filters."""
    out, i = bytearray(raw[:8]), 8
    while i + 8 <= len(raw):
        (n,) = struct.unpack(">I", raw[i : i + 4])
        body = raw[i + 4 : i + 8 + n]
        if len(body) < n + 4:
            out += raw[i:]
            break
        out += raw[i : i + 8 + n] + struct.pack(">I", zlib.crc32(body))
        i += 12 + n
    return bytes(out)


@pytest.mark.parametrize("seed", range(6))
def test_a_corrupted_plan_gives_pillows_rows_or_an_error(tmp_path, seed):
    """Bytes flipped anywhere after the signature (checksums made right): reduced in strips it
    is an InputError whenever Pillow's whole decode fails, and otherwise the same pixels —
    never a traceback, never silently other rows. It also refuses what Pillow shows wrongly
    (17 of 4,400 here): a height whose rows the data lacks (Pillow: black rows), a palette
    image whose palette chunk is gone (Pillow: grey)."""
    from PIL import Image

    from workstation.building.raster import darkest as _darkest
    from workstation.building.raster import downsample as _downsample
    from workstation.errors import InputError

    rng = np.random.default_rng(seed)
    mode, depth = CASES[seed % len(CASES)]
    c = {"L": 1, "RGB": 3, "RGBA": 4, "LA": 2, "P": 1}[mode]
    pixels = rng.integers(0, 2**depth, (30, 23, c) if c > 1 else (30, 23))
    palette = rng.integers(0, 256, (2**depth, 3)) if mode == "P" else None
    write_png(tmp_path / "ok.png", mode, depth, pixels, rng, palette)
    good = (tmp_path / "ok.png").read_bytes()
    same = errors = 0
    for _ in range(40):
        raw = bytearray(good)
        for at in rng.integers(8, len(raw), int(rng.integers(1, 4))):
            raw[at] = int(rng.integers(0, 256))
        path = tmp_path / "bad.png"
        path.write_bytes(_with_crcs_fixed(bytes(raw)))
        try:
            with Image.open(path) as im:
                whole = _darkest(np.asarray(im.convert("RGBA")), 2)
        except Exception:  # noqa: BLE001 - what Pillow refuses, in any way
            whole = None
        try:
            got = _downsample(path, 2)
        except InputError:
            got = None
        if whole is None or got is None:
            errors += 1
            assert got is None or png_strips.header(path) is None, "Pillow refused it, we read rows"
        else:
            same += 1
            assert np.array_equal(got, whole)
    assert same + errors == 40


@pytest.mark.parametrize("f", [4, 6, 5])
def test_a_large_jpeg_plan_is_decoded_scaled_down_its_lines_kept(tmp_path, monkeypatch, f):
    """A JPEG is no PNG read in strips: beyond ``WHOLE_PX`` libjpeg decodes it at 1/2, 1/4 or
    1/8 (a divisor of the reduction), never whole — the same size of plan, its one-pixel
    lines lighter but there (black → grey 63 at 1/2, 140–200 at 1/4; a 108-Mpixel JPEG:
    751 → 171 MB)."""
    from PIL import Image

    import workstation.building.raster as building

    a = np.full((1500, 2000, 3), 255, np.uint8)
    a[:, ::97] = 0
    a[::53, :] = 0
    Image.fromarray(a).save(tmp_path / "p.jpg", quality=90)
    whole = building.downsample(tmp_path / "p.jpg", f)
    monkeypatch.setattr(building, "WHOLE_PX", 500_000)
    with Image.open(tmp_path / "p.jpg") as im:
        scaled = building._jpeg_scaled(im, f)
    assert scaled == {4: 4, 6: 2, 5: 1}[f]  # 3 Mpixel / 4² under 0.5; 6: only 2 divides it
    small = building.downsample(tmp_path / "p.jpg", f)
    assert small.shape == whole.shape
    lines = np.zeros(whole.shape[:2], bool)
    lines[:, np.arange(0, 2000, 97) // f] = True
    assert small[lines].max(axis=1).mean() < 220 and np.median(small[~lines]) >= 250


@pytest.mark.parametrize("depth,interlace,what", [(8, 1, "interlaced PNG"),
                                                  (16, 0, "PNG of 16 bits a sample")])  # fmt: skip
def test_a_large_plan_pillow_would_decode_whole_is_refused_saying_how_to_save_it(
    tmp_path, capsys, depth, interlace, what
):
    """Issue #55 item 4: what is not read in strips (an interlaced or 16-bit PNG) was decoded
    whole — 4 bytes a pixel, 1.6 GB for 20,000 × 20,000 — once shown. Beyond 64 Mpixel it is
    refused when the building is loaded, naming what to save the plan as; never decoded."""
    from workstation.building.raster import WHOLE_PX
    from workstation.building.raster import downsample as _downsample
    from workstation.cli import main
    from workstation.errors import InputError

    w, h = 9000, 8000
    assert w * h > WHOLE_PX
    ihdr = struct.pack(">IIBBBBB", w, h, depth, 2, 0, 0, interlace)
    plan = tmp_path / "plan.png"
    plan.write_bytes(png_strips.SIGNATURE + _chunk(b"IHDR", ihdr)
                     + _chunk(b"IDAT", zlib.compress(b"\0" * 64)) + _chunk(b"IEND", b""))  # fmt: skip
    with pytest.raises(InputError, match=what):
        _downsample(plan, 3)
    (tmp_path / "b.yaml").write_text(
        "name: b\nfloors:\n  0:\n    image: plan.png\n    transform: [[0.1, 0, 0], [0, -0.1, 800]]\n"
    )
    assert main(["building", "validate", str(tmp_path / "b.yaml")]) == 2
    err = capsys.readouterr().err
    assert "plan.png" in err and what in err and "non-interlaced PNG of 8 bits" in err
    assert "Traceback" not in err
