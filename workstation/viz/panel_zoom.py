"""Landmarks stay easy to hit and read at any zoom (issue #30 item 5): at building zoom a 0.6-m
sphere was ~3 px and labels piled into unreadable clusters. After each camera move the panel
works out how many metres a screen pixel spans and

- scales every landmark sphere so it is at least ``HIT_PX`` pixels across (a fixed hit target
  on screen, never smaller than its 0.6-m size in metres);
- shows only the labels that do not overlap one already shown (:func:`thin`), the selected
  landmark's first, then landmarks with rules, then the rest: zooming in shows them all;
- stacks an ambiguous start's ranked hints ("start? #1 …") so none hides another, and hides
  the landmark labels under them (:func:`stack`; issue #50 item 8: candidates a few metres
  apart printed on top of each other).

viser's scene is shared by every tab, so the last tab that moved its camera decides.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from workstation.viz.panel_host import PanelHost

HIT_PX = 16.0  # a landmark's sphere at least this many pixels across
NODE_RADIUS_M = 0.6
CHAR_PX, LINE_PX = 7.0, 18.0  # a label's character width and line height on screen
CHANGE = 0.15  # re-thin when the scale changed by more than this fraction


def metres_per_pixel(position, look_at, fov: float, image_height: int) -> float:
    """Metres one screen pixel spans at the point looked at (perspective camera)."""
    dist = float(np.linalg.norm(np.subtract(position, look_at)))
    return 2.0 * dist * math.tan(fov / 2.0) / max(int(image_height), 1)


def stack(xy: np.ndarray, chars: np.ndarray, mpp: float) -> np.ndarray:
    """Heights for labels anchored bottom-right at ``xy`` (in order: the first stays where it
    is): each goes up a line at a time until its box overlaps none placed before it."""
    w = np.asarray(chars, float) * CHAR_PX * mpp
    h = LINE_PX * mpp
    y = np.asarray(xy, float)[:, 1].copy()
    for i in range(len(y)):
        for _ in range(i + 1):  # at most one line up per label below it
            hit = [j for j in range(i) if abs(y[i] - y[j]) < h
                   and xy[i, 0] - w[i] < xy[j, 0] and xy[j, 0] - w[j] < xy[i, 0]]  # fmt: skip
            if not hit:
                break
            y[i] = max(y[j] for j in hit) + h
    return y


def thin(xy: np.ndarray, chars: np.ndarray, mpp: float, fixed: int = 0) -> np.ndarray:
    """Keep-mask over labels at ``xy`` (metres, in priority order) of ``chars`` characters:
    greedily, a label is kept unless its box (centred; ``CHAR_PX`` per character by
    ``LINE_PX``, in pixels × ``mpp``) overlaps a kept one. The first ``fixed`` are kept
    whatever they overlap (labels shown in any case, that the others make room for)."""
    n = len(xy)
    keep = np.zeros(n, bool)
    if n == 0:
        return keep
    w = np.asarray(chars, float) * CHAR_PX * mpp
    h = LINE_PX * mpp
    cell = max(float(w.max()), h, 1e-9)
    grid: dict[tuple[int, int], list[int]] = {}
    for i in range(n):
        cx, cy = int(xy[i, 0] // cell), int(xy[i, 1] // cell)
        clash = False
        for gx in (cx - 1, cx, cx + 1):
            for gy in (cy - 1, cy, cy + 1):
                for j in grid.get((gx, gy), ()):
                    if (abs(xy[i, 0] - xy[j, 0]) < (w[i] + w[j]) / 2
                            and abs(xy[i, 1] - xy[j, 1]) < h):  # fmt: skip
                        clash = True
                        break
                if clash:
                    break
            if clash:
                break
        if not clash or i < fixed:
            keep[i] = True
            grid.setdefault((cx, cy), []).append(i)
    return keep


class ZoomFit:
    """Built by the panel: ``attach(client)`` for each tab, ``apply()`` after each redraw."""

    def __init__(self, panel: PanelHost):
        self.p = panel
        self.mpp: float | None = None
        self._applied: float | None = None

    def attach(self, client) -> None:
        @client.camera.on_update
        def _(cam) -> None:
            mpp = metres_per_pixel(cam.position, cam.look_at, cam.fov, cam.image_height)
            if self._applied is None or abs(mpp / self._applied - 1.0) > CHANGE:
                self.mpp = mpp
                with self.p.redraw_lock:
                    self.apply()

    def node_scale(self) -> float:
        """The landmark spheres' scale for the last camera (1 before the first)."""
        return 1.0 if self.mpp is None else max(1.0, HIT_PX * self.mpp / (2 * NODE_RADIUS_M))

    def apply(self) -> None:
        """Size the spheres and thin the labels of the landmarks on view for the last scale."""
        if self.mpp is None:
            return
        self._applied = self.mpp
        scale = self.node_scale()
        for ring in self.p.scene.hint_rings:  # the start hints ring the spheres: scaled alike
            if ring.scale != scale:
                ring.scale = scale
        for form in list(self.p.forms.values()):  # and each tab's selection halo
            sel = form._sel
            if sel is not None and sel.scale != scale:
                try:
                    sel.scale = scale
                except RuntimeError:  # the tab went away: its next draw makes a new one
                    form._sel = None
        marks = self.p.scene.mark_at  # stay put; the start hints stack above them
        hints = marks + self.p.scene.hint_at
        hxy = np.array([[x, y] for _, x, y in hints], float).reshape(-1, 2)
        hchars = np.array([len(lab.text) for lab, _, _ in hints], float)
        hy = stack(hxy, hchars, self.mpp)
        for (lab, x, _), y in list(zip(hints, hy))[len(marks) :]:
            lab.position = (x, float(y), 2.4)
        # the landmark labels make room for them: thinned with the hints' boxes (centred) first
        boxes = np.column_stack([hxy[:, 0] - hchars * CHAR_PX * self.mpp / 2,
                                 hy + LINE_PX * self.mpp / 2]).reshape(-1, 2)  # fmt: skip
        drawn = self.p.scene.node_handles
        if not drawn:
            return
        g = self.p.ed.graph
        selected = {f.selected for f in self.p.forms.values()}
        ids = [i for i in drawn if i in g.ids]
        ids.sort(key=lambda i: (i not in selected, not g.node(i).rules))
        xy = np.array([[g.node(i).x, g.node(i).y] for i in ids]).reshape(-1, 2)
        chars = np.array([len(drawn[i][2].text) for i in ids])
        n = len(hints)
        keep = thin(np.vstack([boxes, xy]), np.concatenate([hchars, chars]), self.mpp, n)[n:]
        for i, k in zip(ids, keep):
            state, sphere, label = drawn[i]
            if sphere.scale != scale:
                sphere.scale = scale
            if label.visible != bool(k):
                label.visible = bool(k)
