"""The building's walks correct each other (walks/joint.py, issue #62), on a simulated corridor
with a log-distance WiFi field and its ground truth, over several seeds: a walk placed a few
metres off is moved back towards where its scans were taken, the walks placed right barely
move; a walk placed 20 m off — farther than the links' robust kernel lets fingerprints pull —
is named with about that distance and left out where others cover it; a walk where nobody else
walked, or some of whose scans look like a place far away, is neither; σ narrows only where
other walks add evidence. On real walks: `merge` names a walk given a start 20 m off."""

from dataclasses import replace

import numpy as np
import pytest

from tests.conftest import REPO
from workstation.cli import main
from workstation.fingerprints.localize import Fingerprints
from workstation.walks.correction import UNRECONCILED_M
from workstation.walks.joint import correct, robust_weight

APS = np.array([(x, 4.0) for x in range(0, 121, 8)], float)


def _walk(rng, shift: float = 0.0, n: int = 24, far_rows: int = 0, sigma: float = 1.5,
          span=(10, 110)):  # fmt: skip
    """Scans along a 120-m corridor (y = 0), one every 2 s: RSS −35 − 25 log10(d) + N(0, 3) dB;
    placed at the truth + N(0, 1 m), plus ``shift`` m along x; ``far_rows`` of its scans carry
    the fingerprint of a place 60 m away (stale or moved APs). Returns the map and the truth."""
    x = np.sort(rng.uniform(*span, n))
    d = np.hypot(x[:, None] - APS[None, :, 0], APS[None, :, 1])
    rss = -35 - 25 * np.log10(d) + rng.normal(0, 3, d.shape)
    if far_rows:
        src = np.clip(x[-far_rows:] + np.where(x[-far_rows:] > 60, -60, 60), 0, 120)
        dd = np.hypot(src[:, None] - APS[None, :, 0], APS[None, :, 1])
        rss[-far_rows:] = -35 - 25 * np.log10(dd) + rng.normal(0, 3, dd.shape)
    px = x + rng.normal(0, 1, n) + shift
    py = rng.normal(0, 1, n)
    bssids = np.array([f"ap{i:02d}" for i in range(len(APS))])
    fp = Fingerprints(px, py, np.zeros(n), bssids, rss, t=np.arange(n) * 2.0,
                      sigma=np.full(n, sigma))  # fmt: skip
    return fp, x


def _walks(rng, **odd):
    maps, truth = {}, {}
    for i in range(8):
        maps[f"w{i}"], truth[f"w{i}"] = _walk(rng)
    maps["odd"], truth["odd"] = _walk(rng, **odd)
    return maps, truth


def _joined(rng, second_span, short_m: float) -> Fingerprints:
    """Two walks joined into one (every clock re-timed): 14 scans placed right over x 10–60 m,
    then 14 taken over ``second_span`` but placed ``short_m`` m short of it (the track runs on
    from where the first ended), one scan every 2 s."""
    first, _ = _walk(rng, n=14, span=(10, 60))
    second, _ = _walk(rng, n=14, span=second_span)
    joined = Fingerprints.merge([first, replace(second, x=second.x - short_m)])
    return replace(joined, t=np.arange(len(joined)) * 2.0, sigma=np.full(len(joined), 1.5))


