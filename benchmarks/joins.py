"""Two walks joined into one file with every clock re-timed (issue #67 item 2), on demand: each
building's real walks and joined pairs of them, read as a surveyor's ``run`` reads them.

A Microsoft ILC pair: path file B's rows re-timed to follow A's last by 20 ms, its WiFi "last
seen" moved alike (tests/test_two_clocks.py ``join_ilc(careful=True)``); pairs of one floor of
site1. A GetSensorData pair: B's app times moved to follow A's by 10 ms and each sensor's own
timestamps moved to A's offset from the app clock, so neither clock shows the join
(tests/test_second_phone.py ``join_gsd``); every ordered pair of the museum's walks. Each joined file is loaded (the reader's barometer check
may refuse it; the reader looks for a second recording, :mod:`workstation.session.clocks`: with
every clock re-timed, only the phone's state can show it — its calibration, or another phone's
magnetometer resolution) and looked at by
:func:`workstation.pipeline.continuity.facing_jump`, as ``run`` does. Prints, per building:
real walks and how many are flagged by either (must be 0), pairs, refused by the barometer,
caught by the phone's state, by the compass, in all, and how many of the compass's cuts lie
within 2 s of the join.

    python benchmarks/joins.py [PAIRS_PER_MALL_FLOOR]   (default 100)
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from tests.conftest import SHARED_DATA  # noqa: E402
from tests.test_second_phone import join_gsd  # noqa: E402
from tests.test_two_clocks import join_ilc  # noqa: E402
from workstation.errors import WorkstationError  # noqa: E402
from workstation.pipeline.continuity import facing_jump_of  # noqa: E402
from workstation.session import load_session  # noqa: E402
from workstation.session.split import inertial_start  # noqa: E402

FLOORS = ("f1", "f2", "f3", "b1")


def _looks(path: Path) -> tuple[bool, tuple[float, float] | None]:
    """Whether the reader found a second recording (a second clock, the phone's state:
    session/clocks.py), and the compass's jump (where, on the inertial clock, and how much)."""
    s = load_session(path)
    found = facing_jump_of(s)
    jump = None if found is None else (found[0] - inertial_start(s), found[1])
    return s.metadata.clock_jump is not None, jump


def _row(name: str, walks: list[Path], pairs, join, tmp: Path) -> None:
    flagged = sum(reader or jump is not None for reader, jump in map(_looks, walks))
    refused = caught = state = either = near = 0
    for i, (a, b) in enumerate(pairs):
        p = tmp / f"j{i}{''.join(a.suffixes[:1])}"
        at = join(a, b, p)
        try:
            reader, found = _looks(p)
        except WorkstationError:
            refused += 1
            continue
        state += reader
        either += reader or found is not None
        if found is not None:
            caught += 1
            near += abs(found[0] - at) <= 2.0
    n = max(len(pairs), 1)
    print(f"| {name} | {len(walks)} | {flagged} | {len(pairs)} | {refused} | {state} ({state / n:.0%}) "
          f"| {caught} ({caught / n:.0%}) | {refused + either} ({(refused + either) / n:.0%}) "
          f"| {near} of {caught} |", flush=True)  # fmt: skip


def _ilc_join(a: Path, b: Path, out: Path) -> float:
    join_ilc(a, b, out, careful=True)
    first = load_session(a)
    return max(first.accelerometer.t[-1], first.gyroscope.t[-1]) - inertial_start(first) + 0.02


def main(per_floor: int) -> int:
    tmp = Path(tempfile.mkdtemp())
    rng = np.random.default_rng(67)
    print("| building | real walks | flagged | pairs joined | refused (barometer) | caught (the "
          "phone's state) | caught (compass) | caught in all | compass cut within 2 s |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|")
    for fl in FLOORS:
        walks = sorted((SHARED_DATA / f"microsoft-ilc2020-site1-{fl}" / "path_data_files").glob("*.gz"))
        if not walks:
            print(f"| mall {fl.upper()} | not in {SHARED_DATA} | | | | | | | |")
            continue
        idx = [rng.choice(len(walks), 2, replace=False) for _ in range(per_floor)]
        _row(f"mall {fl.upper()}", walks, [(walks[i], walks[j]) for i, j in idx], _ilc_join, tmp)
    museum = sorted((SHARED_DATA / "ipin2023-track3" / "logfiles").glob("*.txt"))
    if museum:
        pairs = [(a, b) for a in museum for b in museum if a != b]
        _row("museum", museum, pairs, join_gsd, tmp)
    return 0


if __name__ == "__main__":
    sys.exit(main(int(sys.argv[1]) if len(sys.argv) > 1 else 100))
