"""A campaign walk's row (campaign/walk_row.py): typed reads of what campaign.json holds, and
the row written and read back unchanged — the reasons the joint estimate adds included."""

import json
from dataclasses import replace

from workstation.campaign.outcome import BuildingReport, CampaignReport
from workstation.campaign.walk_row import SUMMARY_KEYS, WalkRow
from workstation.walks.correction import WalkCorrection
from workstation.walks.start_by_map import MapRanking

FIGURES = {k: None for k in SUMMARY_KEYS} | {
    "steps": 120, "start_node": "L3", "end_node": "L9", "end_how": "closed", "end_sigma_m": 1.2,
    "reference_points": 14, "quarantine": [],
}  # fmt: skip


def _rows():
    left = WalkCorrection("b/left", 30, 12, 2.0, 4.5, "the whole walk", 18.0, 0.9, 0.1, True)
    held = dict(FIGURES, quarantine=[{"reason": "start_ambiguous", "detail": "L3 or L5",
                                      "what_to_do": "give the start"}])  # fmt: skip
    return [
        WalkRow(
            "b/ok",
            "b",
            "ok",
            None,
            3.2,
            False,
            "phone",
            FIGURES,
            joint=WalkCorrection("b/ok", 40, 9, 0.4, 0.9, "its first half", 1.0, 0.5),
        ),
        WalkRow("b/left", "b", "ok", None, 2.0, False, "", FIGURES, joint=left),
        WalkRow(
            "b/held",
            "b",
            "ok",
            None,
            1.0,
            False,
            "",
            held,
            candidates=("L3", "L5"),
            map_lacks=4,
            edit_command="workstation edit x --graph g",
            start_by_map=MapRanking((("L5", 2.5, -3.0), ("L3", 9.0, -8.0)), "L5", 0.0, 5.0),
        ),
        WalkRow("b/bad", "b", "failed", "InputError: not a walk", 0.1, True),
    ]


def test_a_row_says_what_its_run_and_the_report_found():
    ok, left, held, bad = _rows()
    assert ok.summary.start_node == "L3" and ok.summary.end.how == "closed" and not ok.quarantined
    assert [q.reason for q in left.quarantine] == ["unreconciled"]
    assert "left out" in left.quarantine[0].detail  # the joint estimate's words
    assert [q.reason for q in held.quarantine] == ["start_ambiguous"] and held.name == "held"
    assert not bad.ok and bad.summary.steps == 0 and not bad.quarantined


def test_campaign_json_reads_back_as_it_was_written():
    rows = _rows()
    report = CampaignReport(4, 3, 4, 0, 2, 9.5, {"b": BuildingReport(4, 3, 2, 40, 7)},
                            tuple(rows), {"b": "starts.yaml"}, {"b": "ends.yaml"})  # fmt: skip
    doc = json.loads(json.dumps(report.to_json()))
    left = doc["per_walk"][1]
    assert left["quarantine"][0]["reason"] == "unreconciled" and left["joint"]["left_out"]
    assert doc["per_walk"][2]["start_by_map"] == [["L5", 2.5, -3.0], ["L3", 9.0, -8.0]]
    assert doc["per_walk"][3]["retry"] is True and "steps" not in doc["per_walk"][3]
    back = CampaignReport.from_json(doc)
    assert json.loads(json.dumps(back.to_json())) == doc
    assert [w.quarantine for w in back.per_walk] == [w.quarantine for w in rows]
    assert back.per_walk[2].start_by_map == rows[2].start_by_map


def test_a_walk_whose_half_is_left_out_is_said_in_campaign_md_and_kept_in_its_json():
    """Issue #67 item 2: the joint estimate left out one half of a walk (walks/joint.py) — the
    walk is not held, campaign.md says which half, from when to when and what to do, and
    campaign.json keeps it."""
    from workstation.campaign.report_md import markdown

    half = WalkCorrection("b/joined", 30, 14, 1.0, 1.4, "the whole walk", 79.0, 0.92, 0.0,
                          False, "its second half", (28.5, 54.8), True)  # fmt: skip
    rows = (WalkRow("b/joined", "b", "ok", None, 1.0, False, "", FIGURES, joint=half),)
    report = CampaignReport(1, 1, 1, 0, 0, 1.0, {"b": BuildingReport(1, 1, 0, 30, 7)}, rows,
                            {"b": "starts.yaml"}, {"b": "ends.yaml"})  # fmt: skip
    assert not rows[0].quarantined
    md = markdown(report)
    assert "## Half of a walk left out" in md and "| b/joined |" in md
    assert "its second half (28–55 s) 79 m away" in md and "workstation split" in md
    doc = json.loads(json.dumps(report.to_json()))
    assert doc["per_walk"][0]["joint"]["part_s"] == [28.5, 54.8]
    assert CampaignReport.from_json(doc).per_walk[0].joint == half
    others = CampaignReport(4, 3, 4, 0, 2, 9.5, {"b": BuildingReport(4, 3, 2, 40, 7)},
                            tuple(_rows()), {"b": "s"}, {"b": "e"})  # fmt: skip
    assert "Half of a walk" not in markdown(others)  # a walk left out whole is held instead


