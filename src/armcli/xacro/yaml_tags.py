"""The xacro library's `load_yaml` in safe mode: its YAML, without xacro's `eval`.

xacro reads YAML with PyYAML's `safe_load` plus its unit tags (`!degrees 90`,
`!radians pi/2`, `!millimeters 35`, ...), whose text it evaluates as an
expression, and it keeps the last value of a duplicated key silently. Here the
same loader runs with the unit expressions evaluated by xacro.expr's whitelist
(the caller's `evaluate`), the unit table taken from the installed xacro, and a
duplicate key accepted as xacro does but reported (`warn`, with file and line).
Anchors and aliases are kept (xacro accepts them) but counted, so a
"billion laughs" document cannot turn into a huge structure.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import yaml

MAX_ALIASES = 1000  # alias nodes per YAML file (real description files use none or a few)
MAX_DEPTH = 64  # nesting of collections


class YamlRefusedError(Exception):
    """A YAML file that safe mode will not load (too many aliases, too deep, a bad unit)."""

    def __init__(self, message: str, line: int | None) -> None:
        super().__init__(message)
        self.message = message
        self.line = line


def load_yaml(
    text: str,
    source: str,
    units: Mapping[str, float],
    evaluate: Callable[[str], Any],
    warn: Callable[[str], None],
) -> Any:
    """The document in `text` as xacro's load_yaml builds it (before xacro's wrappers)."""
    _scan(text)
    loader = _loader_class(source, units, evaluate, warn)(text)
    try:
        return loader.get_single_data()
    finally:
        loader.dispose()


def _scan(text: str) -> None:
    """Count aliases and nesting before anything is built."""
    aliases = depth = 0
    for ev in yaml.parse(text, Loader=yaml.SafeLoader):
        line = ev.start_mark.line + 1 if ev.start_mark else None
        if isinstance(ev, yaml.AliasEvent):
            aliases += 1
            if aliases > MAX_ALIASES:
                raise YamlRefusedError(f"more than {MAX_ALIASES} YAML aliases", line)
        elif isinstance(ev, yaml.CollectionStartEvent):
            depth += 1
            if depth > MAX_DEPTH:
                raise YamlRefusedError(f"YAML nested deeper than {MAX_DEPTH} levels", line)
        elif isinstance(ev, yaml.CollectionEndEvent):
            depth -= 1


def _loader_class(
    source: str,
    units: Mapping[str, float],
    evaluate: Callable[[str], Any],
    warn: Callable[[str], None],
) -> type[yaml.SafeLoader]:
    class Loader(yaml.SafeLoader):
        """SafeLoader plus xacro's unit tags; duplicate keys reported."""

        def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> Any:
            seen: dict[Any, int] = {}
            for key_node, _ in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge":
                    continue
                key = self.construct_object(key_node, deep=True)
                line = key_node.start_mark.line + 1
                if isinstance(key, str | int | float | bool) and key in seen:
                    warn(
                        f"{source}:{line}: duplicate YAML key {key!r} (first on line "
                        f"{seen[key]}); the last value is used, as xacro does"
                    )
                if isinstance(key, str | int | float | bool):
                    seen.setdefault(key, line)
            return super().construct_mapping(node, deep=deep)

    def unit(factor: float) -> Callable[[yaml.SafeLoader, yaml.Node], float]:
        def construct(loader: yaml.SafeLoader, node: yaml.Node) -> float:
            text = loader.construct_scalar(node)  # type: ignore[arg-type]
            return float(evaluate(str(text))) * factor

        return construct

    for tag, factor in units.items():
        Loader.add_constructor(tag, unit(factor))
    return Loader
