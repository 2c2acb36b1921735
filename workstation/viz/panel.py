"""The viser survey panel: a browser view over :class:`SurveyEditor`.

Scene (top-down, +z up): the floor plan of the selected floor, landmarks coloured by rule
(click to select, drag to move), edges (one-way edges carry an arrow head), the corrected
trajectory, ground truth, and accepted / rejected reference points. Panel: floor selector, the
selected landmark's name, floor, position and rules, add / delete / connect / disconnect /
undo, every parameter grouped like Table I, Re-run, Save and Export, a run summary and a status
line where refused edits are explained.
"""

from __future__ import annotations

import threading
from pathlib import Path
from typing import Any

import numpy as np
import viser

from workstation.building.floorplan import FloorPlan
from workstation.editor import SurveyEditor
from workstation.export import FORMATS
from workstation.viz import origin_guard, page_keys
from workstation.viz.colours import panel_legend
from workstation.viz.gui import set_value
from workstation.viz.panel_draw import DrawTools
from workstation.viz.panel_form import LandmarkForm
from workstation.viz.panel_georef import ControlPoints
from workstation.viz.panel_params import params_folder, show_params
from workstation.viz.panel_quality import QualityLayer
from workstation.viz.panel_route import PlanLayer
from workstation.viz.panel_scene import SceneLayer
from workstation.viz.panel_text import segments_table, status_markdown, summary_markdown
from workstation.viz.panel_view import walk_floor, walk_view
from workstation.viz.panel_zoom import ZoomFit


