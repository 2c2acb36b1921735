"""Scans held back for their σ wait on standby and join a merged map where no reference point
covers them within the join radius (workstation/fingerprints/standby.py; ``COVER_M`` for 1-NN,
``JOIN_M`` = 0 — every one joins — with the default weighted 5-NN): the rule, its leave-one-out
form, the files that carry it, and the evaluation's pooled maps against merging the others anew."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from workstation.errors import InputError
from workstation.evaluate.map_kinds import _Pool, score_kind
from workstation.fingerprints.localize import Fingerprints, localize
from workstation.fingerprints.matchers import of_params
from workstation.fingerprints.standby import (
    COVER_M,
    JOIN_M,
    JOIN_MAX_SIGMA_M,
    joins,
    joins_without_one,
)
from workstation.params import Params

REPO = Path(__file__).resolve().parents[1]


def _walk(rng, n, standby_share, aps, x0=0.0, floor=0.0):
    """A walk's map: n points along a corridor, a share of them on standby."""
    x = x0 + np.sort(rng.uniform(0, 60, n))
    y = rng.normal(0, 1.0, n)
    rss = rng.uniform(-95, -40, (n, aps.size))
    rss[rng.random(rss.shape) < 0.4] = np.nan
    wait = rng.random(n) < standby_share
    return Fingerprints(x, y, np.full(n, floor), aps, rss, standby=wait if wait.any() else None)


def test_a_row_on_standby_joins_only_where_no_point_covers_it():
    x = np.array([0.0, 20.0, 2.0, 30.0, 0.0 + COVER_M + 0.01, 3.0])
    y = np.zeros(6)
    floor = np.array([0, 0, 0, 0, 0, 1.0])
    wait = np.array([False, False, True, True, True, True])
    # 2 m from a point: out; 10 m: in; just beyond the radius: in; above a point, another floor: in
    assert joins(x, y, floor, wait, COVER_M).tolist() == [False, False, False, True, True, True]
    assert not joins(x, y, floor, np.zeros(6, bool), COVER_M).any()
    assert joins(x, y, floor, np.ones(6, bool), COVER_M).all()  # nothing covers anything
    assert JOIN_M == 0 and np.array_equal(joins(x, y, floor, wait), wait)  # the default: all


def test_a_row_on_standby_whose_sigma_is_over_the_cap_never_joins():
    """A row on standby with σ over JOIN_MAX_SIGMA_M stays out under either radius, in the
    merged map's rule, its leave-one-out form and a map settled for use; at the cap it joins."""
    x, y, floor = np.array([0.0, 20.0, 40.0, 60.0]), np.zeros(4), np.zeros(4)
    wait = np.array([False, True, True, True])
    sig = np.array([1.0, JOIN_MAX_SIGMA_M, JOIN_MAX_SIGMA_M + 0.1, np.inf])
    for r in (JOIN_M, COVER_M):
        assert joins(x, y, floor, wait, r, sig).tolist() == [False, True, False, False]
        always, only = joins_without_one(x, y, floor, wait, np.arange(4), r, sig)
        assert always.tolist() == [False, True, False, False] and (only == -1).all()
    fp = Fingerprints(x, y, floor, np.array(["a"]), np.full((4, 1), -60.0), standby=wait,
                      sigma=sig)  # fmt: skip
    assert fp.settled().x.tolist() == [0.0, 20.0]
    assert len(replace(fp, sigma=None).settled()) == 4  # no σ carried: the radius alone


