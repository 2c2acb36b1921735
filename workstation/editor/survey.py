"""The survey editor's state (:mod:`workstation.editor`): :class:`SurveyEditor`."""

from __future__ import annotations

import threading
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from workstation.editor.history import Conflict, History
from workstation.editor.notes import far_note, start_hints, start_note
from workstation.editor.recovery import keep_recovery, recovery_paths, sweep
from workstation.errors import GraphError, ParameterError, WorkstationError
from workstation.export import radiomap_table, write_radiomap
from workstation.graph import RULES, Landmark, LandmarkGraph
from workstation.io.store import is_remote, place
from workstation.io.walk_fixes import WalkFixes
from workstation.params import Params
from workstation.pipeline import Pipeline, Result
from workstation.pipeline.metrics import start_inference
from workstation.pipeline.summary import Summary
from workstation.pipeline.tracking.map_prior import prior_for_walk
from workstation.pipeline.tracking.state import Track
from workstation.pipeline.verdict import mark, reasons
from workstation.session import Session
from workstation.walks.start_by_map import MapRanking


class SurveyEditor:
    def __init__(
        self,
        session: Session,
        graph: LandmarkGraph,
        params: Params | None = None,
        graph_path: str | Path | None = None,
        params_path: str | Path | None = None,
        out_dir: str | Path = "out",
        observers: list | None = None,
        building_map=None,
        start_within: tuple | None = None,
    ):
        self.lock = threading.RLock()
        # a graph in a store (a campaign there) is saved back to it; recovery copies stay here
        self.graph_path = place(graph_path) if graph_path else None
        # parameters read from a store are saved here (--out), as parameters given none are
        self.params_path = None if not params_path or is_remote(params_path) else Path(params_path)
        self.out_dir = Path(out_dir)
        # the building's radio map (``edit --map``): weighs in choosing the chain of matches
        # (map_prior.py) and ranks an ambiguous start's candidates
        self.building_map = building_map
        self._by_map: tuple[tuple, MapRanking] | None = None  # the start hint (editor/notes.py)
        self._placed: tuple | None = None  # (result, placed with the map): editor/placed.py
        # a campaign walk's start and end files (walk_fixes.py): "Start here" writes there too
        self.fixes: WalkFixes | None = None
        params = params or Params()
        prior = prior_for_walk(building_map, session, params.localize, "--map")
        self.pipeline = Pipeline(  # start_within: the start searched only there (walks/chain.py)
            session, graph, params, observers, prior=prior, start_within=start_within
        )
        # the edits to undo and redo, each with the tab that made it, and what each tab was
        # told (editor/history.py): a tab's Undo takes back its own edit
        self.edits = History()
        self.by = self.edits.by  # ``with editor.by(tab_id):`` what follows is that tab's
        if swept := self._sweep():
            self.message = f"removed {swept} temporary file(s) a killed save had left"
        self.last_run_ms = 0.0
        self.result: Result = self.rerun()
        self.inferred_start: Track | None = None
        self._keep_start()
        self._saved_graph = graph
        self._saved_params = self.params

    # ---- unsaved work ----------------------------------------------------------------------
    @property
    def unsaved(self) -> list[str]:
        """What differs from the files: "graph", "parameters"."""
        out = []
        if self.graph != self._saved_graph:
            out.append("graph")
        if self.params != self._saved_params:
            out.append("parameters")
        return out

    def recovery_paths(self) -> tuple[Path, Path]:
        return recovery_paths(self.graph_path, self.params_path, self.out_dir)

    def _keep_recovery(self) -> None:
        keep_recovery(self.recovery_paths(), self.unsaved, self.graph, self.params)

    def _run(self, graph=None, params=None) -> None:
        """Re-run after a change, timed, and note which matches the change lost."""
        old = self.result.track if self.result else None
        before = set(old.detections.node[old.detections.matched]) if old is not None else set()
        t = time.perf_counter()
        self.result = self.pipeline.run(graph=graph, params=params)
        self.last_run_ms = (time.perf_counter() - t) * 1e3
        after = set(self.result.track.detections.node[self.result.track.detections.matched])
        self.lost_matches = sorted(before - after)
        if self.pipeline.start is None:
            self._keep_start()  # inferred again (the kept start was deleted): keep the new one
        self._keep_recovery()

    def _keep_start(self) -> None:
        """Keep an inferred start for the edits that follow (a search over every landmark on
        each edit is slow on a real walk, and a graph edit elsewhere should not move the start);
        :meth:`infer_start` searches again."""
        tr = self.result.track
        if not self.params.pdr.start_node and tr.start.node and not np.isnan(tr.start.margin):
            self.inferred_start = tr
            self.pipeline.start = tr.start.node

    def infer_start(self) -> str:
        """Search every landmark for the start again (after the graph changed a lot, or to drop
        a start the surveyor gave)."""
        with self.lock:
            self.pipeline.start = None
            self.pipeline.forget("tracking")
            given = self.params.pdr.start_node
            self._run(params=self.params.updated(**{"pdr.start_node": None}) if given else None)
            self._keep_start()
            tr = self.result.track
            alt = f"; next best {tr.start.alternative}" if tr.start.alternative else ""
            said = f"start inferred: {tr.start.node}{alt}" + self._lost_note()
            if given and self.fixes is not None:  # the start given in the campaign is dropped
                said += self.fixes.record("start", None)
            self.message = said  # (once written: what it says is done)
            return tr.start.node

    def set_start(self, node_id: str) -> bool:
        """The walk starts at ``node_id`` (the surveyor knows better than an ambiguous
        inference): ``pdr.start_node``, saved with the parameters."""
        return self._given("start", node_id)

    def set_end(self, node_id: str | None) -> bool:
        """The walk ended at ``node_id`` (the surveyor stopped recording there; None: found
        again from the walk): ``pdr.end_node``, saved with the parameters (walk_end.py)."""
        return self._given("end", node_id)

    def _given(self, what: str, node_id: str | None) -> bool:
        node_id = None if node_id is None else str(node_id)  # a numpy string does not save
        if node_id is not None and node_id not in self.graph.ids:
            self.message = f"refused: no landmark {node_id!r} to {what} at"
            return False
        ok = self.set_param(f"pdr.{what}_node", node_id)
        if ok:
            said = f"{what}s at {node_id} (given)" if node_id else f"{what} is found again"
            said = f"the walk {said}" + self._lost_note()
            if self.fixes is not None:
                said += self.fixes.record(what, node_id)
            self.message = said
        return ok

    def start_note(self, s: Summary | None = None) -> str:
        """Where the walk starts and how sure that is, for the panel (markdown); ``s``: the
        :meth:`summary` when the caller has it (:func:`.notes.start_note`)."""
        return start_note(self, self.summary() if s is None else s)

    def start_hints(self, s: Summary | None = None) -> list[tuple[str, str]]:
        """Where to look for an ambiguous start, drawn on the plan beside "Start here"
        (:func:`.notes.start_hints`); ``s``: the :meth:`summary` when the caller has it."""
        return start_hints(self, self.summary() if s is None else s)

    # ---- state -----------------------------------------------------------------------------
    @property
    def message(self) -> str:
        """What the last action said (to the tab acting now: what its own last action said)."""
        return self.edits.message

    @message.setter
    def message(self, text: str) -> None:
        self.edits.say(text)

    @property
    def history(self) -> list:
        """The edits that can be undone, oldest first."""
        return self.edits.done

    @property
    def graph(self) -> LandmarkGraph:
        return self.pipeline.graph

    @property
    def params(self) -> Params:
        return self.pipeline.params

    @property
    def session(self) -> Session:
        return self.pipeline.session

    def _sweep(self) -> int:
        return sweep(self.graph_path, self.params_path, self.out_dir)

    def summary(self) -> Summary:
        out = self.result.summary(self.session, self.graph)
        inf = self.inferred_start
        if inf is not None and self.pipeline.start == self.result.track.start.node:
            start = start_inference(inf) or out.start  # the start inferred at load decides
            out = mark(replace(out, start=start, start_inferred_at_load=True), bool(self.graph.nodes))
        return out

    def rerun(self) -> Result:
        with self.lock:
            t = time.perf_counter()
            self.result = self.pipeline.run()
            self.last_run_ms = (time.perf_counter() - t) * 1e3
            return self.result

    # ---- graph edits -----------------------------------------------------------------------
    def _edit(self, what, make) -> bool:
        with self.lock:
            try:
                new = make(self.graph)
            except (GraphError, KeyError, ValueError) as e:
                self.message = f"refused: {e}".replace("invalid landmark graph:\n  ", "")
                return False
            what = what() if callable(what) else what  # (known once made: a new id)
            old = self.graph
            self.edits.record(old, new, what)
            before = self.result.track if self.result else None  # (a moved start drags the new)
            self._run(graph=new)
            self.message = what + self._far_note(old, new, before) + self._lost_note()
            return True

    def _far_note(self, old: LandmarkGraph, new: LandmarkGraph, track: Track | None) -> str:
        moved = [n for n in new.nodes if n not in set(old.nodes)]
        return far_note(moved, new, track)

    def _lost_note(self) -> str:
        lost = getattr(self, "lost_matches", [])
        if not lost:
            return ""
        shown = ", ".join(lost[:6]) + ("…" if len(lost) > 6 else "")
        return f" — {len(lost)} landmark(s) no longer matched: {shown}"

    def move_node(self, node_id: str, x: float, y: float) -> bool:
        return self._edit(
            f"moved {node_id} to ({x:.2f}, {y:.2f})",
            lambda g: g.with_node(replace(g.node(node_id), x=float(x), y=float(y))),
        )

    def set_floor(self, node_id: str, floor: float) -> bool:
        return self._edit(
            f"{node_id} is on floor {floor:g}",
            lambda g: g.with_node(replace(g.node(node_id), floor=float(floor))),
        )

    def set_rules(self, node_id: str, rules) -> bool:
        rules = frozenset(rules)
        bad = sorted(rules - set(RULES))
        if bad:
            self.message = f"refused: unknown rule {bad[0]!r}"
            return False
        return self._edit(
            f"{node_id} rules: {', '.join(sorted(rules)) or 'none'}",
            lambda g: g.with_node(replace(g.node(node_id), rules=rules)),
        )

    def set_name(self, node_id: str, name: str) -> bool:
        return self._edit(
            f"{node_id} renamed", lambda g: g.with_node(replace(g.node(node_id), name=name or None))
        )

    def new_id(self) -> str:
        used = set(self.graph.ids)
        k = len(used) + 1
        while f"N{k}" in used:
            k += 1
        return f"N{k}"

    def add_node(
        self,
        x: float,
        y: float,
        floor: float,
        rules=(),
        name: str | None = None,
        node_id: str | None = None,
    ) -> str | None:
        chosen: list[str] = []

        def make(g: LandmarkGraph):  # under the editor's lock: two tabs never pick one new id
            nid = node_id or self.new_id()
            if nid in g.ids:
                raise GraphError(f"node {nid}: duplicate id")
            chosen.append(nid)
            return g.with_node(
                Landmark(nid, float(x), float(y), float(floor), frozenset(rules), name)
            )

        ok = self._edit(lambda: f"added {chosen[0]}", make)
        return chosen[0] if ok else None

    def delete_node(self, node_id: str) -> bool:
        return self._edit(f"deleted {node_id} and its edges", lambda g: g.without_node(node_id))

    def connect(self, a: str, b: str, oneway: bool = False) -> bool:
        return self._edit(
            f"connected {a} {'->' if oneway else '<->'} {b}", lambda g: g.with_edge(a, b, oneway)
        )

    def disconnect(self, a: str, b: str) -> bool:
        return self._edit(f"disconnected {a} and {b}", lambda g: g.without_edge(a, b))

    def undo(self) -> bool:
        """Take back the acting tab's last edit (the Python API: the last of all)."""
        return self._step("undo")

    def redo(self) -> bool:
        return self._step("redo")

    def _step(self, how: str) -> bool:
        with self.lock:
            mine = " of this tab" if self.edits.origin is not None else ""
            try:
                step = getattr(self.edits, how)(self.graph)
            except Conflict as c:
                self.message = (f"refused: cannot {how} — {c.node} was changed since "
                                "(in another tab?); change it back by hand")  # fmt: skip
                return False
            except GraphError as err:
                self.message = f"refused: cannot {how} — {err}"
                return False
            if step is None:
                self.message = f"nothing{mine} to {how}"
                return False
            g, edit, later = step
            self._run(graph=g)
            kept = f" ({later} later edit(s) of other tabs kept)" if later else ""
            self.message = f"{how}ne: {edit.what}{kept}" + self._lost_note()
            return True

    # ---- parameters ------------------------------------------------------------------------
    def set_param(self, key: str, value) -> bool:
        with self.lock:
            try:
                p = self.params.updated(**{key: value})
            except ParameterError as e:
                self.message = f"refused: {e}"
                return False
            old = self.params
            try:
                self._run(params=p)
            except GraphError as e:  # a start or end typed in that is no landmark of the graph
                self._run(params=old)
                self.message = f"refused: {e}"
                return False
            self.message = f"{key} = {value}" + self._lost_note()
            return True

    # ---- saving and export -----------------------------------------------------------------
    def save_graph(self, path: str | Path | None = None) -> Path:
        with self.lock:
            path = Path(path) if path else self.graph_path
            if path is None:
                raise WorkstationError("no graph file to save to")
            bak = self.graph.save(path)
            self._saved_graph = self.graph
            self._keep_recovery()
            self.message = f"saved {path}" + (f" (previous kept as {bak.name})" if bak else "")
            return path

    def save_params(self, path: str | Path | None = None) -> Path:
        with self.lock:
            path = Path(path) if path else (self.params_path or self.out_dir / "params.yaml")
            bak = self.params.save(path)
            self._saved_params = self.params
            self._keep_recovery()
            self.message = f"saved {path}" + (f" (previous kept as {bak.name})" if bak else "")
            return path

    def export_radiomap(self, fmt: str = "csv") -> Path:
        with self.lock:
            path = self.out_dir / f"radiomap.{fmt}"
            held = reasons(self.summary())
            device = self.session.metadata.device
            write_radiomap(
                radiomap_table(self.result), path, self.graph.frame, quarantined=held, device=device
            )
            rm = self.result.radiomap
            self.message = (f"exported {rm.reference_points} reference points (and "
                            f"{int(rm.held_for_sigma.sum())} on standby) to {path}")  # fmt: skip
            return path
