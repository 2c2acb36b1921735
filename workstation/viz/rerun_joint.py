"""The building's walks placed together (:mod:`workstation.walks.joint`) in Rerun: ``merge
--save FILE.rrd`` (or ``--connect URL``). An observer at the edge: it draws a
:class:`~workstation.walks.joint.JointResult` beside the maps as each walk's run placed them.

Entity paths, per floor and per walk (a walk can be shown alone in the viewer's tree):
``/map/<floor>/joint/<walk>/alone`` its points as its own run placed them, ``…/moved`` arrows
from there to where the walks placed together put them, ``…/together`` the points the merged
map holds (left-out walks in the quarantine colour), ``…/links`` its links to other walks'
scans (fainter where the robust weight is low). ``/joint/walks``: what the estimate did to
each walk, as a table."""

from __future__ import annotations

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from workstation.fingerprints.localize import Fingerprints
from workstation.viz.colours import rgb
from workstation.viz.layouts import APP_ID, floor_path
from workstation.viz.rerun_log import _xy  # map coordinates for display: north up
from workstation.walks.joint import JointResult

SHOWN_MOVE_M = 0.5  # arrows only for points moved at least this far


def _entity(name: str) -> str:
    """A walk's name as one entity-path part (a map's path has slashes)."""
    stem = name.rsplit("/", 2)
    short = stem[-2] if len(stem) >= 2 and stem[-1].startswith("radiomap") else stem[-1]
    return rr.escape_entity_path_part(short)


def log_joint(rec: rr.RecordingStream, before: dict[str, Fingerprints], res: JointResult) -> None:
    """Every walk's points before and after, its arrows and links, on each of its floors."""
    names = [n for n in res.maps if len(res.maps[n])]
    after = [res.maps[n] for n in names]
    x = np.concatenate([m.x for m in after]) if after else np.empty(0)
    y = np.concatenate([m.y for m in after]) if after else np.empty(0)
    start = np.concatenate([[0], np.cumsum([len(m) for m in after])]).astype(int)
    links = res.links
    ends = links[:, :2].astype(int) if len(links) else np.empty((0, 2), int)
    slate, khaki = rgb("placed_alone"), rgb("joint_links")
    for k, name in enumerate(names):
        a, b = before[name], res.maps[name]
        w = res.walks[name]
        ent = _entity(name)
        here = rgb("quarantined") if w.left_out else rgb("accepted")
        for f in np.unique(b.floor):
            on = b.floor == f
            root = f"/map/{floor_path(f)}/joint/{ent}"
            rec.log(f"{root}/alone", rr.Points2D(_xy(a.x[on], a.y[on]), colors=[slate],
                                                 radii=[0.25]), static=True)  # fmt: skip
            rec.log(f"{root}/together", rr.Points2D(_xy(b.x[on], b.y[on]), colors=[here],
                                                    radii=[0.35]), static=True)  # fmt: skip
            d = np.hypot(b.x - a.x, b.y - a.y)
            mv = on & (d >= SHOWN_MOVE_M)
            if mv.any():
                rec.log(f"{root}/moved", rr.Arrows2D(origins=_xy(a.x[mv], a.y[mv]),
                        vectors=_xy(b.x[mv] - a.x[mv], b.y[mv] - a.y[mv]), colors=[slate],
                        radii=[0.08]), static=True)  # fmt: skip
            mine = (ends[:, 0] >= start[k]) & (ends[:, 0] < start[k + 1])
            mine &= np.isin(ends[:, 0] - start[k], np.flatnonzero(on))
            if mine.any():
                i, j = ends[mine, 0], ends[mine, 1]
                strips = np.stack([_xy(x[i], y[i]), _xy(x[j], y[j])], axis=1)
                alpha = (40 + 200 * np.clip(links[mine, 2], 0, 1)).astype(np.uint8)
                cols = np.tile(np.array(khaki[:3], np.uint8), (alpha.size, 1))
                rec.log(f"{root}/links", rr.LineStrips2D(strips, radii=[0.04],
                        colors=np.column_stack([cols, alpha])), static=True)  # fmt: skip
    rec.log("/joint/walks", rr.TextDocument(table_markdown(res), media_type=rr.MediaType.MARKDOWN),
            static=True)  # fmt: skip


def table_markdown(res: JointResult) -> str:
    """What the estimate did to each walk, the most moved first."""
    rows = sorted(res.walks.values(), key=lambda w: (not w.unreconciled, -w.shift_max_m))
    out = ["# The walks placed together", "",
           "| walk | verdict | moved, mean / max (m) | where | links | agreeing | covered |",
           "|---|---|---|---|---|---|---|"]  # fmt: skip
    for w in rows:
        fate = w.fate
        verdict = f"**{fate}**" if fate and fate != "kept" else "unreconciled, kept" if fate \
            else "in the map"
        if fate and w.only_against:
            verdict += f" (at odds with {_entity(w.only_against)} alone)"
        out.append(f"| {_entity(w.name)} | {verdict} | {w.shift_mean_m:.1f} / "
                   f"{w.shift_max_m:.1f} | {w.where} | {w.links} | {100 * w.agree:.0f} % | "
                   f"{100 * w.covered:.0f} % |")  # fmt: skip
    return "\n".join(out)


def blueprint(floors) -> rrb.Blueprint:
    """One tab per floor, the table beside."""
    views = [rrb.Spatial2DView(origin=f"/map/{floor_path(f)}", name=f"Floor {f:g}")
             for f in floors]  # fmt: skip
    return rrb.Blueprint(
        rrb.Horizontal(rrb.Tabs(*views), rrb.TextDocumentView(origin="/joint/walks",
                       name="Walks placed together"), column_shares=[3, 2]),  # fmt: skip
        rrb.TimePanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
    )


def save_or_send(before: dict[str, Fingerprints], res: JointResult, save=None, connect=None) -> None:
    """The recording written to ``save`` (.rrd) or streamed to the viewer at ``connect``."""
    rec = rr.RecordingStream(APP_ID)
    rec.set_log_time_enabled(False)
    floors = sorted({float(f) for m in res.maps.values() for f in np.unique(m.floor)})
    bp = blueprint(floors)
    if save is not None:
        rec.save(str(save), default_blueprint=bp)
    else:
        rec.connect_grpc(connect, default_blueprint=bp)
    log_joint(rec, before, res)
    rec.flush()
    if connect is not None:
        rec.disconnect()
