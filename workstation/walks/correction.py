"""What a walk's links to the other walks say after the joint estimate
(:mod:`workstation.walks.joint`): the record of what the estimate did to one walk, and the bars
that name it — a median disagreement of at least ``UNRECONCILED_M`` over ``MIN_LINKS`` links or
more, at most ``AGREE_SHARE`` of them within ``AGREE_M`` — over the whole walk or one half of it
in time; and whether that doubt rests on one other walk alone, itself in doubt (then the links
cannot say which of the two is off, and the words say so: :func:`alone`, :func:`resting`)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from workstation.walks.joint_solve import LINK_M

UNRECONCILED_M = 15.0  # the median disagreement of a walk's links that names it
MIN_LINKS = 10  # links a walk needs for anything to be said of it (a median over fewer is noise)
AGREE_M = 2 * LINK_M  # a link agrees when its residual is within this …
AGREE_SHARE = 0.25  # … and a walk is unreconciled only when at most this share of its links do
MOVED_M = 2.0  # a walk moved this far somewhere is named (merge, the campaign report)

#: the reason a walk the estimate left out is held for (a campaign's and evaluate's rows)
UNRECONCILED = "unreconciled"

WHAT_TO_DO = (
    "open it in the panel (workstation edit) on the building's map: check its start and the "
    "landmarks it matched where its track leaves the others; fix the start, the end or the "
    "graph and run it again, or walk it again"
)


@dataclass(frozen=True)
class WalkCorrection:
    """What the joint estimate did to one walk."""

    name: str
    rows: int
    links: int
    shift_mean_m: float  # mean length of the correction over its rows
    shift_max_m: float
    where: str  # the part that moved most: "the whole walk", "its first half", "its second half"
    disagree_m: float  # after the estimate: length of the median residual of its links
    covered: float  # share of its rows another kept walk's point lies within COVER_M of
    agree: float = 1.0  # share of its links within AGREE_M after the estimate
    left_out: bool = False
    #: what ``links``, ``disagree_m``, ``agree`` and ``covered`` are of: the whole walk, or the
    #: half of it in time the others cannot reconcile (:func:`.joint._report`), from
    #: ``part_s[0]`` to ``part_s[1]`` (s); ``part_out``: that half's rows left out, the rest kept
    part: str = "the whole walk"
    part_s: tuple[float, float] | None = None
    part_out: bool = False
    #: the one other walk its doubt rests on, itself in doubt — without that walk's links the
    #: bars would not hold, so which of the two is off the links cannot say (:func:`alone`)
    only_against: str = ""

    @property
    def unreconciled(self) -> bool:
        """Off the same way at most of its scans: a large median disagreement, and hardly any
        link agreeing (a good walk some of whose scans look like a place far away — stale or
        moved APs — has the rest agreeing)."""
        return doubt(self.links, self.disagree_m, self.agree)

    @property
    def moved(self) -> bool:
        """Moved ``MOVED_M`` or more somewhere, and reconciled: named by merge, listed in
        campaign.md (the farthest on average first: the likeliest placed wrong)."""
        return self.shift_max_m >= MOVED_M and not self.unreconciled

    @property
    def fate(self) -> str:
        """What became of it in the merged map, when the others cannot reconcile it: "left out",
        "its second half left out" (or first), "kept" (nothing else covers it); "" when they
        can."""
        if not self.unreconciled:
            return ""
        return ("left out" if self.left_out else f"{self.part} left out" if self.part_out
                else "kept")  # fmt: skip

    def words(self) -> str:
        """What the estimate did to it, as merge, the campaign and evaluate say it."""
        if not self.unreconciled:
            return (f"{self.name}: moved by {self.shift_mean_m:.1f} m on average (at most "
                    f"{self.shift_max_m:.1f} m, {self.where}) to agree with {self.links} links "
                    "to other walks")  # fmt: skip
        what = "it" if self.part_s is None else (
            f"{self.part} ({self.part_s[0]:.0f}–{self.part_s[1]:.0f} s)")  # fmt: skip
        if self.only_against:
            why = (f"the WiFi of {self.only_against} alone puts {what} {self.disagree_m:.0f} m "
                   f"away ({self.links} links, {100 * self.agree:.0f} % within {AGREE_M:g} m), "
                   f"and the other walks cannot reconcile {self.only_against} either: one of "
                   "the two is off, the links cannot say which — look at both")  # fmt: skip
        elif self.part_s is not None:
            why = (f"the other walks' WiFi still puts {what} {self.disagree_m:.0f} m away, the "
                   f"rest agreeing ({self.links} links of that half, {100 * self.agree:.0f} % "
                   f"within {AGREE_M:g} m): two walks joined, or a wrong landmark there")  # fmt: skip
        else:
            why = (f"the other walks' WiFi still puts it {self.disagree_m:.0f} m away after "
                   f"moving it by {self.shift_max_m:.1f} m ({self.links} links, "
                   f"{100 * self.agree:.0f} % of them within {AGREE_M:g} m)")  # fmt: skip
        if self.left_out or self.part_out:
            out = "that half left out" if self.part_out else "left out"
            return f"{self.name}: {why}; {out}: other walks cover where it went"
        went = "where it went" if self.part_s is None else "where that half went"
        alone = f"only it covers {100 * (1 - self.covered):.0f} % of {went}"
        return f"{self.name}: {why}; kept: {alone}"

    def to_dict(self) -> dict[str, Any]:
        out = {"walk": self.name, "rows": self.rows, "links": self.links,
               "shift_mean_m": round(self.shift_mean_m, 2),
               "shift_max_m": round(self.shift_max_m, 2), "where": self.where,
               "disagree_m": round(self.disagree_m, 2), "covered": round(self.covered, 3),
               "agree": round(self.agree, 3),
               "unreconciled": self.unreconciled, "left_out": self.left_out}  # fmt: skip
        if self.part_s is not None:
            out |= {"part": self.part, "part_s": [round(v, 1) for v in self.part_s],
                    "part_out": self.part_out}  # fmt: skip
        return out | ({"only_against": self.only_against} if self.only_against else {})

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> WalkCorrection:
        """:meth:`to_dict` read back (a campaign report's row)."""
        part_s = d.get("part_s")
        return cls(str(d["walk"]), int(d["rows"]), int(d["links"]), float(d["shift_mean_m"]),
                   float(d["shift_max_m"]), str(d["where"]), float(d["disagree_m"]),
                   float(d["covered"]), float(d.get("agree", 1.0)), bool(d.get("left_out")),
                   str(d.get("part") or "the whole walk"),
                   None if part_s is None else (float(part_s[0]), float(part_s[1])),
                   bool(d.get("part_out")), str(d.get("only_against") or ""))  # fmt: skip


def doubt(links: int, disagree_m: float, agree: float) -> bool:
    """The bars that name a walk (or a half of one): enough links, a large median
    disagreement, hardly any link agreeing."""
    return links >= MIN_LINKS and disagree_m >= UNRECONCILED_M and agree <= AGREE_SHARE


def alone(rx: np.ndarray, ry: np.ndarray, partner: np.ndarray) -> str:
    """The other walk (``partner``: per link) without whose links the bars (:func:`doubt`)
    would no longer hold, "" if there is none or they do not hold at all. A doubt that rests
    on one walk in doubt too does not say which of the two is off: a good walk most of whose
    links go to a wrong one (two walks joined into one file, placed 80 m off where the good
    walk went) is named for the wrong walk's error — and the words say so
    (:func:`resting`; the four mall floors with joins: 3 good walks, docs/experiments.md)."""
    if not doubt(*agreement(rx, ry)):
        return ""
    ids, counts = np.unique(partner, return_counts=True)
    for p in ids[np.argsort(-counts, kind="stable")]:
        if not doubt(*agreement(rx[partner != p], ry[partner != p])):
            return str(p)
    return ""


def resting(walks: dict[str, WalkCorrection]) -> dict[str, WalkCorrection]:
    """Which doubts rest on one other walk itself in doubt (``only_against`` kept; else
    cleared: the walk is the odd one out). Both stay named, and both leave the map where
    others cover them: a wrong half 80 m off kept costs the map more than a covered good walk
    left out (mall F1 with joins: 1.53 → 1.98 × the tap oracle, docs/experiments.md)."""
    out = dict(walks)
    for n, w in walks.items():
        p = walks.get(w.only_against)
        if w.only_against and (p is None or not doubt(p.links, p.disagree_m, p.agree)):
            out[n] = replace(w, only_against="")
    return out


def agreement(rx: np.ndarray, ry: np.ndarray) -> tuple[int, float, float]:
    """Links' count, the length of their median residual, the share within ``AGREE_M``."""
    if not rx.size:
        return 0, 0.0, 1.0
    return (int(rx.size), float(np.hypot(np.median(rx), np.median(ry))),
            float(np.mean(np.hypot(rx, ry) <= AGREE_M)))  # fmt: skip