@pytest.mark.parametrize("seed", range(5))
def test_leave_one_out_form_is_the_rule_on_the_other_walks(seed):
    """For each walk left out, the rows that join are exactly those the rule gives on the other
    walks' rows alone."""
    rng = np.random.default_rng(seed)
    aps = np.array(["a", "b", "c"])
    maps = [_walk(rng, 40, 0.3, aps, x0=rng.uniform(0, 40)) for _ in range(5)]
    merged = Fingerprints.merge(maps, settle=False)
    owner = np.repeat(np.arange(5), [len(m) for m in maps])
    always, only = joins_without_one(merged.x, merged.y, merged.floor, merged.on_standby, owner,
                                     COVER_M)  # fmt: skip
    assert not (only == owner).any()  # never waiting for its own walk to leave
    for w in range(5):
        rest = owner != w
        direct = joins(merged.x[rest], merged.y[rest], merged.floor[rest], merged.on_standby[rest],
                       COVER_M)  # fmt: skip
        assert np.array_equal((always | (only == w))[rest], direct)


def test_merging_settles_and_keeps_the_device_offsets_of_the_reference_points():
    rng = np.random.default_rng(3)
    aps = np.array(["a", "b", "c", "d"])
    a, b = _walk(rng, 50, 0.0, aps), _walk(rng, 50, 0.0, aps)
    wait = np.zeros(70, bool)
    wait[50:] = True  # 20 rows on standby, far off along the corridor and 12 dB weaker
    far = Fingerprints(
        np.concatenate([b.x, b.x[:20] + 200]), np.concatenate([b.y, b.y[:20]]), np.zeros(70),
        aps, np.vstack([b.rss, b.rss[:20] - 12]), standby=wait, device="",
    )  # fmt: skip
    m = Fingerprints.merge([a, far], align_devices=True)
    assert m.standby is None and len(m) == 120  # all 20 join: nothing within 5 m of them
    plain = Fingerprints.merge([a, b], align_devices=True)
    assert m.offsets_db == plain.offsets_db  # fitted on the reference points alone
    near = Fingerprints.merge([a, _walk(rng, 50, 0.5, aps)], settle=False)
    assert len(near.settled(COVER_M)) < 100  # 1-NN's rule: the covered ones leave
    assert near.settled().standby is None and len(near.settled()) == 100  # the default: all


@pytest.mark.parametrize("align", [False, True])
def test_pooled_maps_are_the_map_merged_from_the_others(align):
    """The evaluation's pool settles rows on standby once for every walk left out; each walk
    localized on it gets what merging the other walks anew gives."""
    rng = np.random.default_rng(7)
    aps = np.array([f"ap{i}" for i in range(8)])
    maps = {f"w{i}": _walk(rng, 15, 0.5, aps, x0=rng.uniform(0, 80)) for i in range(6)}
    maps = {k: m.shifted(float(rng.normal(0, 4))) for k, m in maps.items()}  # device offsets
    queries = {k: _walk(rng, 10, 0.0, aps, x0=float(m.x.mean()) - 30) for k, m in maps.items()}
    lp = Params().localize
    assert _Pool(maps, COVER_M).extra  # 1-NN's rule: some rows join only while one walk is out
    res = score_kind("ours", {k: {"ours": m} for k, m in maps.items()}, queries,
                     {k: np.ones(len(q), bool) for k, q in queries.items()}, lp, align)  # fmt: skip
    err = []
    for q, qf in queries.items():
        rm = Fingerprints.merge([m for k, m in maps.items() if k != q], align_devices=align)
        est = localize(rm, qf, tau=lp.tau_dbm, align_device=align, matcher=of_params(lp))
        err.append(np.hypot(est.x - qf.x, est.y - qf.y))
    assert res.mean_with_floor_penalty_m == pytest.approx(np.concatenate(err).mean(), abs=1e-3)


def test_a_radio_map_file_carries_its_rows_on_standby(tmp_path):
    from workstation.export import write_radiomap

    rng = np.random.default_rng(1)
    m = _walk(rng, 20, 0.5, np.array(["a", "b"]))
    p = tmp_path / "radiomap.csv"
    write_radiomap(m.to_frame(), p, None)
    back = Fingerprints.read(p)
    assert np.array_equal(back.on_standby, m.on_standby)
    assert len(Fingerprints.merge([back])) == len(m.settled())
    text = p.read_text().splitlines()
    col = text[0].split(",").index("standby")
    row = text[3].split(",")
    row[col] = "Tru"
    text[3] = ",".join(row)
    p.write_text("\n".join(text) + "\n")
    with pytest.raises(InputError, match=r"radiomap.csv:4: standby must be True or False"):
        Fingerprints.read(p)


