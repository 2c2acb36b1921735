"""A campaign's ``campaign.md``: the table of buildings, the table of walks and what the surveyor
does about each walk that needs them — from the report's records (:mod:`.outcome`,
:mod:`.walk_row`)."""

from __future__ import annotations

from workstation.campaign.outcome import CampaignReport
from workstation.campaign.walk_row import WalkRow
from workstation.fingerprints.standby import COVER_M
from workstation.pipeline.summary import Quarantine
from workstation.walks.correction import MOVED_M
from workstation.walks.start_by_map import MapRanking, describe


def markdown(r: CampaignReport) -> str:
    L = [
        "# Campaign",
        "",
        f"{r.walks} walks, {r.walks_ok} processed, {r.failed} failed; "
        f"{r.run_now} run this time"
        + (
            f", {r.run_again_with_map} again with the map of their building's other walks"
            if r.run_again_with_map
            else ""
        )
        + f" in {r.wall_seconds} s"
        + (f" ({r.runs} walk runs, {r.busy_seconds} s of the workers' time)" if r.runs else "")
        + ". "
        f"{r.walks_quarantined} walks need the surveyor: their points are kept out "
        "of the merged maps (below). LOO: each walk's scans (at most 200 walks a building, every "
        "n-th) localized on the map of the others, with the building's matcher.",
        "",
        "| building | walks | ran | in the map | need the surveyor | reference points | APs | LOO mean, floor right (m) | with floor penalty (m) | floor accuracy |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name, b in r.buildings.items():
        lo = b.leave_one_out or {}
        L.append(
            f"| {name} | {b.walks} | {b.walks_ok} | {b.walks_ok - b.walks_quarantined} | "
            f"{b.walks_quarantined} | {b.reference_points} | "
            f"{b.access_points} | {lo.get('mean_m', '–')} | "
            f"{lo.get('mean_with_floor_penalty_m', '–')} | {lo.get('floor_accuracy', '–')} |"
        )
    L += ["", "| walk | status | start | steps | matched | ends on | RPs | error at fixes (m) | seconds |",
          "|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    L += [_walk_line(w) for w in r.per_walk]
    held = [w for w in r.per_walk if w.ok and w.quarantined]
    held.sort(key=lambda w: -(w.map_lacks or 0))  # (stable: the walks' order within ties)
    if held:
        L += ["", "## Needs the surveyor", "",
              "These walks ran, but the pipeline is unsure of them: their reference points are "
              "not in the merged map until the walk is fixed and run again. First the walks "
              f"whose scans lie where the building's map has no point within {COVER_M:g} m (as "
              "their own track places them): fixing those adds most.", "",
              "| walk | why | scans where the map has none | what to do |",
              "|---|---|---|---|"]  # fmt: skip
        L += [f"| {w.key} | {q.detail} | {_or_dash(w.map_lacks)} | {_what_to_do(r, w, q)} |"
              for w in held for q in w.quarantine]  # fmt: skip
    L += _joint_section(r, lambda j: j.part_out, "Half of a walk left out",
                        "The building's other walks put one half of these walks far from where "
                        "the walk itself does, and agree with the other half: two walks joined "
                        "into one file, or a wrong landmark there. That half's points are not in "
                        "the merged map; the rest are. `workstation split WALK --at SECONDS` cuts "
                        "the walk (at the half's start or end); each part runs on its own.")  # fmt: skip
    L += _joint_section(r, lambda j: j.fate == "kept",
                        "In the map, though the other walks disagree",
                        "The building's other walks put these walks (or one half of them) far "
                        "from where they are placed, but nothing else covers where they went, so "
                        "their points stay in the merged map: the first walks to check. Open each "
                        "in the panel (`workstation edit`) on the building's map; fix its start, "
                        "end or the graph, or walk there again.")  # fmt: skip
    L += _joint_section(r, lambda j: j.moved, "Moved by the other walks",
                        f"The building's other walks moved these walks by {MOVED_M:g} m or more "
                        "somewhere to agree with them; their points are in the merged map where "
                        "the estimate put them. The farther a walk was moved on average (first "
                        "here), the likelier it was placed wrong: check the first ones in the "
                        "panel (`workstation edit`) on the building's map, then their start, "
                        "end and the landmarks they matched.",
                        order=lambda j: -j.shift_mean_m)  # fmt: skip
    return "\n".join(L) + "\n"


def _joint_section(r: CampaignReport, which, title: str, text: str,
                   order=None) -> list[str]:  # fmt: skip
    """A section of campaign.md listing the walks whose joint estimate ``which`` picks, with
    what the other walks say of each (none: no section), in the order ``order`` gives (a key on
    the estimate) or the walks'."""
    rows = [(w, w.joint) for w in r.per_walk if w.joint is not None and which(w.joint)]
    if order is not None:
        rows.sort(key=lambda wj: order(wj[1]))
    if not rows:
        return []
    return (["", f"## {title}", "", text, "", "| walk | what the other walks say |", "|---|---|"]
            + [f"| {w.key} | {j.words()} |" for w, j in rows])  # fmt: skip


def _or_dash(v: object) -> object:
    return "–" if v is None else v


def _walk_line(w: WalkRow) -> str:
    """A walk's row of campaign.md's table of walks."""
    status = w.status if w.ok else f"{w.status}: {w.error}"
    if w.ok and w.quarantined:
        status = "needs the surveyor"
    f = w.figures
    start = f.get("start_node") or "–"
    if w.start_shared_with:
        start += " (decided with " + ", ".join(w.start_shared_with) + ")"
    h = f.get("start_after")
    if h:
        start += (f" (within {h['reach_m']:g} m of where {h['walk_before']} ended, "
                  f"{h['gap_s']:g} s before)")  # fmt: skip
    return (
        f"| {w.key} | {status} | {start} | {f.get('steps', '–')} | {f.get('landmarks_matched', '–')} "
        f"| {_ends_on(w)} | {f.get('reference_points', '–')} | {f.get('fix_error_mean_m', '–')} | {w.seconds} |"
    )  # fmt: skip


def _what_to_do(r: CampaignReport, w: WalkRow, q: Quarantine) -> str:
    """What the surveyor does about one reason a walk needs them, in this campaign's files."""
    todo = q.what_to_do
    if q.reason == "start_ambiguous":
        return _start_fix(w, r.starts_files.get(w.building, "starts.yaml"))
    if q.reason in ("nothing_matched", "end_far"):
        where = r.ends_files.get(w.building, "ends.yaml")
        todo += f"; in this campaign the walk's end goes in {where} ({w.name}: LANDMARK)"
        if w.edit_command:
            writes = (" — 'End here' there writes it"
                      if " --ends-file " in w.edit_command else "")  # fmt: skip
            todo += f"; to look at it: `{w.edit_command}`{writes}"
    return todo


def _ends_on(w: WalkRow) -> str:
    """Where a walk's end was closed (walk_end.py) and how tightly: "L124 (σ 0.9 m)"; a closed
    end within ``state.END_CHECK_M`` checks a walk that matched no detection, so "matched 0"
    with "ok" is read beside it."""
    f = w.figures
    how, node = f.get("end_how"), f.get("end_node")
    if how in ("given", "given_far"):
        return f"{node} (given" + ("; the sensors end it elsewhere)" if how == "given_far" else ")")
    if how == "closed" and node:
        sd = f.get("end_sigma_m")
        return f"{node} (σ {sd:g} m)" if sd is not None else str(node)
    return {"at_last_match": "last match", None: "–"}.get(how, "open")


def _start_fix(w: WalkRow, starts_file: str) -> str:
    """What to do for a campaign walk whose start is ambiguous: where to give it, and what the
    building's map says of its candidates (:mod:`..start_by_map`)."""
    cmd = w.edit_command or "workstation edit"
    ringed = "the map's likeliest starts are ringed, " if " --map " in cmd else ""
    if " --starts-file " in cmd:  # the panel writes the fix
        out = (f"check the start on the plan (`{cmd}`: {ringed}'Start here' on the right "
               f"landmark shows the walk from it and writes `{w.name}: LANDMARK` to "
               f"{starts_file}), then run the campaign again")  # fmt: skip
    else:
        out = (f"check the start on the plan (`{cmd}`: {ringed}'Start here' shows the walk from "
               f"one), then add `{w.name}: LANDMARK` to {starts_file} and run the campaign again")  # fmt: skip
    ranking = w.start_by_map or MapRanking()
    if ranking.ranked:
        out += (". Its candidate starts by the building's map (likeliest first; the median "
                "distance between where each places its scans and where the map's WiFi puts "
                "them; a hint, not a decision): " + describe(ranking))  # fmt: skip
    elif w.candidates:
        out += ". Its candidate starts: " + ", ".join(w.candidates)
    return out
