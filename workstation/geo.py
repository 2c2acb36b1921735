"""Local metric frame for WGS-84 positions (east = x, north = y, metres).

A local tangent plane on the WGS-84 ellipsoid: accurate to millimetres over a building.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

_A = 6378137.0  # WGS-84 semi-major axis (m)
_E2 = 6.69437999014e-3  # first eccentricity squared


@dataclass(frozen=True)
class LocalFrame:
    """East-north plane tangent at (origin_lat, origin_lon), degrees."""

    origin_lat: float
    origin_lon: float

    def _radii(self) -> tuple[float, float]:
        phi = np.radians(self.origin_lat)
        s2 = np.sin(phi) ** 2
        n = _A / np.sqrt(1.0 - _E2 * s2)  # prime vertical radius
        m = _A * (1.0 - _E2) / (1.0 - _E2 * s2) ** 1.5  # meridian radius
        return float(m), float(n * np.cos(phi))

    def to_xy(self, lat, lon) -> tuple[np.ndarray, np.ndarray]:
        m, ncos = self._radii()
        x = np.radians(np.asarray(lon, dtype=np.float64) - self.origin_lon) * ncos
        y = np.radians(np.asarray(lat, dtype=np.float64) - self.origin_lat) * m
        return x, y

    def to_latlon(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        m, ncos = self._radii()
        lat = self.origin_lat + np.degrees(np.asarray(y, dtype=np.float64) / m)
        lon = self.origin_lon + np.degrees(np.asarray(x, dtype=np.float64) / ncos)
        return lat, lon

    @classmethod
    def around(cls, lat: float, lon: float) -> LocalFrame:
        """The default frame for data near (lat, lon): origin rounded to 1e-3 degrees.

        Rounding makes the frame stable between files of one building; sessions keep their
        fixes' lat/lon, so a session can always be re-projected into a graph's frame.
        """
        return cls(round(float(lat), 3), round(float(lon), 3))

    def to_dict(self) -> dict:
        return {"origin_lat": self.origin_lat, "origin_lon": self.origin_lon}


#: up to this many points :func:`distance_to_segments` takes every segment at once (a loop over
#: the segments cost a walk's dozen fixes 2.4 ms on the mall's 300 edges, 0.05 ms so); beyond,
#: a loop over the segments is faster (200,000 points, 500 walls: 2.2 s against 2.6 s)
FEW_POINTS = 256


def distance_to_segments(x, y, segs) -> np.ndarray:
    """Distance from each point (x, y) to the nearest of ``segs`` ((S, 2, 2) metres); inf when
    there are none. Both ways give the same bits: the same operations on each pair."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    s = np.asarray(segs, float).reshape(-1, 2, 2)
    if 0 < x.size <= FEW_POINTS and s.size:
        px, py = x.reshape(-1, 1), y.reshape(-1, 1)
        ax, ay = s[:, 0, 0], s[:, 0, 1]
        dx, dy = s[:, 1, 0] - ax, s[:, 1, 1] - ay
        L2 = dx * dx + dy * dy
        real = L2 > 0  # a segment of no length: t = 0, its end point
        tt = np.where(real, np.clip(((px - ax) * dx + (py - ay) * dy) / np.where(real, L2, 1.0),
                                    0, 1), 0.0)  # fmt: skip
        return np.hypot(px - (ax + tt * dx), py - (ay + tt * dy)).min(axis=1).reshape(x.shape)
    best = np.full(x.shape, np.inf)
    for (ax, ay), (bx, by) in s:
        dx, dy = bx - ax, by - ay
        L2 = dx * dx + dy * dy
        t = np.clip(((x - ax) * dx + (y - ay) * dy) / L2, 0, 1) if L2 > 0 else 0.0
        best = np.minimum(best, np.hypot(x - (ax + t * dx), y - (ay + t * dy)))
    return best
