"""Making a building file (:mod:`.building`) from what comes with a floor plan: an IPIN
``.cal`` (image centre in lat/lon, rotation, metres per pixel), a Microsoft ILC
``floor_info.json`` (the image spans width × height metres, origin bottom-left), or two or more
control points (pixel ↔ metres, fitted by :func:`fit_transform`)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from workstation.building import (
    MAX_CAL_FLOORS,
    MAX_COORD,
    MAX_FLOOR,
    MAX_SCALE,
    MIN_SCALE,
    Building,
    FloorImage,
    FloorInfo,
    check_transform,
    is_file,
)
from workstation.errors import InputError
from workstation.geo import LocalFrame


def from_ipin_cal(cal: str | Path, frame: LocalFrame, name: str | None = None) -> Building:
    """An IPIN ``.cal`` (GetSensorData tools): per floor image file, floor, building, centre
    latitude/longitude, rotation (°) and scale (m/px). Floors whose image is not beside the
    ``.cal`` get no plan. The image is rotated by −rotation about its centre (checked against
    the competition's reference markers: 0.36 m mean over 9 markers)."""
    cal = Path(cal)
    names, cols, lines = _cal_rows(cal)
    fl, _, lat, lon, rot, scale = cols
    if len(set(fl)) < len(fl):
        raise InputError(cal, "a floor number appears twice", lines[1])
    floors: dict[float, FloorInfo] = {}
    for i, fname in enumerate(names):
        img = cal.parent / fname
        if not is_file(img):
            floors[fl[i]] = FloorInfo()
            continue
        a = _cal_affine(img, frame, lat[i], lon[i], rot[i], scale[i])
        if not np.isfinite(a).all() or np.abs(a[:, 2]).max() > MAX_COORD:
            raise InputError(cal, f"{fname}: lies {np.abs(a[:, 2]).max():.3g} m from the "
                             "graph's origin: another place", lines[3])  # fmt: skip
        floors[fl[i]] = FloorInfo(None, FloorImage(img, a))
    return Building(name or cal.stem, floors, frame, str(cal))


def _cal_rows(cal: Path) -> tuple[list[str], list[list[float]], list[int]]:
    """A ``.cal``'s image names, its six rows of numbers (floor, building, latitude,
    longitude, rotation, scale; each checked against its range) and their line numbers."""
    try:
        text = cal.read_text(encoding="utf-8", errors="replace")
    except OSError as e:
        raise InputError(cal, f"cannot read: {e}") from None
    rows, lines = [], []  # the data rows and their line numbers
    for k, ln in enumerate(text.splitlines(), 1):
        if ln.strip() and not ln.lstrip().startswith("%"):
            rows.append(ln.split())
            lines.append(k)
    if len(rows) < 7:
        raise InputError(
            cal, "expected 7 rows (files, floors, buildings, lat, lon, rotation, scale)"
        )
    names, rest = rows[0], rows[1:7]
    n = len(names)
    if n > MAX_CAL_FLOORS:
        raise InputError(cal, f"{n} floor images: at most {MAX_CAL_FLOORS}", lines[0])
    for r, k in zip(rest, lines[1:7]):
        if len(r) != n:
            raise InputError(cal, f"every row needs {n} columns, one per floor image", k)
    what = ("floor", "building", "latitude", "longitude", "rotation (°)", "scale (m/px)")
    lo_hi = ((-MAX_FLOOR, MAX_FLOOR), (-1e9, 1e9), (-90.0, 90.0), (-180.0, 180.0), (-1e4, 1e4),
             (MIN_SCALE, MAX_SCALE))  # fmt: skip
    cols = [_cal_numbers(cal, r, k, label, lo, hi)
            for r, k, label, (lo, hi) in zip(rest, lines[1:7], what, lo_hi)]  # fmt: skip
    return names, cols, lines


def _cal_numbers(cal: Path, r: list[str], k: int, label: str, lo: float, hi: float) -> list[float]:
    """One row of a ``.cal`` as numbers within [lo, hi], else an error naming its line."""
    try:
        if any("_" in x for x in r):  # Python reads 1_000 as 1000; a .cal does not
            raise ValueError(f"could not convert string to float: {next(x for x in r if '_' in x)!r}")
        v = [float(x) for x in r]
    except ValueError as e:
        raise InputError(cal, f"{label}: not a number: {e}", k) from None
    bad = [x for x in v if not (math.isfinite(x) and lo <= x <= hi)]
    if bad:
        raise InputError(cal, f"{label} {bad[0]:g}: must lie within {lo:g}…{hi:g}", k)
    return v


def _cal_affine(img: Path, frame: LocalFrame, lat: float, lon: float, rot: float,
                scale: float) -> np.ndarray:  # fmt: skip
    """An image's pixel → frame affine: its centre at (lat, lon), rotated by −rot about it,
    ``scale`` m/px; (u, v) → image metres (east-right, north-up) → rotated → frame."""
    w, h = FloorImage(img, np.eye(2, 3)).size()
    cx, cy = frame.to_xy(lat, lon)
    th = math.radians(-rot)
    c, s = math.cos(th) * scale, math.sin(th) * scale
    a = np.array([[c, s, 0.0], [s, -c, 0.0]])
    a[0, 2] = float(cx) - (a[0, 0] * w / 2 + a[0, 1] * h / 2)
    a[1, 2] = float(cy) - (a[1, 0] * w / 2 + a[1, 1] * h / 2)
    return a


def from_msilc(info: str | Path, image: str | Path | None = None, floor: float = 0.0,
               name: str | None = None) -> Building:  # fmt: skip
    """A Microsoft ILC floor: ``floor_info.json`` gives the metres the image spans
    (``map_info.width`` × ``height``), origin at its bottom-left corner (the walks' frame)."""
    info = Path(info)
    image = Path(image) if image else info.with_name("floor_image.png")
    try:
        mi = json.loads(info.read_text(encoding="utf-8"))["map_info"]
        wm, hm = float(mi["width"]), float(mi["height"])
    except (OSError, ValueError, KeyError, TypeError) as e:
        raise InputError(info, f"not a floor_info.json with map_info width/height: {e}") from None
    if not (wm > 0 and hm > 0 and math.isfinite(wm * hm)):
        raise InputError(info, "map_info width and height must be positive metres")
    if not is_file(image):
        raise InputError(image, "floor image not found")
    w, h = FloorImage(image, np.eye(2, 3)).size()
    a = np.array([[wm / w, 0.0, 0.0], [0.0, -hm / h, hm]])
    check_transform(a, info, "map_info width and height")
    return Building(name or info.parent.name, {float(floor): FloorInfo(None, FloorImage(image, a))})


#: control points must spread across their line at least this share of their spread along it
MIN_SPREAD = 0.02


def fit_transform(uv, xy) -> np.ndarray:
    """Pixel → metres from control points: a similarity (rotation, one scale, shift) from two,
    a least-squares affine from three or more. Raises ValueError when degenerate or not finite
    (a point at -inf once kept ``building from-points`` busy for 38 minutes), and when the
    transform is not one a plan can have (a scale of zero or beyond MAX_SCALE)."""
    uv, xy = np.asarray(uv, float), np.asarray(xy, float)
    if uv.shape != xy.shape or uv.ndim != 2 or uv.shape[1] != 2 or len(uv) < 2:
        raise ValueError("need two or more control points, each pixel (u, v) and metres (x, y)")
    bad = ~(np.isfinite(uv).all(axis=1) & np.isfinite(xy).all(axis=1))
    if bad.any():
        raise ValueError(f"control point {int(np.argmax(bad)) + 1} is not finite")
    if np.abs(uv).max() > MAX_COORD or np.abs(xy).max() > MAX_COORD:
        raise ValueError(f"control points beyond ±{MAX_COORD:g} (pixels or metres)")
    t = _fit(uv, xy)
    scale = np.sqrt(abs(np.linalg.det(t[:, :2])))
    if not np.isfinite(t).all() or not MIN_SCALE <= scale <= MAX_SCALE:
        raise ValueError(
            f"the control points give {scale:.3g} m per pixel: not a floor plan's scale "
            f"({MIN_SCALE:g}–{MAX_SCALE:g})"
        )
    return t


def _fit(uv: np.ndarray, xy: np.ndarray) -> np.ndarray:
    if len(uv) == 2:
        # y axis flipped: image v grows downwards while y grows north
        zu = complex(uv[1, 0] - uv[0, 0], -(uv[1, 1] - uv[0, 1]))
        zx = complex(*(xy[1] - xy[0]))
        if abs(zu) < 1e-9 or abs(zx) < 1e-9:
            raise ValueError("the two control points coincide")
        k = zx / zu
        a = np.array([[k.real, k.imag, 0.0], [k.imag, -k.real, 0.0]])
        a[:, 2] = xy[0] - a[:, :2] @ uv[0]
        return a
    # (almost) on one line, an affine fit is free across it: three nearly collinear points gave
    # an offset of 1.25e9 m (issue #55 item 7). The spread across the line against along it:
    spread = np.linalg.svd(uv - uv.mean(axis=0), compute_uv=False)
    if spread[0] == 0 or spread[1] / spread[0] < MIN_SPREAD:
        raise ValueError(
            "the control points lie (almost) on one line: add one well off that line"
        )
    m = np.column_stack([uv, np.ones(len(uv))])
    sol, _, rank, _ = np.linalg.lstsq(m, xy, rcond=None)
    if rank < 3:
        raise ValueError("control points are collinear")
    return sol.T
