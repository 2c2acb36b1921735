"""The panel's survey-plan layer (issue #32): "Plan the walk" covers every level edge of the
graph as it is now; "Plan the re-walk" only the edges the current result's kept reference points
cover thinly (:func:`workstation.fingerprints.quality.thin_edges`). The route is drawn on the floor on view,
under the graph, each leg numbered walk.leg (at most ``LABELS`` numbers a floor: thinned on long
routes), and sent to the Rerun viewer when one is attached; "Save plan" writes plan.md,
plan.json and plan.geojson to the output folder."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from workstation.fingerprints.localize import Fingerprints
from workstation.fingerprints.quality import thin_edges
from workstation.survey_plan.output import floor_legs, plan_legs, totals, write_plan
from workstation.survey_plan.plan import plan_survey
from workstation.viz.colours import rgb

if TYPE_CHECKING:
    from workstation.graph import LandmarkGraph
    from workstation.survey_plan.plan import SurveyPlan
    from workstation.viz.panel_host import PanelHost

LABELS = 40  # leg numbers on one floor at most
ROUTE_PX = 5.0  # the route's width on screen, at any zoom


class PlanLayer:
    """Built by panel (:class:`~workstation.viz.panel_host.PanelHost`); draws into its scene."""

    def __init__(self, panel: PanelHost):
        self.p = panel
        self.plan: SurveyPlan | None = None
        self.graph: LandmarkGraph | None = None  # the graph the plan was made on
        self._labels: list = []
        gui = panel.server.gui
        with gui.add_folder("Survey plan", expand_by_default=False):
            self.minutes = gui.add_number("Walks of at most (min)", 10.0, min=0.5, max=600.0)
            walk = gui.add_button("Plan the walk", hint="every level edge of the graph")
            rewalk = gui.add_button(
                "Plan the re-walk", hint="the edges this walk's kept reference points cover thinly"
            )
            save = gui.add_button("Save plan", hint="plan.md, plan.json, plan.geojson")
            clear = gui.add_button("Clear plan")
            self.note = gui.add_markdown("")

        walk.on_click(lambda _e: self.p.guard(self.make, False))
        rewalk.on_click(lambda _e: self.p.guard(self.make, True))
        save.on_click(lambda _e: self.p.guard(self.save))
        clear.on_click(lambda _e: self.p.guard(self.clear))

    def make(self, rewalk: bool) -> None:
        ed = self.p.ed
        required = None
        if rewalk:
            fp = Fingerprints.of_walk(ed.result.radiomap, ed.graph.frame)
            required = list(thin_edges(fp, ed.graph))
        try:
            self.plan = plan_survey(ed.graph, None, required, None, float(self.minutes.value))
        except ValueError as e:
            raise ValueError(f"no plan: {e}") from None
        self.graph = ed.graph
        t = self._totals()
        what = "re-walk" if rewalk else "survey walk"
        ed.message = (
            f"planned the {what}: {t['walks']} walk(s), {t['duration_s'] / 60:.1f} min, "
            f"{t['distance_m']:.0f} m"
            if self.plan.walks
            else "nothing to re-walk: every edge is covered"
        )
        self._log_to_rerun()

    def _totals(self) -> dict:
        return totals(self.plan) if self.plan is not None else {}

    def save(self) -> None:
        if self.plan is None or self.graph is None:
            raise ValueError("plan the walk first")
        out = self.p.ed.out_dir
        write_plan(self.plan, self.graph, out, float(self.minutes.value))
        self.p.ed.message = f"wrote {out}/plan.md, plan.json, plan.geojson"

    def clear(self) -> None:
        self.plan = None
        self.p.ed.message = "plan cleared"
        self._log_to_rerun()

    def _log_to_rerun(self) -> None:
        legs: list = plan_legs(self.plan) if self.plan is not None else []
        for obs in getattr(self.p.ed.pipeline, "observers", []):
            if hasattr(obs, "log_route"):
                obs.log_route(legs, self.p.ed.graph if self.plan is None else self.graph)

    def legs_on(self, floor: float) -> list[tuple[str, np.ndarray]]:
        """(walk.leg labels, (2, 2) ends) of the plan's level legs on ``floor``, as planned,
        one per edge (:func:`~workstation.survey_plan.output.floor_legs`)."""
        if self.plan is None or self.graph is None:
            return []
        g = self.graph
        out = []
        for label, u, v in floor_legs(plan_legs(self.plan), g, floor):
            a, b = g.node(u), g.node(v)
            out.append((label, np.array([[a.x, a.y], [b.x, b.y]])))
        return out

    def draw(self) -> None:
        sc = self.p.server.scene
        for h in self._labels:
            h.remove()
        self._labels = []
        legs = self.legs_on(float(self.p.floor))
        if not legs:
            sc.add_line_segments("/route", np.zeros((1, 2, 3)), (0, 0, 0), visible=False)
            self.note.content = self._note()
            return
        ends = np.stack([e for _, e in legs])
        pts = np.concatenate([ends, np.full((len(legs), 2, 1), 0.03)], axis=2)
        # a leg's direction: a stroke from its last quarter back to one side, as an arrow barb
        d = ends[:, 1] - ends[:, 0]
        n = np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-9)[:, None]
        tip = ends[:, 0] + 0.75 * d
        side = tip - 0.6 * d / n + 0.5 * np.column_stack([-d[:, 1], d[:, 0]]) / n
        barb = np.stack([tip, side], axis=1)
        barb = np.concatenate([barb, np.full((len(legs), 2, 1), 0.03)], axis=2)
        sc.add_line_segments(
            "/route", np.concatenate([pts, barb]), rgb("planned_route"),
            thickness=ROUTE_PX, thickness_units="screen",
        )  # fmt: skip
        every = max(1, int(np.ceil(len(legs) / LABELS)))
        for k in range(0, len(legs), every):
            label, e = legs[k]
            mid = e.mean(axis=0)
            self._labels.append(
                sc.add_label(f"/route_labels/{k}", label, position=(mid[0], mid[1], 0.6))
            )
        self.note.content = self._note()

    def _note(self) -> str:
        if self.plan is None:
            return ""
        t = self._totals()
        lines = [
            f"{t['walks']} walk(s), {t['duration_s'] / 60:.1f} min, {t['distance_m']:.0f} m, "
            f"about {t['scans']} scans (numbers on the plan: walk.leg)"
        ]
        lines += [
            f"- walk {w.index}: {w.start} → {w.end}, {w.duration_s / 60:.1f} min"
            for w in self.plan.walks[:12]
        ]
        if self.graph is not self.p.ed.graph:
            lines.append("*planned before the last graph edit: plan again*")
        return "\n".join(lines)
