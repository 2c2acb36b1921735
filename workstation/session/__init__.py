"""Sessions: one walk's streams in memory, and one reader per file format."""

from __future__ import annotations

from pathlib import Path

from workstation.errors import InputError
from workstation.session import getsensordata, msilc
from workstation.session._parse import head_text
from workstation.session.getsensordata import read_getsensordata
from workstation.session.metadata import ClockJump, Metadata
from workstation.session.model import GroundTruth, Scalar, Session, Vector3, WifiScans
from workstation.session.msilc import read_msilc
from workstation.session.native import is_native, read_session, write_session
from workstation.session.sanity import sanitize

__all__ = [
    "ClockJump",
    "GroundTruth",
    "Metadata",
    "Scalar",
    "Session",
    "Vector3",
    "WifiScans",
    "load_session",
    "read_getsensordata",
    "read_msilc",
    "read_session",
    "write_session",
]


def load_session(path: str | Path) -> Session:
    """Open a walk in any supported format: a native session folder, a GetSensorData/IPIN
    logfile, or a Microsoft ILC path file (recognised from its first lines; either file
    may be gzipped)."""
    path = Path(path)
    try:
        return sanitize(_read(path), path)
    except InputError:
        raise
    except (ValueError, TypeError, KeyError, OverflowError, IndexError) as e:
        raise InputError(path, f"not a readable session: {e}") from None


def _read(path: Path) -> Session:
    if path.is_dir():
        if is_native(path):
            return read_session(path)
        raise InputError(path, "folder without session.yaml: not a session folder")
    if not path.exists():
        raise InputError(path, "no such file or folder")
    head = head_text(path).splitlines()[:40]
    if msilc.looks_like(head):
        return read_msilc(path)
    if getsensordata.looks_like(head):
        return read_getsensordata(path)
    if not "".join(head).strip():
        raise InputError(path, "file is empty")
    raise InputError(
        path,
        "unrecognised format (expected a GetSensorData logfile, a Microsoft ILC path file or a session folder)",
        1,
    )
