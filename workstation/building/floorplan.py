"""Floor plans: walls per floor as line segments (metres, the landmark graph's frame).

Used for drawing (Rerun, viser) and by the map-filtering and Zee baselines (a particle that
crosses a wall dies). Stored as YAML::

    name: office2f
    floors:
      0:
        outline: [[0, 0], [80, 0], [80, 50], [0, 50]]
        walls: [[x1, y1, x2, y2], ...]
        rooms: [{name: R1, polygon: [[..], ..]}]      # optional, for drawing
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

from workstation.errors import InputError
from workstation.io.atomic import atomic_write_text
from workstation.io.yamlio import load_yaml


@dataclass(frozen=True)
class Floor:
    walls: np.ndarray  # (W, 4): x1, y1, x2, y2
    outline: np.ndarray = field(default_factory=lambda: np.empty((0, 2)))
    rooms: tuple[tuple[str, np.ndarray], ...] = ()


@dataclass(frozen=True)
class FloorPlan:
    name: str
    floors: dict[float, Floor]

    def walls(self, floor: float) -> np.ndarray:
        f = self.floors.get(float(floor))
        return np.empty((0, 4)) if f is None else f.walls

    def crossings(self, floor: float, p: np.ndarray, q: np.ndarray) -> np.ndarray:
        """Number of walls crossed by each segment p[i] → q[i] on ``floor`` (vectorized)."""
        return count_crossings(self.walls(floor), p, q)

    def to_dict(self) -> dict:
        floors = {}
        for f, fl in sorted(self.floors.items()):
            d = {
                "outline": np.round(fl.outline, 4).tolist(),
                "walls": np.round(fl.walls, 4).tolist(),
            }
            if fl.rooms:
                d["rooms"] = [{"name": n, "polygon": np.round(p, 4).tolist()} for n, p in fl.rooms]
            floors[int(f) if float(f).is_integer() else float(f)] = d
        return {"name": self.name, "floors": floors}

    def save(self, path: str | Path) -> None:
        atomic_write_text(
            path,
            yaml.safe_dump(self.to_dict(), sort_keys=False, default_flow_style=None, width=140),
        )

    @classmethod
    def load(cls, path: str | Path) -> FloorPlan:
        path = Path(path)
        data = load_yaml(path, "floor plan")
        if not isinstance(data, dict) or not isinstance(data.get("floors"), dict):
            raise InputError(path, "a floor plan is a mapping with 'floors'")
        floors = {}
        for f, d in data["floors"].items():
            try:
                walls = np.asarray(d.get("walls") or [], dtype=np.float64).reshape(-1, 4)
                outline = np.asarray(d.get("outline") or [], dtype=np.float64).reshape(-1, 2)
                rooms = tuple(
                    (str(r["name"]), np.asarray(r["polygon"], dtype=np.float64))
                    for r in d.get("rooms") or []
                )
                floors[float(f)] = Floor(walls, outline, rooms)
            except (TypeError, ValueError, KeyError, AttributeError):
                raise InputError(
                    path, f"floor {f}: walls must be [x1, y1, x2, y2] rows, outline [x, y] rows"
                ) from None
        return cls(str(data.get("name", path.stem)), floors)


def count_crossings(walls: np.ndarray, p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """For segments p[i]→q[i] (N, 2), how many of ``walls`` (W, 4) each one properly crosses."""
    p = np.asarray(p, dtype=np.float64).reshape(-1, 2)
    q = np.asarray(q, dtype=np.float64).reshape(-1, 2)
    if walls.size == 0 or p.size == 0:
        return np.zeros(p.shape[0], dtype=np.int64)
    a, b = walls[None, :, 0:2], walls[None, :, 2:4]
    pp, qq = p[:, None, :], q[:, None, :]

    def orient(u, v, w):
        return (v[..., 0] - u[..., 0]) * (w[..., 1] - u[..., 1]) - (v[..., 1] - u[..., 1]) * (
            w[..., 0] - u[..., 0]
        )

    d1, d2 = orient(a, b, pp), orient(a, b, qq)
    d3, d4 = orient(pp, qq, a), orient(pp, qq, b)
    hit = (d1 * d2 < 0) & (d3 * d4 < 0)
    return hit.sum(axis=1)
