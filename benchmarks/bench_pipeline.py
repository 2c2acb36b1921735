"""Pipeline speed: multiples of real time on simulated walks of 1, 2, 4 and 16 laps of the office
route (≈5, 10, 20 and 90 minutes), loading excluded; linear growth shows as a flat ×real-time figure.
The re-run latency after an edit, as the surveyor meets it, is bench_editor's."""

from __future__ import annotations

import numpy as np
from _common import SHARED_DATA, Table, median_of

from workstation.params import Params
from workstation.pipeline import Pipeline
from workstation.session import GroundTruth, Scalar, Session, Vector3, WifiScans
from workstation.sim.building import office2f
from workstation.sim.sensors import SensorSpec, barometer, imu
from workstation.sim.styles import STYLES
from workstation.sim.walker import walk
from workstation.sim.wifi import RadioModel, scan_times


def long_walk(laps: int, seed: int = 1) -> Session:
    b = office2f()
    route = b.routes["survey"]
    full = route + sum(((("W0",) + route[1:]) for _ in range(laps - 1)), ())
    rng = np.random.default_rng(seed)
    m = walk(b, full, STYLES["normal"], rng)
    t, acc, gyro, mag = imu(m, SensorSpec(), (), rng)
    tp, p = barometer(m, SensorSpec(), rng)
    ts = scan_times(m.duration, rng)
    g = m.at(ts)
    wt, bs, ss, fr, rs = RadioModel(b).scans(ts, g["x"], g["y"], g["floor"], rng)
    d = m.at(t)
    gt = GroundTruth(t, d["x"], d["y"], d["floor"])
    return Session(
        Vector3(t, acc),
        Vector3(t, gyro),
        Vector3(t, mag),
        Scalar(tp, p),
        WifiScans(wt, bs, ss, fr, rs),
        gt,
    )


def run() -> Table:
    tab = Table("Pipeline (all stages, loading excluded)")
    graph = office2f().graph
    params = Params().updated(**{"pdr.start_node": "W0"})
    greedy = params.updated(**{"pdr.association": "greedy"})
    for laps in (1, 2, 4, 16):
        s = long_walk(laps)
        sec, iqr = median_of(lambda s=s: Pipeline(s, graph, params).run(), repeat=5)
        tab.add(
            f"{laps} lap(s), {s.duration / 60:.1f} min walk, median (IQR {iqr * 1e3:.1f} ms)",
            sec * 1e3,
            "ms",
            "{:,.1f}",
        )
        tab.add(
            "   speed (hmm association, the default)", s.duration / sec, "x real time", "{:,.0f}"
        )
        sec, _ = median_of(lambda s=s: Pipeline(s, graph, greedy).run(), repeat=5)
        tab.add(
            "   speed with greedy association (the paper)",
            s.duration / sec,
            "x real time",
            "{:,.0f}",
        )
    museum(tab)
    return tab


def museum(tab: Table) -> None:
    """Real museum walks (../shared/data): start inferred, as a user runs them."""
    ipin = SHARED_DATA / "ipin2023-track3"
    if not ipin.is_dir():
        tab.add("museum walks: ../shared/data absent, skipped", 0, "")
        return
    from workstation.graph.importers import graph_from_tra
    from workstation.session import load_session

    g = graph_from_tra(sorted((ipin / "supplementary" / "trajectories").glob("*.tra")))
    speeds = []
    for f in sorted((ipin / "logfiles").glob("*.txt")):
        s = load_session(f).in_frame(g.frame)
        sec, _ = median_of(lambda s=s: Pipeline(s, g, Params()).run(), repeat=3)
        speeds.append(s.duration / sec)
    tab.add(
        f"museum, start inferred: median of {len(speeds)} walks",
        float(np.median(speeds)),
        "x real time",
        "{:,.0f}",
    )
    tab.add("   slowest walk", float(np.min(speeds)), "x real time", "{:,.0f}")
