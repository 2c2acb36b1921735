"""A floor plan's pixels, read within bounded memory: the darkest pixel of each block kept (thin
plan lines survive), a strip of rows at a time, refused beyond ``MAX_PIXELS``; the displayed copy
cached under ``$XDG_CACHE_HOME/workstation/plans`` (:meth:`.model.FloorImage.display`)."""

from __future__ import annotations

import os
import zlib
from pathlib import Path

import numpy as np

from workstation.building.png_strips import header
from workstation.building.png_strips import strips as png_strips
from workstation.errors import InputError


def cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "workstation" / "plans"


def downsample(path: Path, f: int) -> np.ndarray:
    """RGB uint8, every f × f block reduced to its darkest pixel (by luminance), over white where
    the image is transparent, a strip of rows at a time: the whole image in RGBA and floats took
    ≈ 37 bytes a pixel (a 438-KB, 20,000 × 20,000 PNG ran out of memory; issue #55 item 4). A
    PNG is also decoded a strip at a time (:mod:`.png_strips`: memory bounded by the strip and
    the output); a JPEG beyond ``WHOLE_PX`` is decoded scaled down by libjpeg
    (:func:`_jpeg_scaled`); an interlaced or 16-bit PNG, a smaller JPEG, other formats are
    decoded whole — and refused beyond ``WHOLE_PX`` (4 bytes a pixel in Pillow: 1.6 GB for
    20,000 × 20,000), saying how to save it so it is read in strips."""
    from PIL import Image

    Image.MAX_IMAGE_PIXELS = MAX_PIXELS  # a header claiming more is refused, never decoded
    head = header(path)
    if head is not None:  # a PNG a strip at a time: memory bounded by the strip and the output
        if head.width * head.height > MAX_PIXELS:
            raise InputError(path, f"not a readable image: {head.width} × {head.height} pixels: "
                             f"more than {MAX_PIXELS:,}")  # fmt: skip
        rows = max(1, STRIP_PX // max(head.width * f, 1)) * f
        try:
            parts = [darkest(s, f) for s in png_strips(path, rows)]
        except (OSError, ValueError, zlib.error, Image.DecompressionBombError) as e:
            raise InputError(path, f"not a readable image: {e}") from None
        return np.concatenate(parts) if parts else np.full((0, 0, 3), 255, np.uint8)
    try:
        with Image.open(path) as im:
            if im.size[0] * im.size[1] > MAX_PIXELS:
                raise ValueError(f"{im.size[0]} × {im.size[1]} pixels: more than {MAX_PIXELS:,}")
            f //= _jpeg_scaled(im, f)
            whole_fits(path, im)
            im.load()
            w, h = im.size
            rows = max(1, STRIP_PX // max(w * f, 1)) * f  # whole blocks of rows per strip
            strips = [
                darkest(np.asarray(im.crop((0, y, w, min(h, y + rows))).convert("RGBA")), f)
                for y in range(0, h, rows)
            ]
    except (OSError, ValueError, Image.DecompressionBombError) as e:
        raise InputError(path, f"not a readable image: {e}") from None
    return np.concatenate(strips) if strips else np.full((0, 0, 3), 255, np.uint8)


STRIP_PX = 1_000_000  # pixels converted at a time (≈ 50 MB of working arrays at most)
WHOLE_PX = 64_000_000  # a JPEG larger than this is decoded scaled down (its lines lighter)


def whole_fits(path: Path, im) -> None:
    """Refuses an image of more than ``WHOLE_PX`` pixels that would be decoded whole (not a
    PNG read in strips, not a JPEG: libjpeg scales it down), naming what to save it as."""
    w, h = im.size
    if w * h <= WHOLE_PX or im.format == "JPEG" or header(path) is not None:
        return
    what = im.format or "image"
    if im.format == "PNG":
        what = "interlaced PNG" if im.info.get("interlace") else "PNG of 16 bits a sample"
    raise InputError(path, f"a {w} × {h} {what} is decoded whole, {w * h * 4 / 1e9:.1f} GB "
                     f"(more than {WHOLE_PX / 1e6:g} Mpixel): save it as a non-interlaced PNG "
                     "of 8 bits a sample, read a strip at a time")  # fmt: skip


def _jpeg_scaled(im, f: int) -> int:
    """A JPEG of more than ``WHOLE_PX`` pixels decoded at 1/s of its size by libjpeg itself
    (``draft``: s of 2, 4 or 8 dividing ``f``, the least that brings it under, else the
    most), so that it never lies in memory whole; returns s (1: decoded as it is). A line one
    pixel wide is then averaged with its neighbours before its block's darkest pixel is kept:
    lighter, but there."""
    w, h = im.size
    if im.format != "JPEG" or w * h <= WHOLE_PX:
        return 1
    fits = [s for s in (2, 4, 8) if f % s == 0]
    if not fits:
        return 1
    s = next((s for s in fits if w * h // (s * s) <= WHOLE_PX), fits[-1])
    im.draft(None, (w // s, h // s))  # (Pillow takes the largest scale this size allows: s)
    got = im.decoderconfig[0] if im.decoderconfig else 1
    if f % got or im.size != (-(-w // got), -(-h // got)):
        raise ValueError(f"libjpeg scaled it by 1/{got}, not 1/{s}")
    return got


def darkest(rgba: np.ndarray, f: int) -> np.ndarray:
    """One strip: over white, then each f × f block to its darkest pixel (by luminance)."""
    if (rgba[..., 3] == 255).all():  # opaque (most plans): the blend below gives these bytes
        rgb = rgba[..., :3]
    else:
        alpha = rgba[..., 3:4].astype(np.float32) / 255.0
        rgb = (rgba[..., :3] * alpha + 255.0 * (1.0 - alpha)).astype(np.uint8)
    if f == 1:
        return rgb
    h, w = rgb.shape[:2]
    H, W = -(-h // f) * f, -(-w // f) * f
    pad = np.full((H, W, 3), 255, np.uint8)
    pad[:h, :w] = rgb
    blocks = (
        pad.reshape(H // f, f, W // f, f, 3)
        .transpose(0, 2, 1, 3, 4)
        .reshape(H // f, W // f, f * f, 3)
    )
    lum = blocks.astype(np.uint16).sum(axis=3)
    k = lum.argmin(axis=2)
    return np.take_along_axis(blocks, k[..., None, None], axis=2)[:, :, 0, :]


# a plan image of a floor: 20,000 × 20,000 pixels at most (a header claiming 100,000² reached
# 8.6 GB before a MemoryError with Pillow's own limit switched off)
MAX_PIXELS = 400_000_000
