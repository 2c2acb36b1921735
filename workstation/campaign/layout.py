"""What a campaign is: buildings, each with a landmark graph, optional building file and
parameters, and walks. Either a folder::

    CAMPAIGN/buildings/<name>/graph.yaml   (building.yaml, params.yaml, starts.yaml, ends.yaml
                                            optional)
    CAMPAIGN/buildings/<name>/walks/<walk files or session folders>

or a YAML file listing them::

    buildings:
      museum: {graph: museum.yaml, params: p.yaml, walks: ["logs/*.txt"], start: first-fix,
               starts: {walk03: L12}, ends: {walk05: L40}}

Paths in the YAML are relative to it; walk entries may be globs. Either may live in an object
store (issue #54): ``s3://bucket/campaign/`` (a folder's layout under the prefix) or
``s3://bucket/campaign.yaml``; entries in the YAML may be URLs themselves. Walks in a store are
listed here, never read: the workers read them (:mod:`.jobs`). ``starts`` (``starts.yaml`` in a
folder: ``walk03: L12`` per line) gives single walks their start landmark — how a surveyor fixes
a walk whose inferred start was ambiguous; the key is the walk's name in the campaign's output
(its file name without the extension). ``ends`` (``ends.yaml``) gives single walks the landmark
they ended on (``pdr.end_node``) — how a surveyor fixes a walk that matched nothing, or whose
end the sensors put elsewhere. Both are checked against the walks and the graph by
:func:`.starts.check_starts`.
"""

from __future__ import annotations

import glob
import re
from dataclasses import dataclass
from pathlib import Path

from workstation.errors import InputError
from workstation.io.store import is_remote, is_url, place, read_via_local, store_errors
from workstation.io.yamlio import load_yaml

# a building's name becomes a folder under --out: one plain name, never a path out of it
NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._ -]{0,99}")


def check_name(name: str, source, where: str) -> str:
    if not NAME.fullmatch(name) or ".." in name:
        raise InputError(
            source,
            f"{where}: {name[:60]!r} is not a building name — one folder name of letters, digits, "
            "'.', '_', '-' and spaces (no '/', no '..'), at most 100 characters",
        )
    return name


def _yaml(p, what: str):
    return read_via_local(p, lambda local: load_yaml(local, what))


@dataclass(frozen=True)
class BuildingSpec:
    """A building of a campaign; its paths are :class:`Path` on disk, ``UPath`` in a store."""

    name: str
    graph: Path
    walks: tuple[Path, ...]
    params: Path | None = None
    building: Path | None = None
    # how each walk's start is found: first-fix (needs truth; inferred without), a landmark id,
    # or infer (walks that stood at one place decide theirs together, campaign/shared_pass.py)
    start: str | None = "first-fix"
    # single walks' start landmarks (walk key, landmark id), and the file they are (or would
    # be) given in: the building's starts.yaml, or the campaign file
    starts: tuple[tuple[str, str], ...] = ()
    starts_source: Path | None = None
    # single walks' end landmarks, likewise (ends.yaml, or the campaign file)
    ends: tuple[tuple[str, str], ...] = ()
    ends_source: Path | None = None


def load_campaign(path: str | Path) -> list[BuildingSpec]:
    where = place(path)
    with store_errors(where):
        if where.is_dir():
            return _from_folder(where)
        if not where.is_file():
            raise InputError(where, "no such campaign folder or file")
        return _from_yaml(where)


def _walks_in(folder: Path) -> tuple[Path, ...]:
    if not folder.is_dir():
        return ()
    out = []
    for p in sorted(folder.iterdir()):
        if p.name.startswith("."):
            continue
        if p.is_dir() and (p / "session.yaml").is_file() or p.is_file():
            out.append(p)
    return tuple(out)


