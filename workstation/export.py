"""Writing a run's results: CSV tables, the radio map (CSV, Parquet, GeoJSON), summary.json.

Every file is written atomically (temporary file, then rename).
"""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from workstation.errors import WorkstationError
from workstation.io.atomic import atomic_write_bytes, atomic_write_set
from workstation.io.map_read import META_KEY
from workstation.pipeline import Result
from workstation.pipeline.summary import Summary
from workstation.pipeline.verdict import reasons

if TYPE_CHECKING:
    import pandas as pd

Columns = dict[str, np.ndarray]  # a table as named columns: what `run` writes without pandas

# the radio map's export formats, one table: file suffix → what the file holds. ``write_radiomap``
# picks the writer by suffix; the panel offers a button per entry.
FORMATS = {
    "csv": "a row per scan and AP; # lines first: the frame, a quarantine, the phone model",
    "parquet": "the same columns, typed, the frame and phone model in its metadata; refused for "
    "a quarantined walk",
    "geojson": "a point per reference point (longitude/latitude when the frame is geographic); "
    "its properties keep x, y, floor, σ, standby and the readings",
}


def _frame(cols: Columns) -> pd.DataFrame:
    import pandas as pd

    return pd.DataFrame(cols)


def trajectory_table(r: Result) -> pd.DataFrame:
    return _frame(trajectory_columns(r))


def landmarks_table(r: Result) -> pd.DataFrame:
    return _frame(landmarks_columns(r))


def segments_table(r: Result) -> pd.DataFrame:
    return _frame(segments_columns(r))


def radiomap_table(r: Result, accepted_only: bool = True) -> pd.DataFrame:
    return _frame(radiomap_columns(r, accepted_only))


def trajectory_columns(r: Result) -> Columns:
    tr = r.track
    return {
        "t": tr.steps.t,
        "x": tr.steps.x,
        "y": tr.steps.y,
        "floor": tr.steps.floor,
        "heading": tr.steps.heading,
        "step_length": tr.steps.step_length,
        "segment": tr.steps.segment,
        "x_corrected": tr.steps.x_bc,
        "y_corrected": tr.steps.y_bc,
        "raw_x": tr.steps.raw_x,
        "raw_y": tr.steps.raw_y,
    }


def landmarks_columns(r: Result) -> Columns:
    d, tr = r.landmarks, r.track
    return {
        "t": d.t,
        "type": d.kind,
        "t_end": d.t_end,
        "value": d.value,
        "confidence": tr.detections.confidence,
        "candidate": tr.detections.candidate,
        "node": tr.detections.node,
        # how far a nearly as likely association puts this detection (m; pipeline/tracking.py)
        "spread_m": tr.detections.spread,
        "reason": tr.detections.reason,
    }


def segments_columns(r: Result) -> Columns:
    tr, b = r.track, r.belief
    return {
        "segment": np.arange(tr.segments.from_node.size),
        "from": tr.segments.from_node,
        "to": tr.segments.to_node,
        "t_start": tr.segments.t0,
        "t_end": tr.segments.t1,
        "steps": b.steps,
        "valid_ratio": b.valid_ratio,
        "period_sd": b.period_sd,
        "belief": b.belief,
        "accepted": b.accepted,
    }


def radiomap_columns(r: Result, accepted_only: bool = True) -> Columns:
    """The walk's radio map: its reference points and, marked ``standby``, the scans held back
    for their σ alone, which join a merged map where no point covers them (standby.py);
    ``accepted_only`` False: every scan, with ``accepted``."""
    full = r.radiomap
    wait = full.held_for_sigma if accepted_only else np.zeros(len(full), bool)
    rows = full.accepted | wait
    rm = full.rows(rows) if accepted_only else full
    cols: Columns = {"x": rm.x, "y": rm.y, "floor": rm.floor, "t": rm.t, "belief": rm.belief}
    if rm.sigma is not None:
        cols["sigma"] = np.round(rm.sigma, 3)
    if wait.any():
        cols["standby"] = wait[rows]
    if not accepted_only:
        cols["accepted"] = rm.accepted
    for j, b in enumerate(rm.bssids):
        cols.setdefault(str(b), rm.rss[:, j])
    return cols


def _columns(table: pd.DataFrame | Columns) -> Columns:
    if isinstance(table, dict):
        return table
    return {str(c): table[c].to_numpy() for c in table.columns}


def _csv(table: pd.DataFrame | Columns) -> str:
    """CSV text as pandas writes it with ``float_format="%.6g"`` (no index; NaN and None empty;
    booleans True/False; minimal quoting) — without importing pandas."""
    cols = _columns(table)
    n = len(next(iter(cols.values()))) if cols else 0
    text = [_strings(np.asarray(v), n) for v in cols.values()]
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(list(cols))
    w.writerows(zip(*text))
    return buf.getvalue()


