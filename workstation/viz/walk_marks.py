"""Where a walk starts, where it ends and which way it went, as marks on the plan (issue #50
item 3: neither the panel nor Rerun showed any of it). One rule for both views: the Rerun
logger (:mod:`.rerun_log`) and the panel's scene (:mod:`.panel_scene`) draw these marks."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from workstation.pipeline.tracking.state import Track

ARROW_EVERY_M = 10.0  # one direction arrow per this much walked, on each floor
ARROW_BASE_M = 1.5  # the direction is measured over this much of the track either side


@dataclass(frozen=True)
class WalkMarks:
    start: tuple[float, float, float]  # x, y, floor of the first step after the start
    start_label: str
    end: tuple[float, float, float]  # the last step
    end_label: str
    #: (n, 5): x, y, floor and the unit direction walked (dx, dy) at each arrow
    arrows: np.ndarray

    def on_floor(self, floor: float) -> np.ndarray:
        return self.arrows[self.arrows[:, 2] == floor]


def walk_marks(tr: Track, corrected: bool = False) -> WalkMarks | None:
    """The marks of ``tr`` (its backward-corrected track when ``corrected``, as the radio map is
    placed; else the forward one); None when the walk never set off."""
    walking = np.flatnonzero(tr.steps.segment >= 0)
    if walking.size < 2:
        return None
    x, y = (tr.steps.x_bc, tr.steps.y_bc) if corrected else (tr.steps.x, tr.steps.y)
    x, y, f, t = x[walking], y[walking], tr.steps.floor[walking], tr.steps.t[walking]
    end = f"end {tr.end.node}" if tr.end.node else "end (open)"
    return WalkMarks(
        (float(x[0]), float(y[0]), float(f[0])),
        f"start {tr.start.node} · {t[0]:.1f} s",
        (float(x[-1]), float(y[-1]), float(f[-1])),
        f"{end} · {t[-1]:.1f} s",
        _arrows(x, y, f),
    )


def _arrows(x: np.ndarray, y: np.ndarray, f: np.ndarray) -> np.ndarray:
    """An arrow every ``ARROW_EVERY_M`` walked on each floor (the first half-way in), pointing
    along the track measured ``ARROW_BASE_M`` either side of it."""
    step = np.hypot(np.diff(x), np.diff(y))
    same = f[1:] == f[:-1]
    walked = np.concatenate([[0.0], np.cumsum(np.where(same, step, 0.0))])
    out = []
    for floor in np.unique(f):
        idx = np.flatnonzero(f == floor)
        d = walked[idx]
        if d[-1] - d[0] < ARROW_EVERY_M / 2:
            continue
        at = np.arange(d[0] + ARROW_EVERY_M / 2, d[-1], ARROW_EVERY_M)
        i = idx[np.clip(np.searchsorted(d, at), 0, idx.size - 1)]
        lo = idx[np.clip(np.searchsorted(d, at - ARROW_BASE_M), 0, idx.size - 1)]
        hi = idx[np.clip(np.searchsorted(d, at + ARROW_BASE_M), 0, idx.size - 1)]
        dx, dy = x[hi] - x[lo], y[hi] - y[lo]
        n = np.hypot(dx, dy)
        ok = n > 1e-6
        out.append(np.column_stack([x[i], y[i], np.full(i.size, floor), dx / np.where(ok, n, 1),
                                    dy / np.where(ok, n, 1)])[ok])  # fmt: skip
    return np.concatenate(out) if out else np.zeros((0, 5))
