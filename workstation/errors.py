"""Typed errors a surveyor can act on: each names the file and line, or the node/edge."""

from __future__ import annotations

from pathlib import Path


class WorkstationError(Exception):
    """Base of every error the CLI reports without a traceback."""


class InputError(WorkstationError):
    """Bad input data: names the file, the line (1-based) when known, and what is wrong."""

    def __init__(self, path: str | Path | None, message: str, line: int | None = None):
        self.path = None if path is None else str(path)
        self.line = line
        self.reason = message
        where = self.path or "<input>"
        if line is not None:
            where = f"{where}:{line}"
        super().__init__(f"{where}: {message}")


class Unreadable(InputError):
    """An input that could not be read — gone from the store or the disk, no permission, the
    network — rather than one whose content is wrong: reading it again later may work."""


class GraphError(WorkstationError):
    """Invalid landmark graph: names the node or edge (and the file when known)."""

    def __init__(self, message: str, path: str | Path | None = None):
        self.path = None if path is None else str(path)
        self.reason = message
        super().__init__(f"{self.path}: {message}" if self.path else message)


class ParameterError(WorkstationError):
    """Unknown or out-of-range parameter value."""
