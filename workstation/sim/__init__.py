"""Walk simulator: sessions that look like phone logs, with dense ground truth.

``simulate(building, walk, seed)`` → :class:`Simulation` (session, graph, floor plan).
Deterministic for a given seed. Walks of ``office2f``: ``normal`` (steady pace), ``varied``
(varying speed, stops, false walking, mid-corridor turns), ``heldout`` (the route walked the
other way, for localization tests) and ``survey5`` / ``survey10`` (the manual grid survey:
reference points every 1.5 m along the route, 5 or 10 stationary scans each).

Two models: ``realistic`` (the default) walks, holds and reads the phone as real walks do —
issue #12's table, measured by :mod:`.realism`, every quantity inside the range of the real
walks; ``ideal`` is the clean model the paper's figures were first reproduced on (steady gait,
no sway, a perfect compass, white pressure noise, 24 APs, one phone).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from workstation.building.floorplan import FloorPlan
from workstation.errors import WorkstationError
from workstation.graph import LandmarkGraph
from workstation.session import (
    GroundTruth,
    Metadata,
    Scalar,
    Session,
    Vector3,
    WifiScans,
    write_session,
)
from workstation.sim.building import BUILDINGS, Building
from workstation.sim.sensors import MagneticZone, SensorSpec, barometer, imu, realistic_spec
from workstation.sim.styles import STYLES, realistic
from workstation.sim.walker import walk
from workstation.sim.wifi import REALISTIC, RadioModel, RadioSpec, scan_times

WALKS = {
    "normal": ("survey", "normal"),
    "varied": ("survey", "varied"),
    "heldout": ("reverse", "heldout"),
}
SURVEYS = {"survey5": 5, "survey10": 10}
GRID_STEP_M = 1.5
MODELS = ("realistic", "ideal")


@dataclass(frozen=True)
class Simulation:
    session: Session
    graph: LandmarkGraph
    plan: FloorPlan
    building: Building

    def write(self, out: str | Path) -> Path:
        """Session folder with ``graph.yaml`` and ``floorplan.yaml`` beside the streams."""
        out = write_session(self.session, out)
        self.graph.save(out / "graph.yaml")
        (out / "graph.yaml.bak").unlink(missing_ok=True)
        self.plan.save(out / "floorplan.yaml")
        return out


def _zones(building: Building) -> tuple[MagneticZone, ...]:
    rng = np.random.default_rng(building.seed + 2000)
    zones = []
    for f in building.plan.floors:
        # the elevator shaft, and a few steel pillars / cabinets along the corridor
        for x, y in [(25.0, 5.0)] + [tuple(rng.uniform([12, 12], [68, 38])) for _ in range(4)]:
            v = rng.normal(0, 1, 3)
            zones.append(
                MagneticZone(
                    float(x),
                    float(y),
                    float(f),
                    float(rng.uniform(2, 4)),
                    tuple(25.0 * v / np.linalg.norm(v)),
                )
            )
    return tuple(zones)


def simulate(
    building: str | Building = "office2f",
    walk_name: str = "normal",
    seed: int = 1,
    model: str = "realistic",
    scan_interval: tuple[float, float] | None = None,
    door_stops: bool = True,
    route: tuple[str, ...] | None = None,
) -> Simulation:
    """One walk (or manual survey) of ``building``. ``scan_interval``: (lo, hi) seconds between
    WiFi scans, drawn uniformly (default 2–4 s). ``door_stops=False``: the walker goes through
    doors without stopping (their accelerometer landmarks are then not detected). ``route``:
    landmark ids to walk instead of the named walk's route (a survey plan's walk), each step
    along an edge of the building's graph; ``walk_name`` then gives the walking style."""
    b = BUILDINGS[building]() if isinstance(building, str) else building
    if model not in MODELS:
        raise WorkstationError(f"unknown model {model!r}: choose from {', '.join(MODELS)}")
    real = model == "realistic"
    radio_spec = REALISTIC if real else RadioSpec()
    if walk_name in SURVEYS:
        if route is not None:
            raise WorkstationError(f"{walk_name} is a manual survey: it walks no route")
        return _manual_survey(b, SURVEYS[walk_name], seed, radio_spec, model)
    if walk_name not in WALKS:
        raise WorkstationError(
            f"unknown walk {walk_name!r}: choose from {', '.join([*WALKS, *SURVEYS])}"
        )
    lo, hi = _scan_interval(scan_interval)
    route_name, style_name = WALKS[walk_name]
    if route is not None:
        _check_route(b, route)
    path = tuple(route) if route is not None else b.routes[route_name]
    rng = np.random.default_rng(seed)
    style = realistic(STYLES[style_name]) if real else STYLES[style_name]
    if not door_stops:
        style = dataclasses.replace(style, door_still_s=(0.0, 0.0))
    motion = walk(b, path, style, rng)
    spec = realistic_spec() if real else SensorSpec()
    t, acc, gyro, mag = imu(motion, spec, _zones(b), rng, b.seed)
    tp, p = barometer(motion, spec, rng, b.floor_levels_hpa)
    ts = scan_times(motion.duration, rng, lo, hi)
    gts = motion.at(ts)
    radio = RadioModel(b, radio_spec)
    offset = float(radio_spec.device_offset_sd_db * rng.standard_normal()) if real else 0.0
    wt, bssid, ssid, freq, rss = radio.scans(ts, gts["x"], gts["y"], gts["floor"], rng, offset)
    gt = _ground_truth(motion, t)
    extra = {
        "kind": "walk",
        "building": b.name,
        "walk": walk_name,
        "model": model,
        "scan_interval_s": [lo, hi],
        "device_offset_db": round(offset, 2),
        "route": list(path),
        "planned": route is not None,
        "seed": seed,
        "landmark_passes": [[round(float(tt), 3), n] for tt, n in motion.landmark_passes],
        "events": [[round(float(tt), 3), k, d] for tt, k, d in motion.events],
        "true_step_count": int(motion.step_times.size),
    }
    # each walk is another phone (its own RSS offset): merging aligns different models only
    device = f"simulated phone ({offset:+.1f} dB)" if offset else "simulated phone"
    meta = Metadata(source="simulator", device=device, extra=extra)
    session = Session(
        Vector3(t, acc),
        Vector3(t, gyro),
        Vector3(t, mag),
        Scalar(tp, p),
        WifiScans(wt, bssid, ssid, freq, rss),
        gt,
        meta,
    )
    return Simulation(session, b.graph, b.plan, b)


