"""Setting a viser GUI input's value from code. viser 1.1 declares the ``value`` setter apart
from its getter, which mypy reads as a read-only property; every assignment goes through here
(one place to drop when viser's typing changes)."""

from __future__ import annotations

from typing import Any


def set_value(handle: Any, value: Any) -> None:
    """``handle.value = value`` (the browser tabs follow, and the handle's on_update runs)."""
    handle.value = value
