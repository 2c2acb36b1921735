"""One browser tab's landmark form and selection (issue #18).

Each tab that opens the panel gets its own "Landmark" folder — selection, name, position, floor,
rules, the landmark to connect — and its own selection highlight, so two tabs never edit each
other's selection: what a tab's Apply changes is the landmark that tab shows. The edits all go to
the one shared :class:`~workstation.editor.SurveyEditor`, which applies them in order under its
lock; every tab then shows the graph as it is (options refreshed, its own fields re-read).
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

from workstation.graph import RULES
from workstation.viz.colours import rgb

if TYPE_CHECKING:
    from workstation.graph import Landmark
    from workstation.viz.panel_host import PanelHost


NONE = "(none)"  # the Selected dropdown when no landmark is selected (issue #50 item 7)
BESIDE_M = 2.0  # a new landmark with no place typed goes this far east and north of the selected


def place_for_new(shown: Landmark | None, typed: tuple[float, float]) -> tuple[float, float]:
    """Where "Add landmark" puts the new one: where the x/y fields say, when they were typed
    (they differ from the selected landmark they showed; issue #50 item 7: the typed place was
    ignored), or with nothing selected (the fields hold the plan's centre); else ``BESIDE_M``
    beside the selected landmark, not on top of it."""
    if shown is None or typed != (round(shown.x, 3), round(shown.y, 3)):
        return typed
    return shown.x + BESIDE_M, shown.y + BESIDE_M


class LandmarkForm:
    def __init__(self, panel: PanelHost, client, order: float):
        self.p, self.client = panel, client
        self.selected: str | None = None
        self._shown: Landmark | None = None  # the landmark as the fields last showed it
        self._sel: Any = None  # the selection highlight in this tab's scene
        self._lock = threading.Lock()
        self._updating = False
        ed = panel.ed
        ids = ed.graph.ids
        gui = client.gui
        with gui.add_folder("Landmark", order=order):
            self.sel_dd = gui.add_dropdown("Selected", [NONE, *ids], initial_value=NONE)
            self.name_in = gui.add_text("Name", "")
            self.x_in = gui.add_number("x (m)", 0.0, step=0.01)
            self.y_in = gui.add_number("y (m)", 0.0, step=0.01)
            self.floor_in = gui.add_number("Floor of node", 0.0, step=1.0)
            self.rule_boxes = {r: gui.add_checkbox(f"rule {r}", False) for r in RULES}
            apply = gui.add_button("Apply to landmark")
            add = gui.add_button("Add landmark")
            delete = gui.add_button("Delete landmark", color="red")
            self.other_dd = gui.add_dropdown(
                "Other landmark", ids or ["-"], initial_value=ids[0] if ids else "-"
            )
            start_here = gui.add_button(
                "Start here", hint="the walk began at this landmark (instead of the inferred start)"
            )
            end_here = gui.add_button(
                "End here",
                hint="the walk ended at this landmark (you stopped recording there): its last "
                "stretch is closed on it, and it checks a walk that matched nothing",
            )
            connect = gui.add_button("Connect")
            disconnect = gui.add_button("Disconnect")
            undo = gui.add_button("Undo")
            redo = gui.add_button("Redo")  # fmt: skip

        @self.sel_dd.on_update
        def _(_e) -> None:
            if not self._updating:
                self.select(self.sel_dd.value)

        @apply.on_click
        def _(_e) -> None:
            self.apply_fields()

        @add.on_click
        def _(_e) -> None:
            typed = (float(self.x_in.value), float(self.y_in.value))
            x, y = place_for_new(self._shown, typed)
            nid = panel.ed.add_node(x, y, panel.floor)
            panel.after_edit(select=nid, client_id=self.client.client_id)

        @delete.on_click
        def _(_e) -> None:
            if self.selected:
                panel.ed.delete_node(self.selected)
                panel.after_edit(select=None, client_id=self.client.client_id)
            else:  # it said nothing (issue #50 item 7)
                panel.ed.message = "nothing to delete: select a landmark first (click it on the plan)"
                panel.after_edit(client_id=self.client.client_id)

        @start_here.on_click
        def _(_e) -> None:
            if self.selected and panel.ed.set_start(self.selected):
                panel.show_floor(panel.ed.graph.node(self.selected).floor)  # where the walk is now
            panel.after_edit()

        @end_here.on_click
        def _(_e) -> None:
            if self.selected:
                panel.ed.set_end(self.selected)
            panel.after_edit()

        @connect.on_click
        def _(_e) -> None:
            if self.selected:
                panel.ed.connect(self.selected, self.other_dd.value)
                panel.after_edit()

        @disconnect.on_click
        def _(_e) -> None:
            if self.selected:
                panel.ed.disconnect(self.selected, self.other_dd.value)
                panel.after_edit()

        @undo.on_click
        def _(_e) -> None:
            panel.ed.undo()
            panel.after_edit()

        @redo.on_click
        def _(_e) -> None:
            panel.ed.redo()
            panel.after_edit()

    # ---- actions -----------------------------------------------------------------------------
    def select(self, node_id: str | None) -> None:
        self.selected = node_id if node_id in self.p.ed.graph.ids else None
        self.sync_fields()
        self.draw_selection()

    def apply_fields(self) -> None:
        """This tab's fields onto this tab's landmark, as one step under the editor's lock."""
        nid, ed = self.selected, self.p.ed
        if not nid:
            ed.message = "select a landmark first: Apply changes the selected one"
            self.p.after_edit()
            return
        with ed.lock:
            if nid not in ed.graph.ids:
                ed.message = f"refused: {nid} was deleted (in another tab?)"
            else:
                n = ed.graph.node(nid)
                rules = {r for r, b in self.rule_boxes.items() if b.value}
                said = []  # every change applied, said together (the last alone hid the rest)
                for changed, edit in (
                    ((self.x_in.value, self.y_in.value) != (n.x, n.y),
                     lambda: ed.move_node(nid, float(self.x_in.value), float(self.y_in.value))),
                    (float(self.floor_in.value) != n.floor,
                     lambda: ed.set_floor(nid, float(self.floor_in.value))),
                    (rules != set(n.rules), lambda: ed.set_rules(nid, rules)),
                    ((self.name_in.value or None) != n.name,
                     lambda: ed.set_name(nid, self.name_in.value)),
                ):  # fmt: skip
                    if changed:
                        edit()
                        said.append(ed.message)
                ed.message = "; ".join(said) or f"nothing to apply: the fields are {nid}'s as it is"
        self.p.after_edit()

    # ---- the graph as it is now ------------------------------------------------------------
    def sync(self) -> None:
        """After any tab's edit: the options, and this tab's fields re-read only if its landmark
        changed (or went): what this tab has typed but not applied is left alone."""
        g = self.p.ed.graph
        ids = g.ids
        self._updating = True
        try:
            self.sel_dd.options = [NONE, *ids]
            self.other_dd.options = ids or ["-"]
            if self.selected in ids:
                self.sel_dd.value = self.selected
            else:  # gone (deleted, an Add undone): nothing selected, and the form says so
                self.selected = None
                self.sel_dd.value = NONE
        finally:
            self._updating = False
        now = g.node(self.selected) if self.selected else None
        if now != self._shown:
            self.sync_fields()
        self.draw_selection()

    def sync_fields(self) -> None:
        self._updating = True
        try:
            g = self.p.ed.graph  # one graph: another tab may delete the landmark meanwhile
            if self.selected not in g.ids:  # (a KeyError here cut every tab's redraw short)
                self.selected = None
            n = g.node(self.selected) if self.selected else None
            self._shown = n
            if n is not None:
                self.sel_dd.value = n.id
                self.name_in.value = n.name or ""
                self.x_in.value = round(n.x, 3)
                self.y_in.value = round(n.y, 3)
                self.floor_in.value = n.floor
                for r, b in self.rule_boxes.items():
                    b.value = r in n.rules
            else:  # nothing selected: no stale name, rules or place of a landmark now gone
                self.sel_dd.value = NONE
                self.name_in.value = ""
                for b in self.rule_boxes.values():
                    b.value = False
                cx, cy = self.p.centre
                self.x_in.value, self.y_in.value = round(cx, 3), round(cy, 3)
                self.floor_in.value = self.p.floor
        finally:
            self._updating = False

    def draw_selection(self) -> None:
        """This tab's selection highlight, in this tab's scene only: one handle, moved and shown
        or hidden (re-adding it by name from two callback threads at once raced in viser)."""
        g = self.p.ed.graph
        n = g.node(self.selected) if self.selected and self.selected in g.ids else None
        with self._lock:
            for _ in range(2):
                try:
                    if self._sel is None:
                        self._sel = self.client.scene.add_icosphere(
                            "/selection", radius=1.0, color=rgb("selection"), opacity=0.4,
                            visible=False,
                        )  # fmt: skip
                    if n is not None:
                        self._sel.position = (n.x, n.y, 0.3)
                    self._sel.visible = n is not None and n.floor == self.p.floor
                    return
                except RuntimeError:  # the handle was removed (the tab went away): once more
                    self._sel = None
