"""The panel's scene: the plan image, the graph (nodes draggable), the run's results and the
selection, for the floor on view: a part of panel (:class:`~workstation.viz.panel_host.PanelHost`), which
holds one and calls it on every redraw."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from workstation.editor.placed import MAP, WALK, placed_with_map
from workstation.pipeline.summary import Summary
from workstation.viz.colours import EDGES, point_kinds, rgb, rule_rgb
from workstation.viz.panel_zoom import NODE_RADIUS_M
from workstation.viz.plan_image import viser_pose
from workstation.viz.walk_marks import walk_marks

# the walk's lines in pixels, whatever the zoom (issue #50 item 5); the landmark spheres let
# the track under them show through
TRACK_PX, TRUTH_PX, MARKS_PX = 3.0, 2.0, 2.0
NODE_OPACITY = 0.75

if TYPE_CHECKING:
    from workstation.viz.panel_host import PanelHost


def _segments(
    x: np.ndarray, y: np.ndarray, keep: np.ndarray, z: float, stride: int = 1
) -> np.ndarray:
    """(K, 2, 3) segments between consecutive samples that are both kept (a polyline with gaps)."""
    x, y, keep = x[::stride], y[::stride], keep[::stride]
    both = keep[:-1] & keep[1:]
    p = np.column_stack([x, y, np.full(x.size, z)])
    return np.stack([p[:-1][both], p[1:][both]], axis=1)


def edge_segments(g, floor: float) -> tuple[np.ndarray, np.ndarray]:
    """(K, 2, 3) segments and (K, 2, 3) uint8 colours of the edges touching ``floor``: a line
    per connected pair, one colour on one floor, the barometer rule's across floors; a one-way edge also gets an
    arrow head (two short strokes) at its middle."""
    if not g.edges:
        return np.zeros((0, 2, 3)), np.zeros((0, 2, 3), np.uint8)
    idx = {nid: i for i, nid in enumerate(g.ids)}
    xyf = g.xyf()
    e = np.array([(idx[u], idx[v]) for u, v in g.edges], np.int64)
    directed = set(g.edges)
    back = np.array([(v, u) in directed for u, v in g.edges])
    u_gt_v = np.array([u > v for u, v in g.edges])
    a, b = xyf[e[:, 0]], xyf[e[:, 1]]
    keep = ((a[:, 2] == floor) | (b[:, 2] == floor)) & ~(back & u_gt_v)  # both ways: one line
    a, b, one_way = a[keep], b[keep], ~back[keep]
    col = np.where((a[:, 2] == b[:, 2])[:, None], EDGES["floor"], EDGES["across"])
    p = np.column_stack([a[:, :2], np.full(len(a), 0.05)])
    q = np.column_stack([b[:, :2], np.full(len(b), 0.05)])
    segs, cols = [np.stack([p, q], axis=1)], [col]
    d = (q - p)[:, :2]
    length = np.hypot(d[:, 0], d[:, 1])
    arrow = one_way & (length > 0.1)
    if arrow.any():
        mid = (p[arrow] + q[arrow]) / 2
        segs.append(chevrons(mid[:, :2], d[arrow] / length[arrow, None], 0.05, 0.8))
        cols.append(np.repeat(col[arrow], 2, axis=0))
    colors = np.concatenate(cols).astype(np.uint8)
    return np.concatenate(segs), np.repeat(colors[:, None, :], 2, axis=1)


def chevrons(at: np.ndarray, d: np.ndarray, z: float, size: float) -> np.ndarray:
    """(2K, 2, 3) segments: an arrow head (two short strokes) at each point of ``at`` (K, 2)
    pointing along the unit directions ``d`` (K, 2); ``size`` metres long."""
    normal = np.column_stack([-d[:, 1], d[:, 0]])
    tip = np.column_stack([at, np.full(len(at), z)])
    wings = [at - size * d + side * 0.5 * size * normal for side in (1, -1)]
    return np.concatenate(
        [np.stack([tip, np.column_stack([w, np.full(len(w), z)])], axis=1) for w in wings]
    )


class SceneLayer:
    """What the panel draws of the floor on view, and the handles it keeps to redraw only what
    changed."""

    def __init__(self, panel: PanelHost):
        self.p = panel
        self.image_key: tuple | None = None  # (floor, opacity) of the plan image drawn
        self.node_handles: dict[str, tuple] = {}  # landmark → (drawn state, sphere, label)
        self.hint_rings: list = []  # the start hints' rings (scaled as the spheres: panel_zoom)
        self.hint_labels: list = []
        self.hint_at: list = []  # (label, x, y) of each ranked hint: stacked by the zoom fit
        self.mark_at: list = []  # (label, x, y) of the walk's start and end labels: kept put
        self.placed_drawn = False  # the building's map's arrows and links are on the scene

    def draw_plan_image(self) -> None:
        """The floor's plan image under everything, faded towards white by the opacity slider;
        sent again only when the floor or the opacity changes."""
        p = self.p
        img = p.building.image(p.floor) if p.building is not None else None
        key = (p.floor, round(float(p.opacity.value), 2)) if img is not None else None
        if key == self.image_key:
            return
        self.image_key = key
        sc = p.server.scene
        if img is None:
            sc.add_frame("/plan_image", show_axes=False, visible=False)
            return

        rgb, a = img.display()
        op = float(p.opacity.value)
        # viser lays the image's rows along +y; ours run south (image v grows downwards)
        faded = (rgb[::-1].astype(np.float32) * op + 255.0 * (1.0 - op)).astype(np.uint8)
        cx, cy, (w, h), theta = viser_pose(a, (rgb.shape[1], rgb.shape[0]))
        q = (float(np.cos(theta / 2)), 0.0, 0.0, float(np.sin(theta / 2)))
        sc.add_image(
            "/plan_image", faded, w, h, format="jpeg", jpeg_quality=85,
            position=(cx, cy, -0.02), wxyz=q, cast_shadow=False, receive_shadow=False,
        )  # fmt: skip

    def draw_graph(self) -> None:
        sc, g, f = self.p.server.scene, self.p.ed.graph, self.p.floor
        arr, colors = edge_segments(g, f)
        if len(arr):
            sc.add_line_segments("/graph/edges", arr, colors, thickness=0.15)
        self._draw_nodes(sc, {n.id: n for n in g.nodes if n.floor == f})

    def _draw_nodes(self, sc, want: dict) -> None:
        """The landmarks on view, each a draggable sphere and a label. Only what changed is
        sent: a moved landmark's handles are moved, an edited one redrawn, the others left
        alone (a 10,000-landmark graph re-sent every node and label after every edit)."""
        drawn = self.node_handles
        for nid in [k for k in drawn if k not in want]:
            for h in drawn.pop(nid)[1:]:
                h.remove()
        for nid, n in want.items():
            state = (n.x, n.y, n.rules, n.name)
            old = drawn.get(nid)
            if old is not None and old[0] == state:
                continue
            if old is not None and old[0][2:] == state[2:]:  # moved only
                old[1].position = (n.x, n.y, 0.3)
                old[2].position = (n.x, n.y, 1.2)
                drawn[nid] = (state, old[1], old[2])
                continue
            if old is not None:
                for h in old[1:]:
                    h.remove()
            h = sc.add_icosphere(
                f"/graph/nodes/{nid}", radius=NODE_RADIUS_M, color=rule_rgb(n.rules),
                opacity=NODE_OPACITY, position=(n.x, n.y, 0.3),
            )  # fmt: skip
            text = nid if not n.name else f"{nid} · {n.name[:24]}"
            lab = sc.add_label(f"/graph/labels/{nid}", text, position=(n.x, n.y, 1.2))
            self._bind_node(h, nid)
            drawn[nid] = (state, h, lab)

    def _bind_node(self, handle, node_id: str) -> None:
        @handle.on_click
        def _(e) -> None:
            self.p.select(node_id, e.client_id)  # in the tab that clicked

        @handle.on_drag
        async def _(e) -> None:
            if e.phase == "end":
                x, y = float(e.end_position[0]), float(e.end_position[1])
                with self.p.ed.by(e.client_id):  # this tab's edit (its Undo takes it back)
                    self.p.ed.move_node(node_id, x, y)
                self.p.after_edit(select=node_id, client_id=e.client_id)

    def draw_results(self, summary: Summary | None = None) -> None:
        """The walk's results on the floor on view (``summary``: the run's, when the caller has
        it: a quarantined walk's track is drawn in the quarantine's colour, as in Rerun)."""
        sc, r, f = self.p.server.scene, self.p.ed.result, self.p.floor
        tr = r.track
        held = bool((summary or self.p.ed.summary()).quarantine)
        # coloured by the segment's trust: blue where belief trusts it, grey where it does not
        trusted = np.zeros(tr.steps.t.size, bool)
        ok = tr.steps.segment >= 0
        trusted[ok] = r.belief.accepted[tr.steps.segment[ok]] if r.belief.accepted.size else False
        on = ok & (tr.steps.floor == f)
        for name, m, col in (
            ("trusted", on & trusted, rgb("quarantined" if held else "trajectory")),
            ("untrusted", on & ~trusted, rgb("quarantined" if held else "untrusted")),
        ):
            segs = _segments(tr.steps.x, tr.steps.y, m, 0.1)
            sc.add_line_segments(  # in pixels: 0.1 m was half a pixel on the whole mall
                f"/results/trajectory/{name}",
                segs if len(segs) else np.zeros((1, 2, 3)),
                col,
                thickness=TRACK_PX,
                thickness_units="screen",
                visible=bool(len(segs)),
            )
        self.draw_walk_marks(tr)
        gt = self.p.ed.session.ground_truth
        if gt is not None and len(gt) > 1:
            segs = _segments(gt.x, gt.y, gt.floor == f, 0.08, stride=max(1, len(gt) // 4000))
            sc.add_line_segments(
                "/results/ground_truth",
                segs if len(segs) else np.zeros((1, 2, 3)),
                rgb("ground_truth"),
                thickness=TRUTH_PX,
                thickness_units="screen",
                visible=bool(len(segs)),
            )
        rm = r.radiomap
        for name, sel in point_kinds(rm):
            col = rgb(name)
            mm = sel & (rm.floor == f)
            pts = (
                np.column_stack([rm.x[mm], rm.y[mm], np.full(int(mm.sum()), 0.2)])
                if mm.any()
                else np.zeros((1, 3))
            )
            sc.add_point_cloud(
                f"/results/reference_points/{name}",
                pts.astype(np.float32),
                col,
                point_size=0.5,
                point_shape="circle",
                visible=bool(mm.any()),
            )

        self.draw_placed()

    def draw_placed(self) -> None:
        """With the building's map (``edit --map``): where merging would move the walk's points
        (slate arrows from where its run placed them) and its links to the map's scans (khaki),
        on the floor on view (:mod:`workstation.editor.placed`)."""
        sc, f = self.p.server.scene, self.p.floor
        got = placed_with_map(self.p.ed)
        if got is None and not self.placed_drawn:  # no map: nothing sent on each redraw
            return
        self.placed_drawn = got is not None
        moved = links = np.zeros((0, 2, 3))
        if got is not None:
            before, res = got
            after, ref = res.maps[WALK], res.maps[MAP]
            on = before.floor == f
            d = np.hypot(after.x - before.x, after.y - before.y)
            mv = on & (d >= 0.5)
            z = np.full(int(mv.sum()), 0.22)
            a = np.column_stack([before.x[mv], before.y[mv], z])
            b = np.column_stack([after.x[mv], after.y[mv], z])
            if mv.any():
                u = (b - a)[:, :2] / d[mv, None]
                moved = np.concatenate([np.stack([a, b], axis=1), chevrons(b[:, :2], u, 0.22, 0.6)])
            n = len(after)
            ends = res.links[:, :2].astype(int) if len(res.links) else np.zeros((0, 2), int)
            mine = ends[(ends[:, 0] < n) & (ends[:, 1] >= n)]
            mine = mine[on[mine[:, 0]]]
            if len(mine):
                i, j = mine[:, 0], mine[:, 1] - n
                zz = np.full(i.size, 0.18)
                links = np.stack([np.column_stack([after.x[i], after.y[i], zz]),
                                  np.column_stack([ref.x[j], ref.y[j], zz])], axis=1)  # fmt: skip
        for name, segs, col in (("moved", moved, rgb("placed_alone")),
                                ("links", links, rgb("joint_links")[:3])):  # fmt: skip
            sc.add_line_segments(f"/results/placed/{name}",
                                 segs if len(segs) else np.zeros((1, 2, 3)), col,
                                 thickness=2.0 if name == "moved" else 1.0,
                                 thickness_units="screen", visible=bool(len(segs)))  # fmt: skip

    def draw_walk_marks(self, tr) -> None:
        """Where the walk starts and ends (labelled with the landmark and the time) and which
        way it went (arrow heads along the track), on the floor on view (:mod:`.walk_marks`)."""
        sc, f, col = self.p.server.scene, self.p.floor, rgb("walk_marks")
        marks = walk_marks(tr)
        none = ((0.0, 0.0, np.nan), "")  # a walk that never set off: hidden
        ends = ((marks.start, marks.start_label), (marks.end, marks.end_label)) if marks else (
            none, none)  # fmt: skip
        self.mark_at = []
        for name, (pos, label) in zip(("start", "end"), ends):
            here = pos[2] == f
            # a halo round the landmark's sphere, labelled above-left (its name is to the right)
            sc.add_icosphere(f"/results/walk_marks/{name}", radius=1.8, color=col, opacity=0.6,
                             position=(pos[0], pos[1], 0.25), visible=here)  # fmt: skip
            lab = sc.add_label(f"/results/walk_marks/{name}_label", label, anchor="bottom-right",
                               position=(pos[0], pos[1], 1.5), visible=here)  # fmt: skip
            if here:  # the start hints stack above it (panel_zoom.py)
                self.mark_at.append((lab, pos[0], pos[1]))
        a = marks.on_floor(f) if marks else np.zeros((0, 5))
        segs = chevrons(a[:, :2], a[:, 3:5], 0.15, 1.6) if len(a) else np.zeros((1, 2, 3))
        sc.add_line_segments("/results/walk_marks/direction", segs, col, thickness=MARKS_PX,
                             thickness_units="screen", visible=bool(len(a)))  # fmt: skip

    def draw_start_hints(self, summary: Summary | None = None) -> None:
        """An ambiguous start's likeliest candidates (``ed.start_hints``: by the building's map,
        else by the sensors), ringed on the plan and numbered: where to select a landmark and
        press "Start here". Drawn again after every run (the rank follows the graph)."""
        for h in self.hint_rings + self.hint_labels:
            h.remove()
        self.hint_rings, self.hint_labels, self.hint_at = [], [], []
        p = self.p
        sc, g = p.server.scene, p.ed.graph
        ids = set(g.ids)
        scale = p.zoom.node_scale()
        for rank, (nid, said) in enumerate(p.ed.start_hints(summary), 1):
            if nid not in ids or g.node(nid).floor != p.floor:
                continue
            n = g.node(nid)
            self.hint_rings.append(sc.add_icosphere(
                f"/start_hints/{rank}/ring", radius=2.2 * NODE_RADIUS_M, color=rgb("start_hint"),
                opacity=0.5, scale=scale, position=(n.x, n.y, 0.3)))  # fmt: skip
            self.hint_labels.append(sc.add_label(
                f"/start_hints/{rank}/label", f"start? #{rank} {nid} · {said}",
                position=(n.x, n.y, 2.4), anchor="bottom-right"))  # fmt: skip
            self.hint_at.append((self.hint_labels[-1], n.x, n.y))
        w = p.ed.pipeline.start_within  # the reach of where the walk before ended (walks/chain.py)
        if w and (w[2] is None or w[2] == p.floor):
            x, y, _, r = w
            a = np.linspace(0.0, 2.0 * np.pi, 73)
            ring = np.column_stack([x + r * np.cos(a), y + r * np.sin(a), np.full(a.size, 0.3)])
            # with the labels: drawn in metres, not scaled with the spheres
            self.hint_labels.append(sc.add_line_segments(
                "/start_hints/reach", np.stack([ring[:-1], ring[1:]], axis=1), rgb("start_hint"),
                thickness=0.4))  # fmt: skip
            self.hint_labels.append(sc.add_label(
                "/start_hints/reach/label", f"start within {r:.0f} m of where the walk before ended",
                position=(x, y + r, 2.4), anchor="bottom-left"))  # fmt: skip
