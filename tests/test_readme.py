"""The README's and the command reference's examples, run as written: every ``workstation``
command of their ``sh`` blocks, in order, each document in a scratch folder of its own (a copy
of sample_sessions, ../shared/data beside it when present); each ``#>`` line under a command is
what that command prints — whitespace aside, ``...`` for the rest of the line. Commands that
serve or open a viewer (``edit``, ``view``) are not run."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import REPO, SHARED_DATA

README = REPO / "README.md"
REFERENCE = REPO / "docs" / "reference.md"  # the full command reference (issue #50 item 12)
DOCS = {"readme": README, "reference": REFERENCE}
NOT_RUN = ("edit", "view")


def commands(doc: Path = README) -> list[tuple[int, str, list[str]]]:
    """(line, command, expected output lines) of every ``workstation`` command, in order."""
    out: list[tuple[int, str, list[str]]] = []
    in_sh, cont = False, ""
    lines = doc.read_text(encoding="utf-8").splitlines()
    for n, line in enumerate(lines, 1):
        if line.startswith("```"):
            in_sh = line.strip() == "```sh"
            continue
        if not in_sh:
            continue
        if cont or line.startswith(("workstation ", "S=")):
            cont += line.rstrip("\\").strip() + " "
            if not line.endswith("\\"):
                out.append((n, cont.strip(), []))
                cont = ""
        elif line.startswith("#>") and out:
            out[-1][2].append(line[2:].strip())
    return out


ALL = {name: commands(doc) for name, doc in DOCS.items()}


def _norm(s: str) -> str:
    return " ".join(s.split())


def _shows(expected: str, printed: str) -> bool:
    """Some printed line holds ``expected`` (whitespace aside; ``...``: anything)."""
    parts = [_norm(p) for p in expected.split("...") if p.strip()]
    pattern = ".*".join(re.escape(p) for p in parts)
    return any(re.search(pattern, _norm(ln)) for ln in printed.splitlines())


_PRINTED: dict[str, dict[int, str | tuple[str]]] = {}


@pytest.fixture(scope="module")
def printed(tmp_path_factory):
    """Each document's commands' output by line, or why it was not run (run once a document)."""

    def of(name: str) -> dict[int, str | tuple[str]]:
        if name not in _PRINTED:
            _PRINTED[name] = _run_all(tmp_path_factory.mktemp(name), ALL[name], name)
        return _PRINTED[name]

    return of


def _run_all(root, cmds, name: str) -> dict[int, str | tuple[str]]:
    work = root / "work"
    shutil.copytree(REPO / "sample_sessions", work / "sample_sessions")
    if SHARED_DATA.is_dir():  # ../shared/data beside the scratch folder, wherever it is
        (root / "shared").mkdir()
        (root / "shared" / "data").symlink_to(SHARED_DATA.resolve())
    env = f"workstation() {{ '{sys.executable}' -m workstation \"$@\"; }}\n"
    out: dict[int, str | tuple[str]] = {}
    missing: set[str] = set()  # what the commands not run would have written
    script = env
    for n, cmd, _ in cmds:
        if cmd.startswith("S="):
            script += cmd + "\n"
            continue
        if cmd.split()[1] in NOT_RUN:
            out[n] = ("it serves until stopped (the browser tests run the panel)",)
            continue
        absent = _absent_data(cmd)
        if absent:
            out[n] = (f"it needs {absent}, absent from {SHARED_DATA}",)
            missing |= _outputs(cmd)
            continue
        if any(p == m or p.startswith(m.rstrip("/") + "/") for p in cmd.split() for m in missing):
            out[n] = ("it reads what a command that needs ../shared/data writes",)
            missing |= _outputs(cmd)
            continue
        r = subprocess.run(
            ["bash", "-c", script + cmd], cwd=work, capture_output=True, text=True, timeout=600
        )
        out[n] = r.stdout + r.stderr
        assert r.returncode in (0, 3), f"{name} line {n}: {cmd}\n{out[n]}"
    return out


def _absent_data(cmd: str) -> str | None:
    """The first ``../shared/data`` path (or glob) of ``cmd`` that names nothing there."""
    for tok in cmd.split():
        if "../shared/data" not in tok:
            continue
        rel = tok.split("../shared/data", 1)[1].strip("/")
        if not SHARED_DATA.is_dir() or (rel and not any(SHARED_DATA.glob(rel))):
            return tok
    return None


def _outputs(cmd: str) -> set[str]:
    """The paths a command writes (-o, --output, --out)."""
    return set(re.findall(r"(?:-o|--output|--out)\s+(\S+)", cmd))


@pytest.mark.parametrize(
    "doc,n,cmd,expected",
    [
        pytest.param(
            name, *c, id=f"{name}-line{c[0]}",
            marks=[pytest.mark.shared_data] if "../shared" in c[1] else [],
        )  # fmt: skip
        for name, cmds in ALL.items()
        for c in cmds
        if c[2]
    ],
)
def test_readme_example_prints_what_it_says(printed, doc, n, cmd, expected):
    got = printed(doc)[n]
    if isinstance(got, tuple):
        pytest.skip(f"{doc} line {n} is not run: {got[0]}")
    missing = [e for e in expected if not _shows(e, got)]
    assert not missing, f"{doc} line {n}: {cmd}\nnot printed: {missing}\nprinted:\n{got}"


def test_the_readme_has_checked_examples():
    """The bundled ones at least: docs whose examples all need ../shared/data check nothing
    without it; the README stays a short path (issue #50 item 12: a 426-line wall)."""
    for name, cmds in ALL.items():
        bundled = [c for c in cmds if c[2] and "../shared" not in c[1]]
        assert len(bundled) >= (1 if name == "readme" else 3), name
    assert len(README.read_text(encoding="utf-8").splitlines()) <= 150


def test_the_readme_steps_leave_the_bundled_samples_as_they_are(printed):
    """Issue #50 item 11: following the README rewrote the tracked sample graph.yaml and left
    .bak files beside it. Its commands write only outside sample_sessions/."""
    for name, cmds in ALL.items():
        for n, cmd, _ in cmds:
            outs = re.findall(r"(?:-o|--output|--out)\s+(\S+)", cmd)
            assert not any(o.startswith(("sample_sessions", "$S")) for o in outs), (name, n, cmd)


def _subparsers(parser):
    import argparse

    for a in parser._actions:  # argparse keeps its subcommands here
        if isinstance(a, argparse._SubParsersAction):
            return a.choices
    return {}


def synopses() -> list[tuple[list[str], str]]:
    """(subcommand words, synopsis) of every ``**`workstation …`**`` heading of the docs."""
    text = "\n".join(d.read_text(encoding="utf-8") for d in DOCS.values())
    return [
        (m.group(1).split()[:2], m.group(0))
        for m in re.finditer(r"\*\*`workstation ([^`]*)`\*\*", text)
    ]


def test_every_option_is_in_the_readme_synopsis():
    """The synopses of a command name every option it takes, long or short (``--building`` and
    ``--plan`` were missing from view's and edit's)."""
    from workstation.cli import build_parser

    texts: dict[tuple[str, ...], str] = {}  # a command's synopses, together
    top = _subparsers(build_parser())
    for words, syn in synopses():
        p = top.get(words[0])
        if p is None:
            continue
        key = (words[0], words[1]) if _subparsers(p) else (words[0],)
        texts[key] = texts.get(key, "") + syn

    def named(o: str, syn: str) -> bool:
        return re.search(r"(?<![\w-])" + re.escape(o) + r"(?![\w-])", syn) is not None

    wrong = []
    for key, syn in texts.items():
        p = top[key[0]] if len(key) == 1 else _subparsers(top[key[0]])[key[1]]
        missing = [
            a.option_strings[-1]
            for a in p._actions
            if a.option_strings
            and "--help" not in a.option_strings
            and not any(named(o, syn) for o in a.option_strings)
        ]
        if missing:
            wrong.append(f"workstation {' '.join(key)}: {missing}")
    assert not wrong, "README synopses miss options:\n" + "\n".join(wrong)
    assert len(texts) >= 10
