"""Reading a radio-map file: a run's or an export's CSV (an optional ``# frame …``, ``#
quarantined: …`` and ``# device: …`` header), Parquet and GeoJSON (the frame and phone model
in their metadata), or a campaign's merged map of one building (the folder
``radiomap/building=NAME``, partitioned by floor, the metadata in each part). Every error names the
file, and the line where there is one (:class:`.errors.InputError`)."""

from __future__ import annotations

import csv
import io
import json
from collections import Counter
from pathlib import Path

import numpy as np

from workstation.errors import InputError
from workstation.geo import LocalFrame
from workstation.io.store import is_url, read_via_local
from workstation.physical import MAX_FLOOR, RSS_DBM

#: the key of a radio map's own facts (frame, phone model) in a Parquet file's schema metadata
#: and in a GeoJSON FeatureCollection (export.py writes them)
META_KEY = "workstation"
MAX_GEOJSON_BYTES = 512 * 2**20

#: a radio map's columns that are not access points
FIXED_COLUMNS = ("x", "y", "floor", "t", "belief", "sigma", "accepted", "segment", "standby")


def read_map(path: str | Path) -> dict:
    """The radio map at ``path`` (or at a store's URL: :mod:`.store`) as the fields of a
    :class:`.localize.Fingerprints`."""
    import pandas as pd

    if is_url(path):
        return read_via_local(path, read_map)
    path = Path(path)
    frame, held, device, kind, head = None, "", "", "points", 0
    try:
        if path.is_dir() or path.suffix.lower() == ".parquet":  # a folder: floor=… parts
            parts = sorted(path.glob("floor=*/*.parquet")) if path.is_dir() else [path]
            if not parts:
                raise InputError(path, "a folder, but no campaign radio map (floor=…/*.parquet)")
            df = pd.read_parquet(path).drop(columns=["building"], errors="ignore")
            frame, device, kind = _meta(path, _parquet_meta(parts[0]))
        elif path.suffix.lower() in (".geojson", ".json"):
            df, frame, device, kind = _geojson(path)
        else:
            df, frame, held, device, kind, head = _csv(path)
    except FileNotFoundError:
        raise InputError(path, "no such radio map") from None
    except (ValueError, KeyError, pd.errors.ParserError) as e:
        raise InputError(path, f"not a radio map: {e}") from None
    df, cols, aps, rss, wait = _checked(path, df, head)
    extra = {c: _column(path, df, c) for c in ("t", "sigma")}
    return dict(
        **extra,
        x=cols["x"],
        y=cols["y"],
        floor=cols["floor"],
        bssids=np.array(aps, dtype=str),
        rss=rss,
        frame=frame,
        quarantined=held,
        device=device,
        kind=kind,
        standby=wait if wait is not None and wait.any() else None,
    )


def _csv(path: Path):
    """A CSV map: its table, and what its comment lines say (frame, quarantine, phone model,
    kind) with how many there are."""
    import pandas as pd

    frame, held, device, kind = None, "", "", "points"
    text = path.read_text(encoding="utf-8-sig")  # spreadsheets add a BOM
    head = 0  # the comment lines that open the file (only there: a '#' inside a
    for line in text.split("\n", 5)[:5]:  # row is data, not the end of it)
        if not line.startswith("#"):
            break
        head += 1
        if line.startswith("# frame"):
            kv = dict(p.split("=") for p in line[len("# frame") :].split())
            frame = _frame(path, float(kv["origin_lat"]), float(kv["origin_lon"]))
        elif line.startswith("# quarantined:"):
            held = line[len("# quarantined:") :].strip() or "quarantined"
        elif line.startswith("# device:"):
            device = line[len("# device:") :].strip()
        elif line.startswith("# kind:"):
            kind = line[len("# kind:") :].strip() or "points"
    lines = text.split("\n", head + 1)
    if len(lines) <= head or not lines[head].strip():
        raise InputError(path, "no header line (x, y, floor, then one column per AP)",
                         head + 1)  # fmt: skip
    names = next(csv.reader(io.StringIO(lines[head])), [])
    if len(names) > MAX_COLUMNS:  # a row of a million commas: 21 GB in localize
        raise InputError(
            path, f"{len(names):,} columns (at most {MAX_COLUMNS:,})", head + 1
        )
    twice = sorted(c for c, n in Counter(names).items() if n > 1)
    if twice:
        raise InputError(path, f"column {twice[0]!r} appears twice", head + 1)
    if any(not c.strip() for c in names):
        i = next(i for i, c in enumerate(names) if not c.strip())
        raise InputError(path, f"column {i + 1} of the header has no name", head + 1)
    _same_width(path, text, head, len(names))
    df = pd.read_csv(io.StringIO(text), skiprows=head, index_col=False)
    return df, frame, held, device, kind, head


