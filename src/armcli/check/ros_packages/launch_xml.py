"""XML and YAML launch files -> `LaunchDoc`: the same frontend actions from either syntax.

ROS 2's XML and YAML launch formats hold the same actions (`arg`, `let`, `node` with
`param` and `remap`, `include`, `executable`, `set_parameter`, `group`) with `$(...)`
substitutions in their attribute values; YAML files are read by armcli's safe reader into
the same element tree as XML's (lxml without DTDs, entities or network). Substitutions
are expanded from literals only (substitute.expand); `$(command 'xacro FILE ...')` names
a robot description.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from armcli.check.ros_packages.files import Jail, Problem, line_of
from armcli.check.ros_packages.launch_model import (
    UNKNOWN,
    Description,
    Include,
    LaunchDoc,
    Node,
    Process,
    Where,
    truthy,
)
from armcli.check.ros_packages.substitute import (
    DIRNAME,
    HOLE,
    Shares,
    expand,
    known,
    xacro_command,
)
from armcli.errors import InputError

if TYPE_CHECKING:
    from lxml import etree

MAX_ELEMENTS = 20_000


@dataclass
class Elem:
    """One launch action: tag, attributes, children and its line (XML or YAML alike)."""

    tag: str
    attrs: dict[str, str]
    children: list[Elem] = field(default_factory=list)
    line: int | None = None


def read_xml_launch(
    jail: Jail, path: Path, shares: Shares, args: Mapping[str, str | None]
) -> LaunchDoc:
    """An XML or YAML launch file's actions; a malformed file is one Problem."""
    try:
        root = _yaml_tree(jail, path) if path.suffix in (".yaml", ".yml") else _xml_tree(jail, path)
    except InputError as exc:
        return LaunchDoc(path, problems=(Problem.of(exc, path),))
    reader = _Reader(path, shares, {DIRNAME: str(path.parent)})
    reader.declare(root, args)
    reader.walk(root.children, True)
    return LaunchDoc(
        path,
        tuple(reader.nodes),
        tuple(reader.includes),
        tuple(reader.processes),
        (),
        tuple(reader.descriptions.values()),
        dict(reader.global_params),
        dict(shares.uses),
    )


def _xml_tree(jail: Jail, path: Path) -> Elem:
    root = jail.xml(path, "launch file")
    if root.tag != "launch":
        raise InputError(
            f"root element is <{root.tag}>, expected <launch>", file=path, line=line_of(root)
        )
    count = 0

    def conv(el: etree._Element) -> Elem:
        nonlocal count
        count += 1
        if count > MAX_ELEMENTS:
            raise InputError(f"more than {MAX_ELEMENTS} elements", file=path)
        kids = [conv(c) for c in el if isinstance(c.tag, str)]
        attrs = {str(k): str(v) for k, v in el.attrib.items()}
        return Elem(str(el.tag), attrs, kids, line_of(el))

    return conv(root)


def _yaml_tree(jail: Jail, path: Path) -> Elem:
    doc = jail.yaml(path, "launch file")
    data = doc.data
    if not isinstance(data, dict) or not isinstance(data.get("launch"), list):
        raise InputError("expected a top-level `launch:` list", file=path, line=1)

    def conv(tag: str, body: object, where: tuple[str | int, ...]) -> Elem:
        attrs: dict[str, str] = {}
        kids: list[Elem] = []
        if isinstance(body, dict):
            for k, v in body.items():
                if isinstance(v, list):  # param:, remap:, arg:, children:
                    for i, item in enumerate(v):
                        if isinstance(item, dict) and k == "children":
                            kids += [conv(t, b, (*where, k, i, t)) for t, b in item.items()]
                        elif isinstance(item, dict):
                            kids.append(conv(k, item, (*where, k, i)))
                elif v is not None:
                    attrs[k] = _yaml_text(v)
        return Elem(tag, attrs, kids, doc.line_of(where))

    children = []
    for i, item in enumerate(data["launch"]):
        if isinstance(item, dict):
            children += [conv(t, b, ("launch", i, t)) for t, b in item.items()]
    return Elem("launch", {}, children, 1)


def _yaml_text(v: object) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    return str(v)


