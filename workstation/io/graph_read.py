"""Reading a landmark graph's mapping (YAML or JSON): each part checked, and an error that names
the file, the line and the node or edge for anything a surveyor could have mistyped. Plain values
out; :meth:`.graph.LandmarkGraph.from_dict` builds the graph from them."""

from __future__ import annotations

import math
from typing import Any

import yaml

from workstation.errors import GraphError
from workstation.geo import LocalFrame
from workstation.rules import NAMES as RULES

TOP_KEYS = ("frame", "floors", "landmark_sigma_m", "nodes", "edges")
NODE_KEYS = ("id", "x", "y", "floor", "rules", "name")
EDGE_KEYS = ("from", "to", "oneway")


def lists(data: Any, source: str | None) -> tuple[list, list]:
    """The mapping's node and edge lists (no unknown top-level key)."""
    if not isinstance(data, dict):
        raise GraphError("a landmark graph is a mapping with 'nodes' and 'edges'", source)
    unknown = set(data) - set(TOP_KEYS)
    if unknown:
        raise GraphError(
            f"unknown top-level key(s): {', '.join(sorted(map(str, unknown)))}", source
        )
    raw_nodes = data.get("nodes") or []
    raw_edges = data.get("edges") or []
    if not isinstance(raw_nodes, list) or not isinstance(raw_edges, list):
        raise GraphError("'nodes' and 'edges' must be lists", source)
    return raw_nodes, raw_edges


def frame(raw: Any, source: str | None) -> LocalFrame | None:
    """``frame: {origin_lat, origin_lon}`` → the frame (None when absent)."""
    if raw is None:
        return None
    try:
        out = LocalFrame(float(raw["origin_lat"]), float(raw["origin_lon"]))
    except (TypeError, KeyError, ValueError, OverflowError):
        raise GraphError("frame needs numeric origin_lat and origin_lon", source) from None
    if not (abs(out.origin_lat) <= 90 and abs(out.origin_lon) <= 180):
        raise GraphError("frame: origin_lat/origin_lon out of range", source)
    return out


def node(
    rn: Any, at: str, source: str | None
) -> tuple[str, float, float, float, frozenset, str | None]:
    """One item of ``nodes`` (``at``: where it is, for errors) → id, x, y, floor, rules, name."""
    if not isinstance(rn, dict):
        raise GraphError(f"{at}: a node is a mapping with id, x, y, floor", source)
    extra = set(rn) - set(NODE_KEYS)
    if extra:
        raise GraphError(f"{at}: unknown key(s) {', '.join(sorted(map(str, extra)))}", source)
    nid = rn.get("id")
    if nid is None or isinstance(nid, (bool, float, list, dict)) or str(nid).strip() == "":
        raise GraphError(f"{at}: missing or invalid id", source)
    nid = str(nid)
    xyf = []
    for k in ("x", "y", "floor"):
        v = rn.get(k)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not finite(v):
            raise GraphError(f"node {nid} ({at}): {k} must be a finite number, got {v!r}", source)
        xyf.append(float(v))
    rules = rn.get("rules") or []
    if isinstance(rules, str):
        rules = [rules]
    if not isinstance(rules, list):
        raise GraphError(f"node {nid}: rules must be a list", source)
    bad = [r for r in rules if r not in RULES]
    if bad:
        raise GraphError(
            f"node {nid} ({at}): unknown rule {bad[0]!r} (known: {', '.join(RULES)})", source
        )
    name = rn.get("name")
    return nid, xyf[0], xyf[1], xyf[2], frozenset(rules), None if name is None else str(name)


def edge(re_: Any, at: str, source: str | None) -> list[tuple[str, str]]:
    """One item of ``edges`` → its directed pairs (both ways unless ``oneway``)."""
    if not isinstance(re_, dict) or "from" not in re_ or "to" not in re_:
        raise GraphError(f"{at}: an edge is a mapping with from and to", source)
    extra = set(re_) - set(EDGE_KEYS)
    if extra:
        raise GraphError(f"{at}: unknown key(s) {', '.join(sorted(map(str, extra)))}", source)
    u, v = str(re_["from"]), str(re_["to"])
    if not isinstance(re_.get("oneway", False), bool):  # "false" (a string) is true
        raise GraphError(f"{at}: oneway must be true or false, not {re_['oneway']!r}", source)
    return [(u, v)] if re_.get("oneway", False) else [(u, v), (v, u)]


def floor_heights(raw: Any, source: str | None) -> tuple[tuple[float, float], ...]:
    """``floors: {floor: height_m}`` → sorted pairs; numbers only, finite, one height a floor."""
    if raw is None:
        return ()
    if not isinstance(raw, dict):
        raise GraphError("floors: expected a mapping of floor number to height in metres", source)
    out = []
    for f, h in raw.items():
        try:
            fv, hv = float(f), float(h)
        except (TypeError, ValueError, OverflowError):
            raise GraphError(
                f"floors: {f!r}: {h!r} is not a floor number and a height in metres", source
            ) from None
        if not (math.isfinite(fv) and math.isfinite(hv)) or abs(hv) > 1e4:
            raise GraphError(
                f"floors: {f!r}: height {h!r} is not a plausible height in metres", source
            )
        out.append((fv, hv))
    out.sort()
    for (f0, h0), (f1, h1) in zip(out, out[1:]):
        if h1 <= h0:
            raise GraphError(
                f"floors: floor {f1:g} ({h1:g} m) is not above floor {f0:g} ({h0:g} m)", source
            )
    return tuple(out)


def landmark_sigma(raw: Any, source: str | None) -> float | None:
    """``landmark_sigma_m``: a number of metres in (0, 50], or absent."""
    if raw is None:
        return None
    if isinstance(raw, bool) or not isinstance(raw, (int, float)) or not finite(raw):
        raise GraphError(f"landmark_sigma_m must be a number of metres, got {raw!r}", source)
    if not 0 < raw <= 50:
        raise GraphError(f"landmark_sigma_m must be in (0, 50] m, got {raw!r}", source)
    return float(raw)


def item_lines(root) -> dict[str, dict[int, int]]:
    """Line numbers (1-based) of each item of the top-level 'nodes' and 'edges' lists."""
    out: dict[str, dict[int, int]] = {}
    if not isinstance(root, yaml.MappingNode):
        return out
    for k, v in root.value:
        if (
            isinstance(k, yaml.ScalarNode)
            and k.value in ("nodes", "edges")
            and isinstance(v, yaml.SequenceNode)
        ):
            out[k.value] = {i: item.start_mark.line + 1 for i, item in enumerate(v.value)}
    return out


def finite(v) -> bool:
    try:
        return math.isfinite(v) and abs(float(v)) < 1e12
    except OverflowError:  # an int too large for a float
        return False
