"""The colours of the Rerun recording and of the survey panel, in one place (issue #30: orange
was untrusted in the panel and plain PDR in Rerun). Each reads on the viewer's dark theme and on
a white floor-plan image (issue #14: ground truth was black on black; then white, invisible on
the plans). The legend logged with every recording is written from this table."""

from __future__ import annotations

from functools import cache

import numpy as np

from workstation.rules import BARO, FLOOR_CHANGE, FLOOR_ENTRY, FLOOR_EXIT, STOP, TABLE, TURN

# the rules with a colour of their own (the paper's four); any other rule added to
# workstation/rules.py is drawn in "landmark_other"
_OWN = (STOP, TURN, FLOOR_ENTRY, FLOOR_EXIT)
OTHER_RULES = tuple(r.name for r in TABLE if r.name not in _OWN)

# name → (RGB or RGBA, what it shows): one entry a meaning, and no two meanings alike (CIELAB
# ΔE ≥ 20 between any two: tests/viz/test_colours.py; issue #64 item 4). The colour's name in
# every legend and in docs/reference.md's table is made from its RGB (:func:`colour_name`).
MAP = {
    "walls": ((110, 100, 90), "walls of the floor plan"),
    "graph_edges": ((170, 170, 210), "landmark graph edges (Rerun)"),
    "edges_one_floor": ((120, 120, 220), "landmark graph edges on one floor (panel, over the plan)"),
    "landmark_gyro": ((40, 140, 230), "a landmark of the gyroscope's rule (a turn), and its detections"),
    "landmark_acc": ((200, 60, 200), "a landmark of the accelerometer's rule (a stop), and its detections"),
    "landmark_baro": ((120, 140, 70), "a landmark of the barometer's rule (a stair or lift end), its floor-entry detections, and the edges across floors"),
    "landmark_none": ((150, 150, 150), "a landmark with no detection rule"),
    "landmark_other": ((235, 145, 145), "a landmark of a rule without a colour of its own ("
                       + (", ".join(OTHER_RULES) or "none today") + ": workstation/rules.py), "
                       "and its detections"),
    "floor_exit": ((250, 200, 90), "a detection of leaving a floor (barometer)"),
    "ground_truth": ((150, 70, 240), "ground truth (dots: the fixes)"),
    "raw_pdr": ((215, 130, 60), "plain PDR, no graph"),
    "trajectory": ((30, 70, 220), "our trajectory as the walker went (forward; in the panel where belief trusts its segment)"),
    "untrusted": ((140, 110, 140), "our trajectory where belief does not trust the segment (panel)"),
    "trajectory_corrected": ((20, 170, 190), "our trajectory, backward-corrected: where scans are placed"),
    "walk_marks": ((20, 110, 130), "where the walk starts and ends (large dots, labelled with the landmark and the time) and which way it went (arrows)"),
    "quarantined": ((230, 30, 80), "a quarantined walk's corrected track (thick in Rerun): its points stay out of merged maps"),
    "walker": ((255, 70, 200), "the walker now"),
    "matched_landmarks": ((250, 200, 0, 150), "landmarks matched (halo)"),
    "accepted": ((40, 190, 80), "reference points kept"),
    "rejected": ((220, 70, 50), "scans left out"),
    "standby": ((175, 150, 0), "scans on standby: held back for their σ, they join a merged map with their σ, if it is at most 7.5 m"),
    "selection": ((250, 240, 0), "the selected landmark (halo, panel)"),
    "start_hint": ((235, 70, 140), "an ambiguous start's likeliest candidates (rings, numbered; panel), and the reach of where the walk before ended (circle)"),
    "control_points": ((150, 90, 40), "control points placing the plan (panel)"),
    "walk_here_next": ((250, 0, 250), "graph edges to walk again: the map is thin along them (quality; over the plan's pale-blue shops)"),
    "planned_route": ((0, 150, 120), "the planned survey route (band; numbers: walk.leg)"),
    "localized": ((135, 60, 105), "a scan localized on the building's map, a thin line to where the track was then (view --map)"),
    "placed_alone": ((80, 90, 150), "a walk's points where its own run placed them, arrows to where the walks placed together put them (merge --save, edit --map)"),
    "joint_links": ((215, 195, 120, 110), "links between scans of different walks that heard the APs alike (fainter where they weigh less; merge --save, edit --map)"),
}  # fmt: skip
# drawn over the floor-plan images: each must read on white as on the dark theme
OVER_PLANS = ("ground_truth", "raw_pdr", "trajectory", "untrusted", "trajectory_corrected", "walk_marks", "quarantined",
              "walker", "accepted", "rejected", "standby", "control_points",
              "planned_route", "start_hint", "localized")  # fmt: skip
SERIES = {
    "step_period": ((220, 220, 230), "step period (dots)"),
    "aps_per_scan": ((170, 110, 240), "APs heard per scan"),
    "belief": ((100, 190, 20), "belief per segment"),
    "threshold": ((160, 20, 40), "belief threshold ε_S"),
}


