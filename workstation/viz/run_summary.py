"""The run summary the Rerun recording shows (``/summary``): a quarantined walk says so first —
the headline, each reason and what to do — then the start, the end and the figures that matter,
in words; no raw key list, no empty values (issue #50: the viewer once showed a wrong walk as
``end_margin: None`` under a key list that looked like any other)."""

from __future__ import annotations

from workstation.pipeline.run_words import describe_end
from workstation.pipeline.summary import Summary

#: the figures shown, in order, with their words (those absent or None are left out)
SHOWN = {
    "steps": "Steps after the start",
    "landmarks_detected": "Landmarks detected",
    "landmarks_matched": "Landmarks matched",
    "reference_points": "Reference points",
    "scans": "WiFi scans",
    "step_length_m": "Step length at the end (m)",
    "trajectory_error_mean_m": "Trajectory error, mean (m)",
    "fix_error_mean_m": "Error at the fixes, mean (m)",
    "floor_accuracy": "Floor right",
    "landmark_node_accuracy": "Landmark right at the fixes",
    "off_graph_m": "Track's distance from the graph, median (m)",
    "sensor_hole_s": "Inertial sensors silent for (s)",
    "sensor_hole_at_s": "… from (s)",
    "clock_jump_at_s": "A second recording from (s)",
}


def summary_markdown(summ: Summary) -> str:
    held = summ.quarantine
    lines: list[str] = []
    if held:
        lines += [
            "# QUARANTINED — this walk's points stay out of merged maps",
            "",
            *(f"- **{q.reason}**: {q.detail}. *What to do:* {q.what_to_do}" for q in held),
            "",
            "Its track is drawn in the quarantine colour (see the legend).",
            "",
        ]
    else:
        lines += ["# Run summary: in the map", ""]
    start = f"{summ.start_node} at {summ.start_time_s} s"
    if summ.start is not None and summ.start.margin is not None:
        start += f" (inferred; next best {summ.start.alternative}, "
        start += f"{summ.start.margin} log-likelihood lower)"
    lines += [f"- **Starts**: {start}", f"- **Ends on**: {describe_end(summ)}"]
    for w in summ.input_warnings:
        lines.append(f"- **Input**: {w}")
    figures = summ.to_json()
    lines += [
        f"- **{label}**: {figures[k]}" for k, label in SHOWN.items() if figures.get(k) is not None
    ]
    why = summ.scans_not_points
    if why:
        lines.append("- **Scans not used**: " + "; ".join(f"{n} {r}" for r, n in why.items()))
    return "\n".join(lines)
