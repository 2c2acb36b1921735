"""Particle filters over the floor plan: map filtering (known start) and Zee (unknown start,
backward smoothing). Particles that walk through a wall die; the filter resamples."""

from __future__ import annotations

import numpy as np
from matplotlib.path import Path as MplPath

from workstation.baselines import Trajectory
from workstation.baselines.pdr import floors, step_headings
from workstation.building.floorplan import FloorPlan
from workstation.params import Params
from workstation.pipeline.pdr import step as pdr_step

WALL_PENALTY = 1e-6


def _systematic(w: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    n = w.size
    pos = (rng.random() + np.arange(n)) / n
    return np.minimum(np.searchsorted(np.cumsum(w), pos), n - 1)


def particle_filter(
    session,
    plan: FloorPlan,
    start_xy=None,
    start_floor: float = 0.0,
    n: int = 200,
    seed: int = 0,
    params: Params | None = None,
    smooth: bool = False,
    known_floors=None,
) -> Trajectory:
    """PDR I steps (compass heading, fixed length) moved through the walls of ``plan``.

    ``start_xy`` None: particles spread over the floor outline with unknown heading offsets
    (Zee); then ``smooth`` traces the survivors' ancestry back (backward smoothing)."""
    params = params or Params()
    rng = np.random.default_rng(seed)
    t, theta = step_headings(session, params, "compass")
    fl, f_cont = floors(
        session, t, start_floor, params.pdr.floor_hpa, known_floors, continuous=True
    )
    # between floors (on a stair) the plan of neither floor applies: walls are not checked there
    transit = np.abs(f_cont - np.round(f_cont)) > 0.15
    outlines = {f: MplPath(fl_.outline) for f, fl_ in plan.floors.items() if len(fl_.outline) >= 3}
    step = params.pdr.initial_step_length_m
    lo, hi = _floor_box(plan, start_floor)
    if start_xy is None:
        px = rng.uniform(lo[0], hi[0], n)
        py = rng.uniform(lo[1], hi[1], n)
        off = rng.normal(
            0, np.radians(20), n
        )  # the compass is roughly right; where we are is unknown
    else:
        px = start_xy[0] + rng.normal(0, 0.5, n)
        py = start_xy[1] + rng.normal(0, 0.5, n)
        off = rng.normal(0, np.radians(10), n)
    scale = rng.normal(1.0, 0.1, n)
    w = np.full(n, 1.0 / n)
    hist_x = np.empty((t.size, n))
    hist_y = np.empty((t.size, n))
    parent = np.empty((t.size, n), dtype=np.int64)
    est_x = np.empty(t.size)
    est_y = np.empty(t.size)
    for i in range(t.size):
        h = theta[i] + off + rng.normal(0, np.radians(5), n)
        ln = step * scale + rng.normal(0, 0.05, n)
        nx, ny = pdr_step(px, py, ln, h)  # eq. 7–8, one step of every particle
        hit = (
            np.zeros(n, bool)
            if transit[i]
            else plan.crossings(fl[i], np.column_stack([px, py]), np.column_stack([nx, ny])) > 0
        )
        inside = outlines.get(float(fl[i]))
        if inside is not None:
            hit |= ~inside.contains_points(np.column_stack([nx, ny]))  # out of the building
        # a particle that walks through a wall dies; a (tiny) weight remains so that, when every
        # particle hits one (e.g. stair steps counted as full steps), the least wrong survive
        w = np.where(hit, w * WALL_PENALTY, w)
        if start_xy is None and not (~hit).any():
            # Zee lost every hypothesis: start again from anywhere on the floor
            nx, ny = rng.uniform(lo[0], hi[0], n), rng.uniform(lo[1], hi[1], n)
            off, scale = rng.normal(0, np.radians(20), n), rng.normal(1.0, 0.1, n)
            w = np.ones(n)
        w = w / w.sum()
        idx = np.arange(n)
        if 1.0 / np.sum(w**2) < n / 2:
            idx = _systematic(w, rng)
            nx, ny, off, scale = nx[idx], ny[idx], off[idx], scale[idx]
            w = np.full(n, 1.0 / n)
        px, py = nx, ny
        parent[i] = idx
        hist_x[i], hist_y[i] = px, py
        est_x[i], est_y[i] = np.sum(w * px), np.sum(w * py)
    if smooth and t.size:
        est_x, est_y = _smoothed(parent, hist_x, hist_y)
    return Trajectory(t, est_x, est_y, fl)


def _floor_box(plan: FloorPlan, floor: float) -> tuple[np.ndarray, np.ndarray]:
    """The corners (lo, hi) of the floor's outline's box; 0–50 m without an outline."""
    outline = plan.floors[float(floor)].outline if float(floor) in plan.floors else None
    if outline is not None and len(outline):
        return outline.min(axis=0), outline.max(axis=0)
    return np.zeros(2), np.full(2, 50.0)


def _smoothed(parent: np.ndarray, hist_x: np.ndarray, hist_y: np.ndarray):
    """Backward smoothing: the final particles' ancestry followed back to the start, keeping the
    lineages of the largest family (the particles that share the most common root); per step,
    the mean of their positions."""
    steps, n = parent.shape
    lineage = np.arange(n)
    paths = np.empty((steps, n), dtype=np.int64)
    for i in range(steps - 1, -1, -1):
        paths[i] = lineage
        lineage = parent[i, lineage]
    family = lineage == np.bincount(lineage).argmax()
    sx = np.array([hist_x[i, paths[i, family]].mean() for i in range(steps)])
    sy = np.array([hist_y[i, paths[i, family]].mean() for i in range(steps)])
    return sx, sy
