"""Reader for Microsoft Indoor Location Competition 2.0 path files (tab-separated).

Rows are not in time order in these files: every stream is sorted. A WiFi row is a stale cached
result, and is dropped, when its ``lastSeen`` is not newer than the previous scan or is more
than ``max_wifi_age_s`` before its own scan.
Waypoints (metres in the floor-plan frame) are the ground truth; the floor comes from the
header's ``FloorName`` (F1 → 0, F2 → 1, B1 → -1, ...).
"""

from __future__ import annotations

import re
import sys
from pathlib import Path
from typing import Any

import numpy as np

from workstation.errors import InputError
from workstation.session._bulk import BulkRecords
from workstation.session._bulk_tsv import split_tsv
from workstation.session._parse import (
    Records,
    order_readings,
    order_times,
    read_bytes,
    text_column,
    text_lines,
)
from workstation.session.clocks import (
    FUTURE_MS,
    MIN_SCANS,
    PAST_MS,
    another_sensor,
    block_start,
    calibration_change,
    first_jump,
)
from workstation.session.metadata import Metadata
from workstation.session.model import GroundTruth, Session, Vector3, WifiScans

_VEC = {
    "TYPE_ACCELEROMETER": "accelerometer",
    "TYPE_GYROSCOPE": "gyroscope",
    "TYPE_MAGNETIC_FIELD": "magnetometer",
}
_LAYOUT = {
    "TYPE_ACCELEROMETER": (5, "ms TYPE x y z"),
    "TYPE_GYROSCOPE": (5, "ms TYPE x y z"),
    "TYPE_MAGNETIC_FIELD": (5, "ms TYPE x y z"),
    "TYPE_WIFI": (7, "ms TYPE ssid bssid rssi freq lastSeen"),
    "TYPE_WAYPOINT": (4, "ms TYPE x y"),
}
# fields read in bulk per record type (the time is field 0, the type 1): (as numbers, as text)
_XYZ = ((0, 2, 3, 4), ())
#: read as evidence only (no stream; counted among the skipped types as before): the phone's
#: magnetometer calibration, raw x y z and the bias it subtracted (session/clocks.py)
_UNCAL = "TYPE_MAGNETIC_FIELD_UNCALIBRATED"
_UNCAL_FIELDS = {0: "time", 2: "x", 3: "y", 4: "z", 5: "bx", 6: "by", 7: "bz"}
_BULK = {"TYPE_ACCELEROMETER": _XYZ, "TYPE_GYROSCOPE": _XYZ, "TYPE_MAGNETIC_FIELD": _XYZ,
         "TYPE_WIFI": ((0, 4, 5, 6), (2, 3)), "TYPE_WAYPOINT": ((0, 2, 3), ()),
         _UNCAL: (tuple(_UNCAL_FIELDS), ())}  # fmt: skip
BULK_MIN_BYTES = 16 << 20  # in bulk beyond this size, or beyond the next with Arrow loaded
BULK_MIN_BYTES_LOADED = 2 << 20
DEFAULT_MAX_WIFI_AGE_S = 5.0


def looks_like(first_lines: list[str]) -> bool:
    return any(("\tTYPE_" in ln) or ln.startswith("#\tstartTime") for ln in first_lines)


def floor_number(name: str | None) -> float:
    """F1 → 0, F2 → 1, ..., B1 → -1, B2 → -2; 1F/1B forms too; NaN if unrecognised."""
    if not name:
        return float("nan")
    m = re.fullmatch(r"([FB])(\d+)|(\d+)([FB])", name.strip().upper())
    if not m:
        return float("nan")
    letter = m.group(1) or m.group(4)
    num = int(m.group(2) or m.group(3))
    return float(num - 1 if letter == "F" else -num)


