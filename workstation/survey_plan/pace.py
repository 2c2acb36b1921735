"""How fast a surveyor covers the building: the pace a plan's durations are predicted from.

Walking time of a level edge is its length over the walking speed (step length × cadence,
the quantities the pipeline measures on every walk); a floor change costs a fixed time per floor
by stairs, or a wait plus a time per floor by lift (a floor-change edge whose ends are less than
``LIFT_RUN_M`` apart horizontally is a lift). :func:`measure_pace` takes step length, cadence,
scan interval and the time walkers stood at matched landmarks from the pipeline's results on
the building's own walks; anything not measured keeps its default (docs/decisions.md).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from workstation.params import Params

LIFT_RUN_M = 2.0  # a floor change with less horizontal run than this is a lift ride
STOP_S = 3.0  # a stop the acc rule sees (K2 is 1–8 s by default) with a scan or two in it


@dataclass(frozen=True)
class Pace:
    step_length_m: float = 0.63
    cadence_hz: float = 1.8
    scan_interval_s: float = 3.0
    stop_s: float = STOP_S  # at a landmark with the acc rule
    stand_s: float = 4.0  # still at the start of each walk (pdr.start_still_s)
    stairs_s_per_floor: float = 15.0
    lift_wait_s: float = 30.0
    lift_s_per_floor: float = 4.0
    still_share: float = 0.0  # of a walk's time its walkers stand (tapping, waiting, looking)
    source: str = "defaults"

    def standing_s(self, moving_s: float, stops_s: float) -> float:
        """Time standing on the way (between a walk's start and end) for ``moving_s`` of
        walking: the stops the plan asks for, or what this building's walkers stand on such a
        walk (``still_share``), whichever is longer."""
        k = self.still_share / (1.0 - self.still_share)
        return max(stops_s, k * moving_s)

    @property
    def speed_mps(self) -> float:
        return self.step_length_m * self.cadence_hz

    def kind(self, run_m: float, floor_change: float) -> str:
        if not floor_change:
            return "level"
        return "lift" if run_m < LIFT_RUN_M else "stairs"

    def seconds(self, run_m: float, floor_change: float) -> float:
        """Time to walk (or ride) one edge of ``run_m`` horizontal metres and ``floor_change``
        floors."""
        k, floors = self.kind(run_m, floor_change), abs(floor_change)
        if k == "lift":
            return self.lift_wait_s + self.lift_s_per_floor * floors
        walk = run_m / self.speed_mps
        return walk + self.stairs_s_per_floor * floors if k == "stairs" else walk

    def to_dict(self) -> dict:
        d = {k: (round(v, 3) if isinstance(v, float) else v) for k, v in vars(self).items()}
        d["speed_mps"] = round(self.speed_mps, 3)
        return d


def default_pace(params: Params | None = None) -> Pace:
    """The defaults, with the step length and start stand the pipeline's parameters assume and
    a stop inside the acc rule's still window."""
    p = params or Params()
    stop = float(np.clip(STOP_S, p.acc.still_min_s + 0.5, max(p.acc.still_max_s - 0.5, 0.1)))
    return Pace(step_length_m=p.pdr.initial_step_length_m, stand_s=p.pdr.start_still_s, stop_s=stop)


def measure_pace(results, base: Pace | None = None) -> Pace:
    """The pace the building's walks show: medians over ``results`` (pipeline results) of the
    calibrated step length at each walk's end, the cadence while walking (steps under 1 s
    apart), the time between WiFi scans, the share of time standing between the walk's start
    and its last step, and the stops at matched landmarks after the start (no shorter than the
    acc rule needs: the plan asks for at least ``base.stop_s``)."""
    base = base or default_pace()
    lengths, cadence, scans, stops, still = [], [], [], [], []
    for r in results:
        sp = r.steps
        on = (sp.state_t >= r.track.start.time) & (sp.state_t <= (sp.t[-1] if sp.t.size else -1))
        if on.sum() > 10:
            still.append(1.0 - float(sp.walking[on].mean()))
        st = r.track.steps.step_length[np.isfinite(r.track.steps.step_length)]
        if st.size:
            lengths.append(float(st[-1]))
        dt = np.diff(r.steps.t)
        dt = dt[(dt > 0) & (dt < 1.0)]
        if dt.size >= 10:
            cadence.append(1.0 / float(np.median(dt)))
        ts = np.unique(r.radiomap.t)
        if ts.size >= 3:
            scans.append(float(np.median(np.diff(ts))))
        b = r.belief
        if b.stop_t0.size > 1:
            d = (b.stop_t1 - b.stop_t0)[1:]
            stops += d[np.isfinite(d) & (d > 0)].tolist()
    if not lengths and not cadence:
        return base
    pick = {
        "step_length_m": lengths,
        "cadence_hz": cadence,
        "scan_interval_s": scans,
    }
    kw = {k: float(np.median(v)) for k, v in pick.items() if v}
    if still:
        kw["still_share"] = float(np.clip(np.median(still), 0.0, 0.9))
    if stops:
        kw["stop_s"] = max(base.stop_s, float(np.median(stops)))
    return replace(base, **kw, source=f"measured on {len(lengths)} walk(s)")
