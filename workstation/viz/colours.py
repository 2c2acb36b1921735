"""The colours of the Rerun recording and of the survey panel, in one place (issue #30: orange
was untrusted in the panel and plain PDR in Rerun). Each reads on the viewer's dark theme and on
a white floor-plan image (issue #14: ground truth was black on black; then white, invisible on
the plans). The legend logged with every recording is written from this table."""

from __future__ import annotations

from functools import cache

import numpy as np

from workstation.rules import BARO, FLOOR_CHANGE, FLOOR_ENTRY, FLOOR_EXIT, STOP, TURN

# name → (RGB or RGBA, what it shows)
MAP = {
    "walls": ((105, 105, 115), "walls of the floor plan"),
    "graph_edges": ((170, 170, 210), "landmark graph edges (nodes: blue gyro, magenta acc, moss green barometer, grey no rule)"),
    "ground_truth": ((150, 70, 240), "ground truth (violet; dots: the fixes)"),
    "raw_pdr": ((215, 130, 60), "plain PDR, no graph (orange)"),
    "trajectory": ((80, 140, 255), "our trajectory, forward (blue)"),
    "untrusted": ((140, 140, 140), "our trajectory where belief does not trust the segment (grey, panel)"),
    "trajectory_corrected": ((20, 170, 190), "our trajectory, backward-corrected (cyan): where scans are placed"),
    "walk_marks": ((20, 170, 190), "where the walk starts and ends (large cyan dots, labelled with the landmark and the time) and which way it went (cyan arrows)"),
    "quarantined": ((230, 30, 80), "a quarantined walk's corrected track (crimson; thick in Rerun): its points stay out of merged maps"),
    "walker": ((255, 70, 200), "the walker now (pink)"),
    "matched_landmarks": ((250, 200, 0, 150), "landmarks matched (yellow halo)"),
    "accepted": ((40, 190, 80), "reference points kept (green)"),
    "rejected": ((225, 60, 60), "scans left out (red)"),
    "standby": ((175, 150, 0), "scans on standby: held back for their σ, they join a merged map where no point lies within 5 m (olive)"),
    "selection": ((255, 220, 0), "the selected landmark (yellow halo, panel)"),
    "start_hint": ((235, 70, 140), "an ambiguous start's likeliest candidates (rose rings, numbered; panel), and the reach of where the walk before ended (rose circle)"),
    "control_points": ((150, 90, 40), "control points placing the plan (brown, panel)"),
    "walk_here_next": ((0, 190, 255), "graph edges to walk again: the map is thin along them (sky blue, quality)"),
    "planned_route": ((0, 150, 120), "the planned survey route (teal band; numbers: walk.leg)"),
    "localized": ((135, 60, 105), "a scan localized on the building's map, a thin line to where the track was then (plum; view --map)"),
    "placed_alone": ((120, 110, 190), "a walk's points where its own run placed them, arrows to where the walks placed together put them (slate; merge --save)"),
    "joint_links": ((215, 195, 120, 110), "links between scans of different walks that heard the APs alike (khaki, fainter where they weigh less; merge --save)"),
}  # fmt: skip
# drawn over the floor-plan images: each must read on white as on the dark theme
OVER_PLANS = ("ground_truth", "raw_pdr", "trajectory", "untrusted", "trajectory_corrected", "walk_marks", "quarantined",
              "walker", "accepted", "rejected", "standby", "control_points",
              "planned_route", "start_hint", "localized")  # fmt: skip
SERIES = {
    "step_period": ((210, 210, 230), "step period (light grey dots)"),
    "aps_per_scan": ((120, 120, 230), "APs heard per scan"),
    "belief": ((40, 190, 80), "belief per segment (green)"),
    "threshold": ((225, 60, 60), "belief threshold ε_S (red)"),
}


# landmarks by their detection rule, and detections by their kind
RULES = {BARO: (120, 140, 70), STOP: (200, 60, 200), TURN: (40, 140, 230), "": (150, 150, 150)}
# the panel's graph edges: on one floor (darker than Rerun's: they lie on a white plan), and
# across floors (stairs, lifts: the barometer rule's colour)
EDGES = {"floor": (120, 120, 220), "across": RULES[BARO]}
KINDS = {
    STOP: RULES[STOP], TURN: RULES[TURN],
    FLOOR_ENTRY: RULES[BARO], FLOOR_EXIT: (230, 180, 30),
}  # fmt: skip


def rgb(name: str):
    return (MAP.get(name) or SERIES[name])[0]


def rule_rgb(rules) -> tuple[int, int, int]:
    """A landmark's colour by its rules: barometer first, then acc, then gyro; grey for none."""
    if rules & FLOOR_CHANGE:
        return RULES[BARO]
    for r in (STOP, TURN):
        if r in rules:
            return RULES[r]
    return RULES[""]