def read_msilc(path: str | Path, max_wifi_age_s: float = DEFAULT_MAX_WIFI_AGE_S) -> Session:
    path = Path(path)
    data = read_bytes(path)
    # in bulk where it pays: Arrow's CSV reader costs ~1.5 ms a record type and its import 90 ms
    # (a 1-MB walk reads in 16 ms either way, a 4-MB one 60 → 36 ms); the same records either way
    least = BULK_MIN_BYTES if "pyarrow" not in sys.modules else BULK_MIN_BYTES_LOADED
    split = split_tsv(data, _BULK) if len(data) > least else None
    recs, header, skipped = split if split is not None else _split_lines(path, text_lines(data))
    del data, split
    calibration = recs.pop(_UNCAL, None)
    if calibration is not None and len(calibration):
        skipped[_UNCAL] = len(calibration)
    for k, r in recs.items():
        r.require_fields(path, *_LAYOUT[k])
    if not len(recs["TYPE_ACCELEROMETER"]):
        raise InputError(path, "no accelerometer (TYPE_ACCELEROMETER) records: cannot detect steps")

    t0 = _start_ms(path, header, recs)
    warnings: list[str] = ["no barometer: treated as a single-floor walk"]
    streams = {}
    for k, name in _VEC.items():
        r = recs[k]
        if not len(r):
            warnings.append(f"no {name} ({k}) records")
            streams[k] = Vector3.empty()
            continue
        n = r.numbers(path, {0: "time", 2: "x", 3: "y", 4: "z"})
        t = (n["time"] - t0) / 1000.0
        keep = order_times(t, k, warnings, path, r.lines)
        streams[k] = Vector3(t[keep], np.column_stack([n["x"], n["y"], n["z"]])[keep])
    jumps = _calibration(path, calibration, t0) + another_sensor(streams["TYPE_MAGNETIC_FIELD"])
    return _session(path, recs, header, skipped, t0, streams, warnings, max_wifi_age_s, jumps)


def _calibration(path: Path, r: Records | BulkRecords | None, t0: float) -> list[tuple[float, str]]:
    """Where the phone's magnetometer calibration says a second recording begins
    (:func:`.clocks.calibration_change`): a list of that one piece of evidence, or empty when
    there is none, the file has no such rows or any of them is malformed (they are evidence,
    not a stream: never a refusal)."""
    if r is None or len(r) < 2:
        return []
    if isinstance(r, Records):
        if min(map(len, r.fields)) <= max(_UNCAL_FIELDS):
            return []
        first = r.fields[0][5:8]
        if all(f[5:8] == first for f in r.fields):
            return []  # one estimate throughout, as written: nothing to parse
    try:
        n = r.numbers(path, _UNCAL_FIELDS)
    except (InputError, ValueError):
        return []
    v = np.column_stack([n[k] for k in _UNCAL_FIELDS.values()])
    if not np.isfinite(v).all():
        return []
    v = v[np.argsort(v[:, 0], kind="stable")]
    found = calibration_change((v[:, 0] - t0) / 1000.0, v[:, 1:4], v[:, 4:7])
    return [] if found is None else [found]


def _split_lines(
    path: Path, lines: list[str]
) -> tuple[dict[str, Records], dict[str, str], dict[str, int]]:
    """Line by line: the records of each type, the header and the other types' counts."""
    recs = {k: Records(k) for k in (*_LAYOUT, _UNCAL)}
    skipped: dict[str, int] = {}
    header: dict[str, str] = {}
    for i, raw in enumerate(lines, start=1):
        line = raw.strip("\n")
        if not line.strip():
            continue
        fields = line.split("\t")
        if fields[0].strip() == "#":
            for f in fields[1:]:
                key, sep, val = f.partition(":")
                if sep:
                    header.setdefault(key.strip(), val.strip())
            continue
        if len(fields) < 2:
            raise InputError(
                path, f"not a path-file record (no tab-separated type): {line[:60]!r}", i
            )
        r = recs.get(fields[1])
        if r is not None:
            r.add(i, fields)
        elif fields[1].startswith("TYPE_"):
            skipped[fields[1]] = skipped.get(fields[1], 0) + 1
        else:
            raise InputError(path, f"unknown record type {fields[1][:40]!r}", i)
    return recs, header, skipped


