"""What the panel says in words: the run's summary (a quarantine first), the status line and
the segments table — markdown built from the editor, no viser here."""

from __future__ import annotations

from typing import TYPE_CHECKING

from workstation.editor.placed import placed_note
from workstation.pipeline.run_words import describe_end, what_the_map_did
from workstation.pipeline.summary import Summary

if TYPE_CHECKING:
    from workstation.editor import SurveyEditor

SUMMARY_KEYS = {
    "steps": "Steps",
    "landmarks_detected": "Landmarks detected",
    "landmarks_matched": "Landmarks matched",
    "end_node": "Ends on",
    "step_length_m": "Step length at the end (m)",
    "segments": "Segments",
    "segments_accepted": "Segments belief trusts",
    "reference_points": "Reference points",
    "trajectory_error_mean_m": "Trajectory error, mean (m)",
    "floor_accuracy": "Floor right",
    "landmark_node_accuracy": "Landmark right at the fixes",
}


#: what the segments table says decides the reference points (radiomap.acceptance)
DECIDES = {
    "sigma": "Belief (eq. 17) is shown, not used: a scan becomes a reference point when its "
    "placement σ is at most **radiomap.max_sigma_m** (or it was taken standing at a matched "
    "landmark). On the real walks belief did not change a single point (docs/decisions.md).",
    "belief": "A scan becomes a reference point when its segment's belief passes "
    "**belief.threshold** (radiomap.acceptance: belief, the paper's rule).",
}


def segments_table(result, acceptance: str = "sigma") -> str:
    """Each segment: its landmarks, belief and whether it is trusted (and why not); first,
    what decides the reference points under ``acceptance`` (:data:`DECIDES`)."""
    tr, b = result.track, result.belief
    rows = [DECIDES.get(acceptance, ""), "", "| # | from → to | belief | trusted |",
            "|---|---|---|---|"]  # fmt: skip
    for i in range(b.belief.size):
        why = b.reason[i] if b.reason is not None else ""
        ok = "yes" if b.accepted[i] else f"no: {why}"
        to = tr.segments.to_node[i] or "…"
        if i == b.belief.size - 1 and tr.end.node and tr.segments.to_node[i] == tr.end.node:
            to += " (the walk's end)"
        rows.append(f"| {i} | {tr.segments.from_node[i]} → {to} | {b.belief[i]:.1f} | {ok} |")
    return "\n".join(rows)


def summary_markdown(ed: SurveyEditor, s: Summary | None = None) -> str:
    """The run's summary (``s``: :meth:`SurveyEditor.summary` when the caller has it): a
    quarantine and what to do first, then the start, the counts, the figures against ground
    truth when the walk has it, what became of the scans."""
    s = ed.summary() if s is None else s
    lines = [f"- **Start**: {ed.start_note(s)}"]
    for q in s.quarantine:  # a walk kept out of maps says so first
        said = (  # an ambiguous start: what to do is said once, on the Start line
            "its points stay out of merged maps until its start is given (Start, below)"
            if q.reason == "start_ambiguous"
            else f"{q.detail}: {q.what_to_do}"
        )
        lines.insert(0, f"- <span style='color:#d62728'>**Quarantined** — {said}</span>")
    figures = s.to_json()
    shown = {**figures, "end_node": describe_end(s)}
    lines += [f"- **{label}**: {shown[k]}" for k, label in SUMMARY_KEYS.items() if k in figures]
    lines += [f"- **The building's map**: {said}" for said in what_the_map_did(s)]
    placed = placed_note(ed)
    if placed:
        lines.append(f"- **Placed with the building's walks**: {placed}")
    lost = s.scans_not_points
    if lost:  # what became of the rest of the scans
        lines.append(
            f"- **Scans not used** ({sum(lost.values())} of {s.scans}): "
            + "; ".join(f"{n} {why}" for why, n in lost.items())
        )
    lines.append(f"- re-run took {ed.last_run_ms:.0f} ms")
    return "\n".join(lines)


def status_markdown(ed: SurveyEditor, said: str) -> str:
    """A tab's status line: what it was told (``said``), and what is not saved yet."""
    unsaved = ed.unsaved
    mark = (
        f" <span style='color:#e6781e'>● unsaved {' and '.join(unsaved)}</span>" if unsaved else ""
    )
    return f"**status:** {said}{mark}"