def test_a_walk_kept_though_the_others_disagree_is_listed_first_to_check():
    """A walk the joint estimate cannot reconcile but keeps (nothing else covers where it
    went) — the map's likeliest wrong walk — is listed in campaign.md with what the others
    say; one it left out is not (it is held), nor one it reconciled."""
    from workstation.campaign.report_md import markdown

    kept = WalkCorrection("b/lone", 20, 16, 0.5, 0.9, "the whole walk", 18.0, 0.3, 0.1)
    fine = WalkCorrection("b/fine", 20, 30, 0.5, 0.9, "the whole walk", 1.0, 0.9, 0.8)
    rows = tuple(WalkRow(k, "b", "ok", None, 1.0, False, "", FIGURES, joint=j)
                 for k, j in (("b/lone", kept), ("b/fine", fine)))  # fmt: skip
    report = CampaignReport(2, 2, 2, 0, 0, 1.0, {"b": BuildingReport(2, 2, 0, 40, 7)}, rows,
                            {"b": "starts.yaml"}, {"b": "ends.yaml"})  # fmt: skip
    md = markdown(report)
    section = md.split("## In the map, though the other walks disagree")[1]
    assert "| b/lone |" in section and "18 m away" in section and "kept" in section
    assert "b/fine" not in section
    others = CampaignReport(4, 3, 4, 0, 2, 9.5, {"b": BuildingReport(4, 3, 2, 40, 7)},
                            tuple(_rows()), {"b": "s"}, {"b": "e"})  # fmt: skip
    assert "though the other walks disagree" not in markdown(others)


def test_an_evaluated_walk_left_out_by_the_joint_estimate_is_held_for_it():
    """evaluate --walks' row (evaluate/scored_walk.py): the joint estimate's verdict joins the
    run's reasons, and the row in results.json says both."""
    from workstation.evaluate.scored_walk import PER_WALK_KEYS, ScoredWalk

    figures = {k: None for k in PER_WALK_KEYS} | {"reference_points": 12}
    ok = ScoredWalk(figures, placed_m=1.2, start="L3", start_right=True, start_same_place=True)
    assert ok.in_map and ok.quarantine == ()
    left = WalkCorrection("w", 30, 12, 2.0, 4.5, "the whole walk", 18.0, 0.9, 0.1, True)
    out = ScoredWalk(figures, reasons=("end_far",), joint=left)
    assert out.quarantine == ("end_far", "unreconciled") and not out.in_map
    row = out.to_json()
    assert row["quarantine"] == ["end_far", "unreconciled"] and row["joint"]["left_out"]
    assert list(row)[: len(PER_WALK_KEYS)] == list(PER_WALK_KEYS) and "device_offset_db" in row


def test_the_walks_the_others_moved_are_listed_farthest_on_average_first():
    """campaign.md lists the walks the joint estimate moved by MOVED_M or more somewhere and
    reconciled, those moved farthest on average first (the likeliest placed wrong, issue #62:
    docs/experiments.md); a walk barely moved, or one the others cannot reconcile (its own
    section), is not among them."""
    from workstation.campaign.report_md import markdown

    def j(name, mean, most, disagree=1.0, agree=0.9):
        return WalkCorrection(name, 20, 30, mean, most, "the whole walk", disagree, 0.9, agree)

    joints = [j("b/some", 1.2, 2.5), j("b/most", 3.1, 4.0), j("b/still", 0.3, 0.8),
              j("b/odd", 2.0, 3.0, disagree=20.0, agree=0.1)]  # fmt: skip
    rows = tuple(WalkRow(x.name, "b", "ok", None, 1.0, False, "", FIGURES, joint=x)
                 for x in joints)  # fmt: skip
    report = CampaignReport(4, 4, 4, 0, 0, 1.0, {"b": BuildingReport(4, 4, 0, 80, 7)}, rows,
                            {"b": "starts.yaml"}, {"b": "ends.yaml"})  # fmt: skip
    section = markdown(report).split("## Moved by the other walks")[1]
    assert section.index("| b/most |") < section.index("| b/some |")
    assert "moved by 3.1 m on average (at most 4.0 m" in section
    assert "b/still" not in section and "b/odd" not in section
    assert "Moved by the other walks" not in markdown(replace(report, per_walk=rows[2:3]))


def test_merge_says_the_walks_moved_farthest_on_average_first(capsys):
    """merge's lines for the walks the joint estimate moved: the likeliest placed wrong (moved
    farthest on average) first, as campaign.md lists them — not the one moved most at one
    point."""
    from workstation.commands.radiomap import _said_joint

    spike = WalkCorrection("spike", 20, 30, 0.9, 6.0, "its first half", 1.0, 0.9, 0.9)
    whole = WalkCorrection("whole", 20, 30, 3.0, 3.5, "the whole walk", 1.0, 0.9, 0.9)
    _said_joint({"spike": spike, "whole": whole}, False, 0)
    out = capsys.readouterr().out
    assert out.index("whole: moved by 3.0 m") < out.index("spike: moved by 0.9 m")
    assert "2 moved by 2 m or more" in out
