"""PDR I (compass) and PDR II (gyro): step counting with a fixed step length (Table I's 0.63 m),
x += l cos θ, y += l sin θ (eq. 7–8), floor from pressure (eq. 9)."""

from __future__ import annotations

import numpy as np

from workstation.baselines import Trajectory
from workstation.params import GYRO_HEADING, Params
from workstation.pipeline.floors import FloorModel
from workstation.pipeline.heading import estimate_heading
from workstation.pipeline.pdr import dead_reckon, gyro_offset
from workstation.pipeline.start import find_start_time
from workstation.pipeline.steps import detect_steps


def step_headings(session, params: Params, source: str):
    """(steps after the start, their headings): compass, or gyro aligned to the compass over
    the first steps."""
    steps = detect_steps(session.accelerometer, params.steps)
    heading = estimate_heading(session, params.heading)
    t0 = find_start_time(steps, params.pdr, heading)
    t = steps.t[steps.t > t0]
    hc = heading.at(t, "compass")
    if source == "compass":
        return t, hc
    hg = heading.at(t, GYRO_HEADING)
    offset = gyro_offset(hc, hg) if t.size else 0.0
    return t, hg + offset


def floors(
    session,
    t: np.ndarray,
    start_floor: float,
    p_d: float,
    known: np.ndarray | None = None,
    continuous: bool = False,
):
    """Eq. 9 from the start (:class:`~workstation.pipeline.floors.FloorModel`, the floors
    ``p_d`` apart), rounded to the nearest known floor (and the unrounded value)."""
    p = session.pressure
    if p is None or not len(p) or t.size == 0:
        f = np.full(t.size, float(start_floor))
        rounded = f
    else:
        pt = np.interp(t, p.t, p.value)
        given = known is not None and len(known) > 0
        near = np.asarray(known, float) if given else float(start_floor) + np.array([-1.0, 1.0])
        fm = FloorModel.prior(near, p_d, float(pt[0]), float(start_floor))
        f = fm.continuous(pt)
        rounded = fm.nearest(pt) if given else np.round(f)
    return (rounded, f) if continuous else rounded


def pdr(
    session,
    start_xy,
    start_floor: float,
    source: str = "compass",
    params: Params | None = None,
    known_floors=None,
) -> Trajectory:
    params = params or Params()
    t, theta = step_headings(session, params, source)
    step = params.pdr.initial_step_length_m
    x, y = dead_reckon(start_xy[0], start_xy[1], step, theta)
    return Trajectory(t, x, y, floors(session, t, start_floor, params.pdr.floor_hpa, known_floors))
