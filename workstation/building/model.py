"""The building file's records: a floor's plan image and its pixel → metres transform, a floor's
height, the building (its floors and georeference), read and written as YAML (the package
doc)."""


from __future__ import annotations

import hashlib
import math
import os
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import yaml

from workstation.building.raster import MAX_PIXELS, cache_dir, downsample, whole_fits
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
                whole_fits(self.path, im)  # refused as soon as looked at (building validate)
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
        cache = cache_dir() / f"{self._key(f)}.npy"
        if cache.is_file():
            try:
                return np.load(cache), disp
            except (OSError, ValueError):
                pass
        rgb = downsample(self.path, f)
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


MAX_COORD = 1e7  # pixels or metres: no plan image or building is larger
MIN_SCALE, MAX_SCALE = 1e-4, 1e3  # metres per pixel
MAX_CAL_FLOORS = 1000  # floor images one .cal may list