class _Reader:
    def __init__(self, path: Path, shares: Shares, variables: dict[str, str | None]) -> None:
        self.path, self.shares, self.vars = path, shares, variables
        self.nodes: list[Node] = []
        self.includes: list[Include] = []
        self.processes: list[Process] = []
        self.descriptions: dict[tuple[object, ...], Description] = {}
        self.global_params: dict[str, object] = {}

    def sub(self, text: str | None, line: int | None) -> str:
        if text is None:
            return HOLE

        def command(cmd: str) -> str:
            found = xacro_command(cmd, Where(str(self.path), line))
            if found is not None:
                self.descriptions.setdefault(found.key, found)
                self.shares.uses.setdefault("xacro", line or 0)
            return HOLE

        return expand(text, self.vars, self.shares, line, command=command)

    def declare(self, root: Elem, given: Mapping[str, str | None]) -> None:
        """Launch arguments: the includer's values, else their literal defaults."""
        for el in root.children:
            if el.tag == "arg" and el.attrs.get("name"):
                name = el.attrs["name"]
                default = el.attrs.get("default", el.attrs.get("value"))
                value = (
                    given[name]
                    if name in given
                    else (known(self.sub(default, el.line)) if default is not None else None)
                )
                self.vars[name] = value

    def active(self, el: Elem) -> bool | None:
        if "if" in el.attrs:
            return truthy(known(self.sub(el.attrs["if"], el.line)))
        if "unless" in el.attrs:
            v = truthy(known(self.sub(el.attrs["unless"], el.line)))
            return None if v is None else not v
        return True

    def walk(self, elems: list[Elem], parent: bool | None) -> None:
        for el in elems:
            on = _both(parent, self.active(el))
            if el.tag == "let" and el.attrs.get("name"):
                self.vars[el.attrs["name"]] = known(self.sub(el.attrs.get("value"), el.line))
            elif el.tag == "node":
                self.nodes.append(self.node(el, on))
            elif el.tag == "include":
                self.includes.append(self.include(el, on))
            elif el.tag == "executable":
                cmd = self.sub(el.attrs.get("cmd"), el.line)
                tokens = tuple(known(t) for t in cmd.split()) if cmd else ()
                self.processes.append(Process(Where(str(self.path), el.line), tokens, on))
            elif el.tag == "set_parameter" and el.attrs.get("name"):
                self.global_params[el.attrs["name"]] = _typed(
                    known(self.sub(el.attrs.get("value"), el.line))
                )
            elif el.tag == "group":
                self.walk(el.children, on)

    def node(self, el: Elem, on: bool | None) -> Node:
        params: dict[str, object] = {}
        lines: dict[str, int] = {}
        files: list[str] = []
        description = None
        remaps: list[tuple[str | None, str | None]] = []
        for c in el.children:
            if c.tag == "param" and c.attrs.get("from"):
                path = known(self.sub(c.attrs["from"], c.line))
                if path:
                    files.append(path)
            elif c.tag == "param" and c.attrs.get("name"):
                before = len(self.descriptions)
                value = self.sub(c.attrs.get("value"), c.line)
                params[c.attrs["name"]] = _typed(known(value))
                lines[c.attrs["name"]] = c.line or el.line or 0
                if c.attrs["name"] == "robot_description" and len(self.descriptions) > before:
                    description = list(self.descriptions.values())[-1]
            elif c.tag == "remap":
                remaps.append(
                    (
                        known(self.sub(c.attrs.get("from"), c.line)),
                        known(self.sub(c.attrs.get("to"), c.line)),
                    )
                )
        argv = self.sub(el.attrs.get("args"), el.line) if "args" in el.attrs else ""
        a = el.attrs
        return Node(
            Where(str(self.path), el.line),
            known(self.sub(a.get("pkg"), el.line)),
            known(self.sub(a.get("exec", a.get("type")), el.line)),
            known(self.sub(a.get("name"), el.line)) if "name" in a else None,
            known(self.sub(a.get("namespace", a.get("ns")), el.line))
            if ("namespace" in a or "ns" in a)
            else None,
            params,
            lines,
            tuple(files),
            False,
            tuple(known(t) for t in argv.split()),
            tuple(remaps),
            on,
            description,
        )

    def include(self, el: Elem, on: bool | None) -> Include:
        args = {
            c.attrs["name"]: known(self.sub(c.attrs.get("value"), c.line))
            for c in el.children
            if c.tag == "arg" and c.attrs.get("name")
        }
        return Include(
            Where(str(self.path), el.line), known(self.sub(el.attrs.get("file"), el.line)), args, on
        )


def _both(a: bool | None, b: bool | None) -> bool | None:
    if a is False or b is False:
        return False
    return True if (a and b) else None


def _typed(text: str | None) -> object:
    """A launch XML parameter string as ROS reads it: bool, int, float or string."""
    if text is None:
        return UNKNOWN
    low = text.strip().lower()
    if low in ("true", "false"):
        return low == "true"
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text
