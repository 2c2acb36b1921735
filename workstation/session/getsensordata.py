"""Reader for GetSensorData (LOPSI/CSIC) logfiles, the IPIN competition format.

Records used: ACCE, GYRO, MAGN (m/s², rad/s, µT), PRES (hPa), WIFI, POSI (ground truth). Every
other record type is counted and skipped. IMU/pressure times come from the sensor's own clock
(clean sampling intervals) shifted onto the app clock (common to all streams and to POSI).
"""

from __future__ import annotations

from datetime import datetime
from pathlib import Path

import numpy as np

from workstation.errors import InputError
from workstation.geo import LocalFrame
from workstation.session._bulk import BulkRecords, split_records
from workstation.session._parse import (
    Records,
    order_readings,
    order_times,
    read_bytes,
    text_column,
    text_lines,
)
from workstation.session.clocks import another_sensor, first_jump, second_clock
from workstation.session.metadata import Metadata
from workstation.session.model import GroundTruth, Scalar, Session, Vector3, WifiScans

_VEC = {"ACCE": "accelerometer", "GYRO": "gyroscope", "MAGN": "magnetometer"}
_LAYOUT = {
    "ACCE": (6, "ACCE;AppTs;SensorTs;X;Y;Z"),
    "GYRO": (6, "GYRO;AppTs;SensorTs;X;Y;Z"),
    "MAGN": (6, "MAGN;AppTs;SensorTs;X;Y;Z"),
    "PRES": (4, "PRES;AppTs;SensorTs;hPa"),
    "WIFI": (7, "WIFI;AppTs;SensorTs;SSID;BSSID;FreqMHz;RSSdBm"),
    "POSI": (6, "POSI;AppTs;Counter;Lat;Lon;Floor[;Building]"),
}
# fields read in bulk per record type (the type is field 0): (as numbers, as text)
_IMU = ((1, 2, 3, 4, 5), ())
_BULK = {"ACCE": _IMU, "GYRO": _IMU, "MAGN": _IMU, "PRES": ((1, 2, 3), ()),
         "WIFI": ((1, 5, 6), (3, 4)), "POSI": ((1, 3, 4, 5), ())}  # fmt: skip
# A sample whose sensor clock disagrees with the app clock by more than this is re-timed
# from the app clock instead.
_MAX_CLOCK_RESIDUAL_S = 1.0


def looks_like(first_lines: list[str]) -> bool:
    text = "\n".join(first_lines)
    return "GetSensorData" in text or any(
        ln.split(";", 1)[0] in _LAYOUT for ln in first_lines if ";" in ln
    )


def read_getsensordata(path: str | Path, frame: LocalFrame | None = None) -> Session:
    """Read a GetSensorData logfile into a :class:`Session`.

    ``frame``: metric frame for POSI fixes; default :meth:`LocalFrame.around` the first fix.
    """
    path = Path(path)
    data = read_bytes(path)
    split = split_records(path, data, _BULK)
    recs, header, skipped = split if split is not None else _split_lines(path, data)
    del data, split  # the text is kept only where a value must be re-read to name an error
    for k, r in recs.items():
        r.require_fields(path, *_LAYOUT[k])
    if not len(recs["ACCE"]):
        raise InputError(path, "no accelerometer (ACCE) records: cannot detect steps")

    warnings: list[str] = []
    jumps: list[tuple[float, str]] = []
    streams = {k: _vector(path, recs[k], warnings, jumps) for k in _VEC}
    jumps += another_sensor(streams["MAGN"])
    pressure = None
    if len(recs["PRES"]):
        n = recs["PRES"].numbers(path, {1: "AppTimestamp", 2: "SensorTimestamp", 3: "pressure"})
        t = _sensor_time(n["AppTimestamp"], n["SensorTimestamp"], "PRES", warnings, jumps)
        keep = order_times(t, "PRES", warnings)
        pressure = Scalar(t[keep], n["pressure"][keep])
    else:
        warnings.append("no barometer (PRES): treated as a single-floor walk")

    wifi = _wifi(path, recs["WIFI"], warnings)
    gt, frame = _posi(path, recs["POSI"], frame, warnings)

    device = " ".join(v for v in (header.get("Manufacturer"), header.get("Model")) if v)
    jump = first_jump(jumps, warnings)
    meta = Metadata(
        source="getsensordata",
        path=str(path),
        device=device,
        frame=frame,
        # the wall clock of the app's time 0, to the second: which walk came right before
        # which (walks/chain.py); None when the header does not say it
        start_time_ms=created_ms(header.get("Date of creation")),
        skipped=dict(sorted(skipped.items())),
        warnings=tuple(warnings),
        clock_jump=jump,
        extra={"android": header.get("Android version Release")},
    )
    return Session(
        accelerometer=streams["ACCE"],
        gyroscope=streams["GYRO"],
        magnetometer=streams["MAGN"],
        pressure=pressure,
        wifi=wifi,
        ground_truth=gt,
        metadata=meta,
    )


