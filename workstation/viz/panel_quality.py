"""The panel's radio-map quality layer (issue #15): a coverage toggle and an AP selector. The
maps (:mod:`workstation.fingerprints.quality`) are computed from the kept reference points of the current
result when first asked for, and again only after a re-run changed them; drawn as one dot per
walkable cell of the floor on view, under the graph. Colours as in the viewer's radiomap layout:
coverage 0 m yellow … 10 m and more purple; RSS −100 dBm blue … −30 dBm red."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from workstation.fingerprints.localize import Fingerprints
from workstation.fingerprints.quality import FIELD_REACH_M, quality, strongest_aps
from workstation.viz.colours import coverage_rgb, rss_rgb, scale_legend
from workstation.viz.gui import set_value

if TYPE_CHECKING:
    from workstation.viz.panel_host import PanelHost

NONE = "none"
N_APS = 10


class QualityLayer:
    """Built by panel (:class:`~workstation.viz.panel_host.PanelHost`); draws into its scene."""

    def __init__(self, panel: PanelHost):
        self.p = panel
        self._key: Any = None  # (run, graph) the layer was drawn for
        self._options_key: Any = None  # the radio map the AP list was made from
        self._maps: dict = {}
        gui = panel.server.gui
        with gui.add_folder("Radio-map quality", expand_by_default=False):
            self.coverage = gui.add_checkbox(
                "Coverage", False, hint="distance to the nearest kept reference point"
            )
            self.ap = gui.add_dropdown("AP heatmap", [NONE], initial_value=NONE)
            self.note = gui.add_markdown("")

        @self.coverage.on_update
        def _(_e) -> None:
            if self.coverage.value and self.ap.value != NONE:
                set_value(self.ap, NONE)  # one layer at a time
            self.draw()

        @self.ap.on_update
        def _(_e) -> None:
            if self.ap.value != NONE and self.coverage.value:
                set_value(self.coverage, False)
            self.draw()

    def _fingerprints(self):
        return Fingerprints.of_walk(self.p.ed.result.radiomap, self.p.ed.graph.frame)

    def _fill_options(self) -> None:
        """The AP selector's choices, from the reference points alone (no map computed)."""
        rm = self.p.ed.result.radiomap
        if self._options_key is rm:
            return
        self._options_key = rm
        options = [NONE] + strongest_aps(self._fingerprints(), N_APS)
        if self.ap.value not in options:
            set_value(self.ap, NONE)
        self.ap.options = options

    def _quality(self):
        """Per-floor maps of the current result (cached until the reference points change)."""
        r = self.p.ed.result
        key = (id(r.radiomap), self.p.ed.graph)
        if key != self._key:
            fp = self._fingerprints()
            self._maps = quality(fp, self.p.ed.graph, n_aps=N_APS) if len(fp) else {}
            self._key = key
        self._fill_options()
        return self._maps

    def _hide(self) -> None:
        sc = self.p.server.scene
        sc.add_point_cloud("/quality", np.zeros((1, 3), np.float32), (0, 0, 0), visible=False)

    def draw(self) -> None:
        want = self.coverage.value or self.ap.value != NONE
        if not want:
            self._hide()
            self.note.content = ""
            self._fill_options()  # the selector has choices before any map is computed
            return
        q = self._quality().get(float(self.p.floor))
        if q is None:
            self._hide()
            self.note.content = "no reference points on this floor"
            return

        xs, ys = q.centres()
        gx, gy = np.meshgrid(xs, ys)
        m = q.mask
        if self.coverage.value:
            rgb = coverage_rgb(q.coverage_m[m])
            s = q.summary()
            self.note.content = (
                f"{100 * s['coverage_share']:.0f} % of {s['walkable_m2']:.0f} m² within 3 m of a "
                f"kept reference point; edges to walk again: "
                f"{', '.join(s['edges_to_rewalk'][:6]) or 'none'}<br>distance to the nearest: "
                f"{scale_legend('coverage', 'm')}"
            )
        else:
            ids = [str(b) for b in q.bssids]
            if self.ap.value not in ids:
                self._hide()
                self.note.content = f"{self.ap.value} is not among this floor's strongest APs"
                return
            field = q.rss[ids.index(self.ap.value)]
            m = m & np.isfinite(field)  # the field ends FIELD_REACH_M from the points
            rgb = rss_rgb(field[m])
            self.note.content = (
                f"RSS of {self.ap.value}: {scale_legend('rss', 'dBm')}; within "
                f"{FIELD_REACH_M:g} m of a reference point"
            )
        pts = np.column_stack([gx[m], gy[m], np.full(int(m.sum()), 0.01)]).astype(np.float32)
        self.p.server.scene.add_point_cloud(
            "/quality", pts, rgb, point_size=0.9 * q.cell_m, point_shape="square"
        )
