"""Radio-map quality: is the map good enough, and where is it thin? Pure functions over a radio
map (:class:`~workstation.fingerprints.localize.Fingerprints`) and the landmark graph; drawn by the CLI
(PNGs) and the viewer.

Per floor, on a grid of ``cell_m`` cells clipped to the walkable network (cells within
``clip_m`` of a graph edge on that floor, or of a reference point when the floor has no edges):

- **RSS fields** per AP: thin-plate-spline radial basis interpolation (scipy ``RBFInterpolator``)
  of the reference points' RSS, unheard readings taken as the noise floor −100 dBm so a field
  falls off where the AP is not heard. All APs share one kernel matrix, so one solve serves them
  all (500 points × 100 APs well under a second). Smoothing (the kernel diagonal) σ² with σ = 4 dB,
  the scan-to-scan fading of a phone. Chosen over a Gaussian process because a GP's
  hyper-parameters per AP would have to be fitted on a few dozen points per walk and its cost is
  cubic per AP; the uncertainty here is a stated model instead: σ(d) = σ_far · (1 − e^(−d/ℓ))
  with d the distance to the nearest reference point, ℓ = 3 m, σ_far = the RSS spread of the AP.
  The field is given only within ``FIELD_REACH_M`` = 3ℓ of a reference point, where that σ is
  still under 95 % of the AP's spread; farther on it is the interpolator's guess, not data (the
  heatmaps coloured corridors 30 m from any point: issue #30).
- **Coverage**: distance from each cell to the nearest reference point.
- **Predicted localization error**: the distance to the nearest reference point (1-NN can
  answer no closer than that) plus ``LOO_WEIGHT`` × each reference point's error localized
  (1-NN) on the rest of the map, interpolated to the cells by inverse distance (power 2, 8
  nearest points). The leave-one-out term only breaks ties between equally covered places: on a
  walk's map a scan's nearest fingerprint is mostly the next scan of the same walk, and where it
  is not the error is a floor's 15 m, so at full weight it drowned the coverage signal.
- **Walk here next**: graph edges whose points are farther than ``gap_m`` from every reference
  point over more than half their length.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from workstation.fingerprints.kinds import MapKind
from workstation.fingerprints.localize import Fingerprints, Metric, nearest, positive
from workstation.geo import distance_to_segments
from workstation.stats import FLOOR_PENALTY_M

NOISE_FLOOR_DBM = -100.0
FADING_SD_DB = 4.0
LENGTH_SCALE_M = 3.0
FIELD_REACH_M = 3 * LENGTH_SCALE_M  # RSS fields end here (module doc)
LOO_WEIGHT = 0.1  # of the leave-one-out error in the predicted error (module doc)
GAP_M = 5.0  # an edge is thin where it lies farther than this from every reference point
SMOOTHING = 16.0  # RBF smoothing (the kernel's diagonal): the fading variance, FADING_SD_DB²


@dataclass(frozen=True)
class FloorQuality:
    floor: float
    x0: float
    y0: float
    cell_m: float
    mask: np.ndarray  # (ny, nx) bool: walkable cells
    coverage_m: np.ndarray  # (ny, nx) distance to the nearest reference point (NaN off mask)
    predicted_error_m: np.ndarray  # (ny, nx)
    bssids: np.ndarray = field(default_factory=lambda: np.empty(0, str))  # strongest first
    rss: np.ndarray | None = None  # (A, ny, nx) interpolated dBm
    rss_sd: np.ndarray | None = None  # (A, ny, nx)
    thin_edges: tuple[tuple[str, str], ...] = ()
    # what the walkable cells are: "graph" (within clip_m of its edges on this floor) or
    # "points" (no edge here: a buffer round the map's own points — coverage is ~100 % by
    # construction, issue #64 item 6)
    against: str = "graph"

    def centres(self) -> tuple[np.ndarray, np.ndarray]:
        ny, nx = self.mask.shape
        return self.x0 + (np.arange(nx) + 0.5) * self.cell_m, self.y0 + (
            np.arange(ny) + 0.5
        ) * self.cell_m

    def summary(self, covered_m: float = 3.0, bad_error_m: float = 3.0) -> dict:
        cells = self.mask.sum()
        area = self.cell_m**2
        return {
            "floor": self.floor,
            "walkable_m2": round(float(cells * area), 1),
            "coverage_share": round(float((self.coverage_m[self.mask] <= covered_m).mean()), 4)
            if cells
            else 0.0,
            "area_predicted_error_over_3m_m2": round(
                float((self.predicted_error_m[self.mask] > bad_error_m).sum() * area), 1
            ),
            "edges_to_rewalk": [f"{a}-{b}" for a, b in self.thin_edges],
            "walkable_from": self.against,
        }


def loo_errors(x, y, floor, rss) -> np.ndarray:
    """Each reference point localized (1-NN, positive representation) on all the others: its
    position error, m, with 15 m per floor of error as localization is scored (inf when it has
    no other point)."""
    heard = rss[np.isfinite(rss)]
    rmin = (float(heard.min()) if heard.size else -100.0) - 1.0
    rep = positive(rss, -90.0, rmin)
    n = rep.shape[0]
    if n < 2:
        return np.full(n, np.inf)
    idx, _ = nearest(rep, rep, Metric.EUCLIDEAN, 2)
    other = np.where(idx[:, 0] == np.arange(n), idx[:, 1], idx[:, 0])
    e = np.hypot(x - x[other], y - y[other])
    return e + FLOOR_PENALTY_M * np.abs(floor - floor[other])


def floor_quality(
    fp,
    floor: float,
    graph=None,
    cell_m: float = 1.0,
    clip_m: float = 3.0,
    gap_m: float = GAP_M,
    n_aps: int | None = 20,
    loo: np.ndarray | None = None,
) -> FloorQuality:
    """One floor's maps; ``loo``: :func:`loo_errors` of the whole map (computed if not given)."""
    from scipy.interpolate import RBFInterpolator
    from scipy.spatial import cKDTree

    on = fp.floor == floor
    x, y, rss = fp.x[on], fp.y[on], fp.rss[on]
    keys, segs = _floor_edges(graph, floor)
    pts = [np.column_stack([x, y])] + ([segs.reshape(-1, 2)] if segs.size else [])
    allp = np.vstack([p for p in pts if p.size]) if any(p.size for p in pts) else np.zeros((1, 2))
    lo, hi = allp.min(axis=0) - clip_m, allp.max(axis=0) + clip_m
    nx, ny = (np.ceil((hi - lo) / cell_m).astype(int) + 1).tolist()
    cx = lo[0] + (np.arange(nx) + 0.5) * cell_m
    cy = lo[1] + (np.arange(ny) + 0.5) * cell_m
    gx, gy = np.meshgrid(cx, cy)
    cells = np.column_stack([gx.ravel(), gy.ravel()])
    if segs.size:
        mask = _corridor_mask(segs.tobytes(), float(lo[0]), float(lo[1]), nx, ny, cell_m, clip_m)
    else:
        mask = (
            cKDTree(np.column_stack([x, y])).query(cells)[0] <= clip_m
            if x.size
            else np.zeros(len(cells), bool)
        )
    mask = mask.reshape(ny, nx)
    cov = np.full((ny, nx), np.nan)
    pred = np.full((ny, nx), np.nan)
    if x.size:
        tree = cKDTree(np.column_stack([x, y]))
        d, _ = tree.query(cells[mask.ravel()])
        cov[mask] = d
        err = (loo if loo is not None else loo_errors(fp.x, fp.y, fp.floor, fp.rss))[on]
        ok = np.isfinite(err)
        if ok.any():
            t2 = cKDTree(np.column_stack([x[ok], y[ok]]))
            k = min(8, int(ok.sum()))
            dd, ii = t2.query(cells[mask.ravel()], k=k)
            dd, ii = dd.reshape(len(dd), -1), ii.reshape(len(ii), -1)
            w = 1.0 / np.maximum(dd, 0.5) ** 2
            # at least the distance to the nearest point (1-NN can answer no closer), the
            # neighbours' leave-one-out error breaking ties between equally covered places
            pred[mask] = LOO_WEIGHT * (w * err[ok][ii]).sum(axis=1) / w.sum(axis=1) + d
    bss, field, sd = np.empty(0, str), None, None
    order = _strongest(rss, n_aps)
    if x.size >= 3 and order.size:
        bss = fp.bssids[order]
        vals = np.where(np.isfinite(rss[:, order]), rss[:, order], NOISE_FLOOR_DBM)
        xy = np.column_stack([x, y])
        uniq, inv = np.unique(np.round(xy, 3), axis=0, return_inverse=True)
        vals = (
            np.vstack([vals[inv.ravel() == i].mean(axis=0) for i in range(len(uniq))])
            if len(uniq) < len(xy)
            else vals
        )
        xy = uniq if len(uniq) < len(xy) else xy
        rbf = RBFInterpolator(xy, vals, kernel="thin_plate_spline", smoothing=SMOOTHING)
        field = np.full((len(order), ny, nx), np.nan)
        sd = np.full_like(field, np.nan)
        pred_vals = np.clip(rbf(cells[mask.ravel()]), NOISE_FLOOR_DBM, -20.0)
        spread = np.nanstd(np.where(np.isfinite(rss[:, order]), rss[:, order], np.nan), axis=0)
        spread = np.where(np.isfinite(spread), np.maximum(spread, FADING_SD_DB), 10.0)
        dm = cov[mask]
        for a in range(len(order)):
            field[a][mask] = np.where(dm <= FIELD_REACH_M, pred_vals[:, a], np.nan)
            sd[a][mask] = np.hypot(FADING_SD_DB, spread[a] * (1 - np.exp(-dm / LENGTH_SCALE_M)))
    thin = _thin_edges(keys, segs, x, y, gap_m)
    return FloorQuality(
        float(floor), float(lo[0]), float(lo[1]), cell_m, mask, cov, pred, bss, field, sd, thin,
        "graph" if segs.size else "points",
    )


