"""No output path can be steered outside its output folder (issue #33): not by a name in the
data (a campaign's building, an AP column of a radio map), not by an absolute path, not by a
symbolic link planted in the output folder."""

import json
import shutil

import pytest

from tests.conftest import REPO
from workstation.cli import main

OFFICE = REPO / "sample_sessions" / "office2f" / "normal"


def _files(folder):
    return sorted(p for p in folder.rglob("*"))


def test_run_replaces_a_planted_link_instead_of_writing_through_it(tmp_path):
    victim = tmp_path / "elsewhere" / "precious.txt"
    victim.parent.mkdir()
    victim.write_text("keep me\n")
    out = tmp_path / "out"
    out.mkdir()
    (out / "trajectory.csv").symlink_to(victim)
    (out / "summary.json").symlink_to(tmp_path / "elsewhere" / "new.json")  # a dangling one
    assert main(["run", str(OFFICE), "--graph", str(OFFICE / "graph.yaml"), "--out",
                 str(out)]) == 0  # fmt: skip
    assert victim.read_text() == "keep me\n"
    assert _files(victim.parent) == [victim]
    for name in ("trajectory.csv", "summary.json"):
        assert not (out / name).is_symlink() and (out / name).stat().st_size > 100


@pytest.mark.parametrize("hostile", ["../../escaped{}", "/tmp/abs{}", "..{}", "a/../../b{}"])
def test_ap_names_from_a_radio_map_stay_file_names(tmp_path, hostile):
    run = tmp_path / "r"
    assert main(["run", str(OFFICE), "--graph", str(OFFICE / "graph.yaml"), "--out",
                 str(run)]) == 0  # fmt: skip
    lines = (run / "radiomap.csv").read_text().splitlines()
    i = next(k for k, ln in enumerate(lines) if ln.startswith("x,y,"))
    cols = lines[i].split(",")
    fixed = {"x", "y", "floor", "t", "belief", "sigma", "accepted"}
    lines[i] = ",".join(c if c in fixed else hostile.format(k) for k, c in enumerate(cols))
    (run / "radiomap.csv").write_text("\n".join(lines) + "\n")
    out = tmp_path / "deep" / "q"
    before = set(_files(tmp_path)) - set(_files(out) if out.exists() else [])
    assert main(["quality", "--map", str(run / "radiomap.csv"), "--graph",
                 str(OFFICE / "graph.yaml"), "--aps", "3", "--out", str(out)]) == 0  # fmt: skip
    new = set(_files(tmp_path)) - before
    assert new and all(p.is_relative_to(out) or out.is_relative_to(p) for p in new), sorted(new)
    assert len(list(out.glob("floor_0_ap_*.png"))) == 3
    rep = json.loads((out / "quality.json").read_text())
    assert hostile.format("") in rep["floors"][0]["aps"][0]  # the name is kept as data


def test_a_campaign_refuses_a_link_out_of_its_folder(tmp_path, capsys):
    root = tmp_path / "campaign" / "buildings" / "office"
    (root / "walks").mkdir(parents=True)
    shutil.copy(OFFICE / "graph.yaml", root / "graph.yaml")
    shutil.copytree(OFFICE, root / "walks" / "normal")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    out = tmp_path / "out"
    out.mkdir()
    (out / "walks").symlink_to(elsewhere, target_is_directory=True)
    code = main(["campaign", "run", str(tmp_path / "campaign"), "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2 and "leads out of the campaign's folder" in err and str(out / "walks") in err
    assert list(elsewhere.iterdir()) == []
    (out / "walks").unlink()
    assert main(["campaign", "run", str(tmp_path / "campaign"), "--out", str(out)]) == 0
    assert (out / "walks" / "office" / "normal" / "summary.json").is_file()


@pytest.mark.parametrize("kind", ["fifo", "folder", "link to a fifo"])
def test_an_output_that_is_no_regular_file_is_refused(tmp_path, capsys, kind):
    """Issue #55 item 1: as root, `-o /dev/null` replaced the device with a file, and backing up
    /dev/zero copied it until the disk was full. A path that is a device, folder or pipe (here a
    FIFO: safe to make anywhere, and reading it would hang like /dev/zero never ends) is refused
    with one line naming it, for every writer; nothing is written or read through it."""
    import os

    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    target = {"fifo": tmp_path / "m.csv", "folder": tmp_path / "m.csv",
              "link to a fifo": tmp_path / "m.csv"}[kind]  # fmt: skip
    if kind == "fifo":
        os.mkfifo(target)
    elif kind == "folder":
        target.mkdir()
    else:
        target.symlink_to(fifo)
    run = tmp_path / "run"
    assert main(["run", str(OFFICE), "--graph", str(OFFICE / "graph.yaml"), "--out",
                 str(run)]) == 0  # fmt: skip
    capsys.readouterr()
    assert main(["merge", str(run / "radiomap.csv"), "-o", str(target)]) == 2
    err = capsys.readouterr().err
    assert f"{target.resolve() if kind.startswith('link') else target}: is not a regular file" in err
    assert "Traceback" not in err
    # params and graph saves refuse it alike
    g = tmp_path / "g.yaml"
    shutil.copy(OFFICE / "graph.yaml", g)
    from workstation.errors import InputError
    from workstation.graph import LandmarkGraph
    from workstation.params import Params

    with pytest.raises(InputError, match="is not a regular file"):
        Params().save(target)
    with pytest.raises(InputError, match="is not a regular file"):
        LandmarkGraph.load(g).save(target)


def test_a_run_replaces_a_link_to_a_fifo_without_reading_it(tmp_path):
    """The run's own outputs are replaced, never written through, even as a link to a pipe, and
    the backup never reads what the link points at (a copy of a pipe or /dev/zero never ends)."""
    import os

    out = tmp_path / "out"
    out.mkdir()
    os.mkfifo(out / "pipe")
    (out / "radiomap.csv").symlink_to(out / "pipe")
    assert main(["run", str(OFFICE), "--graph", str(OFFICE / "graph.yaml"), "--out",
                 str(out)]) == 0  # fmt: skip
    assert (out / "radiomap.csv").is_file() and not (out / "radiomap.csv").is_symlink()
    assert not (out / "radiomap.csv.bak").exists()
