"""Reading YAML files we are given: ``safe_load`` only, and errors that name file and line."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from workstation.errors import InputError


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


MAX_BYTES = 20 * 1024 * 1024  # our YAML files are kilobytes; a graph of 10,000 nodes ~1 MB
MAX_DEPTH = 64  # our files nest 4 deep


class _Limits(yaml.composer.Composer, yaml.constructor.SafeConstructor):
    """``safe_load``'s limits: aliases are refused (a 1 KB alias bomb expands to gigabytes),
    nesting deeper than ``MAX_DEPTH`` (Python's recursion limit otherwise) and a key given
    twice too. Mixed into a loader before its composer and constructor."""

    _depth = 0

    def construct_mapping(self, node, deep=False):
        """A key given twice is refused (the last silently won: a second ``belief:`` section
        replaced the first)."""
        seen = set()
        for k, _ in node.value:
            key = self.construct_object(k, deep=True)
            try:
                dup = key in seen
                seen.add(key)
            except TypeError:  # an unhashable key: the constructor says so itself
                continue
            if dup:
                raise yaml.constructor.ConstructorError(
                    None, None, f"{key!r} is given twice", k.start_mark
                )
        return super().construct_mapping(node, deep)

    def compose_node(self, parent, index):
        if self.check_event(yaml.AliasEvent):
            ev = self.peek_event()
            raise yaml.composer.ComposerError(
                None, None, "aliases (*name) are not accepted in these files", ev.start_mark
            )
        self._depth += 1
        try:
            if self._depth > MAX_DEPTH:
                raise yaml.composer.ComposerError(
                    None,
                    None,
                    f"nested deeper than {MAX_DEPTH} levels",
                    self.peek_event().start_mark,
                )
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


def _check_tree(root: yaml.Node) -> None:
    """:class:`_Limits` on a composed tree: a node met twice is an alias (libyaml shares the
    anchored node: nothing is expanded, a bomb is found at its first repeat), and no node
    deeper than ``MAX_DEPTH``; walked without recursion."""
    seen: set[int] = set()
    todo: list[tuple[yaml.Node, int]] = [(root, 1)]
    while todo:
        node, depth = todo.pop()
        if id(node) in seen:
            raise yaml.composer.ComposerError(
                None, None, "aliases (*name) are not accepted in these files", node.start_mark
            )
        seen.add(id(node))
        if depth > MAX_DEPTH:
            raise yaml.composer.ComposerError(
                None, None, f"nested deeper than {MAX_DEPTH} levels", node.start_mark
            )
        if isinstance(node, yaml.SequenceNode):
            todo += [(c, depth + 1) for c in node.value]
        elif isinstance(node, yaml.MappingNode):
            todo += [(c, depth + 1) for kv in node.value for c in kv]


class LimitedLoader(_Limits, yaml.SafeLoader):
    """``safe_load`` with :class:`_Limits`, all in Python."""


try:  # libyaml, when PyYAML was built with it
    from yaml.cyaml import CParser
except ImportError:  # pragma: no cover - PyYAML's wheels carry it
    CParser = None


if CParser is not None:

    class _FastLoader(_Limits, CParser, yaml.resolver.Resolver):
        """:class:`LimitedLoader` with libyaml's scanner, parser and composer (issue #53: the
        pure-Python ones took 0.2 s of a 0.5-s ``run`` on the mall's graph): the node tree is
        checked once composed (:func:`_check_tree`); keys given twice, as it is constructed."""

        def __init__(self, stream):
            CParser.__init__(self, stream)
            yaml.composer.Composer.__init__(self)
            yaml.constructor.SafeConstructor.__init__(self)
            yaml.resolver.Resolver.__init__(self)

        def get_single_node(self):
            root = CParser.get_single_node(self)
            if root is not None:
                _check_tree(root)
            return root

    _LOADER: type = _FastLoader
else:  # pragma: no cover
    _LOADER = LimitedLoader


def parse_yaml(text: str, source=None) -> Any:
    """Parse YAML text with :class:`LimitedLoader`; errors name the source and line."""
    if len(text) > MAX_BYTES:
        raise InputError(
            source or "<yaml>", f"larger than {MAX_BYTES // 2**20} MB: not one of our files"
        )
    try:
        return yaml.load(text, Loader=_LOADER)  # noqa: S506 - SafeConstructor only
    except yaml.YAMLError as e:
        raise yaml_error(source or "<yaml>", e) from None
    except RecursionError:
        raise InputError(source or "<yaml>", "nested too deeply") from None
    except ValueError as e:  # a 5,000-digit integer: Python's int-string limit
        raise InputError(source or "<yaml>", f"not valid YAML: {e}") from None


def parse_yaml_nodes(text: str, source=None) -> tuple[Any, Any]:
    """The parsed data and its node tree (line numbers) from one pass of
    :class:`LimitedLoader` — composing, then constructing from the nodes, as ``yaml.load`` does
    (parsing twice took half of ``run``'s time on a mall graph of 261 landmarks)."""
    if len(text) > MAX_BYTES:
        raise InputError(
            source or "<yaml>", f"larger than {MAX_BYTES // 2**20} MB: not one of our files"
        )
    loader = None
    try:
        loader = _LOADER(text)  # (its reader checks the characters at once)
        root = loader.get_single_node()
        return (loader.construct_document(root) if root is not None else None), root
    except yaml.YAMLError as e:
        raise yaml_error(source or "<yaml>", e) from None
    except RecursionError:
        raise InputError(source or "<yaml>", "nested too deeply") from None
    except ValueError as e:  # a 5,000-digit integer: Python's int-string limit
        raise InputError(source or "<yaml>", f"not valid YAML: {e}") from None
    finally:
        if loader is not None:
            loader.dispose()


def load_yaml(path: str | Path, what: str) -> Any:
    """The parsed contents of a YAML file, or an :class:`InputError` naming file and line."""
    return parse_yaml(read_text(path, what), path)


# libyaml's emitter when PyYAML was built with it (same text as the pure-Python one, ~5× faster:
# the editor writes its recovery copies after every edit)
_DUMPER = getattr(yaml, "CSafeDumper", yaml.SafeDumper)


def dump_yaml(data: Any, **kw) -> str:
    """``yaml.safe_dump`` (plain data only), through libyaml when it is there."""
    return yaml.dump(data, Dumper=_DUMPER, allow_unicode=kw.pop("allow_unicode", False), **kw)