@lru_cache(maxsize=32)
def _corridor_mask(segs: bytes, x0: float, y0: float, nx: int, ny: int, cell: float, clip: float):
    """The grid cells (row-major, centres from (x0, y0)) within ``clip`` of an edge; kept for
    the next call with the same graph and grid (every re-run in the editor)."""
    sg = np.frombuffer(segs, float).reshape(-1, 2, 2)
    gx, gy = np.meshgrid(x0 + (np.arange(nx) + 0.5) * cell, y0 + (np.arange(ny) + 0.5) * cell)
    out = distance_to_segments(gx.ravel(), gy.ravel(), sg) <= clip
    out.flags.writeable = False
    return out


def _floor_edges(graph, floor) -> tuple[list[tuple[str, str]], np.ndarray]:
    """The floor's edges, each connected pair once: their (sorted) ids and (E, 2, 2) ends."""
    keys, segs, seen = [], [], set()
    if graph is not None:
        for u, v in graph.edges:
            a, b = graph.node(u), graph.node(v)
            key = tuple(sorted((u, v)))
            if a.floor == floor == b.floor and key not in seen:
                seen.add(key)
                keys.append(key)
                segs.append([[a.x, a.y], [b.x, b.y]])
    return keys, np.array(segs, float).reshape(-1, 2, 2)


