"""Our own session folder: ``session.yaml`` (header) + one Parquet file per stream. Lossless.

::

    walk/
      session.yaml          format, version, metadata, the list of stream files
      accelerometer.parquet t, x, y, z
      gyroscope.parquet     t, x, y, z
      magnetometer.parquet  t, x, y, z
      pressure.parquet      t, hpa                      (optional)
      wifi.parquet          t, bssid, ssid, freq_mhz, rss_dbm
      ground_truth.parquet  t, x, y, floor[, heading, walking, lat, lon]   (optional)
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any, TypeVar

import numpy as np
import yaml

from workstation.errors import InputError
from workstation.io.arrow import column_to_numpy
from workstation.io.atomic import atomic_replace_dir
from workstation.io.yamlio import load_yaml
from workstation.session.metadata import Metadata
from workstation.session.model import GroundTruth, Scalar, Session, Vector3, WifiScans

T = TypeVar("T")

FORMAT = "workstation-session"
VERSION = 1
HEADER = "session.yaml"


def is_native(path: Path) -> bool:
    return path.is_dir() and (path / HEADER).is_file()


def _plain(v: Any) -> Any:
    """Metadata made YAML-safe (numpy scalars/arrays to Python)."""
    if isinstance(v, dict):
        return {str(k): _plain(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_plain(x) for x in v]
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, np.ndarray):
        return v.tolist()
    return v


def write_session(session: Session, folder: str | Path) -> Path:
    """Write ``session`` to ``folder`` atomically (a temporary folder renamed into place)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    def build(tmp: Path) -> None:
        files = {}

        def put(name: str, table: dict) -> None:
            pq.write_table(pa.table(table), tmp / f"{name}.parquet", compression="zstd")
            files[name] = f"{name}.parquet"

        for name in ("accelerometer", "gyroscope", "magnetometer"):
            s: Vector3 = getattr(session, name)
            put(name, {"t": s.t, "x": s.xyz[:, 0], "y": s.xyz[:, 1], "z": s.xyz[:, 2]})
        if session.pressure is not None:
            put("pressure", {"t": session.pressure.t, "hpa": session.pressure.value})
        w = session.wifi
        put(
            "wifi",
            {
                "t": w.t,
                "bssid": pa.array(w.bssid.tolist(), pa.string()),
                "ssid": pa.array(w.ssid.tolist(), pa.string()),
                "freq_mhz": w.freq_mhz,
                "rss_dbm": w.rss_dbm,
            },
        )
        gt = session.ground_truth
        if gt is not None:
            cols = {k: getattr(gt, k) for k in ("t", "x", "y", "floor")}
            cols.update(
                {k: getattr(gt, k) for k in GroundTruth.OPTIONAL if getattr(gt, k) is not None}
            )
            put("ground_truth", cols)
        meta = session.metadata.to_dict()
        src = meta.pop("path", None)
        meta.setdefault("source_path", src)
        header = {
            "format": FORMAT,
            "version": VERSION,
            "metadata": _plain(meta),
            "streams": files,
        }
        (tmp / HEADER).write_text(yaml.safe_dump(header, sort_keys=False, allow_unicode=True))

    return atomic_replace_dir(build, folder)


STREAMS = ("accelerometer", "gyroscope", "magnetometer", "pressure", "wifi", "ground_truth")


def _check_streams(files: dict, folder: Path, hpath: Path) -> list[str]:
    """A header's streams (issue #33: headers that loaded with a wrong value): each a known
    stream, in a file of its own inside the session folder; none listed at all is refused; a
    stream file in the folder that the header does not list is said (it is not read)."""
    if not files:
        raise InputError(hpath, "lists no stream (streams: {accelerometer: ..., ...})")
    for name, f in files.items():
        if name not in STREAMS:
            raise InputError(hpath, f"unknown stream {name!r} (known: {', '.join(STREAMS)})")
        if not isinstance(f, str) or Path(f).name != f or f.startswith(".") or not f:
            raise InputError(
                hpath, f"stream {name}: {f!r} is not the name of a file in the session folder"
            )
    names = list(files.values())
    for f in set(names):
        if names.count(f) > 1:
            both = " and ".join(k for k, v in files.items() if v == f)
            raise InputError(hpath, f"streams {both} name the same file {f}")
    return [
        f"{k}: {k}.parquet is in the folder but {HEADER} does not list it: not read"
        for k in STREAMS
        if k not in files and (folder / f"{k}.parquet").is_file()
    ]