class SurveyPanel:
    """The panel: viser's server and GUI over one editor, composed of parts that each draw one
    thing (the scene, draw tools, control points, quality, survey plan, zoom, a form per tab)."""

    draw: DrawTools

    def __init__(
        self,
        editor: SurveyEditor,
        plan: FloorPlan | None = None,
        host: str = "127.0.0.1",
        port: int = 8080,
        building=None,
        building_path=None,
    ):
        self.ed = editor
        self.plan = plan
        self.building = building  # workstation.building.Building: floor-plan images
        self.building_path = Path(building_path) if building_path else None

        origin_guard.install()  # only this panel's own pages may connect (issue #18)
        origin_guard.allow_host(host)
        page_keys.install()  # Delete, Ctrl+Z, Ctrl+Y (issue #13)
        self.server = viser.ViserServer(
            host=host, port=port, label="workstation — survey panel", verbose=False
        )
        self.server.scene.set_up_direction("+z")
        self.floors = sorted(
            set(editor.graph.floors)
            | (set(plan.floors) if plan else set())
            | ({f for f, i in building.floors.items() if i.image} if building else set())
        )
        start = editor.result.track.start.node
        self.floor = walk_floor(editor.result.track, editor.graph, self.floors, start)
        self.forms: dict[int, Any] = {}  # client id → LandmarkForm
        # callbacks of several tabs run on viser's threads: one redraw at a time
        self.redraw_lock = threading.RLock()
        self._initial: str | None = None  # what a new tab selects first
        self._param_handles: dict[str, Any] = {}
        self._updating = False
        self.scene = SceneLayer(self)  # the plan, graph and results of the floor on view

        self.zoom = ZoomFit(self)  # hit targets and labels sized for the zoom
        self._frame_camera()
        self._build_gui()
        ids = editor.graph.ids
        self._initial = start if start in ids else (ids[0] if ids else None)
        self.server.on_client_connect(self._connect)
        self.server.on_client_disconnect(self._disconnect)
        self.redraw()

    def _frame_camera(self) -> None:
        """Look down (north up) on the walk on the floor on view, ``panel_view.WALK_MARGIN_M`` around it
        (issue #50 item 5: framed on the whole 145-m mall, a walk was a speck under landmark
        spheres); the building when the walk has no steps there. ``centre``/``extent``: the
        building's (the scale bar, a tab's sanity check); ``home``: the view opened."""
        pts = [self.ed.graph.xyf()[:, :2]]
        if self.plan is not None:
            pts += [fl.walls.reshape(-1, 2) for fl in self.plan.floors.values() if fl.walls.size]
        if self.building is not None and self.building.extent() is not None:
            pts.append(self.building.extent())
        xy = (
            np.concatenate([p for p in pts if p.size])
            if any(p.size for p in pts)
            else np.zeros((1, 2))
        )
        lo, hi = xy.min(axis=0), xy.max(axis=0)
        c = (lo + hi) / 2
        extent = float(max(hi - lo)) or 10.0
        self.centre = (float(c[0]), float(c[1]))
        self.extent = extent
        self.bounds = (lo, hi)
        cam = self.server.initial_camera
        walk = walk_view(self.ed.result.track, self.ed.session.ground_truth, self.floor)
        # the walk fills the screen's height (margins included); the building, as before
        self.home = walk or (self.centre, extent)
        self.home_height = (0.55 * walk[1] / np.tan(cam.fov / 2)) if walk else 1.1 * extent
        (hx, hy), hext = self.home
        cam.look_at = (hx, hy, 0.0)
        cam.position = (hx, hy - 0.05 * hext, self.home_height)
        cam.up = (0.0, 0.0, 1.0)

    @property
    def port(self) -> int:
        return self.server.get_port()

    def stop(self) -> None:
        self.server.stop()

    # ---- GUI ---------------------------------------------------------------------------------
    def _build_gui(self) -> None:
        self._view_folder()
        self.draw = DrawTools(self)
        has_building = self.building is not None
        self.georef = ControlPoints(self, self.building_path) if has_building else None
        self.quality = QualityLayer(self)
        self.route = PlanLayer(self)
        # each browser tab its own landmark form and selection, right after the draw tools
        self._form_order = float(self.draw.folder._impl.props.order) + 0.5
        self._parameters_folder()
        self._run_folder()

    def _view_folder(self) -> None:
        """The floor, the legend, the plan's opacity, the run's summary and its segments."""
        gui = self.server.gui  # (each tab's status line: viz/panel_form.py)
        with gui.add_folder("View"):
            self.floor_dd = gui.add_dropdown(
                "Floor", [f"{f:g}" for f in self.floors] or ["0"], initial_value=f"{self.floor:g}"
            )

            gui.add_markdown(panel_legend())
            self.opacity = gui.add_slider(
                "Plan image opacity", 0.0, 1.0, 0.05, 0.7,
                visible=self.building is not None,
            )  # fmt: skip
            self.summary_md = gui.add_markdown("")
        with gui.add_folder("Segments and belief", expand_by_default=False):
            self.segments_md = gui.add_markdown("")

            @self.opacity.on_update
            def _(_e) -> None:
                self.scene.draw_plan_image()

            @self.floor_dd.on_update
            def _(_e) -> None:
                # (a floor shown by the panel itself, e.g. a landmark selected there, comes
                # back here late: the floor is already that one, nothing to do)
                if self._updating or float(self.floor_dd.value) == self.floor:
                    return
                self.floor = float(self.floor_dd.value)
                self._frame_camera()  # framed on the walk there (or the building) again
                self.draw.reset_view()
                self.redraw()

    def _parameters_folder(self) -> None:
        self._param_handles.update(
            params_folder(self.server.gui, self.ed.params, self._param_changed)
        )

    def _run_folder(self) -> None:
        """Re-run, infer the start again, save, export."""
        gui = self.server.gui
        with gui.add_folder("Run and save"):
            run = gui.add_button("Re-run")
            infer = gui.add_button(
                "Infer the start again",
                hint="the start found at load is kept while you edit; search every landmark again",
            )
            save_g = gui.add_button("Save graph")
            save_p = gui.add_button("Save parameters")
            exports = {
                fmt: gui.add_button(f"Export radio map ({fmt})", hint=what)
                for fmt, what in FORMATS.items()
            }

            @run.on_click
            def _(_e) -> None:
                self.ed.rerun()
                self.after_edit()

            @infer.on_click
            def _(e) -> None:
                self.guard(self.ed.infer_start, tab=e.client_id)

            @save_g.on_click
            def _(e) -> None:
                self.guard(self.ed.save_graph, tab=e.client_id)

            @save_p.on_click
            def _(e) -> None:
                self.guard(self.ed.save_params, tab=e.client_id)

            def export_as(fmt: str):
                return lambda e: self.guard(self.ed.export_radiomap, fmt, tab=e.client_id)

            for fmt, b in exports.items():
                b.on_click(export_as(fmt))

    def _param_changed(self, key: str, value) -> None:
        if not self._updating:  # not while the widgets are set from loaded parameters
            self.ed.set_param(key, value)
            self.after_edit(params_changed=True)

    def guard(self, fn, *args, tab: int | None = None) -> None:
        """``fn`` done as tab ``tab``'s (None: every tab's), said in a notification there."""
        ok = True
        with self.ed.by(tab):
            try:
                fn(*args)
            except Exception as e:  # surfaced in the panel, never a dead callback
                self.ed.message = f"failed: {e}"
                ok = False
            said = self.ed.message
        # the buttons sit far below the status line: say it where the surveyor looks, at once
        # (the redraw below can take a while on a big walk)
        for cid, c in self.server.get_clients().items():
            if tab is None or cid == tab:
                c.add_notification(
                    "Done" if ok else "Failed", said, auto_close_seconds=8.0,
                    color="green" if ok else "red",
                )  # fmt: skip
        self.after_edit()

    # ---- actions (each tab its own selection: viz/panel_form.py) -----------------------------
    def _connect(self, client) -> None:
        form = LandmarkForm(self, client, self._form_order)
        self.forms[client.client_id] = form
        form.select(self._initial)
        self._tell(client.client_id, form)
        self.draw.keep_top_down(client)
        self.zoom.attach(client)
        self._frame_once(client)

    def _tell(self, cid: int, form) -> None:
        """Tab ``cid``'s status line (at the top, and under its form's buttons)."""
        said = self.ed.edits.said_to(cid, form.since)
        form.status_md.content = status_markdown(self.ed, said)
        form.form_status_md.content = f"*{said}*"  # (the unsaved mark: at the top only)

    def _frame_once(self, client) -> None:
        """A tab whose 3D view starts late (software WebGL under load) can miss the initial
        camera and open on viser's default view, off the building, on an empty screen: its first
        camera report says so, and the view is put over the building — unless the panel has
        already given the tab a view (Whole floor, another floor), which that report carries."""
        seen: list[bool] = []

        @client.camera.on_update
        def _(cam) -> None:
            if seen:
                return
            seen.append(True)
            if client.client_id in self.draw.placed:  # a view already given (Whole floor, a
                return  # floor): its late first report is that view, no missed camera
            # the tab just opened: anything but the home view is a missed initial camera (once
            # seen looking at the walk from 155 m instead of 29: the walk a speck, CI)
            (hx, hy), _ = self.home
            far = float(np.linalg.norm(np.subtract(cam.position, cam.look_at)))
            off = np.hypot(cam.look_at[0] - hx, cam.look_at[1] - hy)
            home = off <= 0.1 * self.home_height and 0.5 <= far / self.home_height <= 2.0
            if not home or not self.views_building(cam.position, cam.look_at):
                self.draw.reset_view(client)

    def views_building(self, position, look_at) -> bool:
        """A view whose look-at lies within a quarter of the building's extent of its centre,
        from far enough to see a good part of it (a tab once opened looking at the centre from
        viser's default 5 m: every landmark off screen)."""
        x, y = float(look_at[0]), float(look_at[1])
        dist = float(np.linalg.norm(np.subtract(position, look_at)))
        for (cx, cy), ext in ((self.centre, self.extent), self.home):  # the building, the walk
            if np.hypot(x - cx, y - cy) <= 0.25 * ext and dist >= 0.25 * ext:
                return True
        return False

    def _disconnect(self, client) -> None:
        self.forms.pop(client.client_id, None)
        self.draw.placed.discard(client.client_id)  # its per-tab state goes with it

    def _forms(self, client_id: int | None):
        if client_id is None:
            return list(self.forms.values())
        f = self.forms.get(client_id)
        return [f] if f is not None else []

    @property
    def selected(self) -> str | None:
        """The selection of the tab that connected last (the Python API's view)."""
        return next(reversed(self.forms.values())).selected if self.forms else self._initial

    def select(self, node_id: str | None, client_id: int | None = None) -> None:
        """Select in one tab, or in every tab (``client_id`` None: the Python API)."""
        if client_id is None:
            self._initial = node_id if node_id in self.ed.graph.ids else None
        for f in self._forms(client_id):
            f.select(node_id)

    def after_edit(
        self,
        select: str | None | bool = False,
        params_changed: bool = False,
        client_id: int | None = None,
    ) -> None:
        """After any tab's edit: ``select`` (when given) in the acting tab, then every tab's form
        shows the graph as it is now, and the scene is redrawn."""
        with self.redraw_lock:
            self._after_edit(select, params_changed, client_id)

    def _after_edit(self, select, params_changed, client_id) -> None:
        if select is not False:
            for f in self._forms(client_id):
                f.selected = select
        self._updating = True
        try:
            if params_changed is False:
                self._sync_params()
        finally:
            self._updating = False
        for f in list(self.forms.values()):
            f.sync()
        self.redraw()

    def show_floor(self, floor: float) -> None:
        """View ``floor`` (the dropdown follows; redrawn by the caller's after_edit)."""
        if f"{floor:g}" in self.floor_dd.options:
            self.floor = float(floor)
            self._updating = True
            try:
                set_value(self.floor_dd, f"{floor:g}")
            finally:
                self._updating = False

    def _sync_params(self) -> None:
        show_params(self._param_handles, self.ed.params)

    # ---- scene -------------------------------------------------------------------------------
    def redraw(self) -> None:
        with self.redraw_lock:
            self._redraw()

    def _redraw(self) -> None:
        ed, sc, f = self.ed, self.server.scene, self.floor
        s = ed.summary()  # once per redraw: the summary text and the start hints read it
        self.summary_md.content = summary_markdown(ed, s)
        for cid, form in list(self.forms.items()):  # each tab is told what its actions did
            self._tell(cid, form)
        self.segments_md.content = segments_table(ed.result, ed.params.radiomap.acceptance)
        if self.plan is not None:
            walls = self.plan.walls(f)
            if walls.size:
                pts = np.stack(
                    [
                        np.column_stack([walls[:, 0:2], np.zeros(len(walls))]),
                        np.column_stack([walls[:, 2:4], np.zeros(len(walls))]),
                    ],
                    axis=1,
                )
                sc.add_line_segments("/plan", pts, (120, 120, 120), thickness=0.08)
            else:
                sc.remove_by_name("/plan") if hasattr(sc, "remove_by_name") else None
        self.scene.draw_plan_image()
        self.draw.draw_scale_bar(*self.bounds)
        self.scene.draw_graph()
        self.scene.draw_results(s)
        self.scene.draw_start_hints(s)
        self.zoom.apply()  # (after the hints: the landmark labels make room for them)
        for f in list(self.forms.values()):
            f.draw_selection()
        self.quality.draw()
        self.route.draw()