def _checked(path: Path, df, head: int):
    """The columns a map must have, checked (each error names the row): positions and floors
    finite and in range, RSS numbers in a phone's range; rows not accepted dropped."""
    import pandas as pd

    missing = [c for c in ("x", "y", "floor") if c not in df.columns]
    if missing:
        raise InputError(path, f"radio map lacks column(s) {', '.join(missing)}", 1)
    aps = [c for c in df.columns if c not in FIXED_COLUMNS]
    try:
        rss = df[aps].to_numpy(dtype=np.float64) if aps else np.empty((len(df), 0))
    except ValueError:
        raise InputError(path, "RSS columns must be numbers (empty = not heard)") from None
    if "accepted" in df.columns:
        keep = _flags(path, df["accepted"], head)
        df, rss = df[keep], rss[keep]
    wait = _flags(path, df["standby"], head, "standby") if "standby" in df.columns else None
    cols = {}
    for c in ("x", "y", "floor"):
        col = df[c]
        if isinstance(col.dtype, pd.CategoricalDtype):  # a campaign's floor=… partition
            col = col.astype(str)
        try:
            v = pd.to_numeric(col, errors="raise").to_numpy(float)
        except (ValueError, TypeError):
            raise InputError(path, f"column {c}: not all numbers") from None
        if not np.isfinite(v).all():
            row = int(np.flatnonzero(~np.isfinite(v))[0])
            raise InputError(path, f"column {c}: missing or not finite in row {row + 1}")
        far = np.abs(v) > MAX_COORD_M
        if far.any():  # metres (or a floor number): 1e308 read "fine"
            row = int(np.flatnonzero(far)[0])
            raise InputError(path, f"column {c}: {v[row]:g} in row {row + 1} is no position")
        cols[c] = v
    f = cols["floor"]
    bad = (f != np.round(f)) | (np.abs(f) > MAX_FLOOR)
    if bad.any():  # issue #67 item 1: 0.5 or 1e6 read "fine"
        row = int(np.flatnonzero(bad)[0])
        raise InputError(path, f"column floor: {f[row]:g} in row {row + 1} is no floor (a whole "
                         f"number, −{MAX_FLOOR} … {MAX_FLOOR})")  # fmt: skip
    odd = ~np.isnan(rss) & ((rss < RSS_DBM[0]) | (rss > RSS_DBM[1]) | ~np.isfinite(rss))
    if odd.any():  # a digit too many made -78 dBm into -7.9e15, read "fine" (issue #55)
        row, col = (int(v[0]) for v in np.nonzero(odd))
        raise InputError(
            path,
            f"column {aps[col]}: {rss[row, col]:g} dBm in row {row + 1} is no signal strength "
            f"({RSS_DBM[0]:g} … {RSS_DBM[1]:g} dBm)",
        )
    return df, cols, aps, rss, wait


def _column(path, df, name: str) -> np.ndarray | None:
    """A per-row number column the map may carry (``t``, ``sigma``): None when absent or when
    it is not all finite numbers (the map is still a map without them; σ must be ≥ 0)."""
    import pandas as pd

    if name not in df.columns:
        return None
    v = pd.to_numeric(df[name], errors="coerce").to_numpy(float)
    if name == "sigma":  # inf: a row with no σ (a run's scans outside a segment)
        ok = ~np.isnan(v) & (v >= 0)
    else:
        ok = np.isfinite(v)
    return v if ok.all() else None


def _same_width(path, text: str, head: int, width: int) -> None:
    """Every data row has as many fields as the header: one extra comma once shifted every
    column by one (x took y, floor took t) without a word, and a row of a million commas
    took gigabytes. The first row that differs is named with its line."""
    rows = csv.reader(io.StringIO(text))
    for _ in range(head + 1):
        next(rows, None)
    for row in rows:
        if row and len(row) != width:
            raise InputError(path, f"{len(row):,} fields, but the header names {width:,}",
                             rows.line_num)  # fmt: skip


def _parquet_meta(part: Path) -> dict:
    """The :data:`META_KEY` entry of a Parquet file's schema metadata ({} if none)."""
    import pyarrow.parquet as pq

    meta = pq.read_schema(part).metadata or {}
    raw = meta.get(META_KEY.encode())
    try:
        return json.loads(raw) if raw else {}
    except ValueError:
        return {}


