"""Drawing the landmark graph on the plan in the panel: click on the plan to place a landmark
(a click near an existing one selects it instead: snapping), click two landmarks to connect
them; Reset view looks straight down on the walk again, Whole floor on the whole plan; a scale
bar under the plan."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from workstation.rules import NAMES, TURN

if TYPE_CHECKING:
    from workstation.viz.panel_host import PanelHost

SNAP_M = 1.5  # a click this close to a landmark means that landmark
MODES = ("off", "place landmarks", "connect landmarks", "control point")


def ray_to_floor(origin, direction) -> tuple[float, float] | None:
    """Where a click's ray meets the plane z = 0 (None when it points away)."""
    o, d = np.asarray(origin, float), np.asarray(direction, float)
    if abs(d[2]) < 1e-9:
        return None
    t = -o[2] / d[2]
    if t <= 0:
        return None
    p = o + t * d
    return float(p[0]), float(p[1])


def nice_length(extent: float) -> float:
    """A round scale-bar length near a fifth of ``extent`` (1, 2 or 5 × 10^k m)."""
    target = max(extent / 5.0, 0.1)
    k = 10.0 ** np.floor(np.log10(target))
    return float(max(m * k for m in (1, 2, 5) if m * k <= target * 1.0001))


class DrawTools:
    """Attached to a panel (:class:`~workstation.viz.panel_host.PanelHost`)."""

    def __init__(self, panel: PanelHost):
        self.p = panel
        self.pending: str | None = None  # first landmark of a connection
        self.placed: set[int] = set()  # tabs whose view the panel has put somewhere (reset_view)
        self._listening = False
        gui = panel.server.gui
        self.folder = gui.add_folder("Draw on the plan")
        with self.folder:
            self.mode = gui.add_dropdown("Click on the plan", MODES, initial_value="off")
            self.rules = {
                r: gui.add_checkbox(f"new landmarks: {r}", r == TURN)
                for r in sorted(NAMES, key=lambda r: r != TURN)  # a turn first: the default
            }
            reset = gui.add_button("Reset view (top down)", hint="back to the walk")
            whole = gui.add_button("Whole floor", hint="the building's whole plan, top down")
            self.top_down = gui.add_checkbox(
                "Keep the view top-down", True, hint="pan and zoom only: the plan never tilts"
            )

        @self.mode.on_update
        def _(_e) -> None:
            self.pending = None
            self._listen(self.mode.value != "off")
            panel.ed.message = {
                "off": "drawing off",
                "place landmarks": "click on the plan to place a landmark (near one: select it)",
                "connect landmarks": "click a landmark, then the one to connect it to",
                "control point": "click a feature of the plan image, then type where it really is",
            }[self.mode.value]
            panel.after_edit()

        @reset.on_click
        def _(e) -> None:
            self.reset_view(e.client)

        @whole.on_click
        def _(e) -> None:
            self.reset_view(e.client, whole=True)

    # ---- clicks ----------------------------------------------------------------------------
    def _listen(self, on: bool) -> None:
        sc = self.p.server.scene
        if on and not self._listening:
            sc.on_click()(self.on_click)
            self._listening = True
        elif not on and self._listening:
            sc.remove_click_callback(self.on_click)
            self._listening = False

    def nearest(self, x: float, y: float) -> str | None:
        best, dist = None, SNAP_M
        for n in self.p.ed.graph.nodes:
            if n.floor == self.p.floor:
                d = float(np.hypot(n.x - x, n.y - y))
                if d <= dist:
                    best, dist = n.id, d
        return best

    def on_click(self, event) -> None:
        hit = ray_to_floor(event.ray_origin, event.ray_direction)
        if hit is None:
            return
        self.click_at(*hit, client_id=event.client_id)

    def click_at(self, x: float, y: float, client_id: int | None = None) -> None:
        """What a click on the plan at (x, y) metres does in the current mode (the selection
        changes in the tab that clicked; ``client_id`` None: in every tab)."""
        with self.p.ed.by(client_id):  # what the click does and says is that tab's
            self._click_at(x, y, client_id)

    def _click_at(self, x: float, y: float, client_id: int | None) -> None:
        p, ed = self.p, self.p.ed
        if self.mode.value == "control point":
            if p.georef is None:
                ed.message = "no building file: there is no plan image to place"
                p.after_edit()
            else:
                p.georef.pick(x, y)
            return
        near = self.nearest(x, y)
        if self.mode.value == "place landmarks":
            if near is not None:
                ed.message = f"selected {near} (snapped: {SNAP_M:g} m)"
                p.after_edit(select=near, client_id=client_id)
                return
            rules = [r for r, b in self.rules.items() if b.value]
            nid = ed.add_node(x, y, p.floor, rules)
            p.after_edit(select=nid, client_id=client_id)
        elif self.mode.value == "connect landmarks":
            if near is None:
                ed.message = f"no landmark within {SNAP_M:g} m of the click"
            elif self.pending is None or self.pending == near:
                self.pending = near
                ed.message = f"connect {near} to… click the second landmark"
            else:
                ed.connect(self.pending, near)
                self.pending = None
            p.after_edit(select=near if near else False, client_id=client_id)

    # ---- view ------------------------------------------------------------------------------
    TILT_DEG = 1.0

    def keep_top_down(self, client) -> None:
        """While "Keep the view top-down" is on, a camera that tilts (an orbit drag) is put back
        straight above the point it looks at, at the same distance: pan and zoom stay free."""

        @client.camera.on_update
        def _(cam) -> None:
            if not self.top_down.value:
                return
            d = np.asarray(cam.look_at, float) - np.asarray(cam.position, float)
            dist = float(np.linalg.norm(d))
            if dist <= 0 or -d[2] / dist >= np.cos(np.radians(self.TILT_DEG)):
                return  # already looking (almost) straight down
            x, y, z = (float(v) for v in cam.look_at)
            with client.atomic():  # viser moves look_at with position: set it after
                cam.position = (x, y - 1e-3 * dist, z + dist)
                cam.look_at = (x, y, z)

    def reset_view(self, client=None, whole: bool = False) -> None:
        """Back to the view the panel opened on (the walk: panel.home), or the whole floor."""
        (cx, cy), ext = (self.p.centre, self.p.extent) if whole else self.p.home
        height = 1.1 * ext if whole else self.p.home_height
        clients = [client] if client is not None else list(self.p.server.get_clients().values())
        for c in clients:  # viser moves look_at with position: set it after
            self.placed.add(c.client_id)
            with c.atomic():
                c.camera.position = (cx, cy - 1e-3 * ext, height)
                c.camera.look_at = (cx, cy, 0.0)

    def draw_scale_bar(self, lo, hi) -> None:
        sc = self.p.server.scene
        ext = float(max(hi[0] - lo[0], hi[1] - lo[1], 1.0))
        length = nice_length(ext)
        x0, y0 = float(lo[0]), float(lo[1]) - 0.04 * ext
        pts = np.array([[[x0, y0, 0.05], [x0 + length, y0, 0.05]]])
        sc.add_line_segments("/scale_bar/line", pts, (40, 40, 40), thickness=0.25)
        sc.add_label(
            "/scale_bar/label", f"{length:g} m", position=(x0 + length / 2, y0 - 0.02 * ext, 0.1)
        )
