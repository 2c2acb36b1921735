"""Reading YAML files we are given: ``safe_load`` only, and errors that name file and line."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from .errors import InputError


def yaml_error(path, e: yaml.YAMLError) -> InputError:
    mark = getattr(e, "problem_mark", None)
    return InputError(
        path,
        f"not valid YAML: {getattr(e, 'problem', None) or e}",
        None if mark is None else mark.line + 1,
    )


def read_text(path: str | Path, what: str) -> str:
    path = Path(path)
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError(path, f"no such {what}") from None
    except (OSError, UnicodeDecodeError) as e:
        raise InputError(path, f"cannot read the {what}: {e}") from None


def load_yaml(path: str | Path, what: str) -> Any:
    """The parsed contents of a YAML file, or an :class:`InputError` naming file and line."""
    text = read_text(path, what)
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as e:
        raise yaml_error(path, e) from None