def created_ms(text: str | None) -> float | None:
    """The header's "Date of creation" (``Wed Jun 14 10:00:58 GMT+02:00 2023``) in ms since
    the epoch; None when absent or not in that form."""
    try:
        when = datetime.strptime((text or "").replace("GMT", ""), "%a %b %d %H:%M:%S %z %Y")
    except ValueError:
        return None
    return when.timestamp() * 1000.0


def _split_lines(
    path: Path, data: bytes | bytearray
) -> tuple[dict[str, Records], dict[str, str], dict[str, int]]:
    """Line by line: the records of each type, the header and the other types' counts."""
    recs = {k: Records(k) for k in _LAYOUT}
    skipped: dict[str, int] = {}
    header: dict[str, str] = {}
    for i, raw in enumerate(text_lines(data), start=1):
        line = raw.strip()
        if not line:
            continue
        if line[0] == "%":
            if ":" in line:
                key, _, val = line[1:].partition(":")
                header.setdefault(key.strip(), val.strip())
            continue
        fields = line.split(";")
        r = recs.get(fields[0])
        if r is not None:
            r.add(i, fields)
        elif fields[0].isalnum() and fields[0].isupper() and len(fields) > 1:
            skipped[fields[0]] = skipped.get(fields[0], 0) + 1
        else:
            raise InputError(path, f"not a GetSensorData record: {line[:60]!r}", i)
    return recs, header, dict(sorted(skipped.items()))


def _sensor_time(
    app: np.ndarray, sensor: np.ndarray, kind: str, warnings: list[str],
    jumps: list[tuple[float, str]],
) -> np.ndarray:  # fmt: skip
    """Sensor-clock times moved onto the app clock; samples whose clocks disagree use app time.
    A block of them is a second recording re-timed on the app clock (:mod:`.clocks`): where it
    begins goes to ``jumps``."""
    offset = np.median(app - sensor)
    t = sensor + offset
    off = np.abs(t - app) > _MAX_CLOCK_RESIDUAL_S
    if off.any():
        warnings.append(
            f"{kind}: {int(off.sum())} samples with an inconsistent sensor clock re-timed from the app clock"
        )
        t = np.where(off, app, t)
        # a second recording: a block on another offset than the opening samples' (not the
        # median's: two recordings of one length put it between them), itself on one offset
        order = np.argsort(app, kind="stable")
        found = second_clock(app[order], (app - sensor)[order], _MAX_CLOCK_RESIDUAL_S)
        if found is not None:
            jumps.append((found[0], f"{found[1]} of {off.size} {kind} samples on another "
                                    "sensor clock"))  # fmt: skip
    return t


def _vector(
    path: Path, r: Records | BulkRecords, warnings: list[str], jumps: list[tuple[float, str]]
) -> Vector3:
    if not len(r):
        warnings.append(f"no {_VEC[r.kind]} ({r.kind}) records")
        return Vector3.empty()
    n = r.numbers(path, {1: "AppTimestamp", 2: "SensorTimestamp", 3: "x", 4: "y", 5: "z"})
    t = _sensor_time(n["AppTimestamp"], n["SensorTimestamp"], r.kind, warnings, jumps)
    keep = order_times(t, r.kind, warnings, path, r.lines)
    xyz = np.column_stack([n["x"], n["y"], n["z"]])
    return Vector3(t[keep], xyz[keep])


def _wifi(path: Path, r: Records | BulkRecords, warnings: list[str]) -> WifiScans:
    if not len(r):
        warnings.append("no WiFi (WIFI) records")
        return WifiScans.empty()
    n = r.numbers(path, {1: "AppTimestamp", 5: "frequency", 6: "RSS"})
    bssid = np.array([f.strip().lower() for f in text_column(path, r, 4, "BSSID")], dtype=np.str_)
    empty = np.flatnonzero(np.char.str_len(bssid) == 0)
    if empty.size:
        raise InputError(path, "WIFI record with an empty BSSID", r.lines[int(empty[0])])
    ssid = np.array(text_column(path, r, 3, "SSID"), dtype=np.str_)
    t = n["AppTimestamp"]
    keep = order_readings(t, bssid, "WIFI", warnings)
    return WifiScans(t[keep], bssid[keep], ssid[keep], n["frequency"][keep], n["RSS"][keep])


def _posi(
    path: Path, r: Records | BulkRecords, frame: LocalFrame | None, warnings: list[str]
) -> tuple[GroundTruth | None, LocalFrame | None]:
    if not len(r):
        return None, frame
    n = r.numbers(path, {1: "AppTimestamp", 3: "latitude", 4: "longitude", 5: "floor"})
    lat, lon = n["latitude"], n["longitude"]
    bad = np.flatnonzero((np.abs(lat) > 90) | (np.abs(lon) > 180))
    if bad.size:
        raise InputError(path, "POSI latitude/longitude out of range", r.lines[int(bad[0])])
    keep = order_times(n["AppTimestamp"], "POSI", warnings)
    if frame is None:
        frame = LocalFrame.around(lat[keep][0], lon[keep][0])
    x, y = frame.to_xy(lat[keep], lon[keep])
    gt = GroundTruth(
        t=n["AppTimestamp"][keep], x=x, y=y, floor=n["floor"][keep], lat=lat[keep], lon=lon[keep]
    )
    return gt, frame
