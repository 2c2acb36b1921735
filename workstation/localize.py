"""Fingerprint localization (§V-C): positive-values representation (eq. 21), 1-NN / kNN with
Euclidean or Sørensen distance, floor recognition; and radio-map files (read, merge).

Fingerprints are RSS matrices (fingerprints × APs, dBm, NaN where unheard). The positive
representation maps RSS ≥ τ to RSS − min and everything else to 0, where min is the lowest RSS
of all fingerprints minus 1. Distances are vectorized: Euclidean through one matrix product;
Sørensen (Bray–Curtis) as (ΣA + ΣB − 2 Σ min(A, B)) / (ΣA + ΣB), where the minimum only has to
be summed over the APs a query hears, so both stay fast on maps of tens of thousands of points.
"""

from __future__ import annotations

import enum
import io
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd

from .devices import ap_means, fit_offsets, offset_against
from .errors import InputError, WorkstationError
from .geo import LocalFrame
from .stats import error_stats

FIXED_COLUMNS = ("x", "y", "floor", "t", "belief", "accepted", "segment")


class Metric(str, enum.Enum):
    EUCLIDEAN = "euclidean"
    SORENSEN = "sorensen"


@dataclass(frozen=True)
class Fingerprints:
    """Reference points (or queries): positions, floors and an RSS matrix over ``bssids``."""

    x: np.ndarray
    y: np.ndarray
    floor: np.ndarray
    bssids: np.ndarray
    rss: np.ndarray  # (N, A) dBm, NaN = unheard
    frame: LocalFrame | None = None
    offsets_db: tuple[float, ...] = ()  # device offset removed from each map merged here

    def shifted(self, db: float) -> Fingerprints:
        """The same fingerprints with ``db`` added to every RSS."""
        return replace(self, rss=self.rss + db) if db else self

    def __len__(self) -> int:
        return int(self.x.size)

    def aligned(self, bssids: np.ndarray) -> np.ndarray:
        """RSS over another AP list (columns for unknown APs are NaN)."""
        out = np.full((len(self), bssids.size), np.nan)
        if not len(self) or not bssids.size:
            return out
        pos = {b: i for i, b in enumerate(self.bssids)}
        src = np.array([pos.get(b, -1) for b in bssids])
        ok = src >= 0
        out[:, ok] = self.rss[:, src[ok]]
        return out

    @classmethod
    def merge(cls, maps: list[Fingerprints], align_devices: bool = False) -> Fingerprints:
        """One radio map from several (e.g. several walks of one building): the union of APs.
        ``align_devices``: each map is one walk (one phone); its RSS offset is estimated and
        removed first (:mod:`.devices`), the offsets kept in ``offsets_db``."""
        if not maps:
            raise WorkstationError("no radio maps to merge")
        frames = {m.frame for m in maps if m.frame is not None}
        if len(frames) > 1:
            raise WorkstationError("radio maps in different frames cannot be merged")
        bssids = np.unique(np.concatenate([m.bssids for m in maps]))
        rss = [m.aligned(bssids) for m in maps]
        off = np.zeros(len(maps))
        if align_devices and len(maps) > 1:
            off, _ = fit_offsets(np.vstack([ap_means(r) for r in rss]))
            rss = [r - o for r, o in zip(rss, off)]
        return cls(
            np.concatenate([m.x for m in maps]),
            np.concatenate([m.y for m in maps]),
            np.concatenate([m.floor for m in maps]),
            bssids,
            np.vstack(rss),
            next(iter(frames)) if frames else None,
            tuple(round(float(o), 2) for o in off) if align_devices else (),
        )

    @classmethod
    def from_radiomap(
        cls, rm, frame: LocalFrame | None = None, accepted_only: bool = True
    ) -> Fingerprints:
        m = rm.accepted if accepted_only else rm.segment >= 0  # every scan once the walk started
        return cls(rm.x[m], rm.y[m], rm.floor[m], rm.bssids, rm.rss[m], frame)

    @classmethod
    def from_session(cls, session) -> Fingerprints:
        """Every WiFi scan of a session at its ground-truth position (queries, or a manual
        survey's reference points). Real walks: interpolated between the fixes."""
        gt = session.ground_truth
        if gt is None or not len(gt):
            raise WorkstationError(
                f"{session.metadata.get('path')}: the session has no ground truth"
            )
        times, bssids, rss = session.wifi.matrix()
        inside = (times >= gt.t[0]) & (times <= gt.t[-1])
        x, y, f = gt.at(times[inside])
        return cls(x, y, f, bssids, rss[inside], session.frame)

    # ---- files ------------------------------------------------------------------------------
    def to_frame(self) -> pd.DataFrame:
        df = pd.DataFrame({"x": self.x, "y": self.y, "floor": self.floor})
        return pd.concat(
            [df, pd.DataFrame(self.rss, columns=[str(b) for b in self.bssids])], axis=1
        )

    @classmethod
    def read(cls, path: str | Path) -> Fingerprints:
        """A radio map written by ``workstation run``/export (CSV with an optional
        ``# frame origin_lat=.. origin_lon=..`` first line, or Parquet)."""
        path = Path(path)
        frame = None
        try:
            if path.suffix.lower() == ".parquet":
                df = pd.read_parquet(path)
            else:
                text = path.read_text(encoding="utf-8-sig")  # spreadsheets add a BOM
                first = text.split("\n", 1)[0]
                if first.startswith("# frame"):
                    kv = dict(p.split("=") for p in first[len("# frame") :].split())
                    frame = LocalFrame(float(kv["origin_lat"]), float(kv["origin_lon"]))
                df = pd.read_csv(io.StringIO(text), comment="#")
        except FileNotFoundError:
            raise InputError(path, "no such radio map") from None
        except (ValueError, KeyError, pd.errors.ParserError) as e:
            raise InputError(path, f"not a radio map: {e}") from None
        missing = [c for c in ("x", "y", "floor") if c not in df.columns]
        if missing:
            raise InputError(path, f"radio map lacks column(s) {', '.join(missing)}", 1)
        aps = [c for c in df.columns if c not in FIXED_COLUMNS]
        try:
            rss = df[aps].to_numpy(dtype=np.float64) if aps else np.empty((len(df), 0))
        except ValueError:
            raise InputError(path, "RSS columns must be numbers (empty = not heard)") from None
        if "accepted" in df.columns:
            keep = df["accepted"].astype(bool).to_numpy()
            df, rss = df[keep], rss[keep]
        cols = {}
        for c in ("x", "y", "floor"):
            try:
                v = pd.to_numeric(df[c], errors="raise").to_numpy(float)
            except (ValueError, TypeError):
                raise InputError(path, f"column {c}: not all numbers") from None
            if not np.isfinite(v).all():
                row = int(np.flatnonzero(~np.isfinite(v))[0])
                raise InputError(path, f"column {c}: missing or not finite in row {row + 1}")
            cols[c] = v
        rss = np.where(np.isfinite(rss), rss, np.nan)
        return cls(cols["x"], cols["y"], cols["floor"], np.array(aps, dtype=str), rss, frame)