def _scan_interval(given: tuple[float, float] | None) -> tuple[float, float]:
    """(lo, hi) seconds between scans: 2–4 s unless given, within 0.1–60 s."""
    lo, hi = given or (2.0, 4.0)
    if not (0.1 <= lo <= hi <= 60.0):
        raise WorkstationError(f"scan interval {lo:g}-{hi:g} s: need 0.1 ≤ low ≤ high ≤ 60")
    return lo, hi


def _ground_truth(motion, t: np.ndarray) -> GroundTruth:
    """Where the walker was at each IMU sample ``t``."""
    dense = motion.at(t)
    return GroundTruth(
        t,
        dense["x"],
        dense["y"],
        dense["floor"],
        heading=np.angle(np.exp(1j * dense["heading"])),
        walking=dense["walking"],
    )


def _check_route(b: Building, route) -> None:
    if len(route) < 2:
        raise WorkstationError("a route needs at least two landmarks")
    for u in route:
        if u not in b.graph.ids:
            raise WorkstationError(f"route: {u!r} is no landmark of {b.name}")
    for u, v in zip(route[:-1], route[1:]):
        if not b.graph.has_edge(u, v):
            raise WorkstationError(f"route: no edge {u} → {v} in {b.name}'s graph")


def survey_points(b: Building, route: str = "survey", step: float = GRID_STEP_M) -> np.ndarray:
    """(N, 3) reference points every ``step`` metres along the route's level legs."""
    pts = b.route_points(route)
    out = []
    for a, c in zip(pts[:-1], pts[1:]):
        if a[2] != c[2]:
            continue  # stairs and elevator are not surveyed
        length = float(np.hypot(*(c[:2] - a[:2])))
        n = int(length // step)
        f = np.arange(n) * step / length
        out.append(
            np.column_stack([a[0] + (c[0] - a[0]) * f, a[1] + (c[1] - a[1]) * f, np.full(n, a[2])])
        )
    rp = np.concatenate(out)
    # one RP per grid position (the route passes some corridors twice)
    _, idx = np.unique(np.round(rp, 1), axis=0, return_index=True)
    return rp[np.sort(idx)]


def _manual_survey(
    b: Building,
    scans_per_point: int,
    seed: int,
    radio_spec: RadioSpec | None = None,
    model: str = "ideal",
) -> Simulation:
    radio_spec = radio_spec or RadioSpec()
    rng = np.random.default_rng(seed)
    rp = survey_points(b)
    per_scan_s, move_s = 2.0, 8.0  # a scan every 2 s while standing; moving + entering a point
    start = np.arange(rp.shape[0]) * (scans_per_point * per_scan_s + move_s)
    t = (start[:, None] + per_scan_s * np.arange(scans_per_point)[None, :]).ravel()
    x, y, f = (np.repeat(rp[:, i], scans_per_point) for i in range(3))
    radio = RadioModel(b, radio_spec)
    sd = radio_spec.device_offset_sd_db
    offset = float(sd * rng.standard_normal()) if sd else 0.0
    wt, bssid, ssid, freq, rss = radio.scans(t, x, y, f, rng, offset)
    gt = GroundTruth(t, x, y, f, walking=np.zeros_like(t))
    extra = {
        "kind": "manual_survey",
        "building": b.name,
        "walk": f"survey{scans_per_point}",
        "model": model,
        "seed": seed,
        "reference_points": int(rp.shape[0]),
        "scans_per_point": scans_per_point,
        "survey_time_s": float(t[-1] + per_scan_s),
    }
    meta = Metadata(source="simulator", extra=extra)
    e = Vector3.empty()
    session = Session(e, e, e, None, WifiScans(wt, bssid, ssid, freq, rss), gt, meta)
    return Simulation(session, b.graph, b.plan, b)
