"""The full fuzz probe of issues #18, #33 and #55, on demand: N mutations (default 10,000) of
each reader's input — half line-level (tests/test_fuzz_readers.py), half a separator inserted
(a comma, semicolon, colon, tab or space: one extra comma once shifted every column of a radio
map) — for the landmark graph, parameters, building file, radio-map CSV, session header,
GetSensorData logfile (and its sensor values set to what no phone gives), IPIN .cal, survey plan, Microsoft ILC path file, floor_info.json, control
points and campaign definition, each loaded under a 5-s alarm and a 1-GB cap on the memory it
may add (MemoryError past it). What loads is used as a surveyor's next command would: a
building's plan images displayed, a session's summary made, a campaign's jobs planned; and
checked for being silently wrong: saved and read back it must be the same (graph, parameters,
building, radio map). Prints the table: loaded, typed error, uncaught (by exception type), over
5 s, over 1 GB, silently wrong. The CI-sized run is tests/test_fuzz_readers.py.

    python benchmarks/fuzz.py [N] [reader name contains ...]
"""

from __future__ import annotations

import collections
import resource
import shutil
import signal
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from tests.conftest import gsd_lines  # noqa: E402
from tests.test_fuzz_readers import MS, WALK, mutations  # noqa: E402
from workstation.building import Building  # noqa: E402
from workstation.errors import WorkstationError  # noqa: E402
from workstation.fingerprints.localize import Fingerprints  # noqa: E402
from workstation.graph import LandmarkGraph  # noqa: E402
from workstation.params import Params  # noqa: E402
from workstation.session import load_session  # noqa: E402

LIMIT_S = 5
LIMIT_BYTES = 1 << 30  # what one load may add to the probe's address space


class _Slow(Exception):
    pass


class _NotReloaded(Exception):
    """Saved, then refused or changed when read back: a value that loads "fine" but is wrong."""


SEPARATORS = (",", ";", ":", "\t", " ")


def _separators(text: str, n: int, seed: int):
    """``n`` copies of ``text``, each with one separator inserted at a random place."""
    import random

    rng = random.Random(seed)
    for _ in range(n):
        k = rng.randrange(len(text) + 1)
        yield text[:k] + rng.choice(SEPARATORS) + text[k:]