def positive(rss: np.ndarray, tau: float, rss_min: float) -> np.ndarray:
    """Eq. 21: RSS − min where heard and RSS ≥ τ, else 0."""
    out = rss - rss_min
    return np.where(np.isfinite(rss) & (rss >= tau), out, 0.0)


@dataclass(frozen=True)
class Estimate:
    x: np.ndarray
    y: np.ndarray
    floor: np.ndarray
    distance: np.ndarray  # to the nearest reference point
    index: np.ndarray  # of the nearest reference point
    device_offset_db: float = 0.0  # removed from the queries before matching


def nearest(
    ref: np.ndarray, qry: np.ndarray, metric: Metric, k: int
) -> tuple[np.ndarray, np.ndarray]:
    """Indices (Q, k) and distances (Q, k) of the k nearest rows of ``ref`` to each row of ``qry``."""
    metric = Metric(metric)
    n = ref.shape[0]
    k = min(k, n)
    idx = np.empty((qry.shape[0], k), dtype=np.int64)
    dist = np.empty((qry.shape[0], k))
    ref_sq = np.einsum("ij,ij->i", ref, ref)
    ref_sum = ref.sum(axis=1)
    for a in range(0, qry.shape[0], 256):  # chunks keep memory bounded on big maps
        q = qry[a : a + 256]
        if metric is Metric.EUCLIDEAN:
            d = np.maximum(
                ref_sq[None, :] + np.einsum("ij,ij->i", q, q)[:, None] - 2.0 * (q @ ref.T), 0.0
            )
            d = np.sqrt(d)
        else:
            d = np.empty((q.shape[0], n))
            q_sum = q.sum(axis=1)
            for i in range(q.shape[0]):
                nz = np.flatnonzero(q[i])
                common = np.minimum(ref[:, nz], q[i, nz]).sum(axis=1) if nz.size else np.zeros(n)
                tot = ref_sum + q_sum[i]
                with np.errstate(invalid="ignore", divide="ignore"):
                    d[i] = np.where(tot > 0, (tot - 2.0 * common) / tot, 0.0)
        part = (
            np.argpartition(d, k - 1, axis=1)[:, :k]
            if k < n
            else np.tile(np.arange(n), (q.shape[0], 1))
        )
        pd_ = np.take_along_axis(d, part, axis=1)
        order = np.argsort(pd_, axis=1, kind="stable")
        idx[a : a + 256] = np.take_along_axis(part, order, axis=1)
        dist[a : a + 256] = np.take_along_axis(pd_, order, axis=1)
    return idx, dist


