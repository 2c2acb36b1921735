"""Control points in the survey panel (issue #13): put the floor-plan image where it belongs by
clicking features on it and typing where they really are.

"Click on the plan" → "control point" picks a pixel of the floor's image (the click, through the
image's current placement); the surveyor types that point's true position in metres (x east, y
north of the graph's frame) and adds it. With two points the image gets a similarity (rotation,
one scale, shift), with three or more a least-squares affine — :func:`workstation.building.fit_transform`,
the same as ``workstation building from-points``. "Fit and save" writes the building file
(atomically, the previous one kept as ``.bak``) and redraws the plan; the residual of each point
is listed.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from workstation.building import FloorImage, FloorInfo
from workstation.building.importers import fit_transform
from workstation.errors import WorkstationError
from workstation.viz.colours import rgb
from workstation.viz.gui import set_value

if TYPE_CHECKING:
    from workstation.viz.panel_host import PanelHost


class ControlPoints:
    """Attached to a panel (:class:`~workstation.viz.panel_host.PanelHost`) that shows a building."""

    def __init__(self, panel: PanelHost, path: Path | None):
        self.p, self.path = panel, path
        self.points: list[tuple[float, float, float, float]] = []  # u, v pixels; x, y metres
        self.pixel: tuple[float, float] | None = None
        self.picked_at: tuple[float, float] | None = None  # where the plan puts the pixel now
        self.clear_asked = False  # Clear drops the points on its second click only
        gui = panel.server.gui
        with gui.add_folder("Control points (place the plan)", expand_by_default=False):
            self.info = gui.add_markdown("")
            self.x_in = gui.add_number("true x (m)", 0.0, step=0.01)
            self.y_in = gui.add_number("true y (m)", 0.0, step=0.01)
            add = gui.add_button("Add control point")
            clear = gui.add_button("Clear control points")
            fit = gui.add_button("Fit and save building")

        @add.on_click
        def _(_e) -> None:
            self.add(float(self.x_in.value), float(self.y_in.value))

        @clear.on_click
        def _(_e) -> None:
            self.clear()

        @fit.on_click
        def _(_e) -> None:
            self.fit_and_save()

        self._show()

    def image(self):
        b = self.p.building
        return b.image(self.p.floor) if b is not None else None

    def pick(self, x: float, y: float) -> None:
        """A click on the plan at (x, y) metres: the image pixel there, its coordinates offered."""
        img = self.image()
        self.clear_asked = False
        if img is None:
            self.p.ed.message = f"floor {self.p.floor:g} has no plan image to place"
        else:
            u, v = img.to_pixels(x, y)
            self.pixel = (float(u), float(v))
            self.picked_at = (round(x, 2), round(y, 2))
            set_value(self.x_in, self.picked_at[0])
            set_value(self.y_in, self.picked_at[1])
            self.p.ed.message = (
                f"pixel ({u:.0f}, {v:.0f}) picked: type where it really is, then Add control point"
            )
        self._show()
        self.p.after_edit()

    def add(self, x: float, y: float) -> None:
        self.clear_asked = False
        if self.pixel is None:
            self.p.ed.message = "refused: first click the point on the plan (mode: control point)"
        elif (round(x, 2), round(y, 2)) == self.picked_at:
            self.p.ed.message = (
                "refused: type where the point really is first — the fields still say where "
                "the plan puts it now, which would pin the plan where it is"
            )
        else:
            self.points.append((*self.pixel, x, y))
            self.pixel = None
            self.p.ed.message = f"control point {len(self.points)} added"
        self._show()
        self.p.after_edit()

    def clear(self) -> None:
        """Drop the control points — on a second click: the first says how many would go."""
        if self.points and not self.clear_asked:
            self.clear_asked = True
            self.p.ed.message = (
                f"click Clear control points again to drop all {len(self.points)} control points"
            )
        else:
            n, self.points, self.pixel, self.clear_asked = len(self.points), [], None, False
            self.p.ed.message = f"{n} control points dropped" if n else "no control points"
        self._show()
        self.p.after_edit()

    def fit_and_save(self) -> None:
        p, img = self.p, self.image()
        try:
            if img is None or p.building is None:
                raise ValueError(f"floor {p.floor:g} has no plan image")
            pts = np.array(self.points, float).reshape(-1, 4)
            t = fit_transform(pts[:, :2], pts[:, 2:])
        except ValueError as e:
            p.ed.message = f"refused: {e}"
            self._show()
            p.after_edit()
            return
        floors = dict(p.building.floors)
        floors[float(p.floor)] = FloorInfo(floors[float(p.floor)].height_m, FloorImage(img.path, t))
        p.building = replace(p.building, floors=floors)
        p.scene.image_key = None  # the plan is drawn again, in its new place
        saved = ""
        if self.path is not None:
            try:
                p.building.save(self.path)
                saved = f"; saved {self.path.name} (previous kept as {self.path.name}.bak)"
            except (OSError, WorkstationError) as e:
                saved = f"; NOT saved: {e}"
        x, y = FloorImage(img.path, t).to_metres(pts[:, 0], pts[:, 1])
        res = np.hypot(x - pts[:, 2], y - pts[:, 3])
        p.ed.message = (
            f"plan placed from {len(pts)} control points, residual max {res.max():.2f} m{saved}"
        )
        self._show(res)
        p.redraw()

    def _show(self, residuals=None) -> None:
        lines = [
            "Mode *control point* under **Click on the plan**: click a feature of the image, "
            "type its true position, **Add**. Two points: rotation, scale and shift; three or "
            "more: an affine fit."
        ]
        if self.pixel is not None:
            lines.append(f"picked pixel ({self.pixel[0]:.0f}, {self.pixel[1]:.0f})")
        for i, (u, v, x, y) in enumerate(self.points):
            r = f", residual {residuals[i]:.2f} m" if residuals is not None else ""
            lines.append(f"{i + 1}. pixel ({u:.0f}, {v:.0f}) → ({x:.2f}, {y:.2f}) m{r}")
        self.info.content = "\n\n".join(lines)
        self._mark()

    def _mark(self) -> None:
        """The control points (and the picked pixel) as purple dots where the image now puts
        them, with their numbers."""
        sc, img = self.p.server.scene, self.image()
        uv = [(u, v) for u, v, _x, _y in self.points] + ([self.pixel] if self.pixel else [])
        if img is None or not uv:
            sc.add_frame("/control_points", show_axes=False, visible=False)
            return
        x, y = img.to_metres(*np.array(uv, float).T)
        pts = np.column_stack([x, y, np.full(x.size, 0.3)]).astype(np.float32)
        sc.add_frame("/control_points", show_axes=False, visible=True)
        sc.add_point_cloud("/control_points/dots", pts, colors=rgb("control_points"), point_size=1.2,
                           point_shape="circle")  # fmt: skip
        for i, (px, py, _z) in enumerate(pts):
            name = str(i + 1) if i < len(self.points) else "?"
            sc.add_label(f"/control_points/{i}", name, position=(float(px), float(py), 0.6))
