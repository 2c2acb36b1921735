"""The building file: per floor, an optional raster floor plan georeferenced into the metric
frame the landmark graph uses, and the floor's height. YAML beside the graph::

    name: museum
    frame: {origin_lat: 49.461, origin_lon: 11.111}   # the graph's frame (optional)
    floors:
      -1:
        height_m: -3.1                                # optional
        image: Map_Floor_-01.png                      # relative to this file
        transform: [[a, b, c], [d, e, f]]             # pixel (u, v) → metres: x = a u + b v + c

Pixel (0, 0) is the top-left corner of the image. Made from an IPIN ``.cal``, a Microsoft ILC
``floor_info.json`` or control points by :mod:`.importers`. Large images are downsampled
for display once and cached (:meth:`FloorImage.display`). Beside it: the floor plan's walls
(:mod:`.floorplan`) and the checks that a walk, a graph and a building belong together
(:mod:`.consistency`).
"""

from __future__ import annotations

import hashlib
import math
import os
import zlib
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import yaml

from workstation.building import png_strips
from workstation.errors import InputError
from workstation.geo import LocalFrame
from workstation.io.atomic import atomic_write_text
from workstation.io.yamlio import load_yaml

DISPLAY_PX = 2048  # longest side of a plan image as displayed


@dataclass(frozen=True)
class FloorImage:
    """A raster plan and its pixel → metres affine transform (2 × 3)."""

    path: Path
    transform: np.ndarray

    def to_metres(self, u, v) -> tuple[np.ndarray, np.ndarray]:
        a = self.transform
        u, v = np.asarray(u, float), np.asarray(v, float)
        return a[0, 0] * u + a[0, 1] * v + a[0, 2], a[1, 0] * u + a[1, 1] * v + a[1, 2]

    def to_pixels(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        m = np.vstack([self.transform, [0.0, 0.0, 1.0]])
        inv = np.linalg.inv(m)
        x, y = np.asarray(x, float), np.asarray(y, float)
        return inv[0, 0] * x + inv[0, 1] * y + inv[0, 2], inv[1, 0] * x + inv[1, 1] * y + inv[1, 2]

    def size(self) -> tuple[int, int]:
        """(width, height) in pixels, read from the header only."""
        from PIL import Image

        Image.MAX_IMAGE_PIXELS = MAX_PIXELS  # a header claiming more is refused, never decoded
        try:
            with Image.open(self.path) as im:
                _whole_fits(self.path, im)  # refused as soon as looked at (building validate)
                return im.size
        except (OSError, ValueError, Image.DecompressionBombError) as e:
            raise InputError(self.path, f"not a readable image: {e}") from None

    def corners(self) -> np.ndarray:
        """(4, 2) metres of the image's corners."""
        w, h = self.size()
        x, y = self.to_metres([0, w, w, 0], [0, 0, h, h])
        return np.column_stack([x, y])

    @property
    def metres_per_pixel(self) -> float:
        return float(math.sqrt(abs(np.linalg.det(self.transform[:, :2]))))

    def display(self, max_px: int = DISPLAY_PX) -> tuple[np.ndarray, np.ndarray]:
        """(RGB uint8 image at most ``max_px`` on a side, its pixel → metres transform).

        Downsampled once by keeping each block's darkest pixel (thin plan lines survive) over
        white where the image is transparent, then cached on disk."""
        w, h = self.size()
        f = max(1, math.ceil(max(w, h) / max_px))
        disp = self.transform @ np.diag([float(f), float(f), 1.0])
        cache = _cache_dir() / f"{self._key(f)}.npy"
        if cache.is_file():
            try:
                return np.load(cache), disp
            except (OSError, ValueError):
                pass
        rgb = _downsample(self.path, f)
        try:
            cache.parent.mkdir(parents=True, exist_ok=True)
            tmp = cache.with_suffix(".tmp.npy")
            np.save(tmp, rgb)
            os.replace(tmp, cache)
        except OSError:
            pass  # a read-only cache only costs time
        return rgb, disp

    def _key(self, f: int) -> str:
        st = self.path.stat()
        raw = f"{self.path.resolve()}|{st.st_size}|{st.st_mtime_ns}|{f}"
        return hashlib.sha1(raw.encode()).hexdigest()[:20]


@dataclass(frozen=True)
class FloorInfo:
    height_m: float | None = None
    image: FloorImage | None = None


@dataclass(frozen=True)
class Building:
    name: str
    floors: dict[float, FloorInfo] = field(default_factory=dict)
    frame: LocalFrame | None = None
    source: str | None = None

    def image(self, floor: float) -> FloorImage | None:
        info = self.floors.get(float(floor))
        return info.image if info else None

    def heights(self) -> dict[float, float]:
        return {f: i.height_m for f, i in self.floors.items() if i.height_m is not None}

    def extent(self) -> np.ndarray | None:
        """(2, 2) [[xmin, ymin], [xmax, ymax]] over every plan image, or None."""
        pts = [i.image.corners() for i in self.floors.values() if i.image is not None]
        if not pts:
            return None
        p = np.vstack(pts)
        return np.array([p.min(axis=0), p.max(axis=0)])

    def merged(self, other: Building) -> Building:
        floors = dict(self.floors)
        for f, i in other.floors.items():
            old = floors.get(f, FloorInfo())
            floors[f] = FloorInfo(
                i.height_m if i.height_m is not None else old.height_m, i.image or old.image
            )
        return replace(self, floors=floors, frame=self.frame or other.frame)

    # ---- files ------------------------------------------------------------------------------
    def to_dict(self, base: Path) -> dict:
        d: dict = {"name": self.name}
        if self.frame is not None:
            d["frame"] = {"origin_lat": self.frame.origin_lat, "origin_lon": self.frame.origin_lon}
        floors = {}
        for f, info in sorted(self.floors.items()):
            e: dict = {}
            if info.height_m is not None:
                e["height_m"] = float(info.height_m)
            if info.image is not None:
                e["image"] = os.path.relpath(info.image.path, base)
                e["transform"] = [[round(float(v), 9) for v in row] for row in info.image.transform]
            floors[int(f) if float(f).is_integer() else float(f)] = e
        d["floors"] = floors
        return d

    def save(self, path: str | Path) -> Path:
        path = Path(path)
        text = yaml.safe_dump(
            self.to_dict(path.parent.resolve()), sort_keys=False, default_flow_style=None
        )
        atomic_write_text(path, text, backup=True)
        return path

    @classmethod
    def load(cls, path: str | Path) -> Building:
        path = Path(path)
        data = load_yaml(path, "building file")
        if not isinstance(data, dict):
            raise InputError(path, "a building file is a mapping (name, frame, floors)")
        unknown = set(data) - {"name", "frame", "floors"}
        if unknown:
            raise InputError(path, f"unknown key(s) {', '.join(sorted(map(str, unknown)))}")
        frame = None
        fr = data.get("frame")
        if fr is not None:
            try:
                frame = LocalFrame(float(fr["origin_lat"]), float(fr["origin_lon"]))
            except (TypeError, KeyError, ValueError, OverflowError):
                raise InputError(
                    path, "frame: needs origin_lat and origin_lon in degrees"
                ) from None
            if not (abs(frame.origin_lat) <= 90 and abs(frame.origin_lon) <= 180):
                raise InputError(path, "frame: origin_lat/origin_lon out of range")
        floors_raw = data.get("floors") or {}
        if not isinstance(floors_raw, dict):
            raise InputError(path, "floors: expected a mapping of floor number to its entry")
        floors = {}
        for key, e in floors_raw.items():
            floors[_floor_key(key, path)] = _floor_entry(key, e, path)
        return cls(str(data.get("name") or path.stem), floors, frame, str(path))


MAX_FLOOR = 500  # the largest |floor number| a building file takes (every writer keeps to it)


def _floor_key(key, path: Path) -> float:
    try:
        f = float(key)
    except (TypeError, ValueError, OverflowError):
        raise InputError(path, f"floors: {key!r} is not a floor number") from None
    if not math.isfinite(f) or abs(f) > MAX_FLOOR:
        raise InputError(path, f"floors: {key!r} is not a plausible floor number")
    return f


def _floor_entry(key, e, path: Path) -> FloorInfo:
    where = f"floors: {key}"
    if e is None:
        return FloorInfo()
    if not isinstance(e, dict):
        raise InputError(path, f"{where}: expected height_m, image and transform")
    unknown = set(e) - {"height_m", "image", "transform"}
    if unknown:
        raise InputError(path, f"{where}: unknown key(s) {', '.join(sorted(map(str, unknown)))}")
    h = e.get("height_m")
    if h is not None:
        try:
            h = float(h)
        except (TypeError, ValueError, OverflowError):
            raise InputError(path, f"{where}: height_m {h!r} is not a number") from None
        if not math.isfinite(h) or abs(h) > 2000:
            raise InputError(path, f"{where}: height_m {h!r} is not a plausible height")
    img = None
    if e.get("image") is not None:
        p = Path(str(e["image"]))
        p = p if p.is_absolute() else path.parent / p
        if not is_file(p):
            raise InputError(path, f"{where}: image {e['image']} not found (looked in {p})")
        t = e.get("transform")
        try:
            a = np.asarray(t, dtype=float)
        except (TypeError, ValueError, OverflowError):
            a = np.empty(0)
        if a.shape != (2, 3) or not np.isfinite(a).all():
            raise InputError(path, f"{where}: transform must be [[a, b, c], [d, e, f]] numbers")
        check_transform(a, path, where)
        img = FloorImage(p, a)
    return FloorInfo(h, img)


def check_transform(a: np.ndarray, path: Path, where: str) -> None:
    """A plan image's pixel → metre transform must be one a floor plan can have: every reader
    that makes one checks it, so what is saved loads again (issue #33: a floor_info.json 10³⁰ m
    wide was saved, then refused when read back)."""
    scale = math.sqrt(abs(np.linalg.det(a[:, :2])))
    if not MIN_SCALE <= scale <= MAX_SCALE or np.abs(a[:, 2]).max() > MAX_COORD:
        raise InputError(
            path,
            f"{where}: transform gives {scale:.3g} m per pixel, offset up to "
            f"{np.abs(a[:, 2]).max():.3g} m: not a floor plan's (scale {MIN_SCALE:g}–"
            f"{MAX_SCALE:g} m per pixel, offset within ±{MAX_COORD:g} m)",
        )


def is_file(p: Path) -> bool:
    """``p.is_file()``, False for a path the system cannot even look up (a name over its
    length limit raised OSError from a fuzzed building file)."""
    try:
        return p.is_file()
    except (OSError, ValueError):  # ValueError: a NUL byte in the name
        return False


def _cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "workstation" / "plans"


def _downsample(path: Path, f: int) -> np.ndarray:
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
    head = png_strips.header(path)
    if head is not None:  # a PNG a strip at a time: memory bounded by the strip and the output
        if head.width * head.height > MAX_PIXELS:
            raise InputError(path, f"not a readable image: {head.width} × {head.height} pixels: "
                             f"more than {MAX_PIXELS:,}")  # fmt: skip
        rows = max(1, STRIP_PX // max(head.width * f, 1)) * f
        try:
            parts = [_darkest(s, f) for s in png_strips.strips(path, rows)]
        except (OSError, ValueError, zlib.error, Image.DecompressionBombError) as e:
            raise InputError(path, f"not a readable image: {e}") from None
        return np.concatenate(parts) if parts else np.full((0, 0, 3), 255, np.uint8)
    try:
        with Image.open(path) as im:
            if im.size[0] * im.size[1] > MAX_PIXELS:
                raise ValueError(f"{im.size[0]} × {im.size[1]} pixels: more than {MAX_PIXELS:,}")
            f //= _jpeg_scaled(im, f)
            _whole_fits(path, im)
            im.load()
            w, h = im.size
            rows = max(1, STRIP_PX // max(w * f, 1)) * f  # whole blocks of rows per strip
            strips = [
                _darkest(np.asarray(im.crop((0, y, w, min(h, y + rows))).convert("RGBA")), f)
                for y in range(0, h, rows)
            ]
    except (OSError, ValueError, Image.DecompressionBombError) as e:
        raise InputError(path, f"not a readable image: {e}") from None
    return np.concatenate(strips) if strips else np.full((0, 0, 3), 255, np.uint8)


STRIP_PX = 1_000_000  # pixels converted at a time (≈ 50 MB of working arrays at most)
WHOLE_PX = 64_000_000  # a JPEG larger than this is decoded scaled down (its lines lighter)


def _whole_fits(path: Path, im) -> None:
    """Refuses an image of more than ``WHOLE_PX`` pixels that would be decoded whole (not a
    PNG read in strips, not a JPEG: libjpeg scales it down), naming what to save it as."""
    w, h = im.size
    if w * h <= WHOLE_PX or im.format == "JPEG" or png_strips.header(path) is not None:
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


def _darkest(rgba: np.ndarray, f: int) -> np.ndarray:
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
MAX_COORD = 1e7  # pixels or metres: no plan image or building is larger
MIN_SCALE, MAX_SCALE = 1e-4, 1e3  # metres per pixel
MAX_CAL_FLOORS = 1000  # floor images one .cal may list