def test_real_walks_merge_their_standby_rows_where_nothing_covers_them(tmp_path, capsys):
    """Two bundled mall walks through `run` and `merge`: each radiomap.csv carries its scans
    held back for σ on standby; the merged map holds every reference point and every standby
    row (the default join radius, 0), and 1-NN's rule would have kept exactly those farther than
    COVER_M from all of them (checked by brute force)."""
    from workstation.cli import main

    data = REPO / "tests" / "data" / "msilc"
    graph = data / "site1_f1_graph.yaml"
    outs = []
    for w in ("5dd9e7b29191710006b5705b", "5dd9e7c1c5b77e0006b17333"):
        out = tmp_path / w
        assert main(["run", str(data / f"{w}.txt.gz"), "--graph", str(graph),
                     "--start", "first-fix", "--out", str(out)]) == 0  # fmt: skip
        outs.append(out / "radiomap.csv")
    from workstation.walks.joint import correct

    # where merge puts the points: the walks placed together first (walks/joint.py)
    read = {str(p): Fingerprints.read(p) for p in outs}
    maps = list(correct(read).maps.values())
    wait = np.concatenate([m.on_standby for m in maps])
    assert wait.sum() >= 5 and (~wait).sum() >= 20
    x, y = np.concatenate([m.x for m in maps]), np.concatenate([m.y for m in maps])
    d = np.hypot(x[wait][:, None] - x[~wait][None], y[wait][:, None] - y[~wait][None]).min(axis=1)
    ok = (np.concatenate([m.sigma for m in maps]) <= JOIN_MAX_SIGMA_M)[wait]  # σ lets them
    assert 0 < ok.sum() < ok.size  # (some of these walks' rows are over the cap)
    merged = Fingerprints.merge(maps, settle=False)
    assert len(merged.settled(COVER_M)) == int((~wait).sum() + ((d > COVER_M) & ok).sum())
    capsys.readouterr()
    assert main(["merge", *map(str, outs), "-o", str(tmp_path / "merged.csv")]) == 0
    said = capsys.readouterr().out
    assert len(Fingerprints.read(tmp_path / "merged.csv")) == int((~wait).sum() + ok.sum())
    assert f"{ok.sum()} of the {wait.sum()} scans on standby" in said
    assert f"{ok.size - ok.sum()} with sigma over {JOIN_MAX_SIGMA_M:g} m left out" in said


def test_a_walks_rows_held_for_sigma_are_found_by_time_beside_a_half_left_out():
    """evaluate's placement of the rows on standby that join (walk_scores.standby_joined): a
    half of the walk the joint estimate left out is on standby too (never joining) — the rows
    held back for their σ are still the ones scored, found by their times."""
    from workstation.evaluate.walk_scores import _held_joining

    t = np.arange(10) * 2.0
    held = np.array([0, 0, 1, 0, 0, 1, 0, 1, 0, 0], bool)  # held back for σ: t = 4, 10, 14
    m = Fingerprints(np.zeros(10), np.zeros(10), np.zeros(10), np.array(["a"]),
                     np.full((10, 1), -60.0), standby=held, t=t)  # fmt: skip
    joined = np.array([0, 0, 1, 0, 0, 0, 0, 1, 0, 0], bool)
    assert _held_joining(m, joined, t[held]).tolist() == [True, False, True]
    # its second half (t ≥ 10) left out: on standby, never joining
    out = replace(m, standby=held | (t >= 10))
    assert _held_joining(out, joined & (t < 10), t[held]).tolist() == [True, False, False]
