"""The walk in the panel placed with the building's walks (``edit --map``): the same joint
estimate as ``merge`` (:mod:`workstation.walks.joint`), the building's merged map held still
and this walk moved where their WiFi and its own run agree — what merging it would do to it,
before it is merged. Kept on the editor until the next run."""

from __future__ import annotations

from typing import TYPE_CHECKING

from workstation.fingerprints.devices import one_model
from workstation.fingerprints.localize import Fingerprints
from workstation.walks.correction import AGREE_M, WHAT_TO_DO
from workstation.walks.joint import JointResult, correct

if TYPE_CHECKING:
    from workstation.editor import SurveyEditor

WALK, MAP = "this walk", "the building's map"


def placed_with_map(ed: SurveyEditor) -> tuple[Fingerprints, JointResult] | None:
    """(the walk's points as its run placed them, the joint estimate) — None without a map or
    without a point."""
    if ed.building_map is None or not len(ed.building_map):
        return None
    if ed._placed is not None and ed._placed[0] is ed.result:
        return ed._placed[1]
    device = ed.session.metadata.device
    walk = Fingerprints.from_radiomap(ed.result.radiomap, ed.graph.frame, device=device,
                                      standby=True)  # fmt: skip
    got = None
    if len(walk):
        lp = ed.params.localize
        align = lp.align_devices and not one_model([walk.device, ed.building_map.device])
        res = correct({WALK: walk, MAP: ed.building_map}, lp.tau_dbm, bool(align), fixed={MAP})
        got = (walk, res)
    ed._placed = (ed.result, got)
    return got


def placed_note(ed: SurveyEditor) -> str:
    """What the building's walks would do to this walk, for the panel's summary ("" without a
    map)."""
    got = placed_with_map(ed)
    if got is None:
        return ""
    w = got[1].walks[WALK]
    if not w.links:
        return ("no scan of it links to the map's (nobody walked where it went, or they share no "
                "AP): nothing to correct it by")  # fmt: skip
    if w.unreconciled:
        return (f"<span style='color:#d62728'>**cannot be reconciled**: the map's WiFi still puts "
                f"it {w.disagree_m:.0f} m away ({w.links} links, {100 * w.agree:.0f} % of them "
                f"within {AGREE_M:g} m)</span> — {WHAT_TO_DO}")  # fmt: skip
    return (f"merged, it would move by {w.shift_mean_m:.1f} m on average (at most "
            f"{w.shift_max_m:.1f} m, {w.where}): {w.links} links to the map's scans, "
            f"{100 * w.agree:.0f} % of them within {AGREE_M:g} m after (arrows and links on the "
            "plan: the legend says their colours)")  # fmt: skip