def _strings(v: np.ndarray, n: int) -> list[str]:
    if v.dtype.kind == "f":
        s = np.char.mod("%.6g", v)
        s[np.isnan(v)] = ""
        return s.tolist()
    if v.dtype.kind in "biu":
        return [str(x) for x in v.tolist()]
    return [
        "" if x is None or (isinstance(x, float) and np.isnan(x)) else str(x) for x in v.tolist()
    ]


def write_radiomap(
    df: pd.DataFrame | Columns,
    path: str | Path,
    frame=None,
    quarantined: str = "",
    device: str = "",
    kind: str = "points",
) -> Path:
    """Radio map to one of :data:`FORMATS` (by the file's suffix), atomically,
    the previous file kept as ``<name>.bak`` (:func:`radiomap_bytes` says what is written)."""
    path = Path(path)
    atomic_write_bytes(path, radiomap_bytes(df, path, frame, quarantined, device, kind),
                       backup=True)  # fmt: skip
    return path


def radiomap_bytes(
    df: pd.DataFrame | Columns, path: Path, frame=None, quarantined: str = "", device: str = "",
    kind: str = "points",
) -> bytes:
    """A radio map as the file ``path`` names it. A CSV starts with ``# frame origin_lat=..
    origin_lon=..`` when the positions belong to a geographic frame, and with ``# quarantined:
    REASONS`` when the walk is quarantined (:mod:`.pipeline.verdict`: merge and localize refuse
    it), with ``# device: MODEL`` when the walks' phone model is known (merge and localize align
    devices only across models), with ``# kind: NAME`` when the map is not the walks' points
    (fingerprints/kinds.py); Parquet and GeoJSON keep the same in their metadata."""
    suffix = path.suffix.lower()
    if quarantined and suffix != ".csv":
        raise WorkstationError(
            f"{path}: this walk is quarantined ({quarantined}); fix it before exporting its map"
        )
    if suffix == ".csv":
        head = (
            (
                f"# frame origin_lat={frame.origin_lat} origin_lon={frame.origin_lon}\n"
                if frame is not None
                else ""
            )
            + (f"# quarantined: {quarantined}\n" if quarantined else "")
            + (f"# device: {device}\n" if device and "\n" not in device else "")
            + (f"# kind: {kind}\n" if kind != "points" else "")
        )
        return (head + _csv(df)).encode("utf-8")
    if suffix == ".parquet":
        import pyarrow.parquet as pq

        buf = io.BytesIO()
        pq.write_table(map_table(_frame(df) if isinstance(df, dict) else df, frame, device, kind),
                       buf)  # fmt: skip
        return buf.getvalue()
    if suffix in (".geojson", ".json"):
        df = _frame(df) if isinstance(df, dict) else df
        return json.dumps(_geojson(df, frame, device, kind)).encode("utf-8")
    known = ", ".join(f".{k}" for k in FORMATS)
    raise WorkstationError(f"{path}: radio map format must be one of {known}")


def map_meta(frame=None, device: str = "", kind: str = "points") -> dict:
    """What a radio map file says of itself beyond its rows: its geographic frame (positions
    are metres in it), its walks' phone model and its kind (fingerprints/kinds.py)."""
    return {"format": 1, "frame": None if frame is None else frame.to_dict(), "device": device,
            "kind": kind}  # fmt: skip


def map_table(df: pd.DataFrame, frame=None, device: str = "", kind: str = "points"):
    """A radio map as an Arrow table whose schema metadata holds :func:`map_meta` (a Parquet
    file written from it keeps its frame and phone model)."""
    import pyarrow as pa

    table = pa.Table.from_pandas(df, preserve_index=False)
    meta = dict(table.schema.metadata or {})
    meta[META_KEY.encode()] = json.dumps(map_meta(frame, device, kind)).encode()
    return table.replace_schema_metadata(meta)


def fingerprints_table(fp, building: str = ""):
    """A radio map (:class:`~.fingerprints.localize.Fingerprints`) as :func:`map_table` makes
    it from :meth:`~.fingerprints.localize.Fingerprints.to_frame` — the same columns, NaN as
    null, the same metadata — but column by column from its arrays: the pandas frame and the
    table made from it were two more copies of a building's readings (0.8 GB each at 40,000
    rows × 2,400 APs: the campaign's client at 10,000 walks, issue #66). ``building``: a first
    column naming it (a campaign's dataset is partitioned by it)."""
    import pyarrow as pa

    cols: dict[str, object] = {}
    if building:
        cols["building"] = pa.array([building] * len(fp), pa.large_string())
    cols |= {"x": pa.array(fp.x), "y": pa.array(fp.y), "floor": pa.array(fp.floor)}
    if fp.sigma is not None:
        cols["sigma"] = pa.array(np.round(fp.sigma, 3), from_pandas=True)
    if fp.standby is not None:
        cols["standby"] = pa.array(fp.on_standby)
    for j, b in enumerate(fp.bssids):
        cols[str(b)] = pa.array(np.ascontiguousarray(fp.rss[:, j]), from_pandas=True)
    table = pa.table(cols)
    meta = {META_KEY.encode(): json.dumps(map_meta(fp.frame, fp.device, fp.kind)).encode()}
    return table.replace_schema_metadata(meta)


