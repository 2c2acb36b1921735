"""How the parameters are offered in the editor panel: the slider range a surveyor would try for
each (the validation bounds in :mod:`.params` are wider) and one description per parameter."""

from __future__ import annotations

from dataclasses import fields
from typing import Any

from workstation.params.model import GROUPS

# Slider ranges for the editor panel: the values a surveyor would try (the validation bounds
# above are wider).
UI_RANGES: dict[str, tuple[float, float]] = {
    "steps.variance_threshold": (0.05, 5.0),
    "steps.lowpass_hz": (1.0, 6.0),
    "steps.min_period_s": (0.15, 0.6),
    "steps.min_peak_ms2": (0.0, 2.0),
    "steps.still_gap_s": (0.0, 1.0),
    "steps.variance_window": (10, 150),
    "heading.gravity_lowpass_hz": (0.1, 2.0),
    "acc.walking_s": (0.5, 6.0),
    "acc.still_min_s": (0.2, 5.0),
    "acc.still_max_s": (2.0, 20.0),
    "gyro.window": (1, 50),
    "gyro.threshold_rad_s": (0.2, 3.0),
    "gyro.merge_s": (0.0, 3.0),
    "baro.window_s": (0.2, 3.0),
    "baro.horizontal_hpa": (0.005, 0.2),
    "baro.vertical_hpa": (0.05, 1.0),
    "baro.dead_band_hpa": (0.0, 0.1),
    "baro.max_level_s": (0.0, 20.0),
    "pdr.floor_hpa": (0.2, 1.0),
    "pdr.heading_threshold_deg": (5.0, 90.0),
    "pdr.confidence_threshold": (0.0, 2.0),
    "pdr.initial_step_length_m": (0.4, 1.0),
    "pdr.min_step_length_m": (0.2, 0.8),
    "pdr.max_step_length_m": (0.6, 1.5),
    "pdr.min_calibration_m": (0.0, 30.0),
    "pdr.max_hops": (1, 4),
    "pdr.min_distance_m": (0.05, 2.0),
    "pdr.relocalize_after_m": (10.0, 200.0),
    "pdr.distance_slack": (0.0, 0.5),
    "pdr.floor_distance_m": (1.0, 20.0),
    "pdr.beam_width": (1, 64),
    "pdr.step_length_cv": (0.0, 0.3),
    "pdr.match_gain": (0.0, 10.0),
    "pdr.miss_cost": (0.0, 10.0),
    "pdr.relocalize_cost": (0.0, 20.0),
    "pdr.start_walk_s": (0.0, 10.0),
    "pdr.start_still_s": (0.0, 15.0),
    "pdr.handling_rate": (0.3, 6.0),
    "pdr.start_search_s": (0.0, 300.0),
    "belief.t_min_s": (0.2, 0.8),
    "belief.t_max_s": (0.6, 2.0),
    "belief.threshold": (0.0, 250.0),
    "belief.min_period_sd_s": (0.0, 0.05),
    "belief.min_valid_steps": (2, 20),
    "radiomap.max_sigma_m": (0.3, 5.0),
    "radiomap.fill_gaps_m": (0.0, 20.0),
}


def describe() -> list[dict[str, Any]]:
    """Every parameter with its range, unit, help and Table I name (for the editor panel)."""
    out = []
    for sec, kind in GROUPS.items():
        for f in fields(kind):
            key = f"{sec}.{f.name}"
            out.append(
                {"key": key, "default": f.default, **f.metadata, "ui_range": UI_RANGES.get(key)}
            )
    return out