def legend_markdown() -> str:
    lines = ["# Legend", "", "**Map**", ""]
    lines += [f"- {what}" for _, what in MAP.values()]
    lines += [
        "- radiomap layout: coverage (distance to the nearest reference point: yellow "
        f"{SCALES['coverage'][0]:g} m … purple {SCALES['coverage'][1]:g} m and more); per-AP "
        "RSS heatmaps under quality/ap/ (switch on in the blueprint panel)",
        "",
        "**Time series**",
        "",
    ]
    lines += [f"- {what}" for _, what in SERIES.values()]
    return "\n".join(lines)


def _hex(c) -> str:
    r, g, b = c[:3]
    return f"#{r:02x}{g:02x}{b:02x}"


def panel_legend() -> str:
    """The panel's legend, from the same table as Rerun's."""

    def dot(c) -> str:
        return f"<span style='color:{_hex(c)}'>●</span>"

    def line(c) -> str:
        return f"<span style='color:{_hex(c)}'>━</span>"

    return (
        f"Landmarks: {dot(RULES[TURN])} {TURN} {dot(RULES[STOP])} {STOP} "
        f"{dot(RULES[BARO])} barometer {dot(RULES[''])} no rule · trajectory "
        f"{line(rgb('trajectory'))} where belief trusts its segment, {line(rgb('untrusted'))} "
        f"where not, {line(rgb('quarantined'))} all of it when the walk is quarantined, "
        f"{dot(rgb('walk_marks'))} its start and end (labelled), ➤ the way it went"
        f" · ground truth {line(rgb('ground_truth'))} · reference points "
        f"{dot(rgb('accepted'))} kept {dot(rgb('standby'))} on standby {dot(rgb('rejected'))} "
        f"left out · {dot(rgb('start_hint'))} an ambiguous start's likeliest candidates (start? #1 …), the reach of where the walk before ended"
        f" · with the building's map: ➤ {line(rgb('placed_alone'))} where merging moves its points, "
        f"{line(rgb('joint_links'))} their links to the map's scans"
    )


def point_kinds(rm) -> tuple[tuple[str, np.ndarray], ...]:
    """A walk's scans by what became of them (the names are colours of ``MAP``): reference
    points, on standby (held back for their σ alone: standby.py), left out."""
    wait = rm.held_for_sigma
    return (("accepted", rm.accepted), ("standby", wait), ("rejected", ~rm.accepted & ~wait))


@cache
def _lut(name: str) -> np.ndarray:
    """A matplotlib colormap as 256 RGB rows (uint8), looked up once."""
    from matplotlib import colormaps

    return (colormaps[name](np.linspace(0, 1, 256))[:, :3] * 255).astype(np.uint8)


def _scaled(z: np.ndarray, name: str) -> np.ndarray:
    return _lut(name)[(np.clip(np.nan_to_num(z), 0, 1) * 255).round().astype(int)]


#: fixed colour scales, (low, high, colormap), the same in Rerun, the panel and ``quality``'s
#: PNGs (issue #50 item 6: ``quality`` scaled each image to its own range — purple was 2.8 m on
#: one floor and 86 m on the next); values beyond either end take the end's colour
SCALES = {
    "coverage": (0.0, 10.0, "viridis_r"),  # distance to the nearest reference point (m)
    "predicted_error": (0.0, 10.0, "magma_r"),  # predicted 1-NN error (m)
    "rss": (-100.0, -30.0, "turbo"),  # an AP's RSS (dBm)
}


def scaled_rgb(kind: str, z: np.ndarray) -> np.ndarray:
    lo, hi, cmap = SCALES[kind]
    return _scaled((np.asarray(z, float) - lo) / (hi - lo), cmap)


def scale_legend(kind: str, unit: str, n: int = 5) -> str:
    """A colour scale in words for the panel: a swatch at ``n`` values from low to high, the
    last "and more" (markdown)."""
    lo, hi, _ = SCALES[kind]
    values = np.linspace(lo, hi, n)
    cols = scaled_rgb(kind, values)
    parts = [f"<span style='color:{_hex(c)}'>■</span> {v:g}" for c, v in zip(cols, values)]
    return " … ".join(parts) + f" {unit} and more"


def coverage_rgb(distance_m: np.ndarray) -> np.ndarray:
    """Coverage (distance to the nearest reference point): 0 m yellow … 10 m and more purple."""
    return scaled_rgb("coverage", distance_m)


def rss_rgb(dbm: np.ndarray) -> np.ndarray:
    """An AP's RSS heatmap: −100 dBm blue … −30 dBm red."""
    return scaled_rgb("rss", dbm)
