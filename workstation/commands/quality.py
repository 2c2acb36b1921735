"""``workstation quality``: where the radio map is thin — per-AP heatmaps, coverage, predicted
error and the edges to walk next, as PNGs over the floor plan and ``quality.json``."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

from workstation.io.atomic import save_figure
from workstation.io.store import output_path, path_or_url, write_via_local

if TYPE_CHECKING:
    import numpy as np

PAD_M = 3.0  # around the reference points and the quality grid


def _layers(q) -> list[tuple]:
    """A floor's maps to draw: (file name, grid, label, colour scale) — coverage, predicted
    error, then each AP asked for."""
    from workstation.io.atomic import safe_name

    layers = [("coverage", q.coverage_m, "distance to the nearest reference point (m)", "coverage"),
              ("predicted_error", q.predicted_error_m, "predicted 1-NN error (m), indicative", "predicted_error")]  # fmt: skip
    rss = q.rss if q.rss is not None else ()  # fields only where APs were asked for
    for b, field in zip(q.bssids, rss):
        name = safe_name(str(b).replace(":", ""))  # a column name of the CSV: data
        layers.append((f"ap_{name}", field, f"RSS of {b} (dBm)", "rss"))
    return layers


def _draw(args, fp, graph, building, f: float, q, name: str, z, label: str, scale: str) -> None:
    """One map of a floor as ``floor_F_NAME.png`` over its plan, the reference points and the
    edges to walk next on it, framed on the map (not the whole plan)."""
    import matplotlib
    import numpy as np

    from workstation.viz.colours import SCALES, colour_name, rgb

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    xs, ys = q.centres()
    ext = (float(xs[0] - q.cell_m / 2), float(xs[-1] + q.cell_m / 2),
           float(ys[0] - q.cell_m / 2), float(ys[-1] + q.cell_m / 2))  # fmt: skip
    lo, hi, cmap = SCALES[scale]  # one scale on every floor (viz/colours.py)
    fig, ax = plt.subplots(figsize=(8, 6))
    img = building.image(f) if building else None
    if img is not None:
        draw_plan(ax, *img.display(1200))
    im = ax.imshow(np.ma.masked_invalid(z), origin="lower", extent=ext, cmap=cmap,
                   alpha=0.8, vmin=lo, vmax=hi)  # fmt: skip
    fp_on = fp.floor == f
    kind = getattr(fp, "kind", "points") or "points"  # an interpolated map's points are virtual
    ax.scatter(fp.x[fp_on], fp.y[fp_on], s=4, c="k", alpha=0.5,
               label="reference points" + ("" if kind == "points" else f" ({kind} map)"))  # fmt: skip
    ax.legend(loc="upper right", fontsize=8, framealpha=0.8)  # the black dots, named
    if graph is not None:
        next_colour = np.asarray(rgb("walk_here_next")) / 255.0
        for u, v in q.thin_edges:
            a_, b_ = graph.node(u), graph.node(v)
            ax.plot([a_.x, b_.x], [a_.y, b_.y], "-", lw=3, alpha=0.9, color=next_colour)
    fig.colorbar(im, ax=ax, label=label, extend="both" if scale == "rss" else "max")
    ax.set_title(f"floor {f:g}: {label}" + (f" — {colour_name(rgb('walk_here_next'))}: walk here "
                 "next" if q.thin_edges else ""))  # fmt: skip
    xs_, ys_ = np.append(fp.x[fp_on], ext[:2]), np.append(fp.y[fp_on], ext[2:])
    ax.set_xlim(xs_.min() - PAD_M, xs_.max() + PAD_M)  # the map, not the whole plan
    ax.set_ylim(ys_.min() - PAD_M, ys_.max() + PAD_M)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    fig.tight_layout()
    save_figure(fig, args.out / f"floor_{f:g}_{name}.png", dpi=100)
    plt.close(fig)


def _floor_words(f: float, s: dict, against: str) -> str:
    """What the surveyor reads of a floor: its coverage and the edges to walk again."""
    if against != "graph":  # a buffer round the points covers itself: no share (issue #64 item 6)
        return (f"floor {f:g}: no graph edges here — the maps are drawn round the points "
                f"themselves ({s['walkable_m2']:.0f} m²), so no coverage share is given; "
                "--graph GRAPH.yaml measures it against the corridors")  # fmt: skip
    edges = s["edges_to_rewalk"]
    more = f" … (all {len(edges)} in quality.json)" if len(edges) > 8 else ""
    return (f"floor {f:g}: {100 * s['coverage_share']:.0f} % of the graph's corridors "
            f"({s['walkable_m2']:.0f} m²) within 3 m of a reference point; {len(edges)} "
            f"edge(s) to walk again: {', '.join(edges[:8]) or 'none'}{more}")  # fmt: skip


def draw_plan(ax, rgb: np.ndarray, t: np.ndarray):
    """The plan image on ``ax`` in metres by its whole pixel → metres affine ``t`` (rotation
    and shear too: with only the diagonal, the museum's rotated floor −1 plan was drawn ~40 m
    from the walk)."""
    import numpy as np
    from matplotlib.transforms import Affine2D

    h, w = rgb.shape[:2]
    to_m = Affine2D(np.vstack([np.asarray(t, float)[:2], [0.0, 0.0, 1.0]]))
    return ax.imshow(rgb, extent=[0, w, h, 0], alpha=0.6, transform=to_m + ax.transData)


def add_parser(sub) -> None:
    q = sub.add_parser(
        "quality",
        help="radio-map quality: per-AP heatmaps, coverage, predicted error, edges to re-walk",
    )
    q.add_argument("--map", type=path_or_url, action="append", required=True,
                   help="radio map: a file, a campaign's radiomap/building=NAME, or a URL (repeat)")  # fmt: skip
    q.add_argument("--graph", type=Path, help="landmark graph (clips the maps to its corridors)")
    q.add_argument("--building", type=Path, help="building file: plan images under the maps")
    q.add_argument("--aps", type=int, default=10, help="heatmaps for this many strongest APs")
    q.add_argument("--out", type=output_path, required=True,
                   help="a folder here, or a store's URL (s3://…)")  # fmt: skip
    q.add_argument(
        "--densify", type=output_path, metavar="MAP.csv",
        help="also write a densified radio map (an interpolated fingerprint every 2 m near the "
        "reference points); measured not to help 1-NN here (docs/decisions.md)",
    )  # fmt: skip
    q.add_argument(
        "--include-quarantined",
        action="store_true",
        help="use maps of quarantined walks too (refused by default)",
    )
    q.add_argument(
        "--force", action="store_true",
        help="draw even a map that lies outside the building's plans or graph",
    )  # fmt: skip
    q.set_defaults(func=_run)


def _run(args) -> int:
    """The quality report into ``--out`` — in a store, made here first and put there
    (io/store.write_via_local), said with the URL."""
    from argparse import Namespace

    def at(out: Path) -> int:
        return _report(Namespace(**{**vars(args), "out": out, "shown": args.out}))

    return write_via_local(args.out, at)


def _report(args) -> int:
    from dataclasses import replace

    from workstation.building import Building
    from workstation.building.consistency import plan_mismatches, refuse
    from workstation.commands.radiomap import read_maps
    from workstation.fingerprints.localize import Fingerprints
    from workstation.fingerprints.quality import densify, quality
    from workstation.graph import LandmarkGraph
    from workstation.io.atomic import atomic_write_text
    from workstation.progress import Progress

    maps = read_maps(args.map, args.include_quarantined)
    fp = maps[0].settled() if len(maps) == 1 else Fingerprints.merge(maps, align_devices=True)
    graph = LandmarkGraph.load(args.graph) if args.graph else None
    bpath = args.building
    if bpath is None and args.graph and (Path(args.graph).parent / "building.yaml").is_file():
        bpath = Path(args.graph).parent / "building.yaml"  # beside the graph, as edit and view
        print(f"plans from {bpath} (beside the graph)")
    building = Building.load(bpath) if bpath else None
    what = ", ".join(str(p) for p in (*args.map, args.graph, bpath) if p)
    refuse(what, plan_mismatches(fp, graph, building), args.force)
    args.out.mkdir(parents=True, exist_ok=True)
    qs = quality(fp, graph, n_aps=args.aps)
    floors: list[dict] = []
    report = {"reference_points": len(fp), "floors": floors}
    bar = Progress()  # a building's floors take a minute to draw (issue #50 item 9): said
    total = sum(2 + (len(q.bssids) if q.rss is not None else 0) for q in qs.values())
    drawn, said = 0, []
    for f, q in qs.items():
        for name, z, label, scale in _layers(q):
            _draw(args, fp, graph, building, f, q, name, z, label, scale)
            drawn += 1
            bar(drawn, total, f"floor_{f:g}_{name}.png", phase="drawing")
        s = q.summary()
        s["aps"] = [str(b) for b in q.bssids]
        floors.append(s)
        said.append(_floor_words(f, s, q.against))
    bar.close()
    print("\n".join(said))  # after the drawing's progress
    atomic_write_text(args.out / "quality.json", json.dumps(report, indent=1))
    if args.densify:
        from workstation.export import write_radiomap

        dense = replace(densify(fp, graph), kind="densified")
        write_via_local(args.densify, lambda p: write_radiomap(dense.to_frame(), p, fp.frame,
                                                               kind=dense.kind))  # fmt: skip
        print(
            f"wrote {args.densify}: {len(dense)} fingerprints ({len(dense) - len(fp)} interpolated)"
        )
    print(
        f"wrote {args.shown}/quality.json and PNGs per floor (coverage, predicted error, {args.aps} APs)"
    )
    return 0
