"""The leave-one-walk-out sections of results.md (``evaluate --walks`` and the built-in museum
run): every sentence that states a finding is written from the numbers it is about."""

from __future__ import annotations

import numpy as np

from workstation.evaluate.report_kinds import built_kinds_markdown, matchers_markdown
from workstation.evaluate.walks import LooResult
from workstation.fingerprints.standby import JOIN_M
from workstation.pipeline.confidence import ALTERNATIVE_START_M
from workstation.walks.correction import MOVED_M


def _ratio(a: float, b: float) -> str:
    return f"{a / b:.2f}×" if b and np.isfinite(a) and np.isfinite(b) else "–"


def walks_markdown(res: LooResult, title: str) -> list[str]:
    """The leave-one-walk-out section (``evaluate --walks`` and the museum section), its parts
    in order."""
    L = [
        (
            f"## {title}: {len(res.walks)} walks, every {res.queries_every}-th by name localized "
            "on the radio map of the rest"
            if res.queries_every > 1
            else f"## {title}: {len(res.walks)} walks, each localized on the radio map of the others"
        ),
        "",
        "Default parameters unless a parameter file was given; start: "
        + (
            "inferred (walks that stood at one place decide it together)"
            if res.start == "infer"
            else res.start
        )  # fmt: skip
        + "; "
        f"ε_S = {res.threshold:g}; τ = {res.tau_dbm:g} dBm; device offsets "
        f"{'estimated and removed (the walks are of several phone models)' if res.align_devices else 'not corrected (the walks are of one phone model, or alignment is off)'}. Errors pooled over "
        "every query scan; a wrong floor counts 15 m per floor in the penalised mean and the "
        "EvAAL score (75th percentile).",
        "",
        *[f"{note[0].upper()}{note[1:]}." for note in res.notes],
        *([""] if res.notes else []),
        "| radio map | RPs per map | placed, mean / median (m) | floor accuracy | mean, floor "
        "right (m) | p75, floor right (m) | mean with floor penalty (m) | covered queries, with "
        "floor penalty (m) | EvAAL p75 (m) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for kind, r in res.loo.items():
        e = r.error_floor_right
        pl = res.placement_by_kind.get(kind) or {}
        if not r.queries:
            L.append(f"| {r.label} | 0 | no map: no walk gave it a reference point |||||||")
            continue
        L.append(
            f"| {r.label} | {r.reference_points_per_map:g} | {pl.get('mean_m', '–')} / "
            f"{pl.get('median_m', '–')} | {r.floor_accuracy} | "
            f"{e.get('mean_m', '–')} | {e.get('p75_m', '–')} | {r.mean_with_floor_penalty_m} | "
            f"{r.covered_mean_with_floor_penalty_m} | {r.evaal_p75_m} |"
        )
    L += matchers_markdown(res)
    L += built_kinds_markdown(res)
    for part in (_quarantined, _second_pass, _against_baselines, _placed, _trust, _sigma,
                 _per_walk):  # fmt: skip
        L += part(res)
    return L


def _trust(res: LooResult) -> list[str]:
    return ["", *trust_lines(res)]


def _quarantined(res: LooResult) -> list[str]:
    """The walks kept out of our maps, and any with a wrong start in them."""
    L: list[str] = []
    held = {n: w.quarantine for n, w in res.per_walk.items() if w.quarantine}
    L += [
        "",
        f"Walks quarantined — kept out of our maps (both kinds) until a surveyor fixes them: "
        f"{res.walks_quarantined} of {len(res.walks)}"
        + (
            " ("
            + ", ".join(
                f"{why}: {sum(why in v for v in held.values())}"
                for why in sorted({r for v in held.values() for r in v})
            )
            + ")"
            if held
            else ""
        )
        + f". Walks with a wrong start whose points are in our maps: {res.wrong_start_in_map} "
        f"(another floor, or more than {ALTERNATIVE_START_M:g} m from the first fix: the start "
        "inference's own measure of another place)"
        + (
            "; with a start landmark other than the first fix's, nearer than that: "
            + ", ".join(
                f"{n} ({res.per_walk[n].start}, {res.per_walk[n].start_off_m} m off)"
                for n in res.other_start_landmark_in_map
            )
            if res.other_start_landmark_in_map
            else ""
        )
        + ".",
    ]
    return L


def _second_pass(res: LooResult) -> list[str]:
    """What the map of the other walks changed in the walks' second runs."""
    L: list[str] = []
    compared = [c for w in res.per_walk.values() if (c := w.summary.chain_by_map) is not None]
    if compared:  # the second pass (pipeline/map_prior.py)
        L += [
            "",
            f"Each walk ran twice, the second time with the map of the other walks' first runs "
            f"weighing in on its chain of matches: on {sum(bool(c.rank) for c in compared)} "
            f"of the {len(compared)} walks with chains to compare the map chose another chain "
            "than the sensors' best (marked below).",
        ]
        fits = [f for w in res.per_walk.values() if (f := w.summary.open_by_map) is not None]
        moved = [f for f in fits if f.turn_deg or f.scale != 1.0]
        if fits:  # pipeline/open_by_map.py
            L[-1] += (
                f" Of the {len(fits)} walks that matched nothing after their start, the map "
                f"turned and scaled {len(moved)} about their start"
                + (f" (median turn {np.median([abs(f.turn_deg) for f in moved]):.0f}°)"
                   if moved else "") + "."
            )  # fmt: skip
    return L


def _against_baselines(res: LooResult) -> list[str]:
    """Our map against the baselines' (all walks, the walks it holds, the covered queries)."""
    L: list[str] = []
    ours, tap, pdr_ = res.loo["ours"], res.loo["tap_oracle"], res.loo["pdr_i"]
    unf = res.loo["ours_unfiltered"]
    pen = "mean_with_floor_penalty_m"
    made = [r for r in res.loo.values() if r.queries]
    best = min(made, key=lambda r: getattr(r, pen)) if made else None
    L += [
        "",
        f"With the floor penalty our map's mean error is {_ratio(getattr(ours, pen), getattr(tap, pen))} "
        f"the tap oracle's, {_ratio(getattr(ours, pen), getattr(pdr_, pen))} plain PDR's and "
        f"{_ratio(getattr(ours, pen), getattr(unf, pen))} the unfiltered map's; the best map here is "
        f"{best.label}."
        if ours.queries and best is not None
        else "Our maps are empty: every walk was quarantined (see above), so nothing of ours "
        "was localized against.",
    ]
    tin, win = res.loo.get("tap_oracle_in_map"), res.loo.get("waypoint_pdr_in_map")
    if res.walks_quarantined and ours.queries and tin is not None and win is not None:
        L += [
            "",
            "On the walks our maps hold (the quarantined ones left out of the baselines' maps "
            f"too), with the floor penalty: ours {getattr(ours, pen)} m, the tap oracle "
            f"{getattr(tin, pen)} m, the waypoint-anchored PDR {getattr(win, pen)} m. The rest of "
            "the gap to the baselines built from every walk is what the quarantined walks cover: "
            "it closes by getting them matched, or by a surveyor fixing them, not by placing "
            "scans better.",
        ]
    cq = ours.covered_queries
    if cq and cq < ours.queries:
        L += [
            "",
            f"Covered queries (another walk passed within 5 m on the same floor): {cq} of "
            f"{ours.queries}; no map built from the others can place the rest. On them, with the "
            "floor penalty: "
            + ", ".join(
                f"{r.label} {r.covered_mean_with_floor_penalty_m} m (floor {r.covered_floor_accuracy})"
                for r in res.loo.values()
            )
            + ".",
        ]
    return L


def _placed(res: LooResult) -> list[str]:
    """Where the reference points lie against the truth, by how they were placed."""
    L: list[str] = []
    pa = res.placement
    acc, at, fill = pa["accepted"], pa["at_landmark"], pa["gap_fill"]
    tru, rej = pa["trusted_segments"], pa["untrusted_closed"]
    if acc.get("n") and rej.get("n") and tru.get("n"):
        ratio = tru["mean_m"] / rej["mean_m"] if rej["mean_m"] else float("nan")
        verdict = (
            "belief separates well placed points from badly placed ones"
            if ratio <= 0.6
            else "belief separates them only weakly"
            if ratio < 0.9
            else "belief does not separate them on these walks"
        )
        L += [
            "",
            f"Reference points against the ground truth interpolated in time: {acc['n']} accepted, "
            f"placed {acc['mean_m']} m mean (p90 {acc['p90_m']}). Scans of segments belief trusts: "
            f"{tru['n']} at {tru['mean_m']} m; of untrusted closed segments: {rej['n']} at "
            f"{rej['mean_m']} m (p90 {rej['p90_m']}): {verdict} (ratio {ratio:.2f}). Of the "
            f"accepted, {at.get('n', 0)} were taken standing at a matched landmark and placed on "
            f"it ({at.get('mean_m', '–')} m) and {fill.get('n', 0)} fill gaps the trusted ones "
            f"left ({fill.get('mean_m', '–')} m).",
        ]
        sb = pa.get("standby_joined") or {}
        if sb.get("n"):
            L[-1] += (f" Held back for their σ, {sb['n']} scans on standby joined the map"
                      + (f" where no reference point of it lay within {JOIN_M:g} m" if JOIN_M > 0
                         else "") + f" ({sb['mean_m']} m).")  # fmt: skip
    return L


def _sigma(res: LooResult) -> list[str]:
    """How well σ predicts the placement error; the device offsets of the query walks."""
    L: list[str] = []
    sc = res.sigma_check
    if sc is not None and sc.scans is not None:
        if sc.map_points is not None and sc.map_points.scans:
            L += ["", sc.map_points.words() + "."]
        L += [
            "",
            f"Placement uncertainty σ (pipeline/sigma.py) against the true placement error, "
            f"{sc.scans.scans} scans on our trajectories: rank correlation "
            f"{sc.scans.rank_correlation}."
            + (f" {sc.held_out.words()}." if sc.held_out else ""),
            "",
            "| σ (m) | scans | mean error (m) | median error (m) |",
            "|---|---|---|---|",
            *(f"| {b.sigma_m} | {b.scans} | {b.mean_error_m} | {b.median_error_m} |"
              for b in sc.scans.bins),
        ]  # fmt: skip
    ours = res.loo["ours"]
    offs = [v for v in ours.query_device_offsets_db.values() if v is not None]
    if offs and res.align_devices:
        L += [
            "",
            f"Device offsets estimated for the query walks: {min(offs):+.1f} to {max(offs):+.1f} dB.",
        ]
    return L


def _per_walk(res: LooResult) -> list[str]:
    """The tracking figures pooled, then a row per walk."""
    L: list[str] = []
    t = res.tracking
    L += [
        "",
        "Tracking, pooled over the ground-truth fixes: "
        + ", ".join(f"{k} {v}" for k, v in t.items() if k != "walks")
        + ". (landmark_fix_match_rate: of the fixes on a landmark with a detection rule, the "
        "share where that landmark was matched while the walker stood on it — within ±3 s of "
        "the visit, a walk's final stop left out; _strict: within ±3 s of the fix itself; "
        "passed_straight: of those fixes, the ones on a landmark whose only rule is a turn where "
        "the tapped walk went straight on — no detector can fire there; _turned: the rate over "
        "the others. The strict figure counts them all.)",
        "",
        "| walk | start | node acc. | fix match (strict) | floor acc. | fix error (m) | RPs of scans "
        "| RP error (m) | scans not used, why | device offset (dB) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name, w in res.per_walk.items():
        start = w.start + ("" if w.start_right else " (wrong)")
        if w.start_shared_with:
            start += f" (decided with {w.start_shared_with})"
        h = w.start_after
        if h:  # searched within reach of where the walk before ended
            start += f" (within {h.reach_m:g} m of where {h.walk_before} ended)"
        if w.quarantine:
            start += " — quarantined: " + ", ".join(w.quarantine)
        by_map = w.summary.chain_by_map
        if by_map is not None and by_map.rank:  # the map chose another chain (map_prior.py)
            start += f" (the map chose the sensors' chain {by_map.rank + 1} of {by_map.chains})"
        f = w.figures
        L.append(
            f"| {name} | {start} | {f['landmark_node_accuracy']} | "
            f"{f['landmark_fix_match_rate']} ({f.get('landmark_fix_match_rate_strict')}) | "
            f"{f['floor_accuracy']} | {f['fix_error_mean_m']} | "
            f"{f['reference_points']} of {f.get('scans', '–')} | "
            f"{f['reference_point_error_mean_m']} | "
            + ("; ".join(f"{n} {why}" for why, n in w.summary.scans_not_points.items()) or "–")
            + f" | {w.device_offset_db} |"
        )
    return L


def inferred_start_markdown(res: LooResult) -> list[str]:
    """The same walks with every start inferred: each walk alone, then together."""
    t, alone = res.tracking, res.tracking_each_walk_alone or {}
    keys = ("landmark_node_accuracy", "landmark_fix_match_rate", "floor_accuracy",
            "fix_error_mean_m")  # fmt: skip
    shared = {w: v.start_shared_with for w, v in res.per_walk.items() if v.start_shared_with}
    L = [
        "### The same walks, every start inferred",
        "",
        "| starts | " + " | ".join(keys) + " |",
        "|---|" + "---|" * len(keys),
        "| each walk alone | " + " | ".join(str(alone.get(k, "–")) for k in keys) + " |",
        "| the walks helping each other (stood together; one after another) | "
        + " | ".join(str(t.get(k, "–")) for k in keys)
        + " |",
        "",
    ]
    if shared:
        L.append("Decided together: " + "; ".join(
            f"{w} → {res.per_walk[w].start} (with {o})" for w, o in shared.items()) + ".")  # fmt: skip
    else:
        L.append("No walks stood together with an ambiguous start: each keeps its own.")
    after = {w: v.start_after for w, v in res.per_walk.items() if v.start_after}
    if after:
        L.append("")
        L.append("Searched within reach of where the walk recorded just before ended "
                 "(walks/chain.py): " + "; ".join(
                     f"{w} → {res.per_walk[w].start} (after {h.walk_before}, "
                     f"{h.gap_s:g} s, {h.reach_m:g} m)" for w, h in after.items()) + ".")  # fmt: skip
    return L


def trust_lines(res: LooResult) -> list[str]:
    """What the walks' verdicts were worth against their own tapped truth (issue #49): walks in
    our map whose points lie more than 5 m off on average, walks kept out though placed within
    2 m, why walks were kept out, what the walks' joint placement did (walks/joint.py), and the
    queries with a point of the map within 5 m (ours against every row kept)."""
    v = res.verdicts
    if v is None:
        return []
    wrong, good = v.in_map_placed_over_5m, v.held_placed_within_2m
    out = [
        f"verdicts against the truth: {v.in_map} walks in our map, {len(wrong)} of them placed "
        f"more than 5 m off" + (f" ({', '.join(wrong)})" if wrong else "") + f"; {v.held} kept "
        f"out ({', '.join(f'{k} {n}' for k, n in v.held_by_reason.items()) or 'none'}), "
        f"{len(good)} of them placed within 2 m" + (f" ({', '.join(good)})" if good else ""),
    ]
    return out + _joint_lines(res) + _near_lines(res)


def _joint_lines(res: LooResult) -> list[str]:
    """What the walks' joint placement did (walks/joint.py), and whom it could not reconcile
    (its figures as results.json rounds them)."""
    out = []
    joint = [w.joint for w in res.per_walk.values() if w.joint is not None]
    moved = sorted((d for d in joint if round(d.shift_max_m, 2) >= MOVED_M),
                   key=lambda d: -round(d.shift_max_m, 2))  # fmt: skip
    if joint:
        out.append(f"the walks placed together (walks/joint.py): {len(moved)} of {len(joint)} moved "
                   f"by {MOVED_M:g} m or more" + (f" (most: {moved[0].name}, {round(moved[0].shift_max_m, 2):g} m "
                   f"along {moved[0].where})" if moved else ""))  # fmt: skip
    for d in (d for d in joint if d.unreconciled):
        out.append(f"the other walks cannot reconcile {d.name}: {round(d.disagree_m, 2):g} m over "
                   f"{d.links} links, {100 * round(d.agree, 3):.0f} % agreeing — "
                   + ("kept (others do not cover it)" if d.fate == "kept" else d.fate)
                   + (f"; its doubt rests on {d.only_against} alone, in doubt too: look at both"
                      if d.only_against else ""))  # fmt: skip
    return out


def _near_lines(res: LooResult) -> list[str]:
    """The queries with a point of the map within 5 m, ours against every row kept."""
    out = []
    o, u = (res.loo[k].near_map if k in res.loo else None for k in ("ours", "ours_unfiltered"))
    if o is not None and u is not None and np.isfinite([o, u]).all():
        out.append(f"queries with a point of the map within 5 m: ours {100 * o:.1f} %, every row "
                   f"kept {100 * u:.1f} % (what the σ cut and the walks kept out cost in "
                   "coverage)")  # fmt: skip
    return out
