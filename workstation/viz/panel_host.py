"""What a part of the panel (scene, draw tools, form, control points, quality, route, zoom)
needs of the panel that holds it — a small typed face, so the parts depend on it and not on
:class:`~workstation.viz.panel.SurveyPanel` (which builds them)."""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any, Protocol

from workstation.building import Building
from workstation.building.floorplan import FloorPlan
from workstation.editor import SurveyEditor

if TYPE_CHECKING:
    import viser


class SceneHandles(Protocol):
    """What the other parts read of the scene: the landmark spheres and the start hints' rings
    (the zoom fit scales them), the key of the plan image drawn (placing the plan redraws it)."""

    node_handles: dict[str, tuple]
    hint_rings: list
    hint_at: list  # (label, x, y): the start hints' labels and their landmarks (stacked)
    mark_at: list  # (label, x, y): the walk's start and end labels (the hints stack above)
    image_key: tuple | None


class Zoom(Protocol):
    def node_scale(self) -> float: ...


class Picker(Protocol):
    """The control points: a click on the plan in "control point" mode."""

    def pick(self, x: float, y: float) -> None: ...


class PanelHost(Protocol):
    """The panel as its parts see it: the editor, the viser server, the floor on view and where
    the building lies, and the three ways back into the panel (select, after_edit, guard)."""

    ed: SurveyEditor
    server: viser.ViserServer
    plan: FloorPlan | None
    building: Building | None
    floor: float
    centre: tuple[float, float]
    extent: float
    home: tuple[tuple[float, float], float]  # the view opened on (the walk): centre, extent
    home_height: float  # and the camera's height over it
    opacity: Any  # the plan image's opacity slider
    forms: dict[int, Any]  # client id → that tab's LandmarkForm
    redraw_lock: threading.RLock

    @property
    def scene(self) -> SceneHandles: ...

    @property
    def zoom(self) -> Zoom: ...

    @property
    def georef(self) -> Picker | None: ...

    def redraw(self) -> None: ...

    def select(self, node_id: str | None, client_id: int | None = None) -> None: ...

    def after_edit(
        self,
        select: str | None | bool = False,
        params_changed: bool = False,
        client_id: int | None = None,
    ) -> None: ...

    def show_floor(self, floor: float) -> None: ...

    def guard(self, fn, *args, tab: int | None = None) -> None: ...
