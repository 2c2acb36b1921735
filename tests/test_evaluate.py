import json

from tests.conftest import SHARED_DATA
from workstation.evaluate import evaluate


def test_evaluate_regenerates_the_experiments(tmp_path):
    res = evaluate(tmp_path, SHARED_DATA if SHARED_DATA.is_dir() else None)
    for f in (
        "results.md",
        "results.json",
        "fig5_trajectory_cdf.png",
        "fig6_belief.png",
        "fig7_floor_accuracy.png",
        "fig8_mean_error.png",
        "fig9_tau.png",
    ):
        assert (tmp_path / f).stat().st_size > 0, f
    sim = res["simulated"]
    assert sim["trajectory_error"]["Landmark graph (ours)"]["mean_m"] <= 0.71
    split = sim["rp_error_by_belief"]
    assert split["at_least_15"]["mean_m"] < split["below_15"]["mean_m"]
    t = sim["survey_time"]
    manual = t["Manual (10 scans)"]["setup_min"] + t["Manual (10 scans)"]["collection_min"]
    ours = t["Proposed method"]["setup_min"] + t["Proposed method"]["collection_min"]
    assert manual > 5 * ours  # "an order of magnitude faster"
    assert json.loads((tmp_path / "results.json").read_text())["simulated"]["walk_length_m"] > 340
