"""A survey plan as files: ``plan.json`` (everything), ``plan.md`` (a checklist to follow on a
phone) and ``plan.geojson`` (the legs as lines: lon/lat when the graph has a geographic frame,
else the graph's local metres, as the radio-map export)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from workstation.errors import InputError
from workstation.graph import LandmarkGraph
from workstation.io.atomic import atomic_write_text
from workstation.survey_plan.plan import SurveyPlan, Walk


def _r(v: float, n: int = 1) -> float:
    return round(float(v), n)


def walk_dict(w: Walk, plan: SurveyPlan) -> dict[str, Any]:
    return {
        "walk": w.index,
        "start": w.start,
        "end": w.end,
        "duration_s": _r(w.duration_s),
        "distance_m": _r(w.distance_m),
        "scans": w.scans(plan.pace),
        "floors": sorted({leg.floor_from for leg in w.legs} | {leg.floor_to for leg in w.legs}),
        "legs": [
            {
                "from": leg.frm,
                "to": leg.to,
                "kind": leg.kind,
                "length_m": _r(leg.length_m),
                "seconds": _r(leg.seconds),
                "floor_from": leg.floor_from,
                "floor_to": leg.floor_to,
                "at_arrival": v.action,
                "turn_deg": None if v.turn_deg is None else _r(v.turn_deg),
                "stop_s": _r(v.stop_s),
                "seen": v.seen,
            }
            for leg, v in zip(w.legs, w.visits[1:])
        ],  # fmt: skip
        "unseen_landmarks": [v.node for v in w.visits[1:-1] if not v.seen and v.node],
    }


def totals(plan: SurveyPlan) -> dict[str, Any]:
    ws = plan.walks
    return {
        "walks": len(ws),
        "duration_s": _r(sum(w.duration_s for w in ws)),
        "distance_m": _r(sum(w.distance_m for w in ws)),
        "scans": sum(w.scans(plan.pace) for w in ws),
        "required_edges": len(plan.required),
        "route_walking_s": _r(plan.route_s),
        "lower_bound_s": None if plan.bound_s != plan.bound_s else _r(plan.bound_s),
        "connectors": [f"{u}-{v}" for r in plan.routes for u, v in r.connectors],
        "pieces": len(plan.routes),
    }


def plan_dict(plan: SurveyPlan, graph: LandmarkGraph, max_minutes: float | None) -> dict:
    return {
        "kind": "re-walk" if plan.rewalk else "survey",
        "graph": graph.source,
        "max_minutes": max_minutes,
        "pace": plan.pace.to_dict(),
        "totals": totals(plan),
        "required_edges": [f"{u}-{v}" for u, v in plan.required],
        "walks": [walk_dict(w, plan) for w in plan.walks],
    }


def _mmss(s: float) -> str:
    s = int(round(s))
    return f"{s // 60}:{s % 60:02d}"


def plan_markdown(plan: SurveyPlan, graph: LandmarkGraph, max_minutes: float | None) -> str:
    t = totals(plan)
    what = "Re-walk of the thin edges" if plan.rewalk else "Survey walk"
    lines = [
        f"# {what}: {t['walks']} walk(s), {_mmss(t['duration_s'])} min, {t['distance_m']:.0f} m",
        "",
        f"Graph: {graph.source or '(unsaved)'} · {t['required_edges']} edges to walk · "
        f"about {t['scans']} scans · pace: {plan.pace.speed_mps:.2f} m/s walking, "
        f"standing {plan.pace.still_share:.0%} of the time ({plan.pace.source})"
        + (f" · walks of at most {max_minutes:g} min" if max_minutes else ""),
        "",
    ]
    if t["pieces"] > 1:
        lines += [f"The graph is in {t['pieces']} pieces no edge joins: get to each walk's "
                  "start as you like; only the walks are recorded.", ""]  # fmt: skip
    for w in plan.walks:
        d = walk_dict(w, plan)
        fl = ", ".join(f"{f:g}" for f in d["floors"])
        lines += [
            f"## Walk {w.index}: {w.start} → {w.end} · {_mmss(w.duration_s)} min · "
            f"{w.distance_m:.0f} m · floor {fl}",
            "",
            f"- [ ] at {w.start}: {w.visits[0].action}"
            + (f" (workstation run … --start {w.start})" if w.visits[0].seen else ""),
        ]
        for leg, v in zip(w.legs, w.visits[1:]):
            how = "" if leg.kind == "level" else f" by {leg.kind}"
            lines.append(
                f"- [ ] {leg.frm} → {leg.to}{how}, {leg.length_m:.0f} m: at {leg.to} {v.action}"
            )
        if d["unseen_landmarks"]:
            lines.append(
                f"\n{len(d['unseen_landmarks'])} landmark(s) with a rule are passed without "
                "anything their rule sees (a straight pass of a turn): they are no anchor on "
                "this walk."
            )
        lines.append("")
    return "\n".join(lines)


def plan_geojson(plan: SurveyPlan, graph: LandmarkGraph) -> dict:
    feats = []
    for w in plan.walks:
        for i, leg in enumerate(w.legs, 1):
            a, b = graph.node(leg.frm), graph.node(leg.to)
            xs, ys = [a.x, b.x], [a.y, b.y]
            if graph.frame is not None:
                lat, lon = graph.frame.to_latlon(xs, ys)
                coords = [[float(lon[k]), float(lat[k])] for k in range(2)]
            else:
                coords = [[float(xs[k]), float(ys[k])] for k in range(2)]
            feats.append(
                {
                    "type": "Feature",
                    "geometry": {"type": "LineString", "coordinates": coords},
                    "properties": {
                        "walk": w.index,
                        "leg": i,
                        "from": leg.frm,
                        "to": leg.to,
                        "kind": leg.kind,
                        "floor_from": leg.floor_from,
                        "floor_to": leg.floor_to,
                        "length_m": _r(leg.length_m),
                    },  # fmt: skip
                }
            )
    out: dict[str, Any] = {"type": "FeatureCollection", "features": feats}
    if graph.frame is None:
        out["coordinates_note"] = (
            "local metres (x east, y north) of the landmark graph; no geographic frame"
        )
    return out


def write_plan(
    plan: SurveyPlan, graph: LandmarkGraph, out: Path, max_minutes: float | None = None
) -> list[Path]:
    """``plan.json``, ``plan.md`` and ``plan.geojson`` in ``out``, each written atomically with
    the previous one kept as a backup."""
    out.mkdir(parents=True, exist_ok=True)
    files = {
        "plan.json": json.dumps(plan_dict(plan, graph, max_minutes), indent=1),
        "plan.md": plan_markdown(plan, graph, max_minutes),
        "plan.geojson": json.dumps(plan_geojson(plan, graph)),
    }
    paths = []
    for name, text in files.items():
        atomic_write_text(out / name, text, backup=True)
        paths.append(out / name)
    return paths


def plan_legs(plan: SurveyPlan) -> list[tuple[str, str, str]]:
    """(walk.leg label, from, to) of every leg, in walking order."""
    return [
        (f"{w.index}.{i}", leg.frm, leg.to) for w in plan.walks for i, leg in enumerate(w.legs, 1)
    ]


def floor_legs(legs, graph: LandmarkGraph, floor: float) -> list[tuple[str, str, str]]:
    """Of ``legs`` ((walk.leg, from, to) in walking order), those on ``floor``, one per edge:
    an edge walked more than once carries all its numbers ("1.21, 1.32"), drawn once."""
    out: dict[frozenset, tuple[list[str], str, str]] = {}
    for label, u, v in legs:
        if graph.node(u).floor == floor == graph.node(v).floor:
            out.setdefault(frozenset((u, v)), ([], u, v))[0].append(label)
    return [(", ".join(labels), u, v) for labels, u, v in out.values()]


def read_plan_walks(path: Path, graph: LandmarkGraph | None = None) -> dict[int, list[str]]:
    """A ``plan.json``'s walks as landmark ids in walking order, by walk number; with ``graph``,
    every landmark must be in it."""
    try:
        walks = json.loads(Path(path).read_text(encoding="utf-8"))["walks"]
        out = {int(w["walk"]): [w["legs"][0]["from"], *(leg["to"] for leg in w["legs"])]
               for w in walks}  # fmt: skip
    except (OSError, ValueError, KeyError, TypeError, IndexError) as e:
        raise InputError(path, f"not a plan.json ({type(e).__name__}: {e})") from None
    if graph is not None:
        for n, ids in out.items():
            bad = [i for i in ids if i not in graph.ids]
            if bad:
                raise InputError(path, f"walk {n}: landmark {bad[0]} is not in the graph")
    return out
