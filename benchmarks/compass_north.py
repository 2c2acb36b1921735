"""Where the compass points on each floor (issue #62: the evidence σ's compass term stands on,
:func:`workstation.pipeline.sigma.compass_drift`): the angle between the walker's true direction (each walk's ground truth — the taps, the museum's
landmark times — where the walker moves ≥ 0.5 m/s) and the phone's tilt-compensated compass
(:func:`workstation.pipeline.heading.estimate_heading`), every 0.5 s.

Per building it prints the floor's offset (the circular mean over every walk: how far the
plan's +x axis is from where the compass says "east") and its resultant (1: every sample
agrees), how far each walk's own mean strays from the floor's (median, 90th percentile,
largest), the samples' own spread (|deviation| at the median, 75th and 90th percentiles) and
the same over σ's windows (± ``sigma.COMPASS_WINDOW_S``, steady, ≥ ``COMPASS_MIN_M`` walked:
90th, 95th and 99th percentiles — where ``COMPASS_GATE_DEG`` stands).
Where one offset holds for every walk of a floor, a stretch of a placed track heading
elsewhere is a heading error the walk's own run cannot see (docs/experiments.md, "The
compass knows where north is").

    python benchmarks/compass_north.py [EVERY_NTH_WALK]   (default 2)
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from benchmarks._common import SHARED_DATA  # noqa: E402
from workstation.evaluate.walk_files import ipin_museum  # noqa: E402
from workstation.params import Params  # noqa: E402
from workstation.pipeline.heading import estimate_heading  # noqa: E402
from workstation.pipeline.sigma import compass_windows  # noqa: E402
from workstation.session import load_session  # noqa: E402

MOVING_M_S = 0.5
STEP_S = 0.5


def deviations(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """The true direction minus the compass (rad), every ``STEP_S`` where the walker moves; and
    σ's windows over it (:func:`~workstation.pipeline.sigma.compass_windows`, those that
    count)."""
    s = load_session(path)
    gt = s.ground_truth
    if gt is None or gt.t.size < 2 or gt.t[-1] - gt.t[0] < 4:
        return np.empty(0), np.empty(0, complex)
    h = estimate_heading(s, Params().heading)
    t = np.arange(gt.t[0] + 1, gt.t[-1] - 1, STEP_S)
    gx, gy, _ = gt.at(t)
    vx, vy = np.gradient(gx, t), np.gradient(gy, t)
    comp = np.interp(t, h.t, np.unwrap(h.compass))
    d = np.angle(np.exp(1j * (np.arctan2(vy, vx) - comp)))
    ok = (np.hypot(vx, vy) >= MOVING_M_S) & np.isfinite(d)
    zw, counts = compass_windows(t, np.where(ok, np.hypot(vx, vy) * STEP_S, 0.0), d)
    return d[ok], zw[ok & counts]


def row(name: str, paths: list[Path]) -> str:
    got = [dw for dw in (deviations(p) for p in paths) if dw[0].size >= 10]
    if not got:
        return f"| {name} | 0 | – | – | – | – | – |"
    per = [d for d, _ in got]
    z = np.exp(1j * np.concatenate(per)).mean()
    off = np.angle(z)
    walk = np.array([abs(np.angle(np.exp(1j * d).mean() * np.exp(-1j * off))) for d in per])
    sample = np.abs(np.angle(np.exp(1j * (np.concatenate(per) - off))))
    window = np.abs(np.angle(np.concatenate([w for _, w in got]) * np.exp(-1j * off)))
    w50, w90, wmax = np.degrees(np.percentile(walk, [50, 90, 100]))
    s50, s75, s90 = np.degrees(np.percentile(sample, [50, 75, 90]))
    v90, v95, v99 = np.degrees(np.percentile(window, [90, 95, 99])) if window.size else [np.nan] * 3
    return (f"| {name} | {len(per)} | {np.degrees(off):.0f}° ({abs(z):.2f}) | "
            f"{w50:.0f}° / {w90:.0f}° / {wmax:.0f}° | {s50:.0f}° / {s75:.0f}° / {s90:.0f}° | "
            f"{v90:.0f}° / {v95:.0f}° / {v99:.0f}° |")  # fmt: skip


def main() -> None:
    every = int(sys.argv[1]) if len(sys.argv) > 1 else 2
    print("| building | walks | floor offset (resultant) | walk's own mean off it: p50 / p90 / max "
          "| samples off it: p50 / p75 / p90 | σ's windows off it: p90 / p95 / p99 |")  # fmt: skip
    print("|---|---|---|---|---|---|")
    for f in ("f1", "f2", "f3", "b1"):
        root = SHARED_DATA / f"microsoft-ilc2020-site1-{f}" / "path_data_files"
        paths = sorted(root.glob("*.gz"))[::every]
        if paths:
            print(row(f"mall {f.upper()}", paths), flush=True)
    museum = ipin_museum(SHARED_DATA)
    if museum is not None:
        print(row("museum", museum[0]), flush=True)


if __name__ == "__main__":
    main()