def _thin_edges(keys, segs, x, y, gap_m) -> tuple[tuple[str, str], ...]:
    """Of the floor's edges (:func:`_floor_edges`), those more than half of whose length —
    sampled every metre — lies farther than ``gap_m`` from every reference point."""
    from scipy.spatial import cKDTree

    if not keys:
        return ()
    e = segs.reshape(-1, 4)  # ax, ay, bx, by
    n = np.maximum(2, np.hypot(e[:, 2] - e[:, 0], e[:, 3] - e[:, 1]).astype(int) + 1)
    start = np.concatenate([[0], np.cumsum(n)[:-1]])
    edge = np.repeat(np.arange(len(keys)), n)
    s = (np.arange(edge.size) - start[edge]) / (n[edge] - 1)  # 0 … 1 along each edge
    px = e[edge, 0] + s * (e[edge, 2] - e[edge, 0])
    py = e[edge, 1] + s * (e[edge, 3] - e[edge, 1])
    if x.size:
        d = cKDTree(np.column_stack([x, y])).query(np.column_stack([px, py]))[0]
    else:
        d = np.full(px.size, np.inf)
    far = np.add.reduceat((d > gap_m).astype(float), start) / n
    return tuple(k for k, f in zip(keys, far) if f > 0.5)


def thin_edges(fp, graph, gap_m: float = GAP_M) -> tuple[tuple[str, str], ...]:
    """Every floor's level edges that more than half of whose length lies farther than
    ``gap_m`` from the map's reference points (:func:`_thin_edges`), without the fields."""
    out: list[tuple[str, str]] = []
    for f in graph.floors:
        keys, segs = _floor_edges(graph, f)
        on = fp.floor == f
        out += _thin_edges(keys, segs, fp.x[on], fp.y[on], gap_m)
    return tuple(out)


