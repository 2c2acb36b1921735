"""The compass turning where the gyroscope did not (pipeline/continuity.py, issue #67 item 2):
a second recording joined on with every clock re-timed. Simulated headings against the jump
put in, over several seeds; every real and bundled walk here unflagged; a real join of two
mall walks with both clocks re-timed quarantined, and ``split`` cuts it where it was joined."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tests.conftest import IPIN, REPO
from tests.test_two_clocks import MSILC, join_ilc
from workstation.cli import main
from workstation.params import Params
from workstation.pipeline.continuity import JUMP_DEG, WINDOW_S, facing_jump
from workstation.pipeline.heading import Heading, estimate_heading
from workstation.pipeline.verdict import EXIT_QUARANTINED
from workstation.session import Scalar, Vector3, load_session
from workstation.session.split import inertial_start

FS = 50.0
JOIN_S = 40.0


def _walk(seed: int, jump_deg: float, *, noisy_compass: bool = False, tilt_deg: float = 0.0,
          floor_hpa: float = 0.0) -> tuple[Heading, Vector3, Scalar]:  # fmt: skip
    """80 s of walking with turns; at JOIN_S the compass-minus-gyro offset jumps by
    ``jump_deg`` (a second recording), optionally with the phone tilted, or a floor changed."""
    rng = np.random.default_rng(seed)
    t = np.arange(0, 80, 1 / FS)
    rate = np.zeros(t.size)
    for t0 in rng.uniform(5, 75, 4):  # four turns of ±90° over 2 s
        rate[(t >= t0) & (t < t0 + 2)] += rng.choice([-1, 1]) * np.pi / 4
    gyro = np.cumsum(rate) / FS
    offset = rng.uniform(-np.pi, np.pi) + 0.002 * t  # a slow drift of the gyroscope's bias
    offset = offset + np.radians(jump_deg) * (t >= JOIN_S)
    noise = np.radians(15) * rng.standard_normal(t.size)  # the building's disturbances
    if noisy_compass:  # a magnetic storm: the compass points anywhere
        noise = rng.uniform(-np.pi, np.pi, t.size)
    compass = np.angle(np.exp(1j * (gyro + offset + noise)))
    tilt = np.radians(tilt_deg) * (t >= JOIN_S)
    up = np.column_stack([np.zeros(t.size), np.sin(tilt), np.cos(tilt)]) * 9.81
    acc = Vector3(t, up + 1.5 * rng.standard_normal((t.size, 3)))
    pressure = Scalar(t, 1000.0 + floor_hpa * (t >= JOIN_S) + 0.03 * rng.standard_normal(t.size))
    return Heading(t, rate, gyro, compass), acc, pressure


@pytest.mark.parametrize("seed", range(4))
def test_a_jump_of_the_offset_is_found_where_it_is_and_as_large(seed):
    for jump in (100.0, 150.0, -120.0):
        found = facing_jump(*_walk(seed, jump))
        assert found is not None
        assert abs(found[0] - JOIN_S) <= 1.0
        assert abs(found[1] - abs(jump)) <= 10.0


@pytest.mark.parametrize("seed", range(4))
def test_what_a_walk_does_is_not_a_jump(seed):
    assert facing_jump(*_walk(seed, 0.0)) is None
    assert facing_jump(*_walk(seed, JUMP_DEG - 30)) is None  # the building's disturbances
    assert facing_jump(*_walk(seed, 150.0, noisy_compass=True)) is None  # nothing steady
    assert facing_jump(*_walk(seed, 150.0, tilt_deg=45.0)) is None  # taken out of a pocket
    assert facing_jump(*_walk(seed, 150.0, floor_hpa=0.45)) is None  # a lift's steel car
    heading, acc, pressure = _walk(seed, 150.0)
    short = heading.t < 2 * WINDOW_S - 1
    cut = Heading(heading.t[short], heading.vertical_rate[short], heading.gyro[short],
                  heading.compass[short])  # fmt: skip
    assert facing_jump(cut, acc, pressure) is None  # shorter than its two windows


def test_no_real_or_bundled_walk_here_has_its_compass_turn_alone():
    walks = sorted(MSILC.glob("*.txt.gz"))
    walks += [p.parent for p in (REPO / "sample_sessions").rglob("session.yaml")]
    walks += sorted((IPIN / "logfiles").glob("*.txt")) if IPIN.exists() else []
    assert len(walks) >= 15
    hp = Params().heading
    flagged = []
    for w in walks:
        s = load_session(w)
        if facing_jump(estimate_heading(s, hp), s.accelerometer, s.pressure) is not None:
            flagged.append(w.name)
    assert flagged == []


@pytest.mark.parametrize("pair", [(9, 0), (3, 7)])
def test_two_mall_walks_joined_with_every_clock_re_timed(tmp_path, capsys, pair):
    """No pause, no second clock (the WiFi "last seen" moved with the rest), no phone state
    (the rows of its calibration dropped): the compass says where the second recording
    begins; quarantined, and ``split`` cuts there."""
    files = sorted(MSILC.glob("*.txt.gz"))
    joined = tmp_path / "joined.txt"
    join_ilc(files[pair[0]], files[pair[1]], joined, careful=True, phone_state=False)
    first = load_session(files[pair[0]])
    at = max(first.accelerometer.t[-1], first.gyroscope.t[-1]) - inertial_start(first)
    s = load_session(joined)
    assert s.metadata.clock_jump is None  # the clocks say nothing
    out = tmp_path / "run"
    graph = MSILC / "site1_f1_graph.yaml"
    assert main(["run", str(joined), "--graph", str(graph), "--out", str(out)]) == EXIT_QUARANTINED
    said = json.loads((out / "summary.json").read_text())
    held = {q["reason"]: q for q in said["quarantine"]}
    assert "facing_jump" in held and "workstation split" in held["facing_jump"]["what_to_do"]
    assert abs(said["facing_jump_at_s"] - at) <= 2.0 and said["facing_jump_deg"] >= JUMP_DEG
    capsys.readouterr()
    assert main(["split", str(joined), "--out", str(tmp_path / "parts")]) == 0
    assert "compass turned" in capsys.readouterr().out
    for i in (1, 2):
        main(["run", str(tmp_path / "parts" / f"joined-{i}"), "--graph", str(graph),
              "--out", str(tmp_path / f"o{i}")])  # fmt: skip
        said = json.loads((tmp_path / f"o{i}" / "summary.json").read_text())
        assert "facing_jump" not in [q["reason"] for q in said["quarantine"]]
    whole = load_session(tmp_path / "parts" / "joined-1")
    assert abs(whole.duration - at) <= 2.0