def _meta(path, meta) -> tuple[LocalFrame | None, str, str]:
    """The frame, phone model and kind a map file says of itself (:func:`.export.map_meta`)."""
    if not isinstance(meta, dict):
        raise InputError(path, f"its '{META_KEY}' entry is not a mapping")
    fr, device, kind = meta.get("frame"), meta.get("device") or "", meta.get("kind") or "points"
    frame = None
    if fr is not None:
        try:
            frame = _frame(path, float(fr["origin_lat"]), float(fr["origin_lon"]))
        except (TypeError, KeyError, ValueError):
            raise InputError(
                path, f"its frame is not origin_lat/origin_lon numbers: {fr!r}"
            ) from None
    if not isinstance(device, str):
        raise InputError(path, f"its device is not a name: {device!r}")
    if not isinstance(kind, str):
        raise InputError(path, f"its kind is not a name: {kind!r}")
    return frame, device, kind


def _geojson(path: Path):
    """A GeoJSON export (:func:`.export._geojson`): its points' properties as the map's columns
    (x, y in metres from the properties; else from the coordinates, through the frame when
    there is one), the readings as one column per AP."""
    import pandas as pd

    if path.stat().st_size > MAX_GEOJSON_BYTES:
        raise InputError(path, f"larger than {MAX_GEOJSON_BYTES // 2**20} MB: not a radio map")
    try:
        doc = json.loads(path.read_text(encoding="utf-8-sig"))
    except ValueError as e:
        raise InputError(path, f"not JSON: {e}") from None
    if not isinstance(doc, dict) or doc.get("type") != "FeatureCollection":
        raise InputError(path, "not a GeoJSON FeatureCollection")
    frame, device, kind = _meta(path, doc.get(META_KEY) or {})
    feats = doc.get("features")
    if not isinstance(feats, list):
        raise InputError(path, "its features are not a list")
    rows, readings = [], []
    for i, f in enumerate(feats):
        row, heard = _feature(path, i, f, frame)
        rows.append(row)
        readings.append(heard)
    df = pd.DataFrame(rows, columns=[c for c in FIXED_COLUMNS if any(c in r for r in rows)])
    aps = sorted({a for r in readings for a in r})
    if len(aps) > MAX_COLUMNS:
        raise InputError(path, f"{len(aps):,} access points (at most {MAX_COLUMNS:,})")
    col = {a: j for j, a in enumerate(aps)}
    rss = np.full((len(rows), len(aps)), np.nan)
    for i, r in enumerate(readings):
        for a, v in r.items():
            rss[i, col[a]] = v if isinstance(v, (int, float)) else np.nan
    return pd.concat([df, pd.DataFrame(rss, columns=aps)], axis=1), frame, device, kind


def _feature(path: Path, i: int, f, frame: LocalFrame | None) -> tuple[dict, dict]:
    """A GeoJSON point's fixed columns (x, y from its properties, else from its coordinates,
    through the frame when there is one) and its readings (AP → dBm)."""
    props = f.get("properties") if isinstance(f, dict) else None
    geom = f.get("geometry") if isinstance(f, dict) else None
    if not isinstance(props, dict):
        raise InputError(path, f"feature {i}: no properties")
    row = {k: props[k] for k in FIXED_COLUMNS if k in props}
    if "x" not in row or "y" not in row:
        try:
            c = [float(v) for v in (geom or {})["coordinates"][:2]]
        except (TypeError, KeyError, ValueError):
            raise InputError(path, f"feature {i}: no point coordinates") from None
        if frame is not None:
            x, y = frame.to_xy(np.array([c[1]]), np.array([c[0]]))
            c = [float(x[0]), float(y[0])]
        row |= {"x": c[0], "y": c[1]}
    rss = props.get("rss") or {}
    if not isinstance(rss, dict):
        raise InputError(path, f"feature {i}: rss is not a mapping of AP to dBm")
    return row, rss


def _frame(path, lat: float, lon: float) -> LocalFrame:
    if not (np.isfinite(lat) and np.isfinite(lon) and abs(lat) <= 90 and abs(lon) <= 180):
        raise InputError(path, f"frame origin ({lat}, {lon}) is not a latitude and longitude", 1)
    return LocalFrame(lat, lon)


TRUE, FALSE = {"true", "1", "1.0", "yes"}, {"false", "0", "0.0", "no"}
MAX_COORD_M = 1e7  # x, y (m) and floor: beyond this no building
MAX_COLUMNS = 100_000  # a radio map's columns: APs (UJIIndoorLoc has 520) and x, y, floor…


def _flags(path, col, head: int, name: str = "accepted") -> np.ndarray:
    """The ``accepted`` (or ``standby``) column as booleans; anything else named with its line
    (one 'Tru' once dropped half the rows without a word)."""
    if col.dtype == bool:
        return col.to_numpy()
    text = col.astype(str).str.strip().str.lower()
    bad = ~text.isin(TRUE | FALSE)
    if bad.any():
        i = int(np.argmax(bad.to_numpy()))
        raise InputError(path, f"{name} must be True or False, not {col.iloc[i]!r}", head + i + 2)
    return text.isin(TRUE).to_numpy()
