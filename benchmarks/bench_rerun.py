"""Streaming every stage of a ≈5.5-minute walk to an .rrd file (pipeline included)."""

from __future__ import annotations

import tempfile
from pathlib import Path

from _common import Table, best_of

from workstation.pipeline import Pipeline
from workstation.sim import simulate
from workstation.viz.layouts import default_blueprint
from workstation.viz.rerun_log import RerunLogger, new_recording


def run() -> Table:
    tab = Table("Rerun streaming")
    sim = simulate("office2f", "normal", 1)
    tmp = Path(tempfile.mkdtemp())

    def stream():
        rec = new_recording()
        rec.save(
            str(tmp / "bench.rrd"),
            default_blueprint=default_blueprint("overview", sim.graph, sim.plan),
        )
        pipe = Pipeline(sim.session, sim.graph)
        pipe.observers.append(RerunLogger(rec, pipe.session, sim.graph, sim.plan))
        pipe.run()
        rec.flush()

    sec = best_of(stream, repeat=3)
    tab.add(
        f"all stages of a {sim.session.duration / 60:.1f} min walk to a file",
        sec * 1e3,
        "ms",
        "{:,.0f}",
    )
    tab.add("   speed", sim.session.duration / sec, "x real time", "{:,.0f}")
    tab.add("   file size", (tmp / "bench.rrd").stat().st_size / 1e6, "MB")
    return tab
