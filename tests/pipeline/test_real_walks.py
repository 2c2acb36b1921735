"""The pipeline on the real IPIN museum walks, museum graph built from the .tra files, with the
default parameters (no per-building behaviour parameters)."""

import pytest

from tests.conftest import IPIN, need
from workstation.graph.importers import graph_from_tra
from workstation.params import Params
from workstation.pipeline import Pipeline
from workstation.pipeline.metrics import pooled_fix_metrics
from workstation.pipeline.start import resolve_start
from workstation.session import load_session

pytestmark = pytest.mark.shared_data


@pytest.fixture(scope="module")
def museum():
    return graph_from_tra(sorted(need(IPIN / "supplementary" / "trajectories").glob("*.tra")))


@pytest.fixture(scope="module")
def walks(museum):
    return [
        load_session(f).in_frame(museum.frame)
        for f in sorted(need(IPIN / "logfiles").glob("*.txt"))
    ]


def _runs(walks, museum, start):
    out = []
    for s in walks:
        p = Params()
        if start == "first-fix":
            p = p.updated(**{"pdr.start_node": resolve_start("first-fix", s, museum)})
        out.append((Pipeline(s, museum, p).run(), s, museum))
    return out


def test_stairs_over_three_unevenly_spaced_floors(museum, walks):
    """Trial51 goes 0 → −1 → −2 and back twice; its floors are ~0.40 and ~0.32 hPa apart, not
    the 0.45 of eq. 9: the spacings are learnt from the matched stairs."""
    s = next(w for w in walks if "Trial51" in w.metadata.path)
    p = Params().updated(**{"pdr.start_node": resolve_start("first-fix", s, museum)})
    r = Pipeline(s, museum, p).run()
    m = r.summary(s, museum).to_json()
    assert m["floor_accuracy"] == 1.0
    assert m["landmark_node_accuracy"] >= 0.9
    gaps = r.track.floor_gaps_hpa
    assert 0.25 < gaps["-2→-1"] < 0.4 and 0.3 < gaps["-1→0"] < 0.5


def test_all_museum_walks_pooled(museum, walks):
    """Issue #10's bars, with the defaults, start at the first fix. The match rate is counted
    per visit (pipeline/metrics.py); the strict ±3 s figure is reported beside it."""
    m = pooled_fix_metrics(_runs(walks, museum, "first-fix"))
    print(m)
    assert m["landmark_fixes"] >= 130
    assert m["landmark_node_accuracy"] >= 0.97
    assert m["landmark_fix_match_rate"] >= 0.90
    assert m["landmark_fix_match_rate_strict"] >= 0.70
    assert m["floor_accuracy"] == 1.0
    assert m["fix_error_mean_m"] <= 1.0 and m["fix_error_p90_m"] <= 2.0


def test_all_museum_walks_start_inferred(museum, walks):
    """Each walk alone: Trial21 rep01 (22 m out and back along one of three parallel
    corridors) takes the wrong corridor and all its fixes are wrong, flagged ambiguous."""
    m = pooled_fix_metrics(_runs(walks, museum, None))
    print(m)
    assert m["landmark_node_accuracy"] >= 0.90


def test_museum_walks_that_stood_together_share_their_start(museum, walks):
    """Issue #10's inferred-start bar: the 10 walks together. Trial21 rep01 and rep03 stood at
    one place (each other's nearest stand fingerprint); rep01 alone prefers L22 by 0.64,
    rep03 prefers L31 by 1.86, together L31 (the truth, their first fix)."""
    from workstation.walks.shared_start import run_inferring_starts

    results, groups, _ = run_inferring_starts(walks, museum, Params())
    m = pooled_fix_metrics([(r, s, museum) for r, s in zip(results, walks)])
    print(m, groups)
    assert m["landmark_node_accuracy"] >= 0.95
    truth = [resolve_start("first-fix", s, museum) for s in walks]
    for g in groups:
        assert all(truth[i] == g.start for i in g.walks), (g, [truth[i] for i in g.walks])


def test_museum_leave_one_walk_out():
    """Issue #11's bars that hold (10 walks, default parameters, leave one walk out). Not met
    yet, said in the issue: floor accuracy ≥ 0.90 (0.78; queries no other walk covers cap it
    near 0.87 for any map) and ≤ 0.70 × PDR I with the floor penalty (0.88)."""
    from workstation.evaluate.walks import ipin_museum, leave_one_out

    logs, graph = ipin_museum(need(IPIN).parent)
    r = leave_one_out(logs, graph)
    pa = r.placement
    assert pa["accepted"]["n"] >= 300
    assert pa["accepted"]["mean_m"] <= 1.0
    # the bar: accepted (incl. the scans at landmark stops) against untrusted segments;
    # segment belief alone separates more weakly (0.77, said in results.md)
    assert pa["accepted"]["mean_m"] <= 0.6 * pa["untrusted_closed"]["mean_m"]
    assert pa["trusted_segments"]["mean_m"] < pa["untrusted_closed"]["mean_m"]
    ours, tap, pdr_i = r.loo["ours"], r.loo["tap_oracle"], r.loo["pdr_i"]
    assert ours.mean_with_floor_penalty_m <= 1.10 * tap.mean_with_floor_penalty_m
    assert ours.mean_with_floor_penalty_m < pdr_i.mean_with_floor_penalty_m
    assert ours.covered_mean_with_floor_penalty_m <= 0.8 * pdr_i.covered_mean_with_floor_penalty_m
    offsets = list(ours.query_device_offsets_db.values())
    assert max(offsets) - min(offsets) > 3.0  # two phones: offsets found and removed