def _error(m: Fingerprints, x: np.ndarray) -> float:
    return float(np.mean(np.hypot(m.x - x, m.y)))


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_a_walk_placed_8_m_off_is_moved_back_and_the_right_ones_barely_move(seed):
    rng = np.random.default_rng(seed)
    maps, truth = _walks(rng, shift=8.0)
    res = correct(maps)
    before, after = _error(maps["odd"], truth["odd"]), _error(res.maps["odd"], truth["odd"])
    assert after <= before - 1.0  # moved back west, where its scans were taken
    assert float(np.mean(res.maps["odd"].x - maps["odd"].x)) < -1.0
    for n in maps:
        if n != "odd":  # the right ones: no worse than their own placement by more than 1 m
            assert _error(res.maps[n], truth[n]) <= _error(maps[n], truth[n]) + 1.0
    assert not any(w.unreconciled for w in res.walks.values())


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_a_walk_placed_20_m_off_is_named_and_left_out_where_others_cover_it(seed):
    rng = np.random.default_rng(seed)
    maps, _ = _walks(rng, shift=20.0, span=(10, 90))  # placed at 30–110 m: the others were there
    res = correct(maps)
    odd = res.walks["odd"]
    assert odd.unreconciled and odd.left_out and 14.0 <= odd.disagree_m <= 26.0
    assert "still puts it" in odd.words() and "left out" in odd.words()
    assert [n for n, w in res.walks.items() if w.unreconciled] == ["odd"]
    assert "odd" not in res.kept() and len(res.kept()) == 8


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_walk_right_but_with_scans_that_look_far_away_is_kept(seed):
    """A fifth of its scans (its last) look 60 m away: the rest of its links agree, over the
    whole walk and over each half."""
    rng = np.random.default_rng(seed)
    maps, truth = _walks(rng, far_rows=5)
    res = correct(maps)
    assert not res.walks["odd"].unreconciled and not res.walks["odd"].left_out
    assert not res.walks["odd"].part_out
    assert _error(res.maps["odd"], truth["odd"]) <= _error(maps["odd"], truth["odd"]) + 1.0


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_two_walks_joined_into_one_lose_the_half_placed_wrong(seed):
    """Issue #67 item 2: a walk whose second half was recorded elsewhere (two walks joined with
    every clock re-timed: its track runs on from where the first ended, here 45 m short of the
    truth). Its first half agrees with the others, its second does not, and the whole walk's
    links are not unanimous enough to name it: the half is named, with its times, and its rows
    left out (on standby with no σ to join by) where the others cover it — the first half stays
    in the map. No other walk is named. (The WiFi cannot tell a half placed wrong from a half
    most of whose scans look like elsewhere; no real walk of the four mall floors or the
    museum is named so: docs/experiments.md.)"""
    rng = np.random.default_rng(seed)
    maps, _ = _walks(rng)
    maps["odd"] = joined = _joined(rng, (60, 110), 45.0)
    res = correct(maps)
    odd = res.walks["odd"]
    assert odd.unreconciled and odd.part == "its second half" and odd.part_out
    assert not odd.left_out and "odd" in res.kept()
    assert odd.part_s is not None and odd.part_s[1] == pytest.approx(2.0 * (len(joined) - 1))
    assert "its second half" in odd.words() and "that half left out" in odd.words()
    assert [n for n, w in res.walks.items() if w.unreconciled] == ["odd"]
    kept = res.kept()["odd"].settled()  # as a merged map holds it: the first half
    assert len(kept) == 14 and kept.t is not None and kept.t.max() < odd.part_s[0]
    assert len(res.maps["odd"]) == len(joined)  # the walk's own map keeps every row
    whole = correct(maps | {"odd": replace(maps["odd"], t=None)}).walks["odd"]
    assert not whole.unreconciled  # moved as one knot, its halves are not told apart


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_a_walk_in_doubt_only_for_a_joined_walk_s_half_says_so(seed):
    """The others walked x 10–60 m; one walk, placed right, went 75–115 m, where only the second
    half of a joined walk also went — placed 55 m short, over the others. Every link of the
    lone walk goes to that half and disagrees by ~55 m: it is named, but its words say that
    the doubt rests on the joined walk alone, itself in doubt, and to look at both; it is kept
    (nothing else covers it). The joined walk (its half, or all of it) leaves the map as before;
    the others are not named."""
    rng = np.random.default_rng(seed)
    maps = {}
    for i in range(8):
        w, x = _walk(rng)
        maps[f"w{i}"] = w.subset(x < 60)
    w, x = _walk(rng)
    maps["lone"] = w.subset(x > 75)
    maps["odd"] = _joined(rng, (75, 115), 55.0)
    res = correct(maps)
    lone, odd = res.walks["lone"], res.walks["odd"]
    assert lone.unreconciled and lone.only_against == "odd" and not lone.left_out
    assert "odd alone" in lone.words() and "look at both" in lone.words()
    assert "lone" in res.kept()
    assert odd.unreconciled and (odd.part_out or odd.left_out)  # (whole: too few agree)
    assert {n for n, w in res.walks.items() if w.unreconciled} == {"lone", "odd"}
    again = type(lone).from_dict(lone.to_dict())
    assert again == replace(lone, shift_mean_m=again.shift_mean_m, shift_max_m=again.shift_max_m,
                            disagree_m=again.disagree_m, covered=again.covered, agree=again.agree)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_walk_where_nobody_else_walked_is_kept_and_barely_moves(seed):
    """The others walked x 10–60 m; one walk, placed right, covers 75–115 m: its nearest
    fingerprints lie 15–50 m away, the robust kernel lets them pull little, and it is never
    left out (nothing else covers where it went)."""
    rng = np.random.default_rng(seed)
    maps, truth = {}, {}
    for i in range(8):
        w, x = _walk(rng)
        maps[f"w{i}"], truth[f"w{i}"] = w.subset(x < 60), x[x < 60]
    w, x = _walk(rng)
    maps["new"], truth["new"] = w.subset(x > 75), x[x > 75]
    res = correct(maps)
    assert not res.walks["new"].left_out
    assert _error(res.maps["new"], truth["new"]) <= _error(maps["new"], truth["new"]) + 1.5


