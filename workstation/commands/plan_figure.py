"""The planned route drawn per floor over the building's plan: ``plan_floor_<f>.png``, each leg
an arrow in the route colour, numbered walk.leg (thinned to every few legs on long routes),
each walk's start a ring."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from workstation.building import Building
from workstation.commands.quality import draw_plan
from workstation.io.atomic import save_figure
from workstation.survey_plan.output import floor_legs, plan_legs
from workstation.viz.colours import rgb

PAD_M = 5.0  # around the floor's landmarks
LABELS_PER_FLOOR = 60  # at most this many leg numbers on one floor's figure


def draw_plan_floors(plan, graph, building_path: Path, out: Path) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt


    building = Building.load(building_path)
    colour = np.array(rgb("planned_route")) / 255
    edge_c = np.array(rgb("graph_edges")) / 255
    paths = []
    for f in graph.floors:
        legs = [(w, i, leg) for w in plan.walks for i, leg in enumerate(w.legs, 1)
                if leg.floor_from == f and leg.floor_to == f]  # fmt: skip
        starts = [w for w in plan.walks if graph.node(w.start).floor == f]
        if not legs and not starts:
            continue
        fig, ax = plt.subplots(figsize=(10, 8))
        img = building.image(f)
        if img is not None:
            draw_plan(ax, *img.display(1600))
        for u, v in graph.undirected_pairs():
            a, b = graph.node(u), graph.node(v)
            if a.floor == f == b.floor:
                ax.plot([a.x, b.x], [a.y, b.y], color=edge_c, lw=0.8, zorder=1)
        for _w, _i, leg in legs:
            a, b = graph.node(leg.frm), graph.node(leg.to)
            ax.annotate(
                "", xy=(b.x, b.y), xytext=(a.x, a.y), zorder=3,
                arrowprops={"arrowstyle": "-|>", "color": colour, "lw": 1.6, "shrinkA": 0, "shrinkB": 0},
            )  # fmt: skip
        labelled = floor_legs(plan_legs(plan), graph, f)  # an edge walked twice: "1.2, 1.9"
        every = max(1, int(np.ceil(len(labelled) / LABELS_PER_FLOOR)))
        for label, u, v in labelled[::every]:
            a, b = graph.node(u), graph.node(v)
            ax.text((a.x + b.x) / 2, (a.y + b.y) / 2, label, fontsize=7,
                    color=colour, zorder=4, ha="center", va="center",
                    bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.8})  # fmt: skip
        for w in starts:
            n = graph.node(w.start)
            ax.scatter([n.x], [n.y], s=160, facecolors="none", edgecolors=[tuple(colour)], lw=2, zorder=5)
            ax.text(n.x, n.y, f"  walk {w.index} starts", color=colour, fontsize=8, zorder=5)
        xy = np.array([[n.x, n.y] for n in graph.nodes if n.floor == f])
        lo, hi = xy.min(axis=0) - PAD_M, xy.max(axis=0) + PAD_M
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])  # north up, whatever the image's rows
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        n_w = len({w.index for w, _, _ in legs})
        ax.set_title(f"floor {f:g}: {len(legs)} legs of {n_w} walk(s)" +
                     (f" (numbers on every {every}th)" if every > 1 else ""))  # fmt: skip
        p = out / f"plan_floor_{f:g}.png"
        save_figure(fig, p, dpi=110, bbox_inches="tight")  # whole or not at all
        plt.close(fig)
        paths.append(p)
    return paths
