import json

from workstation.cli import main
from workstation.params import Params
from workstation.pipeline import Pipeline

# the paper's acceptance: a segment's belief decides (the default is sigma, sigma.py)
BELIEF = Params().updated(**{"radiomap.acceptance": "belief"})


def test_rerun_recomputes_only_what_changed(sim_normal):
    seen = []
    pipe = Pipeline(
        sim_normal.session,
        sim_normal.graph,
        BELIEF,
        observers=[lambda name, value, p: seen.append(name)],
    )
    r1 = pipe.run()
    assert pipe.recomputed == ["steps", "heading", "landmarks", "tracking", "belief", "radiomap"]
    assert seen[-1] == "done"
    r2 = pipe.run(BELIEF.updated(**{"belief.threshold": 80.0}))
    assert pipe.recomputed == ["belief", "radiomap"]
    assert r2.track is r1.track and r2.radiomap.reference_points < r1.radiomap.reference_points
    g = sim_normal.graph
    n = g.node("DS0")
    moved = g.with_node(n.__class__(n.id, n.x + 1.0, n.y, n.floor, n.rules, n.name))
    pipe.run(graph=moved)
    assert pipe.recomputed == ["tracking", "belief", "radiomap"]
    pipe.run(BELIEF.updated(**{"gyro.threshold_rad_s": 1.3, "belief.threshold": 80.0}), graph=moved)
    assert pipe.recomputed == ["landmarks", "tracking", "belief", "radiomap"]


def test_run_command_writes_everything(tmp_path, capsys):
    from tests.conftest import REPO

    walk = REPO / "sample_sessions" / "office2f" / "normal"
    out = tmp_path / "out"
    assert main(["run", str(walk), "--graph", str(walk / "graph.yaml"), "--out", str(out)]) == 0
    for f in ("trajectory.csv", "landmarks.csv", "segments.csv", "radiomap.csv", "summary.json"):
        assert (out / f).is_file()
    s = json.loads((out / "summary.json").read_text())
    for k in (
        "steps",
        "landmarks_detected",
        "landmarks_matched",
        "segments",
        "segments_accepted",
        "reference_points",
        "trajectory_error_mean_m",
        "trajectory_error_p90_m",
        "floor_accuracy",
    ):
        assert k in s
    text = (out / "radiomap.csv").read_text().splitlines()
    assert text[0] == "# device: simulated phone (+10.3 dB)"  # merge aligns across models only
    rows = [ln for ln in text if not ln.startswith("#")]
    header = rows[0].split(",")
    assert header[:3] == ["x", "y", "floor"] and any(h.startswith("02:0f") for h in header)
    # the reference points, then the scans held back for their σ alone, on standby (standby.py)
    col = header.index("standby") if "standby" in header else None
    wait = [r.split(",")[col] == "True" for r in rows[1:]] if col is not None else []
    assert len(rows) - 1 - sum(wait) == s["reference_points"]
    held = sum(n for why, n in s["scans_not_points"].items() if why.startswith("placed too"))
    assert sum(wait) == held
    assert "trajectory_error_mean_m" in capsys.readouterr().out


def test_run_command_bad_params_file(tmp_path, capsys):
    from tests.conftest import REPO

    walk = REPO / "sample_sessions" / "office2f" / "normal"
    p = tmp_path / "p.yaml"
    p.write_text("belief: {threshold: lots}\n")
    assert (
        main(
            [
                "run",
                str(walk),
                "--graph",
                str(walk / "graph.yaml"),
                "--params",
                str(p),
                "--out",
                str(tmp_path / "o"),
            ]
        )
        == 2
    )
    assert "belief.threshold: expected a number" in capsys.readouterr().err