def test_sigma_narrows_only_with_other_walks_evidence():
    rng = np.random.default_rng(5)
    maps, _ = _walks(rng)
    lone, _ = _walk(rng)
    maps["far"] = replace(lone, floor=np.full(len(lone), 3.0))  # alone on its floor: no links
    res = correct(maps)
    assert np.allclose(res.maps["far"].sigma, 1.5)  # its own σ, untouched
    assert res.walks["far"].links == 0
    for n in (f"w{i}" for i in range(8)):
        s = res.maps[n].sigma
        assert (s <= 1.5 + 1e-9).all() and s.mean() < 1.45


def test_maps_without_times_move_as_a_whole_and_small_inputs_do_nothing():
    rng = np.random.default_rng(2)
    maps, _ = _walks(rng, shift=8.0)
    bare = {n: replace(m, t=None) for n, m in maps.items()}
    res = correct(bare)
    d = res.maps["odd"].x - bare["odd"].x
    assert np.ptp(d) < 1e-9 and d.mean() < -1.0  # one knot: one translation
    one = {"a": maps["w0"]}
    assert correct(one).maps["a"] is maps["w0"] and not correct(one).walks["a"].links


def test_the_robust_weight_is_one_inside_the_knee_and_falls_as_its_square_beyond():
    r = np.array([0.0, 3.9, 8.0, 40.0])
    w = robust_weight(r, 4.0)
    assert w[0] == 1 and w[1] == 1 and w[2] == pytest.approx(0.25) and w[3] == pytest.approx(0.01)
    assert UNRECONCILED_M > 4.0


def test_merge_names_a_displaced_real_walk_and_leaves_it_out(tmp_path, capsys):
    """The bundled mall walks run from their first fix, one of them given a start 20 m from
    where it began (a surveyor's slip): merge says which walk the others cannot reconcile and
    by how much, and merges the others (moved where they agree); --include-disagreeing keeps
    it."""
    import pandas as pd

    data = REPO / "tests" / "data" / "msilc"
    graph = data / "site1_f1_graph.yaml"
    maps, slip = [], "5dd9e7c4c5b77e0006b17335"
    for w in sorted(data.glob("*.gz")):
        out = tmp_path / w.name.split(".")[0]
        start = "L142" if w.name.startswith(slip) else "first-fix"
        if main(["run", str(w), "--graph", str(graph), "--start", start, "--out", str(out)]) == 0:
            maps.append(out / "radiomap.csv")
    moved = tmp_path / slip / "radiomap.csv"
    assert len(maps) >= 6 and moved in maps
    capsys.readouterr()
    merged = tmp_path / "merged.csv"
    assert main(["merge", *map(str, maps), "-o", str(merged), "--save", str(tmp_path / "j.rrd")]) == 0
    said = capsys.readouterr().out
    assert f"wrote {tmp_path / 'j.rrd'}" in said and (tmp_path / "j.rrd").stat().st_size > 10_000
    assert f"warning: {moved}: the other walks' WiFi still puts it" in said
    assert said.count("still puts it") == 1 and "left out" in said and "what to do" in said
    assert "walks placed together" in said
    df = pd.read_csv(merged, comment="#")
    assert "sigma" in df.columns and (df["sigma"] > 0).all()
    assert main(["merge", *map(str, maps), "-o", str(merged), "--include-disagreeing"]) == 0
    assert "kept as asked" in capsys.readouterr().out
    assert len(pd.read_csv(merged, comment="#")) > len(df)


