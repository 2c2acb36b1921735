"""Progress on stderr: plain lines when not a terminal (logs, CI), a bar on a terminal."""

import io

from workstation.progress import Progress


def test_plain_lines_when_not_a_terminal():
    out = io.StringIO()
    p = Progress(out)
    assert not p.bar
    for i in range(1, 4):
        p(i, 3, f"walk {i}")
    assert out.getvalue().splitlines() == ["  [1/3] walk 1", "  [2/3] walk 2", "  [3/3] walk 3"]


def test_a_bar_per_phase_on_a_terminal():
    out = io.StringIO()
    p = Progress(out, bar=True)
    for i in range(1, 3):
        p(i, 2, "x", phase="walks")
    p.write("walk b failed")
    for i in range(1, 4):
        p(i, 3, "y", phase="seeds")
    text = out.getvalue()
    assert "walks: 100%" in text and "2/2" in text
    assert "seeds: 100%" in text and "3/3" in text
    assert "walk b failed" in text
