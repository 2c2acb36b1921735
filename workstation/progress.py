"""Progress of long work, on stderr: a tqdm bar on a terminal, plain lines otherwise (logs, CI,
pipes). One callable, ``Progress()(i, n, what)``, is handed to every long loop (campaign walks,
evaluate experiments, graph import, editor start-up); it opens a new bar whenever the total or
the phase changes and closes it at ``i == n``.
"""

from __future__ import annotations

import sys
from typing import Any, TextIO

from tqdm import tqdm


class Progress:
    """``progress(i, n, what)``: item ``i`` of ``n`` is done; ``what`` names it.

    ``phase`` (optional, keyword) groups items under one bar: the bar is re-opened when it
    changes. ``bar=None`` decides from the stream: a bar only on a terminal.
    """

    def __init__(self, stream: TextIO | None = None, bar: bool | None = None):
        self.stream = stream or sys.stderr
        isatty = getattr(self.stream, "isatty", None)
        self.bar = bool(isatty and isatty()) if bar is None else bar
        self._tqdm: Any = None  # a tqdm bar, imported when first shown
        self._key: tuple | None = None

    def __call__(self, i: int, n: int, what: str = "", phase: str = "") -> None:
        if not self.bar:
            print(f"  [{i}/{n}] {what}", file=self.stream, flush=True)
            return
        key = (n, phase)
        if self._tqdm is None or key != self._key or i <= self._tqdm.n:
            self.close()

            self._tqdm = tqdm(total=n, desc=phase or None, file=self.stream, leave=True,
                              dynamic_ncols=True, unit="")  # fmt: skip
            self._key = key
        self._tqdm.set_postfix_str(what[:60], refresh=False)
        self._tqdm.update(i - self._tqdm.n)
        if i >= n:
            self.close()

    def write(self, line: str) -> None:
        """A message that does not break the bar."""
        if self._tqdm is not None:
            self._tqdm.write(line, file=self.stream)
        else:
            print(line, file=self.stream, flush=True)

    def close(self) -> None:
        if self._tqdm is not None:
            self._tqdm.close()
            self._tqdm = None