def _strongest(rss: np.ndarray, n_aps: int | None) -> np.ndarray:
    """Columns of the APs heard at most points, most first (ties by column), heard ones only."""
    heard_n = np.isfinite(rss).sum(axis=0)
    order = np.argsort(-heard_n, kind="stable")
    return order[heard_n[order] > 0][: n_aps or None]


def strongest_aps(fp, n_aps: int) -> list[str]:
    """The APs :func:`quality` draws heatmaps of, per floor in floor order, each once, at most
    ``n_aps`` (cheap: what a selector lists before any map is computed)."""
    out: list[str] = []
    for f in np.unique(fp.floor):
        on = fp.floor == f
        if on.sum() >= 3:
            out += [str(b) for b in fp.bssids[_strongest(fp.rss[on], n_aps)] if str(b) not in out]
    return out[:n_aps]


def quality(fp, graph=None, **kw) -> dict[float, FloorQuality]:
    """:func:`floor_quality` for every floor of the map (and of the graph)."""
    floors = set(np.unique(fp.floor).tolist()) | (set(graph.floors) if graph is not None else set())
    loo = loo_errors(fp.x, fp.y, fp.floor, fp.rss)  # once for every floor
    return {float(f): floor_quality(fp, f, graph, loo=loo, **kw) for f in sorted(floors)}


def densify(fp, graph=None, cell_m: float = 2.0, max_gap_m: float = 4.0, heard_dbm: float = -95.0):
    """A densified radio map: ``fp`` plus one interpolated fingerprint per walkable cell of
    ``cell_m`` within ``max_gap_m`` of a reference point (no extrapolation into unwalked
    corridors), every AP's RSS field as in :func:`floor_quality`, values below ``heard_dbm``
    taken as unheard. Whether it helps 1-NN is measured, not assumed (docs/decisions.md)."""
    xs, ys, fs, rows = [], [], [], []
    for f in np.unique(fp.floor):
        q = floor_quality(fp, float(f), graph, cell_m=cell_m, n_aps=None, loo=np.zeros(len(fp)))
        if q.rss is None:
            continue
        near = q.mask & (q.coverage_m <= max_gap_m)
        cx, cy = q.centres()
        gx, gy = np.meshgrid(cx, cy)
        vals = np.full((int(near.sum()), fp.bssids.size), np.nan)
        col = {b: i for i, b in enumerate(fp.bssids)}
        for a, b in enumerate(q.bssids):
            v = q.rss[a][near]
            vals[:, col[b]] = np.where(v >= heard_dbm, v, np.nan)
        xs.append(gx[near])
        ys.append(gy[near])
        fs.append(np.full(int(near.sum()), f))
        rows.append(vals)
    if not rows:
        return fp
    dense = Fingerprints(np.concatenate(xs), np.concatenate(ys), np.concatenate(fs),
                         fp.bssids, np.vstack(rows), fp.frame)  # fmt: skip
    return Fingerprints.merge([fp, dense])


#: the densified map as a kind of radio map (fingerprints/kinds.py; ``quality --densify``)
KIND = MapKind("densified", "the walks' points and an interpolated fingerprint every 2 m near "
               "them (each AP's RSS field a thin-plate spline)", densify)  # fmt: skip