def localize(
    radio_map: Fingerprints,
    queries: Fingerprints,
    metric: Metric | str = Metric.EUCLIDEAN,
    k: int = 1,
    tau: float = -90.0,
    rss_min: float | None = None,
    align_device: bool = True,
) -> Estimate:
    """1-NN (k = 1) or kNN: position = mean of the k neighbours, floor = the nearest one's.
    ``align_device``: the queries are one walk (one phone); its RSS offset against the map is
    estimated and removed first (:mod:`.devices`)."""
    if not len(radio_map):
        raise WorkstationError("the radio map has no reference points")
    q = queries.aligned(radio_map.bssids)
    offset = offset_against(ap_means(radio_map.rss), ap_means(q)) if align_device else 0.0
    q = q - offset
    if rss_min is None:
        vals = np.concatenate([radio_map.rss[np.isfinite(radio_map.rss)], q[np.isfinite(q)]])
        rss_min = (float(vals.min()) if vals.size else -100.0) - 1.0
    ref = positive(radio_map.rss, tau, rss_min)
    qry = positive(q, tau, rss_min)
    idx, dist = nearest(ref, qry, Metric(metric), k)
    x = radio_map.x[idx].mean(axis=1)
    y = radio_map.y[idx].mean(axis=1)
    return Estimate(x, y, radio_map.floor[idx[:, 0]], dist[:, 0], idx[:, 0], round(offset, 2))


def errors(est: Estimate, truth: Fingerprints) -> dict[str, float]:
    """Floor accuracy; position error where the floor is right (as the paper: ``mean_m`` …);
    over all queries with 15 m per floor of error (``mean_with_floor_penalty_m``) and the
    EvAAL score (``evaal_p75_m``) — a map that gets floors wrong cannot hide its hardest scans."""
    right = est.floor == truth.floor
    e = np.hypot(est.x - truth.x, est.y - truth.y)
    out: dict[str, float] = {"queries": int(truth.x.size)}
    if not right.size:
        out["floor_accuracy"] = None
        return out
    out["floor_accuracy"] = round(float(right.mean()), 4)
    out.update(error_stats(e[right]))
    allq = error_stats(e, est.floor - truth.floor)
    out["mean_with_floor_penalty_m"] = allq["mean_with_floor_penalty_m"]
    out["evaal_p75_m"] = allq["evaal_p75_m"]
    return out
