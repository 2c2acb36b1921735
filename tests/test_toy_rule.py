"""Issue #65 item 4: a landmark rule is one entry of ``workstation/rules.py`` and one detector
function (``detect_<section>`` in ``pipeline/landmarks.py``) — nothing else. A copy of the
package gets a toy rule that way (a stop, under another name), and the bundled office walk on
its graph (every stop landmark's rule renamed) is run, drawn in Rerun and edited in the panel:
the toy detections are matched, the panel's rule menu offers it, both legends name it."""

import json
import os
import shutil
import subprocess
import sys
import textwrap

from tests.conftest import REPO

WALK = REPO / "sample_sessions" / "office2f" / "normal"

TOY_RULE = (
    '    Rule("toy", "a toy: a stop, under another name (tests/test_toy_rule.py)", "toy", False),\n'
)
TOY_DETECTOR = '''

def detect_toy(steps: Steps, p: None) -> list[Row]:
    """The toy rule: the stops, under its name (its section has no parameters: ``p`` None)."""
    return [(t, "toy", *rest) for t, _, *rest in detect_acc(steps, AccLandmarkParams())]
'''
CHECK = '''
import json, sys, types
from pathlib import Path
from workstation.editor import SurveyEditor
from workstation.graph import LandmarkGraph
from workstation.session import load_session
from workstation.viz.colours import KINDS, legend_markdown, panel_legend
from workstation.viz.panel import SurveyPanel
from workstation.viz.panel_form import LandmarkForm

g = LandmarkGraph.load(sys.argv[1])
ed = SurveyEditor(load_session(sys.argv[2]), g, graph_path=sys.argv[1], out_dir=sys.argv[3])
pan = SurveyPanel(ed, None, port=0)
try:
    form = LandmarkForm(pan, types.SimpleNamespace(gui=pan.server.gui, client_id=0), 1.0)
    menu = sorted(form.rule_boxes)
finally:
    pan.stop()
print(json.dumps({"menu": menu, "rerun_legend": legend_markdown(), "panel_legend": panel_legend(),
                  "kinds": sorted(KINDS)}))
'''


def _toy_package(tmp_path):
    pkg = tmp_path / "pkg"
    shutil.copytree(REPO / "workstation", pkg / "workstation",
                    ignore=shutil.ignore_patterns("__pycache__"))  # fmt: skip
    rules = pkg / "workstation" / "rules.py"
    text = rules.read_text(encoding="utf-8")
    end = text.index("\n)\n", text.index("TABLE: tuple[Rule, ...] = ("))  # the table's last line
    rules.write_text(text[: end + 1] + TOY_RULE + text[end + 1 :], encoding="utf-8")
    det = pkg / "workstation" / "pipeline" / "landmarks.py"
    det.write_text(det.read_text(encoding="utf-8") + TOY_DETECTOR, encoding="utf-8")
    return pkg


def _run(pkg, *args, cwd):
    env = dict(os.environ, PYTHONPATH=str(pkg))
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, env=env,
                          cwd=cwd, timeout=600)  # fmt: skip


def test_a_toy_rule_is_one_table_entry_and_one_detector(tmp_path):
    pkg = _toy_package(tmp_path)
    graph = tmp_path / "graph.yaml"
    text = (WALK / "graph.yaml").read_text(encoding="utf-8")
    assert "[acc]" in text
    graph.write_text(text.replace("[acc]", "[toy]"), encoding="utf-8")

    out = tmp_path / "run"
    r = _run(pkg, "-m", "workstation", "run", str(WALK), "--graph", str(graph), "--out", str(out),
             cwd=tmp_path)  # fmt: skip
    assert r.returncode == 0, r.stderr[-2000:]
    summ = json.loads((out / "summary.json").read_text())
    assert summ["landmarks_detected_by_kind"]["toy"] >= 3
    rows = (out / "landmarks.csv").read_text().splitlines()
    head = rows[0].split(",")
    kind, node = head.index("type"), head.index("node")
    toy_matched = [r for r in rows[1:] if r.split(",")[kind] == "toy" and r.split(",")[node]]
    assert len(toy_matched) >= 3  # the association matched them to the toy landmarks

    r = _run(pkg, "-m", "workstation", "view", str(WALK), "--graph", str(graph), "--save",
             str(tmp_path / "toy.rrd"), cwd=tmp_path)  # fmt: skip
    assert r.returncode == 0, r.stderr[-2000:]
    assert (tmp_path / "toy.rrd").stat().st_size > 10_000

    r = _run(pkg, "-c", textwrap.dedent(CHECK), str(graph), str(WALK), str(tmp_path / "ed"),
             cwd=tmp_path)  # fmt: skip
    assert r.returncode == 0, r.stderr[-2000:]
    seen = json.loads(r.stdout.strip().splitlines()[-1])
    assert "toy" in seen["menu"] and "acc" in seen["menu"]
    assert "toy" in seen["kinds"]
    assert "toy" in seen["rerun_legend"] and "toy" in seen["panel_legend"]


def test_without_the_toy_the_package_knows_no_such_rule():
    """The check above is no tautology: the package as it is has no rule "toy"."""
    from workstation import rules
    from workstation.viz.colours import panel_legend

    assert "toy" not in rules.NAMES and "toy" not in panel_legend()