def test_the_recording_shows_each_walk_before_and_after_its_arrows_and_links(tmp_path):
    """merge --save: per walk and floor its points as its run placed them, where they went
    (arrows for every point moved 0.5 m or more), the merged map's points (a left-out walk in
    the quarantine colour), its links; the table says which walk was left out."""
    from rerun.chunk import RrdReader

    from workstation.viz.colours import rgb
    from workstation.viz.rerun_joint import SHOWN_MOVE_M, save_or_send

    rng = np.random.default_rng(0)
    maps, _ = _walks(rng, shift=20.0, span=(10, 90))
    res = correct(maps)
    rrd = tmp_path / "joint.rrd"
    save_or_send(maps, res, save=rrd)
    found: dict[str, list] = {}
    for ch in RrdReader(rrd).stream():
        b = ch.to_record_batch()
        for name in b.schema.names:
            found.setdefault(f"{ch.entity_path}:{name.rsplit(':', 1)[-1]}", []).extend(
                b.column(name).to_pylist())  # fmt: skip

    def get(entity, component):
        return next(v for k, v in found.items() if k.startswith(entity + ":")
                    and k.endswith(component))  # fmt: skip

    root = "/map/floor_0/joint"
    for n in maps:
        assert len(get(f"{root}/{n}/alone", "positions")[0]) == len(maps[n])
        assert len(get(f"{root}/{n}/together", "positions")[0]) == len(maps[n])
    odd_colour = get(f"{root}/odd/together", "colors")[0][0]
    good_colour = get(f"{root}/w0/together", "colors")[0][0]
    packed = [int.from_bytes(bytes([*c[:3], 255]), "big") for c in (rgb("quarantined"),
                                                                    rgb("accepted"))]  # fmt: skip
    assert [odd_colour, good_colour] == packed
    moved = np.hypot(res.maps["w0"].x - maps["w0"].x, res.maps["w0"].y - maps["w0"].y)
    if (moved >= SHOWN_MOVE_M).any():
        assert len(get(f"{root}/w0/moved", "vectors")[0]) == int((moved >= SHOWN_MOVE_M).sum())
    assert len(get(f"{root}/odd/links", "strips")[0]) == res.walks["odd"].links
    table = str(get("/joint/walks", "text"))
    assert "| odd | **left out** |" in table and "| w0 | in the map |" in table


@pytest.fixture(scope="module")
def mall_map():
    """The bundled mall walks but two, run from their first fix, merged as the building's map."""
    from workstation.graph import LandmarkGraph
    from workstation.params import Params
    from workstation.pipeline import Pipeline
    from workstation.pipeline.start import resolve_start
    from workstation.session import load_session

    data = REPO / "tests" / "data" / "msilc"
    graph = LandmarkGraph.load(data / "site1_f1_graph.yaml")
    maps = []
    for w in sorted(data.glob("*.gz")):
        if w.name.startswith(("5dd9e7c4", "5dd9e7c1")):
            continue
        s = load_session(w).in_frame(graph.frame)
        p = Params().updated(**{"pdr.start_node": resolve_start("first-fix", s, graph)})
        maps.append(Fingerprints.of_walk(Pipeline(s, graph, p).run().radiomap, graph.frame))
    return data, graph, Fingerprints.merge(maps)


@pytest.mark.parametrize(("walk", "start", "far"), [("5dd9e7c4c5b77e0006b17335", "L142", True),
                                                    ("5dd9e7c1c5b77e0006b17333", None, False)])
def test_the_panel_says_and_draws_what_merging_would_do_to_the_walk(mall_map, walk, start, far,
                                                                  tmp_path):
    """edit --map: the walk placed with the building's map held still. A walk given a start
    20 m off is moved metres towards where it was (its truth), and the summary says by how
    much; a walk from its right start barely moves."""
    from workstation.editor import SurveyEditor
    from workstation.editor.placed import MAP, WALK, placed_with_map
    from workstation.params import Params
    from workstation.pipeline.start import resolve_start
    from workstation.session import load_session
    from workstation.viz.panel_text import summary_markdown

    data, graph, ref = mall_map
    s = load_session(data / f"{walk}.txt.gz")
    p = Params().updated(**{"pdr.start_node": start or resolve_start("first-fix", s, graph)})
    ed = SurveyEditor(s, graph, p, out_dir=tmp_path, building_map=ref)
    before, res = placed_with_map(ed)
    assert placed_with_map(ed)[1] is res  # kept until the next run
    after = res.maps[WALK]
    assert np.allclose(res.maps[MAP].x, ref.x) and np.allclose(res.maps[MAP].y, ref.y)
    gx, gy, _ = ed.session.in_frame(graph.frame).ground_truth.at(before.t)
    e0, e1 = np.hypot(before.x - gx, before.y - gy).mean(), np.hypot(after.x - gx, after.y - gy).mean()
    md = summary_markdown(ed)
    assert "**Placed with the building's walks**" in md
    if far:
        assert e0 > 15 and e1 < e0 - 3  # moved metres back towards where it was
        assert "it would move by" in md or "cannot be reconciled" in md
    else:
        assert e0 < 5 and e1 < e0 + 1.5 and res.walks[WALK].shift_mean_m < 2.5


