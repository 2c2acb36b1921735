"""The parameter field (:func:`P`: default, range, help, unit, Table I mark) and the checks every
parameter group runs on its values (:class:`_Group`): type, finiteness and range, the message
naming the key."""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import ClassVar, Literal, get_args

from workstation.errors import ParameterError

#: where the heading between landmarks comes from (``pdr.heading_source``; not a rule's name,
#: though the gyroscope also gives the turn rule its name)
HeadingSource = Literal["gyro", "compass"]
GYRO_HEADING, COMPASS_HEADING = get_args(HeadingSource)


def P(default, lo=None, hi=None, help="", unit="", paper=None, choices=None):
    """A parameter field: default, allowed range [lo, hi], help text, unit, Table I mark."""
    return field(
        default=default,
        metadata={
            "lo": lo,
            "hi": hi,
            "help": help,
            "unit": unit,
            "paper": paper,
            "choices": choices,
        },
    )


_KEEP = object()  # a value that is right as it was given (a choice, a flag, text, None)


def _checked(f, v, where: str):
    """A parameter's value checked against its field: a choice, a flag, text (or None where the
    default is None) kept as given (``_KEEP``); a number made an int or a float and checked to
    be finite and within its range."""
    m = f.metadata
    if m.get("choices"):
        if v not in m["choices"]:
            raise ParameterError(f"{where}: {v!r} is not one of {', '.join(map(str, m['choices']))}")
        return _KEEP
    if isinstance(f.default, bool):
        if not isinstance(v, bool):
            raise ParameterError(f"{where}: expected true or false, got {v!r}")
        return _KEEP
    if f.default is None and v is None:
        return _KEEP
    if isinstance(f.default, str) or (f.default is None and isinstance(v, str)):
        if not isinstance(v, str):
            raise ParameterError(f"{where}: expected text, got {v!r}")
        return _KEEP
    out = _number(f, v, where)
    if (m["lo"] is not None and out < m["lo"]) or (m["hi"] is not None and out > m["hi"]):
        raise ParameterError(f"{where}: {out} is outside [{m['lo']}, {m['hi']}] {m['unit']}".rstrip())
    return out


def _number(f, v, where: str) -> int | float:
    """A finite number as the field's type (a whole number where the default is an int)."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ParameterError(f"{where}: expected a number, got {v!r}")
    try:
        fv = float(v)
    except OverflowError:
        fv = float("inf")
    if fv != fv or fv in (float("inf"), float("-inf")):
        raise ParameterError(f"{where}: expected a finite number, got {v!r}"[:200])
    if isinstance(f.default, int) and not isinstance(f.default, bool):
        if float(v) != int(v):
            raise ParameterError(f"{where}: expected a whole number, got {v!r}")
        return int(v)
    return float(v)


@dataclass(frozen=True)
class _Group:
    """A parameter group (a dataclass): its values checked against their declared ranges."""

    SECTION: ClassVar[str] = ""  # the group's name in parameter files (``steps``, ``pdr``…)

    def __post_init__(self):
        for f in fields(self):
            v = _checked(f, getattr(self, f.name), f"{self.SECTION}.{f.name}")
            if v is not _KEEP:
                object.__setattr__(self, f.name, v)