def _mutations(text: str, n: int, seed: int):
    yield from mutations(text, n - n // 2, seed)
    yield from _separators(text, n // 2, seed)


def _same_after_save(load, save, same):
    """``load``, then used: saved, read back, and compared (``same``) — raising _NotReloaded when
    what came back differs or is refused."""

    def run(p: Path):
        got = load(p)
        again = p.with_name("again-" + p.name)
        try:
            save(got, again)
            back = load(again)
        except WorkstationError as e:
            raise _NotReloaded(str(e)) from None
        if not same(got, back):
            raise _NotReloaded("read back differently")
        return got

    return run


def _building_shown(p: Path):
    """A building file loaded, saved and read back the same, and each plan image displayed."""
    b = _same_after_save(Building.load, lambda b, q: b.save(q),
                         lambda a, c: a.to_dict(p.parent) == c.to_dict(p.parent))(p)  # fmt: skip
    for f in b.floors.values():
        if f.image is not None:
            f.image.display(1200)
    return b


def _map_same(a, b) -> bool:
    import numpy as np

    return (len(a) == len(b) and list(a.bssids) == list(b.bssids)
            and all(np.array_equal(getattr(a, k), getattr(b, k), equal_nan=True)
                    for k in ("x", "y", "floor", "rss")))  # fmt: skip


def _saved_reloads(b, tmp: Path):
    """Save a building made by a reader and read it back, as a surveyor's next command would."""
    try:
        b.save(tmp / "made.yaml")
        Building.load(tmp / "made.yaml")
    except WorkstationError as e:
        raise _NotReloaded(str(e)) from None


def _cap_memory() -> None:
    """Address space capped at what the probe holds now plus LIMIT_BYTES."""
    with open("/proc/self/status") as f:
        vm = next(int(ln.split()[1]) * 1024 for ln in f if ln.startswith("VmSize:"))
    resource.setrlimit(resource.RLIMIT_AS, (vm + LIMIT_BYTES, resource.RLIM_INFINITY))


def _alarm(*_):
    raise _Slow


def _readers(tmp: Path):
    from workstation.cli import main

    main(["run", str(WALK), "--graph", str(WALK / "graph.yaml"), "--out", str(tmp / "r")])
    building = (MS / "building.yaml").read_text()
    building = building.replace("floor_image.png", str(MS / "floor_image.png"))
    folder = tmp / "walk"
    shutil.copytree(MS, folder)
    return [
        ("landmark graph YAML", (WALK / "graph.yaml").read_text(), tmp / "g.yaml",
         _same_after_save(LandmarkGraph.load, lambda g, q: g.save(q),
                          lambda a, b: a.to_dict() == b.to_dict())),
        ("parameters YAML", Params().to_yaml(), tmp / "p.yaml",
         _same_after_save(Params.load, lambda x, q: x.save(q), lambda a, b: a == b)),
        ("building YAML", building, tmp / "b.yaml", _building_shown),
        ("radio-map CSV", _whole_rows((tmp / "r" / "radiomap.csv").read_text(), 40),
         tmp / "m.csv", _same_after_save(Fingerprints.read, _write_map, _map_same)),
        ("session folder header", (folder / "session.yaml").read_text(),
         folder / "session.yaml", lambda p: load_session(p.parent).info()),
        ("GetSensorData logfile", "\n".join(gsd_lines()), tmp / "l.txt",
         lambda p: load_session(p).info()),
        ("GetSensorData, values no phone gives", "\n".join(gsd_lines()), tmp / "v.txt",
         _in_range, _values),
    ] + _cal(tmp) + _plan(tmp) + _msilc(tmp) + _floor_info(tmp) + _points(tmp) + _campaign(tmp)  # fmt: skip


SENSOR_LINES = ("ACCE", "GYRO", "MAGN", "WIFI")
WILD = (1e6, -1e6, 1e15, 5000.5, -500.0, 300.0, float("inf"))


def _values(text: str, n: int, seed: int):
    """``n`` copies of a logfile, each with 1–3 values of its sensor lines (a motion sensor's
    axis, a WiFi reading's RSS) set to one no phone gives (issue #67 item 1)."""
    import random

    rng = random.Random(seed)
    lines = text.split("\n")
    at = [i for i, ln in enumerate(lines) if ln.split(";")[0] in SENSOR_LINES]
    for _ in range(n):
        out = list(lines)
        for i in rng.sample(at, rng.randint(1, 3)):
            f = out[i].split(";")
            k = len(f) - 1 if f[0] == "WIFI" else rng.randint(3, 5)
            f[k] = repr(rng.choice(WILD))
            out[i] = ";".join(f)
        yield "\n".join(out)


def _in_range(p: Path):
    """A logfile loaded and, unless refused, holding no value beyond what phones measure —
    else it loaded silently wrong."""
    import numpy as np

    from workstation.physical import PHYSICAL, RSS_DBM

    s = load_session(p)
    for name, (cap, _unit) in PHYSICAL.items():
        xyz = getattr(s, name).xyz
        if len(xyz) and not (np.linalg.norm(xyz, axis=1) <= cap).all():
            raise _NotReloaded(f"{name}: a value beyond {cap:g} kept")
    r = s.wifi.rss_dbm
    if len(r) and not ((r >= RSS_DBM[0]) & (r <= RSS_DBM[1])).all():
        raise _NotReloaded("wifi: an RSS outside its range kept")
    return s.info().to_json()


def _whole_rows(text: str, n: int) -> str:
    return "\n".join(text.split("\n")[:n]) + "\n"


def _write_map(fp, path: Path) -> None:
    from workstation.export import write_radiomap

    write_radiomap(fp.to_frame(), path, fp.frame, device=fp.device)


def _cal(tmp: Path) -> list:
    """An IPIN .cal over two copies of the bundled plan image."""
    from tests.test_fuzz_readers import CAL
    from workstation.building.importers import from_ipin_cal
    from workstation.geo import LocalFrame

    for n in ("plan_a.png", "plan_b.png"):
        shutil.copy(MS / "floor_image.png", tmp / n)
    frame = LocalFrame.around(49.4613, 11.1110)
    return [("IPIN .cal", CAL, tmp / "calib.cal",
             lambda p: _saved_reloads(from_ipin_cal(p, frame), tmp))]  # fmt: skip


def _plan(tmp: Path) -> list:
    """A survey plan's plan.json, read against its graph."""
    from workstation.cli import main
    from workstation.survey_plan.output import read_plan_walks

    main(["plan", "--graph", str(WALK / "graph.yaml"), "--max-minutes", "3", "--out",
          str(tmp / "plan")])  # fmt: skip
    g = LandmarkGraph.load(WALK / "graph.yaml")
    text = (tmp / "plan" / "plan.json").read_text()
    return [("survey plan.json", text, tmp / "mutated.json", lambda p: read_plan_walks(p, g))]


def _msilc(tmp: Path) -> list:
    """A Microsoft ILC path file (its first 400 lines) when ../shared/data is there."""
    from tests.conftest import MSILC

    files = sorted((MSILC / "path_data_files").glob("*.txt"))
    if not files:
        return []
    head = "\n".join(files[0].read_text(errors="replace").splitlines()[:400])
    return [("Microsoft ILC path file", head, tmp / "ms.txt", load_session)]


def _floor_info(tmp: Path) -> list:
    """A Microsoft ILC floor_info.json beside the bundled plan image, made into a building file
    and read back."""
    from workstation.building.importers import from_msilc

    shutil.copy(MS / "floor_image.png", tmp / "floor_image.png")
    return [("floor_info.json", (MS / "floor_info.json").read_text(), tmp / "floor_info.json",
             lambda p: _saved_reloads(from_msilc(p), tmp))]  # fmt: skip


def _points(tmp: Path) -> list:
    """Control points as `building from-points` takes them (one U,V=X,Y a line), fitted, saved
    and read back."""
    from workstation.cli import main

    text = "120,80=0,0\n910,80=40,0\n910,600=40,-26\n120,600=0,-26"

    def load(p: Path):
        pts = [f"--point={ln}" for ln in p.read_text(encoding="utf-8").split("\n")]
        out = tmp / "cp.yaml"
        out.unlink(missing_ok=True)
        if main(["building", "from-points", str(tmp / "floor_image.png"), *pts, "-o",
                 str(out)]) == 0:  # fmt: skip
            try:
                Building.load(out)
            except WorkstationError as e:
                raise _NotReloaded(str(e)) from None
        else:
            raise WorkstationError("refused")  # main printed the typed error

    return [("control points", text, tmp / "points.txt", load)]


def _campaign(tmp: Path) -> list:
    """A campaign definition naming two buildings, their graphs and walks, its jobs planned."""
    from workstation.campaign import load_campaign, plan_jobs

    text = (
        "buildings:\n"
        f"  office:\n    graph: {WALK / 'graph.yaml'}\n    walks: ['{WALK}']\n"
        "    start: infer\n"
        f"  mall:\n    graph: {MS / 'graph.yaml'}\n    walks: ['{MS}']\n"
    )
    return [("campaign definition", text, tmp / "campaign.yaml",
             lambda p: plan_jobs(load_campaign(p)))]  # fmt: skip


def main(n: int, only: list[str] | None = None) -> int:
    tmp = Path(tempfile.mkdtemp())
    signal.signal(signal.SIGALRM, _alarm)
    print(f"| input | tried | loaded | typed error | uncaught | over {LIMIT_S} s | over 1 GB | "
          "silently wrong | seconds |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|")
    bad = 0
    readers = _readers(tmp)
    _cap_memory()
    for seed, (name, text, path, load, *how) in enumerate(readers):
        mutate = how[0] if how else _mutations
        if only and not any(o.lower() in name.lower() for o in only):
            continue
        counts, uncaught = collections.Counter(), collections.Counter()
        t0 = time.perf_counter()
        for t in mutate(text, n, seed=100 + seed):
            path.write_text(t, encoding="utf-8")
            signal.alarm(LIMIT_S)
            try:
                load(path)
                counts["loaded"] += 1
            except WorkstationError:
                counts["typed"] += 1
            except _Slow:
                counts["slow"] += 1
            except MemoryError:
                counts["memory"] += 1
            except _NotReloaded:
                counts["reload"] += 1
            except Exception as e:  # noqa: BLE001 - what the probe is for
                uncaught[type(e).__name__] += 1
            finally:
                signal.alarm(0)
        u = sum(uncaught.values())
        bad += u + counts["slow"] + counts["memory"] + counts["reload"]
        detail = f"{u} ({', '.join(f'{k} {v}' for k, v in uncaught.most_common())})" if u else "0"
        print(f"| {name} | {n:,} | {counts['loaded']:,} | {counts['typed']:,} | {detail} | "
              f"{counts['slow']} | {counts['memory']} | {counts['reload']} | "
              f"{time.perf_counter() - t0:.0f} |", flush=True)  # fmt: skip
    shutil.rmtree(tmp, ignore_errors=True)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(int(sys.argv[1]) if len(sys.argv) > 1 else 10_000, sys.argv[2:]))