# landmarks by their detection rule, and detections by their kind: the meanings above
RULES = {BARO: MAP["landmark_baro"][0], STOP: MAP["landmark_acc"][0], TURN: MAP["landmark_gyro"][0],
         "": MAP["landmark_none"][0], **dict.fromkeys(OTHER_RULES, MAP["landmark_other"][0])}  # fmt: skip
# the panel's graph edges: on one floor (darker than Rerun's: they lie on a white plan), and
# across floors (stairs, lifts: the barometer rule's meaning)
EDGES = {"floor": MAP["edges_one_floor"][0], "across": RULES[BARO]}
KINDS = {
    STOP: RULES[STOP], TURN: RULES[TURN],
    FLOOR_ENTRY: RULES[BARO], FLOOR_EXIT: MAP["floor_exit"][0],
    **{r: RULES[r] for r in OTHER_RULES},
}  # fmt: skip

# colour names for the legends and the docs: the nearest of these (CIELAB) names a colour
_NAMED = {
    "black": (20, 20, 20), "dark grey": (90, 90, 90), "grey": (150, 150, 150),
    "light grey": (215, 215, 225), "white": (250, 250, 250), "red": (220, 50, 40),
    "crimson": (220, 20, 70), "maroon": (150, 20, 40), "orange": (230, 130, 40),
    "amber": (250, 180, 60), "gold": (230, 200, 0), "yellow": (250, 240, 20),
    "olive": (170, 150, 0), "moss green": (120, 140, 70), "green": (40, 180, 70),
    "lime": (110, 200, 20), "teal": (0, 140, 120), "dark teal": (20, 110, 130),
    "cyan": (20, 180, 200), "sky blue": (0, 190, 250), "blue": (40, 130, 230),
    "deep blue": (30, 60, 210), "slate": (80, 90, 150), "lavender": (170, 170, 215),
    "periwinkle": (120, 120, 220), "violet": (150, 70, 240), "purple": (170, 110, 240),
    "plum": (135, 60, 105), "mauve": (140, 110, 140), "magenta": (200, 60, 200),
    "pink": (255, 80, 200), "rose": (235, 70, 140), "brown": (150, 90, 40),
    "khaki": (215, 195, 120), "fuchsia": (250, 0, 250),
}  # fmt: skip


def lab(c) -> np.ndarray:
    """CIELAB (D65) of an sRGB colour (RGB or RGBA, 0–255)."""
    v = np.asarray(c, float)[..., :3] / 255
    lin = np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)
    xyz = lin @ np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722],
                          [0.0193, 0.1192, 0.9505]]).T / [0.95047, 1.0, 1.08883]  # fmt: skip
    f = np.where(xyz > 0.008856, np.cbrt(xyz), 7.787 * xyz + 16 / 116)
    return np.stack([116 * f[..., 1] - 16, 500 * (f[..., 0] - f[..., 1]),
                     200 * (f[..., 1] - f[..., 2])], axis=-1)  # fmt: skip


def colour_name(c) -> str:
    """The colour's name in words: the nearest of ``_NAMED``."""
    names = list(_NAMED)
    d = np.linalg.norm(lab(np.array(list(_NAMED.values()))) - lab(c), axis=1)
    return names[int(np.argmin(d))]


def meanings() -> dict[str, tuple]:
    """Every meaning with its colour (the map's and the time series'): what must differ."""
    return {**{k: v[0] for k, v in MAP.items()}, **{f"series:{k}": v[0] for k, v in SERIES.items()}}


def colours_markdown() -> str:
    """docs/reference.md's table of colours, made from this module (tests keep it in step)."""
    rows = ["| colour | RGB | what it shows |", "|---|---|---|"]
    for table in (MAP, SERIES):
        for rgb_, what in table.values():
            rows.append(f"| {colour_name(rgb_)} | `{_hex(rgb_)}` | {what} |")
    return "\n".join(rows)


def rgb(name: str):
    return (MAP.get(name) or SERIES[name])[0]


def rule_rgb(rules) -> tuple[int, ...]:
    """A landmark's colour by its rules: barometer first, then acc, then gyro, then any other
    rule; grey for none."""
    if rules & FLOOR_CHANGE:
        return RULES[BARO]
    for r in (STOP, TURN, *OTHER_RULES):
        if r in rules:
            return RULES[r]
    return RULES[""]


def legend_markdown() -> str:
    lines = ["# Legend", "", "**Map**", ""]
    lines += [f"- {colour_name(c)}: {what}" for c, what in MAP.values()]
    lines += [
        "- radiomap layout: coverage (distance to the nearest reference point: yellow "
        f"{SCALES['coverage'][0]:g} m … purple {SCALES['coverage'][1]:g} m and more); per-AP "
        "RSS heatmaps under quality/ap/ (switch on in the blueprint panel)",
        "",
        "**Time series**",
        "",
    ]
    lines += [f"- {colour_name(c)}: {what}" for c, what in SERIES.values()]
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
        f"{dot(RULES[BARO])} barometer {dot(RULES[''])} no rule"
        + "".join(f" {dot(RULES[r])} {r}" for r in OTHER_RULES)
        + " · trajectory "
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