def _geojson(df: pd.DataFrame, frame, device: str = "", kind: str = "points") -> dict:
    """RFC 7946 points in lon/lat when the map has a geographic frame, else local metres; each
    point's properties keep x, y (metres in the frame), floor, σ, standby and its readings."""
    fixed = {"x", "y", "floor", "t", "belief", "sigma", "accepted", "standby"}
    aps = [c for c in df.columns if c not in fixed]
    rss = df[aps].to_numpy(float) if aps else np.empty((len(df), 0))
    x, y = df["x"].to_numpy(float), df["y"].to_numpy(float)
    if frame is not None:
        lat, lon = frame.to_latlon(x, y)
        coords = np.column_stack([lon, lat])
    else:
        coords = np.column_stack([x, y])
    feats = []
    for i in range(len(df)):
        props = {k: df[k].iloc[i].item() for k in fixed if k in df}
        props["rss"] = {a: float(v) for a, v in zip(aps, rss[i]) if np.isfinite(v)}
        feats.append(
            {
                "type": "Feature",
                "geometry": {"type": "Point", "coordinates": [float(c) for c in coords[i]]},
                "properties": props,
            }
        )
    out = {"type": "FeatureCollection", META_KEY: map_meta(frame, device, kind), "features": feats}
    if frame is None:
        out["coordinates_note"] = (
            "local metres (x east, y north) of the landmark graph; no geographic frame"
        )
    return out


def write_estimates(cols: Columns, path, frame=None) -> Path:
    """A walk's estimates (:mod:`.fingerprints.walk_estimates`), one row per scan, to CSV,
    Parquet or GeoJSON by the file's suffix, atomically, the previous file kept as ``.bak``.
    GeoJSON: a point per scan in longitude/latitude when the map has a geographic frame (else
    local metres), no geometry for a scan not localized; every column in its properties."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".csv":
        data = _csv(cols).encode("utf-8")
    elif suffix == ".parquet":
        import pyarrow as pa
        import pyarrow.parquet as pq

        table = pa.table({k: pa.array(v) for k, v in cols.items()})
        meta = {META_KEY.encode(): json.dumps(map_meta(frame)).encode()}
        buf = io.BytesIO()
        pq.write_table(table.replace_schema_metadata(meta), buf)
        data = buf.getvalue()
    elif suffix in (".geojson", ".json"):
        x, y = cols["x"], cols["y"]
        ll = frame is not None and "lon" in cols
        feats = []
        for i in range(x.size):
            props = {k: (None if isinstance(v[i], float) and not np.isfinite(v[i]) else v[i].item())
                     for k, v in cols.items()}  # fmt: skip
            here = bool(np.isfinite(x[i]))
            at = [float(cols["lon"][i]), float(cols["lat"][i])] if ll else [float(x[i]), float(y[i])]
            feats.append({"type": "Feature", "properties": props,
                          "geometry": {"type": "Point", "coordinates": at} if here else None})  # fmt: skip
        data = json.dumps({"type": "FeatureCollection", META_KEY: map_meta(frame),
                           "features": feats}).encode("utf-8")  # fmt: skip
    else:
        raise WorkstationError(f"{path}: estimates go to .csv, .parquet or .geojson")
    atomic_write_bytes(path, data, backup=True)
    return path


def write_run(
    r: Result, summary: Summary, out: str | Path, frame=None, device: str = ""
) -> dict[str, Path]:
    """A run's five outputs, together or not at all (``atomic_write_set``): a full disk used to
    leave trajectory.csv and landmarks.csv of this run beside the previous radiomap.csv."""
    out = Path(out)
    made = [p for p in (out, *out.parents) if not p.exists()]  # the folders this run makes
    out.mkdir(parents=True, exist_ok=True)
    files = {
        "trajectory": out / "trajectory.csv",
        "landmarks": out / "landmarks.csv",
        "segments": out / "segments.csv",
        "radiomap": out / "radiomap.csv",
        "summary": out / "summary.json",
    }
    rm = radiomap_bytes(radiomap_columns(r), files["radiomap"], frame, reasons(summary), device)
    try:
        _write_run(files, r, summary, rm)
    except BaseException:
        for p in made:  # a run that wrote nothing leaves no empty folder (issue #67 item 4)
            try:
                p.rmdir()
            except OSError:
                break
        raise
    return files


def _write_run(files: dict[str, Path], r: Result, summary: Summary, rm: bytes) -> None:
    atomic_write_set(
        {
            files["trajectory"]: _csv(trajectory_columns(r)).encode("utf-8"),
            files["landmarks"]: _csv(landmarks_columns(r)).encode("utf-8"),
            files["segments"]: _csv(segments_columns(r)).encode("utf-8"),
            files["radiomap"]: rm,
            files["summary"]: (json.dumps(summary.to_json(), indent=2) + "\n").encode("utf-8"),
        },
        backup=(files["radiomap"],),
    )
