"""Safe YAML reading for user files: no aliases, no duplicate keys, bounded size, line numbers.

PyYAML's `safe_load` still expands alias bombs and silently keeps the last of
duplicate keys, so user files go through this reader instead. It also returns
a map from field path to line so that validation errors can point at a line.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from armcli.errors import InputError
from armcli.io.userfile import read_regular

MAX_YAML_BYTES = 1_000_000
MAX_YAML_DEPTH = 64
MAX_INT_BITS = 1024  # larger integers exceed the float range every consumer converts to

Path_ = tuple[str | int, ...]
_PLAIN_TAGS = {
    f"tag:yaml.org,2002:{t}" for t in ("str", "int", "float", "bool", "null", "map", "seq")
}


@dataclass
class YamlDoc:
    """Plain Python data plus the line (1-based) each field path starts on."""

    data: Any
    lines: dict[Path_, int] = field(default_factory=dict)
    source: str = "<string>"
    merge_duplicates: bool = False  # ROS's parameter parser merges a repeated key's mappings

    def line_of(self, path: Path_) -> int | None:
        """Line of `path`, or of its closest ancestor that has one."""
        p = tuple(path)
        while True:
            if p in self.lines:
                return self.lines[p]
            if not p:
                return None
            p = p[:-1]


_Base: Any = getattr(yaml, "CSafeLoader", yaml.SafeLoader)  # libyaml when PyYAML has it


class _Loader(_Base):  # type: ignore[misc]
    """The safe loader (C-accelerated where available); anchors are refused before use."""


# YAML 1.1 (PyYAML) reads `1e9` as a string; YAML 1.2 and ROS tools read it as a float.
_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9_]+)[eE][-+]?[0-9]+$"),
    list("-+0123456789."),
)


def _scan_events(text: str, source: str) -> None:
    """Refuse anchors/aliases and excessive nesting before building anything."""
    depth = 0
    try:
        for ev in yaml.parse(text, Loader=_Loader):
            line = ev.start_mark.line + 1 if ev.start_mark else None
            if isinstance(ev, yaml.AliasEvent) or getattr(ev, "anchor", None):
                raise InputError(
                    "YAML anchors/aliases are not allowed in armcli input files",
                    file=source,
                    line=line,
                )
            if isinstance(ev, yaml.CollectionStartEvent):
                depth += 1
                if depth > MAX_YAML_DEPTH:
                    raise _too_deep(source, line)
            elif isinstance(ev, yaml.CollectionEndEvent):
                depth -= 1
    except yaml.YAMLError as exc:
        raise _yaml_error(exc, source, text) from None


def _yaml_error(exc: yaml.YAMLError, source: str, text: str = "") -> InputError:
    mark = getattr(exc, "problem_mark", None)
    line = mark.line + 1 if mark is not None else None
    problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
    if "nesting" in problem:  # the parser's own depth guard fired before the event scan's
        return _too_deep(source, line)
    if _at_tab(mark, text):  # PyYAML: "found character '\\t' that cannot start any token"
        where = f", column {mark.column + 1}" if mark is not None else ""
        return InputError(
            f"malformed YAML: a tab character{where}; YAML indents with spaces only",
            file=source,
            line=line,
        )
    return InputError(f"malformed YAML: {problem}", file=source, line=line)


def _at_tab(mark: Any, text: str) -> bool:
    """Whether the parser stopped on a tab (libyaml's message hides the character)."""
    if mark is None:
        return False
    lines = text.split("\n")
    row = lines[mark.line] if 0 <= mark.line < len(lines) else ""
    return row[mark.column : mark.column + 1] == "\t"


# `ros2 topic echo` ends every message with a `---` line: a file saved from it ends so.
_ECHO_END = re.compile(r"\n---[ \t]*(\n[ \t]*)*\Z")


def _too_deep(source: str, line: int | None) -> InputError:
    """One message for every depth guard (ours, PyYAML's scanner, Python's recursion)."""
    return InputError(f"nesting deeper than {MAX_YAML_DEPTH} levels", file=source, line=line)


def _scalar(node: yaml.ScalarNode, loader: _Loader, path: Path_, doc: YamlDoc) -> Any:
    """A scalar as str/int/float/bool/None; integers beyond any float are refused."""
    try:
        value = loader.construct_object(node, deep=True)
    except ValueError:  # int("9" * 5000): Python's 4300-digit conversion limit
        value = None
        too_big = True
    else:  # 0xfff...: no digit limit, but beyond any float (and str() of it fails)
        too_big = isinstance(value, int) and value.bit_length() > MAX_INT_BITS
    if too_big:
        raise InputError(
            f"integer out of range ({len(node.value)} characters; at most 1.8e308)",
            file=doc.source,
            line=node.start_mark.line + 1,
            field=_dotted(path) or None,
        )
    if isinstance(value, str | int | float | bool) or value is None:
        return value
    # timestamps, binary, ...: keep the source text, the schema decides.
    return str(node.value)


class FlowKeys(list[Any]):
    """`{0.5, 0.3}` read with `flow_sets`: a flow mapping of null values, as its keys in order.

    YAML reads the brace form as a mapping (repeated keys collapse in ROS's reader); the
    list keeps every key and `text` the keys as written, for the caller to explain.
    """

    def __init__(self, keys: list[Any], text: str) -> None:
        super().__init__(keys)
        self.text = text


def _build(
    node: yaml.Node,
    loader: _Loader,
    path: Path_,
    doc: YamlDoc,
    flow_sets: bool,
) -> Any:
    doc.lines.setdefault(path, node.start_mark.line + 1)
    if node.tag not in _PLAIN_TAGS:
        raise InputError(
            f"unsupported YAML tag {node.tag!r}", file=doc.source, line=node.start_mark.line + 1
        )
    if isinstance(node, yaml.ScalarNode):
        return _scalar(node, loader, path, doc)
    if isinstance(node, yaml.SequenceNode):
        return [
            _build(child, loader, (*path, i), doc, flow_sets) for i, child in enumerate(node.value)
        ]
    if isinstance(node, yaml.MappingNode):
        if (
            flow_sets
            and node.flow_style
            and node.value
            and all(
                isinstance(v, yaml.ScalarNode) and v.tag.endswith(":null") and v.value in ("", "~")
                for _, v in node.value
            )
        ):
            # `{0.5, 0.3}`: the course's brace form; its reader decides (armcli.trajectory.brace)
            keys = [
                _build(k, loader, (*path, i), doc, flow_sets) for i, (k, _) in enumerate(node.value)
            ]
            return FlowKeys(keys, "{" + ", ".join(str(k.value) for k, _ in node.value) + "}")
        out: dict[Any, Any] = {}
        for key_node, value_node in node.value:
            key = _build(key_node, loader, path, doc, flow_sets)
            if isinstance(key, list | dict):
                raise InputError(
                    "mapping keys must be scalars",
                    file=doc.source,
                    line=key_node.start_mark.line + 1,
                )
            key = str(key) if not isinstance(key, str) else key
            if key in out and doc.merge_duplicates:
                later = _build(value_node, loader, (*path, key), doc, flow_sets)
                out[key] = _merged(out[key], later)
                continue
            if key in out:
                raise InputError(
                    f"duplicate key {key!r}",
                    file=doc.source,
                    line=key_node.start_mark.line + 1,
                    field=_dotted((*path, key)),
                )
            out[key] = _build(value_node, loader, (*path, key), doc, flow_sets)
        return out
    raise InputError("unsupported YAML node", file=doc.source)  # pragma: no cover


def _merged(first: Any, later: Any) -> Any:
    """A repeated key as rcl's parameter parser reads it: mappings merged, else the later."""
    if isinstance(first, dict) and isinstance(later, dict):
        out = dict(first)
        for k, v in later.items():
            out[k] = _merged(out[k], v) if k in out else v
        return out
    return later


def _dotted(path: Path_) -> str:
    out = ""
    for part in path:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


dotted = _dotted


def loads_yaml(
    text: str,
    source: str = "<string>",
    *,
    flow_sets: bool = False,
    merge_duplicates: bool = False,
    max_bytes: int | None = MAX_YAML_BYTES,
) -> YamlDoc:
    """Parse one YAML document from text under armcli's safety rules.

    `merge_duplicates`: a repeated key is merged as ROS 2 reads parameter files (rcl's
    parser: `/**:` twice in one file is one node's parameters) instead of refused.
    `max_bytes`: the size cap for files users give; None for armcli's own output read back.
    """
    if max_bytes is not None and len(text.encode("utf-8", "surrogatepass")) > max_bytes:
        raise InputError(f"file larger than {max_bytes} bytes", file=source)
    if "\x00" in text:
        raise InputError("binary data (NUL byte) in a YAML file", file=source)
    text = _ECHO_END.sub("\n", text)  # one message saved from `ros2 topic echo`
    _scan_events(text, source)
    loader = _Loader(text)
    doc = YamlDoc(data=None, source=source, merge_duplicates=merge_duplicates)
    try:
        node = loader.get_single_node()
        if node is not None:
            doc.data = _build(node, loader, (), doc, flow_sets)
    except yaml.YAMLError as exc:
        raise _yaml_error(exc, source, text) from None
    except RecursionError:
        raise _too_deep(source, None) from None
    finally:
        loader.dispose()
    return doc


def read_text(path: str | Path, *, max_bytes: int = MAX_YAML_BYTES, what: str = "file") -> str:
    """Read a user text file (regular files only) with a size cap and clear errors."""
    raw = read_regular(path, max_bytes=max_bytes, what=what)
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        raise InputError(f"{what} is not UTF-8 text", file=Path(path)) from None


def load_yaml(path: str | Path, *, flow_sets: bool = False) -> YamlDoc:
    """Read and parse a YAML file under armcli's safety rules."""
    text = read_text(path, what="YAML file")
    return loads_yaml(text, str(path), flow_sets=flow_sets)


def is_finite_number(x: object) -> bool:
    """Whether `x` is a finite int or float; YAML booleans are not numbers here."""
    return isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x)
