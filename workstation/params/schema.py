"""The parameter field (:func:`P`: default, range, help, unit, Table I mark) and the checks every
parameter group runs on its values (:class:`_Group`): type, finiteness and range, the message
naming the key."""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import ClassVar

from workstation.errors import ParameterError

#: where the heading between landmarks comes from (``pdr.heading_source``; not a rule's name,
#: though the gyroscope also gives the turn rule its name)
GYRO_HEADING, COMPASS_HEADING = "gyro", "compass"
HEADING_SOURCES = (GYRO_HEADING, COMPASS_HEADING)


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


@dataclass(frozen=True)
class _Group:
    """A parameter group (a dataclass): its values checked against their declared ranges."""

    SECTION: ClassVar[str] = ""  # the group's name in parameter files (``steps``, ``pdr``…)

    def __post_init__(self):
        for f in fields(self):
            v = getattr(self, f.name)
            m = f.metadata
            where = f"{self.SECTION}.{f.name}"
            if m.get("choices"):
                if v not in m["choices"]:
                    raise ParameterError(
                        f"{where}: {v!r} is not one of {', '.join(map(str, m['choices']))}"
                    )
                continue
            if isinstance(f.default, bool):
                if not isinstance(v, bool):
                    raise ParameterError(f"{where}: expected true or false, got {v!r}")
                continue
            if f.default is None and v is None:
                continue
            if isinstance(f.default, str) or (f.default is None and isinstance(v, str)):
                if not isinstance(v, str):
                    raise ParameterError(f"{where}: expected text, got {v!r}")
                continue
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
                object.__setattr__(self, f.name, int(v))
            else:
                object.__setattr__(self, f.name, float(v))
            v = getattr(self, f.name)
            if (m["lo"] is not None and v < m["lo"]) or (m["hi"] is not None and v > m["hi"]):
                raise ParameterError(
                    f"{where}: {v} is outside [{m['lo']}, {m['hi']}] {m['unit']}".rstrip()
                )
