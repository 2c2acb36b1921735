"""One browser tab's landmark form and selection (issue #18).

Each tab that opens the panel gets its own "Landmark" folder — selection, name, position, floor,
rules, the landmark to connect — and its own selection highlight, so two tabs never edit each
other's selection: what a tab's Apply changes is the landmark that tab shows. The edits all go to
the one shared :class:`~workstation.editor.SurveyEditor`, which applies them in order under its
lock, each as this tab's (its Undo takes back its own edits: editor/history.py); every tab then
shows the graph as it is.

Two tabs on one landmark (issue #51): the form remembers each field as it last showed it. When
another tab changes the landmark, the fields this tab has not typed in follow; the ones it typed
stay. Apply sends only what this tab typed — A's x and B's y are both kept — and a field both
tabs changed is not applied: the status line says what the other tab set and that Apply again
overwrites it.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

from workstation.graph import RULES
from workstation.viz.colours import rgb
from workstation.viz.panel_zoom import NODE_RADIUS_M

if TYPE_CHECKING:
    from workstation.graph import Landmark
    from workstation.viz.panel_host import PanelHost


NONE = "(none)"  # the Selected dropdown when no landmark is selected (issue #50 item 7)
BESIDE_M = 2.0  # a new landmark with no place typed goes this far east and north of the selected
SELECTION_RADIUS = 2.0 * NODE_RADIUS_M  # the selected landmark's halo: twice its sphere
FIELDS = ("x", "y", "floor", "rules", "name")


def fields_of(n: Landmark) -> dict[str, Any]:
    """A landmark as the form shows it (positions to the millimetre, as the fields do)."""
    return {"id": n.id, "x": round(n.x, 3), "y": round(n.y, 3), "floor": float(n.floor),
            "rules": frozenset(n.rules), "name": n.name or None}  # fmt: skip


def place_for_new(shown: dict | None, typed: tuple[float, float]) -> tuple[float, float]:
    """Where "Add landmark" puts the new one: where the x/y fields say, when they were typed
    (they differ from the selected landmark they showed; issue #50 item 7: the typed place was
    ignored), or with nothing selected (the fields hold the plan's centre); else ``BESIDE_M``
    beside the selected landmark, not on top of it."""
    if shown is None or typed != (shown["x"], shown["y"]):
        return typed
    return shown["x"] + BESIDE_M, shown["y"] + BESIDE_M


def merge(typed: dict, shown: dict, now: dict) -> tuple[set[str], set[str]]:
    """What Apply sends (fields this tab typed: they differ from what the form showed) and what
    it holds back (typed here, and changed to something else meanwhile elsewhere)."""
    mine = {k for k in FIELDS if typed[k] != shown[k]}
    clash = {k for k in mine if now[k] != shown[k] and typed[k] != now[k]}
    return mine - clash, clash


class LandmarkForm:
    def __init__(self, panel: PanelHost, client, order: float):
        self.p, self.client = panel, client
        self.selected: str | None = None
        self._shown: dict | None = None  # each field as the form last showed it (fields_of)
        self.since = panel.ed.edits.tick()  # what was said before this tab opened is not its
        self._sel: Any = None  # the selection highlight in this tab's scene
        self._lock = threading.Lock()
        self._updating = False
        ed = panel.ed
        ids = ed.graph.ids
        gui = client.gui
        # this tab's status line: what its own actions did (the panel's top, and in the form
        # under its buttons — the top is off screen while one works here)
        self.status_md = gui.add_markdown("**status:** ready", order=-1.0)
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
            undo = gui.add_button("Undo", hint="take back this tab's last edit")
            redo = gui.add_button("Redo")
            self.form_status_md = gui.add_markdown("")
        self._wire(apply, add, delete, start_here, end_here, connect, disconnect, undo, redo)

    def _wire(self, apply, add, delete, start_here, end_here, connect, disconnect, undo, redo):
        """What each of the form's buttons does — in this tab (editor/history.py)."""
        panel, tab = self.p, self.client.client_id
        act = panel.ed.by

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
            with act(tab):
                nid = panel.ed.add_node(x, y, panel.floor)
            panel.after_edit(select=nid, client_id=tab)

        @delete.on_click
        def _(_e) -> None:
            with act(tab):
                if self.selected:
                    panel.ed.delete_node(self.selected)
                    panel.after_edit(select=None, client_id=tab)
                    return
                # it said nothing (issue #50 item 7)
                panel.ed.message = "nothing to delete: select a landmark first (click it on the plan)"
            panel.after_edit(client_id=tab)

        @start_here.on_click
        def _(_e) -> None:
            with act(tab):
                if self.selected and panel.ed.set_start(self.selected):
                    panel.show_floor(panel.ed.graph.node(self.selected).floor)  # the walk's floor
            panel.after_edit()

        @end_here.on_click
        def _(_e) -> None:
            with act(tab):
                if self.selected:
                    panel.ed.set_end(self.selected)
            panel.after_edit()

        def on_pair(how):
            def _(_e) -> None:
                with act(tab):
                    if self.selected:
                        getattr(panel.ed, how)(self.selected, self.other_dd.value)
                    else:
                        panel.ed.message = f"nothing to {how}: select a landmark first"
                panel.after_edit()

            return _

        connect.on_click(on_pair("connect"))
        disconnect.on_click(on_pair("disconnect"))

        @undo.on_click
        def _(_e) -> None:
            with act(tab):
                panel.ed.undo()
            panel.after_edit()

        @redo.on_click
        def _(_e) -> None:
            with act(tab):
                panel.ed.redo()
            panel.after_edit()

    # ---- actions -----------------------------------------------------------------------------
    def select(self, node_id: str | None) -> None:
        """Select ``node_id`` in this tab; under the panel's redraw lock, so another tab's edit
        refreshing the forms meanwhile cannot put the previous selection's fields back."""
        with self.p.redraw_lock:
            self.selected = node_id if node_id in self.p.ed.graph.ids else None
            self.sync_fields()
            self.draw_selection()

    def apply_fields(self) -> None:
        """What this tab typed onto this tab's landmark, as one step under the editor's lock
        (the fields it did not type are left as they are now, perhaps another tab's)."""
        nid, ed = self.selected, self.p.ed
        with ed.by(self.client.client_id):
            if not nid:
                ed.message = "select a landmark first: Apply changes the selected one"
            else:
                with ed.lock:
                    if nid not in ed.graph.ids:
                        ed.message = (f"not applied: {nid} was deleted meanwhile (in another "
                                      "tab? its Undo brings it back)")  # fmt: skip
                    else:
                        ed.message = self._apply(nid)
        self.p.after_edit()

    def _apply(self, nid: str) -> str:
        ed = self.p.ed
        cur = ed.graph.node(nid)
        now, typed = fields_of(cur), self.typed()
        shown = self._shown if self._shown and self._shown["id"] == nid else now
        go, clash = merge(typed, shown, now)
        said = []  # every change applied, said together (the last alone hid the rest)
        for changed, edit in (
            (go & {"x", "y"}, lambda: ed.move_node(
                nid, typed["x"] if "x" in go else cur.x, typed["y"] if "y" in go else cur.y)),
            ("floor" in go, lambda: ed.set_floor(nid, typed["floor"])),
            ("rules" in go, lambda: ed.set_rules(nid, typed["rules"])),
            ("name" in go, lambda: ed.set_name(nid, typed["name"] or "")),
        ):  # fmt: skip
            if changed:
                edit()
                said.append(ed.message)
        for k in sorted(clash):
            said.append(f"not applied: {nid}'s {k} was set to {_show(now[k])} meanwhile "
                        f"(in another tab?) — yours, {_show(typed[k])}, is still in the form: "
                        "Apply again to overwrite it")  # fmt: skip
        if nid in ed.graph.ids and self.selected == nid:  # (not if another was selected since)
            self._shown = fields_of(ed.graph.node(nid))  # what the form has seen: it as it is
        if not said:
            return f"nothing to apply: the fields are {nid}'s as it is"
        return "; ".join(said)

    def typed(self) -> dict[str, Any]:
        """The fields as they are in this tab."""
        return {"id": self.selected, "x": round(float(self.x_in.value), 3),
                "y": round(float(self.y_in.value), 3), "floor": float(self.floor_in.value),
                "rules": frozenset(r for r, b in self.rule_boxes.items() if b.value),
                "name": self.name_in.value or None}  # fmt: skip

    # ---- the graph as it is now ------------------------------------------------------------
    def sync(self) -> None:
        """After any tab's edit: the options, and this tab's fields: those it has not typed in
        follow its landmark as it is now; what it typed but did not apply is left alone."""
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
        now = fields_of(g.node(self.selected)) if self.selected else None
        if now is None or self._shown is None or self._shown["id"] != now["id"]:
            if now != self._shown:
                self.sync_fields()
        elif now != self._shown:
            self._follow(now)
        self.draw_selection()

    def _follow(self, now: dict) -> None:
        """The fields not typed in take the landmark's values as they are now."""
        typed, shown = self.typed(), dict(self._shown or now)
        self._updating = True
        try:
            for k in FIELDS:
                if typed[k] == shown[k] or typed[k] == now[k]:
                    self._put(k, now[k])
                    shown[k] = now[k]
        finally:
            self._updating = False
        self._shown = shown

    def _put(self, k: str, v) -> None:
        if k == "rules":
            for r, b in self.rule_boxes.items():
                b.value = r in v
        else:
            {"x": self.x_in, "y": self.y_in, "floor": self.floor_in,
             "name": self.name_in}[k].value = v if k != "name" else (v or "")  # fmt: skip

    def sync_fields(self) -> None:
        self._updating = True
        try:
            g = self.p.ed.graph  # one graph: another tab may delete the landmark meanwhile
            if self.selected not in g.ids:  # (a KeyError here cut every tab's redraw short)
                self.selected = None
            n = g.node(self.selected) if self.selected else None
            self._shown = fields_of(n) if n is not None else None
            if n is not None:
                self.sel_dd.value = n.id
                for k in FIELDS:
                    self._put(k, fields_of(n)[k])
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
                    if self._sel is None:  # a halo round the sphere, scaled with it (a
                        # 1-m halo inside a sphere scaled up for the zoom was hardly seen)
                        self._sel = self.client.scene.add_icosphere(
                            "/selection", radius=SELECTION_RADIUS, color=rgb("selection"),
                            opacity=0.6, visible=False,
                        )  # fmt: skip
                    scale = self.p.zoom.node_scale()
                    if self._sel.scale != scale:
                        self._sel.scale = scale
                    if n is not None:
                        self._sel.position = (n.x, n.y, 0.3)
                    self._sel.visible = n is not None and n.floor == self.p.floor
                    return
                except RuntimeError:  # the handle was removed (the tab went away): once more
                    self._sel = None


def _show(v) -> str:
    if isinstance(v, frozenset):
        return ", ".join(sorted(v)) or "none"
    return f"{v:g}" if isinstance(v, float) else repr(v)
