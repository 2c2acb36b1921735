import json
import re
import subprocess
import sys

import pytest

from tests.conftest import REPO, gsd_lines
from workstation.cli import main


def test_info_prints_rates(tmp_path, capsys):
    p = tmp_path / "log.txt"
    p.write_text("\n".join(gsd_lines()) + "\n")
    assert main(["info", str(p)]) == 0
    out = capsys.readouterr().out
    assert re.search(r"accelerometer +200 samples +50.0 Hz", out) and "pressure" in out
    assert main(["info", "--json", str(p)]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["wifi"]["scans"] == 2 and d["ground_truth"]["points"] == 2


def test_bad_input_exits_nonzero_without_traceback(tmp_path):
    p = tmp_path / "log.txt"
    lines = gsd_lines()
    lines[12] = "ACCE;0.3;1000.3;0.1;0.2"
    p.write_text("\n".join(lines) + "\n")
    r = subprocess.run(
        [sys.executable, "-m", "workstation", "info", str(p)], capture_output=True, text=True
    )
    assert r.returncode == 2
    assert "Traceback" not in r.stderr
    assert (
        r.stderr.strip()
        == f"error: {p}:13: ACCE record has 4 fields, expected 5 (ACCE;AppTs;SensorTs;X;Y;Z)"
    )


def test_graph_commands(tmp_path, capsys):
    tra = tmp_path / "a.tra"
    tra.write_text("1 49.0 11.0 0 100\n2 49.0001 11.0 0 100\n3 49.0001 11.0001 0 100\n")
    out = tmp_path / "g.yaml"
    assert main(["graph", "from-tra", str(tra), "-o", str(out)]) == 0
    assert "3 landmarks" in capsys.readouterr().out
    assert main(["graph", "validate", str(out)]) == 0
    out.write_text(out.read_text().replace("rules: [gyro]", "rules: [jump]"))
    assert main(["graph", "validate", str(out)]) == 2
    assert "unknown rule 'jump'" in capsys.readouterr().err


def test_write_errors_and_bad_ports_are_messages_not_tracebacks(tmp_path, capsys):
    """Issue #18: an existing file where --out wants a folder, a port out of range."""
    from workstation.cli import main

    walk = REPO / "sample_sessions" / "office2f" / "normal"
    blocker = tmp_path / "out"
    blocker.write_text("a file, not a folder")
    rc = main(["run", str(walk), "--graph", str(walk / "graph.yaml"), "--out", str(blocker)])
    assert rc == 2 and "error:" in capsys.readouterr().err
    with pytest.raises(SystemExit) as e:
        main(["edit", str(walk), "--graph", str(walk / "graph.yaml"), "--port", "70000"])
    assert e.value.code == 2 and "not a port" in capsys.readouterr().err
    for bad, said in (("1,2,0", "give X,Y,FLOOR,R"), ("1,2,first,5", "give X,Y,FLOOR,R"),
                      ("1,2,any,-3", "must be positive")):  # fmt: skip
        with pytest.raises(SystemExit) as e:
            main(["edit", str(walk), "--graph", str(walk / "graph.yaml"), "--start-within", bad])
        assert e.value.code == 2 and said in capsys.readouterr().err


def test_radiomap_csv_with_a_bom_keeps_its_frame(tmp_path):
    from workstation.fingerprints.localize import Fingerprints

    p = tmp_path / "map.csv"
    p.write_bytes(
        "\ufeff# frame origin_lat=49.461 origin_lon=11.111\nx,y,floor,ap1\n1,2,0,-60\n".encode()
    )
    fp = Fingerprints.read(p)
    assert fp.frame is not None and fp.frame.origin_lat == 49.461 and len(fp) == 1


def test_info_on_a_logfile_imports_no_heavy_library(tmp_path):
    """Issue #17: `workstation info` imports only what it uses (start-up time): neither pandas
    nor matplotlib nor viser nor rerun."""
    import subprocess
    import sys

    from tests.conftest import gsd_lines

    log = tmp_path / "walk.txt"
    log.write_text("\n".join(gsd_lines()) + "\n")
    code = (
        "import sys\nfrom workstation.cli import main\n"
        f"assert main(['info', {str(log)!r}]) == 0\n"
        "print(sorted(m for m in ('pandas', 'matplotlib', 'viser', 'rerun') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip().splitlines()[-1] == "[]", out.stdout


def test_run_imports_no_heavy_library(tmp_path):
    """Issue #17: `workstation run` on the bundled Microsoft walk writes its tables without
    pandas and filters without scipy.signal; 1-NN's Numba is not needed."""
    import subprocess
    import sys

    walk = REPO / "sample_sessions" / "msilc-site1-f1-walk"
    code = (
        "import sys\nfrom workstation.cli import main\n"
        f"assert main(['run', {str(walk)!r}, '--graph', {str(walk / 'graph.yaml')!r}, "
        f"'--out', {str(tmp_path / 'out')!r}]) == 0\n"
        "heavy = ('pandas', 'matplotlib', 'viser', 'rerun', 'scipy.signal', 'scipy.stats', 'numba')\n"
        "print(sorted(m for m in heavy if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip().splitlines()[-1] == "[]", out.stdout


def test_a_misspelled_option_is_named_with_the_one_meant(capsys):
    S = str(REPO / "sample_sessions" / "office2f" / "normal")
    with pytest.raises(SystemExit) as e:
        main(["run", S, "--grpah", "g.yaml", "--out", "x"])
    assert e.value.code == 2
    assert "--grpah: did you mean --graph?" in capsys.readouterr().err


def test_a_misspelled_start_is_named_with_the_one_meant(tmp_path, capsys):
    S = REPO / "sample_sessions" / "office2f" / "normal"
    code = main(["run", str(S), "--graph", str(S / "graph.yaml"), "--start", "frist-fix",
                 "--out", str(tmp_path)])  # fmt: skip
    assert code == 2 and "did you mean first-fix?" in capsys.readouterr().err


def test_ctrl_c_says_it_was_interrupted(monkeypatch, capsys):
    import workstation.commands.walk as walk

    def interrupted(args):
        raise KeyboardInterrupt

    monkeypatch.setattr(walk, "info", interrupted)
    assert main(["info", str(REPO / "sample_sessions" / "office2f" / "normal")]) == 130
    assert "interrupted" in capsys.readouterr().err


def test_the_demo_runs_as_the_readme_says(tmp_path, monkeypatch, capsys):
    """`make demo` (`workstation demo --out DIR`): without a display it runs the bundled walk and
    saves the recording instead of opening a viewer (session 18 broke it, and no test saw)."""
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert main(["demo", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "reference_points" in out and (tmp_path / "normal.rrd").stat().st_size > 10_000
    assert (tmp_path / "normal" / "radiomap.csv").is_file()


def test_run_says_where_and_when_the_walk_starts(tmp_path, capsys):
    """Issue #50 item 3: run's console named the end but not the start landmark or its time."""
    walk = REPO / "sample_sessions" / "office2f" / "normal"
    for start, how in ((None, "inferred"), ("SW0", "given")):
        extra = ["--start", start] if start else []
        code = main(["run", str(walk), "--graph", str(walk / "graph.yaml"), *extra,
                     "--out", str(tmp_path / (start or "infer"))])  # fmt: skip
        assert code == 0
        line = next(ln for ln in capsys.readouterr().out.splitlines() if "start_node" in ln)
        s = json.loads((tmp_path / (start or "infer") / "summary.json").read_text())
        assert f"{s['start_node']} at {s['start_time_s']} s ({how}: the walk starts" in line


def test_a_misspelled_option_of_a_command_and_a_misspelled_command_get_a_suggestion(capsys):
    """Issue #64 item 7: `localize --sesion` (an option the top parser does not know, said by
    it) and `workstation rnu` got none."""
    for argv, hint in ((["localize", "--map", "m.csv", "--sesion", "w"], "--sesion: did you mean --session?"),
                       (["rnu"], "rnu: did you mean run?")):  # fmt: skip
        with pytest.raises(SystemExit) as e:
            main(argv)
        assert e.value.code == 2 and hint in capsys.readouterr().err


def test_info_names_a_walk_in_a_store_by_its_url_and_from_msilc_says_its_floor(tmp_path, capsys):
    """`info s3://…` printed the temporary copy's path (its first line now is the path as
    given: here a local one, the store's case in test_walk_store.py); `building from-msilc`
    without --floor used 0 without a word."""
    ms = REPO / "sample_sessions" / "msilc-site1-f1-walk"
    assert main(["info", str(ms)]) == 0
    assert capsys.readouterr().out.splitlines()[0] == str(ms)
    assert main(["building", "from-msilc", str(ms / "floor_info.json"), "-o",
                 str(tmp_path / "b.yaml")]) == 0  # fmt: skip
    assert "note: --floor not given: the plan is floor 0" in capsys.readouterr().out
    assert main(["building", "from-msilc", str(ms / "floor_info.json"), "--floor", "2", "-o",
                 str(tmp_path / "c.yaml")]) == 0  # fmt: skip
    assert "--floor not given" not in capsys.readouterr().out


def test_example_commands_in_help_are_not_wrapped(monkeypatch):
    """Issue #64 item 7: the help's example command was wrapped mid-path (copy-paste broke)."""
    from workstation.cli import build_parser

    monkeypatch.setenv("COLUMNS", "80")
    p = build_parser()
    sub = next(a for a in p._actions if a.choices and "run" in a.choices).choices["run"]
    text = sub.format_help()
    line = next(ln for ln in text.splitlines() if ln.startswith("example:"))
    assert line.endswith("--out out/normal") and len(line) > 80