def _metadata(data: Any, path: Path) -> Metadata:
    """The header's ``metadata``: a mapping, its typed facts checked (``warnings`` a list of
    text, ``skipped`` a count per record type, a second recording's ``clock_jump`` …: ``info``
    printed a traceback on anything else)."""
    if data is None:
        return Metadata()
    if not isinstance(data, dict):
        raise InputError(path, "metadata: expected a mapping")
    try:
        return Metadata.from_dict(data)
    except ValueError as e:
        raise InputError(path, str(e)) from None


def _header(folder: Path) -> dict:
    """session.yaml, checked: this format and version, its streams a mapping."""
    hpath = folder / HEADER
    header = load_yaml(hpath, "session header (session.yaml)")
    if not isinstance(header, dict) or header.get("format") != FORMAT:
        raise InputError(hpath, f"not a {FORMAT} header (format: {FORMAT} missing)")
    if header.get("version") != VERSION:
        raise InputError(
            hpath, f"unsupported version {header.get('version')!r} (this reader: {VERSION})"
        )
    if not isinstance(header.get("streams") or {}, dict):
        raise InputError(hpath, "'streams' must map stream names to files")
    return header


def _table(
    folder: Path, files: dict, name: str, required: tuple[str, ...]
) -> dict[str, np.ndarray] | None:
    """The stream ``name``'s columns (None when the header lists no such stream)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    if name not in files:
        return None
    p = folder / str(files[name])
    try:
        t = pq.ParquetFile(p).read()  # read_table's dataset layer imports pandas
    except FileNotFoundError:
        raise InputError(p, f"stream file listed in {HEADER} is missing") from None
    except (pa.ArrowInvalid, OSError) as e:
        raise InputError(p, f"not a readable Parquet file: {e}") from None
    missing = [c for c in required if c not in t.column_names]
    if missing:
        raise InputError(p, f"missing column(s) {', '.join(missing)}")
    return {c: column_to_numpy(t.column(c)) for c in t.column_names}


def _build(kind: Callable[..., T], path: Path, *args: Any, **kw: Any) -> T:
    """``kind(*args, **kw)``; what it refuses, said of ``path``."""
    try:
        return kind(*args, **kw)
    except ValueError as e:
        raise InputError(path, str(e)) from None


def read_session(folder: str | Path) -> Session:
    folder = Path(folder)
    header = _header(folder)
    files = header.get("streams") or {}
    unlisted = _check_streams(files, folder, folder / HEADER)

    def table(name: str, required: tuple[str, ...]) -> dict[str, np.ndarray] | None:
        return _table(folder, files, name, required)

    build = _build
    vec = {}
    for name in ("accelerometer", "gyroscope", "magnetometer"):
        t = table(name, ("t", "x", "y", "z"))
        vec[name] = (
            Vector3.empty()
            if t is None
            else build(
                Vector3, folder / files[name], t["t"], np.column_stack([t["x"], t["y"], t["z"]])
            )
        )
    meta = _metadata(header.get("metadata"), folder / HEADER)
    if unlisted:
        meta = meta.said(*unlisted)
    # a walk without accelerometer samples loads, said (session/sanity.MISSING: quarantined,
    # no steps) — as the walk it was saved from did (issue #67 item 6: saved, then refused)
    p = table("pressure", ("t", "hpa"))
    pressure = None if p is None else build(Scalar, folder / files["pressure"], p["t"], p["hpa"])
    w = table("wifi", ("t", "bssid", "ssid", "freq_mhz", "rss_dbm"))
    if w is not None:
        null = [i for i, b in enumerate(w["bssid"]) if b is None]  # read as the AP "None"
        if null:
            raise InputError(folder / files["wifi"], f"bssid: row {null[0] + 1} is null")
    wifi = (
        WifiScans.empty()
        if w is None
        else build(
            WifiScans,
            folder / files["wifi"],
            w["t"],
            w["bssid"].astype(str),
            w["ssid"].astype(str),
            w["freq_mhz"],
            w["rss_dbm"],
        )
    )
    g = table("ground_truth", ("t", "x", "y", "floor"))
    gt = None
    if g is not None:
        gt = build(
            GroundTruth,
            folder / files["ground_truth"],
            **{k: v for k, v in g.items() if k in ("t", "x", "y", "floor", *GroundTruth.OPTIONAL)},
        )
    return Session(
        vec["accelerometer"],
        vec["gyroscope"],
        vec["magnetometer"],
        pressure,
        wifi,
        gt,
        replace(meta, path=str(folder)),
    )