def _session(
    path: Path, recs: dict[str, Any], header: dict[str, str], skipped: dict[str, int], t0: float,
    streams: dict[str, Vector3], warnings: list[str], max_wifi_age_s: float,
    jumps: list[tuple[float, str]],
) -> Session:  # fmt: skip
    """The session from the records split (the streams already ordered); ``jumps``: the
    evidence of a second recording found so far (the WiFi's is added)."""
    wifi, n_stale = _wifi(path, recs["TYPE_WIFI"], t0, max_wifi_age_s, warnings, jumps)
    floor_name = header.get("FloorName")
    floor = floor_number(floor_name)
    gt = None
    r = recs["TYPE_WAYPOINT"]
    if len(r):
        n = r.numbers(path, {0: "time", 2: "x", 3: "y"})
        t = (n["time"] - t0) / 1000.0
        keep = order_times(t, "TYPE_WAYPOINT", warnings)
        gt = GroundTruth(t[keep], n["x"][keep], n["y"][keep], np.full(keep.size, floor))
    if np.isnan(floor):
        warnings.append(f"floor name {floor_name!r} not understood: floor left unknown")
    if n_stale:
        skipped["TYPE_WIFI (stale)"] = n_stale
    device = " ".join(v for v in (header.get("Brand"), header.get("Model")) if v)
    jump = first_jump(jumps, warnings)
    meta = Metadata(
        source="msilc",
        path=str(path),
        device=device,
        floor_name=floor_name,
        start_time_ms=t0,
        skipped=dict(sorted(skipped.items())),
        warnings=tuple(warnings),
        clock_jump=jump,
        extra={
            "site": header.get("SiteName"),
            "site_id": header.get("SiteID"),
            "max_wifi_age_s": max_wifi_age_s,
        },  # fmt: skip
    )
    return Session(
        accelerometer=streams["TYPE_ACCELEROMETER"],
        gyroscope=streams["TYPE_GYROSCOPE"],
        magnetometer=streams["TYPE_MAGNETIC_FIELD"],
        pressure=None,
        wifi=wifi,
        ground_truth=gt,
        metadata=meta,
    )


def _start_ms(path: Path, header: dict[str, str], recs: dict[str, Any]) -> float:
    if "startTime" in header:
        try:
            return float(header["startTime"])
        except ValueError:
            raise InputError(
                path, f"header startTime {header['startTime']!r} is not a number"
            ) from None
    firsts = [r.numbers(path, {0: "time"})["time"].min() for r in recs.values() if len(r)]
    return float(min(firsts))


def _wifi(
    path: Path, r: Records | BulkRecords, t0: float, max_age: float, warnings: list[str],
    jumps: list[tuple[float, str]],
) -> tuple[WifiScans, int]:  # fmt: skip
    if not len(r):
        warnings.append("no WiFi (TYPE_WIFI) records")
        return WifiScans.empty(), 0
    n = r.numbers(path, {0: "time", 4: "RSS", 5: "frequency", 6: "lastSeen"})
    scans, scan_of = np.unique(n["time"], return_inverse=True)
    previous = np.concatenate([[-np.inf], scans[:-1]])[scan_of]
    fresh = (n["lastSeen"] > previous) & ((n["time"] - n["lastSeen"]) <= max_age * 1000.0)
    bssid = np.array([f.strip().lower() for f in text_column(path, r, 3, "BSSID")], dtype=np.str_)
    ssid = np.array(text_column(path, r, 2, "SSID"), dtype=np.str_)
    idx = np.flatnonzero(fresh)
    t = (n["time"][idx] - t0) / 1000.0
    keep = idx[order_readings(t, bssid[idx], "TYPE_WIFI", warnings)]
    t = (n["time"][keep] - t0) / 1000.0
    wifi = WifiScans(t, bssid[keep], ssid[keep], n["frequency"][keep], n["RSS"][keep])
    # scans reporting an access point seen after them, or none seen within 10 min before: a
    # second recording re-timed earlier or later (session/clocks.py); never so in one recording
    newest = np.full(scans.size, np.inf)  # per scan, the age of its freshest reading (ms)
    np.minimum.at(newest, scan_of, n["time"] - n["lastSeen"])
    other = (newest < -FUTURE_MS) | (newest > PAST_MS)
    at = block_start((scans - t0) / 1000.0, other, MIN_SCANS)
    if at is not None:
        jumps.append((at, f"{int(other.sum())} of {other.size} WiFi scans report an access point "
                          f"seen after the scan, or none within {PAST_MS / 60000:g} min "
                          "before it"))  # fmt: skip
    return wifi, int((~fresh).sum())
