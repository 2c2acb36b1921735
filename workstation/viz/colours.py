"""The colours of the Rerun recording, in one place, chosen for the viewer's dark theme (issue
#14: ground truth was black on black, raw PDR the walls' grey). The legend logged with every
recording is written from this table."""

from __future__ import annotations

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