def _from_folder(root: Path) -> list[BuildingSpec]:
    bdir = root / "buildings"
    if not bdir.is_dir():
        raise InputError(root, "a campaign folder holds buildings/<name>/ (graph.yaml, walks/)")
    out = []
    for b in sorted(p for p in bdir.iterdir() if p.is_dir() and not p.name.startswith(".")):
        check_name(b.name, b, "buildings/")
        g = b / "graph.yaml"
        if not g.is_file():
            raise InputError(b, "building without graph.yaml")
        sy, ey = b / "starts.yaml", b / "ends.yaml"
        starts = _starts(_yaml(sy, "walk starts"), sy, "") if sy.is_file() else ()
        ends = _starts(_yaml(ey, "walk ends"), ey, "", "ends") if ey.is_file() else ()
        out.append(
            BuildingSpec(
                b.name,
                g,
                _walks_in(b / "walks"),
                b / "params.yaml" if (b / "params.yaml").is_file() else None,
                b / "building.yaml" if (b / "building.yaml").is_file() else None,
                starts=starts,
                starts_source=sy,
                ends=ends,
                ends_source=ey,
            )  # fmt: skip
        )
    if not out:
        raise InputError(bdir, "no buildings")
    return out


def _from_yaml(path: Path) -> list[BuildingSpec]:
    data = _yaml(path, "campaign file")
    if not isinstance(data, dict) or not isinstance(data.get("buildings"), dict):
        raise InputError(path, "a campaign file has 'buildings: {name: {graph, walks, ...}}'")
    base = path.parent
    out = []
    for name, e in data["buildings"].items():
        check_name(str(name), path, "buildings")
        if not isinstance(e, dict) or "graph" not in e or "walks" not in e:
            raise InputError(path, f"buildings.{name}: needs graph and walks")
        walks: list[Path] = []
        for w in e["walks"] if isinstance(e["walks"], list) else [e["walks"]]:
            walks += _matches(_beside(base, w))
        opt = {k: (_beside(base, e[k]) if e.get(k) else None) for k in ("params", "building")}
        out.append(
            BuildingSpec(
                str(name),
                _beside(base, e["graph"]),
                tuple(walks),
                opt["params"],
                opt["building"],
                _start(e.get("start", "first-fix"), path, f"buildings.{name}.start"),
                _starts(e.get("starts"), path, f"buildings.{name}.starts: "),
                path,
                _starts(e.get("ends"), path, f"buildings.{name}.ends: ", "ends"),
                path,
            )  # fmt: skip
        )
    return out


def _beside(base, entry):
    """A path in a campaign file: a URL or an absolute path as it is, else relative to the
    file's folder (a folder in a store too)."""
    text = str(entry)
    if is_url(text) or (not is_remote(base) and Path(text).is_absolute()):
        return place(text)
    return base / text


def _matches(p) -> list:
    """A walk entry: itself, or what its glob matches (on disk or in the store)."""
    pat = str(p)
    if not any(c in pat for c in "*?["):
        return [p]
    if is_remote(p):
        return sorted(place(f"{p.protocol}://{hit}") for hit in p.fs.glob(p.path))
    return sorted(Path(hit) for hit in glob.glob(pat))


def _start(value, source: Path, where: str) -> str:
    """How a building's walks find their start: a landmark id, ``first-fix`` or ``infer``. A
    value that is none of these (``0`` is a landmark id; ``false``, ``[]``, ``{}``, null or ""
    meant "no start" without a word, issue #55 item 7) is refused, naming the file."""
    if isinstance(value, bool) or not isinstance(value, (str, int)) or str(value).strip() == "":
        raise InputError(
            source, f"{where}: a landmark id, first-fix or infer — not {value!r}"
        )
    return str(value).strip()


def _starts(data, source: Path, where: str, what: str = "starts") -> tuple[tuple[str, str], ...]:
    """``{walk: landmark}`` as pairs (walk starts or ``what``: ends); anything else is refused,
    naming the file."""
    if data is None:
        return ()
    if not isinstance(data, dict) or not all(
        isinstance(k, (str, int)) and isinstance(v, (str, int)) for k, v in data.items()
    ):
        raise InputError(
            source, f"{where}walk {what} are a mapping 'walk name: landmark id' (walk03: L12)"
        )
    return tuple((str(k), str(v)) for k, v in data.items())
