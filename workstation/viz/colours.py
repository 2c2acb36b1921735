"""The colours of the Rerun recording, in one place, chosen for the viewer's dark theme (issue
#14: ground truth was black on black, raw PDR the walls' grey). The legend logged with every
recording is written from this table."""

from __future__ import annotations

from functools import cache

import numpy as np

# name → (RGB or RGBA, what it shows)
MAP = {
    "walls": ((105, 105, 115), "walls of the floor plan"),
    "graph_edges": ((170, 170, 210), "landmark graph edges (nodes: blue gyro, magenta acc, orange barometer, grey no rule)"),
    "ground_truth": ((240, 240, 240), "ground truth (white; dots: the fixes)"),
    "raw_pdr": ((215, 130, 60), "plain PDR, no graph (orange)"),
    "trajectory": ((80, 140, 255), "our trajectory, forward (blue)"),
    "trajectory_corrected": ((40, 210, 200), "our trajectory, backward-corrected (cyan): where scans are placed"),
    "walker": ((255, 70, 200), "the walker now (pink)"),
    "matched_landmarks": ((250, 200, 0, 150), "landmarks matched (yellow halo)"),
    "accepted": ((40, 190, 80), "reference points kept (green)"),
    "rejected": ((225, 60, 60), "scans left out (red)"),
}  # fmt: skip
SERIES = {
    "step_period": ((210, 210, 230), "step period (light grey dots)"),
    "aps_per_scan": ((120, 120, 230), "APs heard per scan"),
    "belief": ((40, 190, 80), "belief per segment (green)"),
    "threshold": ((225, 60, 60), "belief threshold ε_S (red)"),
}


def rgb(name: str):
    return (MAP.get(name) or SERIES[name])[0]


def legend_markdown() -> str:
    lines = ["# Legend", "", "**Map**", ""]
    lines += [f"- {what}" for _, what in MAP.values()]
    lines += [
        "- radiomap layout: coverage (distance to the nearest reference point: yellow 0 m … "
        "purple 10 m and more); per-AP RSS heatmaps under quality/ap/ (switch on in the "
        "blueprint panel)",
        "",
        "**Time series**",
        "",
    ]
    lines += [f"- {what}" for _, what in SERIES.values()]
    return "\n".join(lines)


@cache
def _lut(name: str) -> np.ndarray:
    """A matplotlib colormap as 256 RGB rows (uint8), looked up once."""
    from matplotlib import colormaps

    return (colormaps[name](np.linspace(0, 1, 256))[:, :3] * 255).astype(np.uint8)


def _scaled(z: np.ndarray, name: str) -> np.ndarray:
    return _lut(name)[(np.clip(np.nan_to_num(z), 0, 1) * 255).round().astype(int)]


def coverage_rgb(distance_m: np.ndarray) -> np.ndarray:
    """Coverage (distance to the nearest reference point): 0 m yellow … 10 m and more purple."""
    return _scaled(np.asarray(distance_m, float) / 10.0, "viridis_r")


def rss_rgb(dbm: np.ndarray) -> np.ndarray:
    """An AP's RSS heatmap: −100 dBm blue … −30 dBm red."""
    return _scaled((np.asarray(dbm, float) + 100.0) / 70.0, "turbo")
