"""Every command's help has a description and an example (issue #14), and the examples that
need only the bundled samples run as written."""

import shlex

import pytest

from tests.conftest import REPO
from workstation.cli import build_parser, main
from workstation.commands.examples import EXAMPLES, _sub


def _all_parsers(p, path=""):
    try:
        subs = _sub(p)
    except KeyError:
        return [(path, p)]
    out = [(path, p)] if path else []
    for name, sp in subs.items():
        out += _all_parsers(sp, f"{path} {name}".strip())
    return out


def test_every_command_has_a_description_and_an_example():
    for path, p in _all_parsers(build_parser()):
        text = p.format_help()
        assert p.description, path
        assert "example:" in text, path


RUNNABLE = ["graph validate", "graph from-waypoints", "building from-msilc", "building validate",
            "building from-points", "simulate", "layouts", "plan"]  # fmt: skip


@pytest.mark.parametrize("path", RUNNABLE)
def test_examples_run_as_written(path, tmp_path, monkeypatch):
    monkeypatch.chdir(REPO)
    cmd = (
        EXAMPLES[path][1]
        .replace("out/", f"{tmp_path}/")
        .replace("--out layouts", f"--out {tmp_path}/l")
    )
    argv = shlex.split(cmd)[1:]
    assert main(argv) == 0, cmd


def test_every_argument_says_what_it_is():
    import argparse

    missing = []
    for path, p in _all_parsers(build_parser()):
        for a in p._actions:
            if isinstance(a, (argparse._HelpAction, argparse._SubParsersAction)):
                continue
            if not a.help:
                missing.append(f"{path}: {a.dest}")
    assert not missing, missing