def test_floor_by_floor_is_the_estimate_of_each_floor_put_back_together():
    """joint_floors.py: a building's floors are independent problems. Two floors of walks, one
    walk crossing both (its first half on floor 0, its second on 1): each floor's points equal
    the estimate of that floor alone; the crossing walk's parts come back in its row order, its
    links point at the right rows, its account sums its parts."""
    from workstation.walks.joint_floors import correct_by_floor

    rng = np.random.default_rng(7)
    maps, _ = _walks(rng, shift=6.0)
    upper, _ = _walks(rng)
    maps |= {f"u{n}": replace(m, floor=np.ones(len(m))) for n, m in upper.items()}
    cross = maps["w0"]
    f = np.r_[np.zeros(12), np.ones(len(cross) - 12)]
    maps["w0"] = replace(cross, floor=f)
    res = correct_by_floor(maps)
    alone = correct({n: m.subset(m.floor == 1) for n, m in maps.items() if (m.floor == 1).any()})
    for n, m in alone.maps.items():
        on = maps[n].floor == 1
        assert np.allclose(res.maps[n].x[on], m.x) and np.allclose(res.maps[n].sigma[on], m.sigma)
    w0 = res.walks["w0"]
    assert w0.rows == len(cross) and w0.links == sum(
        r.walks["w0"].links for r in (alone, correct({n: m.subset(m.floor == 0) for n, m in
                                                      maps.items() if (m.floor == 0).any()})))
    x = np.concatenate([res.maps[n].x for n in maps])
    fl = np.concatenate([maps[n].floor for n in maps])
    i, j = res.links[:, 0].astype(int), res.links[:, 1].astype(int)
    assert (fl[i] == fl[j]).all() and len(x) > i.max()  # every link within one floor
    assert float(np.mean(res.maps["odd"].x - maps["odd"].x)) < -1.0  # moved back, as alone


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_a_walk_held_off_by_its_own_confidence_keeps_its_place_but_not_its_sigma(seed):
    """A walk placed 10 m off that says it is placed to 0.3 m (its own σ pins it where the
    others' WiFi says it is not): the estimate cannot move it far, so its σ widens until its
    true error lies within 2σ at 70 % of its points or more (before: none); the walks placed
    right keep theirs."""
    rng = np.random.default_rng(seed)
    maps, truth = _walks(rng, shift=10.0, sigma=0.3)
    res = correct(maps)
    odd, x = res.maps["odd"], truth["odd"]
    err = np.hypot(odd.x - x, odd.y)
    assert err.mean() > 4.0  # still off: its σ held it
    assert np.mean(err <= 2 * odd.sigma) >= 0.7 and odd.sigma.mean() > 10 * 0.3  # before: 0
    for n in (f"w{i}" for i in range(8)):
        assert np.median(res.maps[n].sigma) <= 1.5 + 1e-9


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_a_crowd_s_floor_is_searched_against_every_nth_walk_and_still_corrects(seed, monkeypatch):
    """Issue #66: past ``MAX_LINK_WALKS`` walks a floor is searched against every n-th walk
    only (here 3 of 9: the displaced walk is not among them), so the search grows as the walks,
    not their square — and a walk placed 8 m off is still moved back, the right ones barely."""
    import workstation.walks.joint as joint

    rng = np.random.default_rng(seed)
    maps, truth = _walks(rng, shift=8.0)
    monkeypatch.setattr(joint, "MAX_LINK_WALKS", 4)
    res = correct(maps)
    assert res.walks["odd"].links >= 10  # linked, though not searched against
    assert _error(res.maps["odd"], truth["odd"]) <= _error(maps["odd"], truth["odd"]) - 1.0
    for n in maps:
        if n != "odd":
            assert _error(res.maps[n], truth[n]) <= _error(maps[n], truth[n]) + 1.0
    assert not any(w.unreconciled for w in res.walks.values())
