"""Literal values of a Python launch file's expressions, from its `ast`: nothing is run.

Resolved: constants, lists, tuples, dicts, `+` of strings, f-strings of literals, names
assigned once (anywhere in the module, or to the same value each time), `__file__`,
launch arguments (`LaunchConfiguration`) at the value passed or their literal default, and
the substitutions and helpers launch files build paths and robot descriptions with
(`get_package_share_directory`, `FindPackageShare`, `os.path.join`, `PathJoinSubstitution`,
`Command`, the xacro module's `process_file`, `open(...).read()`, `ParameterValue`,
`PythonExpression` of literals, `MoveItConfigsBuilder`). Everything else is UNKNOWN (or a
HOLE in a string).
"""

from __future__ import annotations

import ast
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from armcli.check.ros_packages.launch_model import UNKNOWN
from armcli.check.ros_packages.substitute import (
    HOLE,
    Shares,
    join_path,
    literal_python_expression,
)

MAX_DEPTH = 40  # nested evaluation (a name defined through names through names ...)
MAX_TEXT = 100_000  # [characters] a longer string (`a = b + b` doubling) is not literal
MAX_ITEMS = 10_000  # a longer list is not literal
SHARE_CALLS = ("get_package_share_directory", "get_package_share_path", "FindPackageShare")


@dataclass(frozen=True)
class Cmd:
    """A launch `Command`: its command line (holes where not literal)."""

    text: str


@dataclass(frozen=True)
class XacroDoc:
    """The xacro module's `process_file(FILE, mappings=...)`: a description expanded there."""

    file: object
    mappings: object


@dataclass(frozen=True)
class FileText:
    """`open(FILE).read()`: a file's text (a URDF loaded as it is)."""

    file: object


@dataclass(frozen=True)
class ParamFile:
    """A launch_ros `ParameterFile(...)`."""

    file: object


@dataclass
class MoveItBuilder:
    """`MoveItConfigsBuilder(robot, package_name=...)` and its chained calls."""

    robot: str | None
    package: str | None
    urdf: object = None


@dataclass
class Evaluator:
    """Evaluates expressions of one module under given launch-argument values."""

    tree: ast.Module
    path: Path
    shares: Shares
    args: Mapping[str, str | None] = field(default_factory=dict)  # passed by an includer
    names: dict[str, list[ast.expr]] = field(default_factory=dict)
    declared: dict[str, ast.expr | None] = field(default_factory=dict)
    bindings: dict[str, object] = field(default_factory=dict)  # loop/comprehension variables
    _busy: set[str] = field(default_factory=set)
    _known: dict[str, object] = field(default_factory=dict)  # names evaluated (one each)

    def bind(self, bindings: dict[str, object]) -> None:
        """Loop variables for the next evaluations (names evaluated before are forgotten)."""
        self.bindings = bindings
        self._known.clear()

    def __post_init__(self) -> None:
        for node in ast.walk(self.tree):
            if isinstance(node, ast.Assign) and len(node.targets) == 1:
                t = node.targets[0]
                if isinstance(t, ast.Name):
                    self.names.setdefault(t.id, []).append(node.value)
            elif isinstance(node, ast.AnnAssign) and node.value is not None:
                if isinstance(node.target, ast.Name):
                    self.names.setdefault(node.target.id, []).append(node.value)
            elif isinstance(node, ast.Call) and callee(node) == "DeclareLaunchArgument":
                name = node.args[0] if node.args else keyword(node, "name")
                if isinstance(name, ast.Constant) and isinstance(name.value, str):
                    default = keyword(node, "default_value")
                    if default is None and len(node.args) > 1:
                        default = node.args[1]
                    self.declared.setdefault(name.value, default)

    def launch_arg(self, name: str) -> object:
        """A launch argument's value: the includer's, else its literal default."""
        if name in self.args:
            value = self.args[name]
            return value if value is not None else HOLE
        default = self.declared.get(name)
        return self.text(default) if default is not None else HOLE

    def text(self, node: ast.AST | None, depth: int = 0) -> str:
        """An expression as a launch substitution text (HOLE where not literal)."""
        return as_text(self.value(node, depth))

    def value(self, node: ast.AST | None, depth: int = 0) -> object:
        """The literal value of an expression, or UNKNOWN."""
        if node is None or depth > MAX_DEPTH:
            return UNKNOWN
        d = depth + 1
        if isinstance(node, ast.Constant):
            return node.value
        if isinstance(node, ast.List | ast.Tuple):
            return [self.value(e, d) for e in node.elts if not isinstance(e, ast.Starred)]
        if isinstance(node, ast.Dict):
            out: dict[object, object] = {}
            for k, v in zip(node.keys, node.values, strict=True):
                key = self.value(k, d) if k is not None else UNKNOWN
                if isinstance(key, str | int | float | bool):
                    out[key] = self.value(v, d)
            return out
        if isinstance(node, ast.Name):
            return self._name(node.id, d)
        if isinstance(node, ast.JoinedStr):
            return "".join(self._fpart(v, d) for v in node.values)
        if isinstance(node, ast.BinOp):
            return self._binop(node, d)
        if isinstance(node, ast.Call):
            return self._call(node, d)
        return UNKNOWN

    def _fpart(self, v: ast.AST, depth: int) -> str:
        if isinstance(v, ast.Constant):
            return str(v.value)
        if isinstance(v, ast.FormattedValue) and v.format_spec is None and v.conversion == -1:
            return as_text(self.value(v.value, depth))
        return HOLE

    def _name(self, name: str, depth: int) -> object:
        if name in self.bindings:
            return self.bindings[name]
        if name == "__file__":
            return str(self.path)
        if name in self._known:  # once per name: `a = b + b; b = c + c; ...` stays linear
            return self._known[name]
        exprs = self.names.get(name)
        if not exprs or name in self._busy:
            return UNKNOWN
        self._busy.add(name)
        try:
            values = [self.value(e, depth) for e in exprs]
        finally:
            self._busy.discard(name)
        first = values[0]
        found = first if all(_same(v, first) for v in values[1:]) else UNKNOWN
        self._known[name] = found
        return found

    def _binop(self, node: ast.BinOp, depth: int) -> object:
        a, b = self.value(node.left, depth), self.value(node.right, depth)
        if isinstance(node.op, ast.Add):
            if isinstance(a, list) and isinstance(b, list):
                return a + b if len(a) + len(b) <= MAX_ITEMS else UNKNOWN
            if isinstance(a, str) or isinstance(b, str):
                text = as_text(a) + as_text(b)
                return text if len(text) <= MAX_TEXT else HOLE
        if isinstance(node.op, ast.Div) and isinstance(a, str) and isinstance(b, str):
            return join_path([a, b])  # pathlib's `/`
        return UNKNOWN

    def _call(self, node: ast.Call, depth: int) -> object:
        name = callee(node)
        args = [self.value(a, depth) for a in node.args if not isinstance(a, ast.Starred)]
        if isinstance(node.func, ast.Attribute) and name in _METHODS:
            return _METHODS[name](self, self.value(node.func.value, depth), node, depth)
        if name in SHARE_CALLS:
            pkg = args[0] if args else self.value(keyword(node, "package"), depth)
            if isinstance(pkg, str) and HOLE not in pkg:
                return self.shares.share(pkg, node.lineno)
            return HOLE
        if name == "LaunchConfiguration":
            arg = args[0] if args else UNKNOWN
            if isinstance(arg, str) and (arg in self.args or arg in self.declared):
                return self.launch_arg(arg)
            default = keyword(node, "default")
            return self.text(default, depth) if default is not None else HOLE
        simple = _SIMPLE.get(name)
        if simple is not None:
            return simple(self, node, args, depth)
        return UNKNOWN


def _same(a: object, b: object) -> bool:
    try:
        return bool(a == b)
    except Exception:
        return False


def as_text(v: object) -> str:
    """A value where launch expects text: strings as they are, lists concatenated."""
    if isinstance(v, str):
        return v
    if isinstance(v, list):
        text = "".join(as_text(x) for x in v[:MAX_ITEMS])
        return text if len(text) <= MAX_TEXT else HOLE
    if isinstance(v, bool | int | float) and not isinstance(v, bool):
        return str(v)
    if isinstance(v, bool):
        return "true" if v else "false"
    return HOLE


def callee(node: ast.Call) -> str:
    """The called name's last part: `launch_ros.actions.Node(...)` -> "Node"."""
    f = node.func
    if isinstance(f, ast.Attribute):
        return f.attr
    if isinstance(f, ast.Name):
        return f.id
    return ""


def keyword(node: ast.Call, name: str) -> ast.expr | None:
    """The expression given for keyword `name`, or None."""
    return next((k.value for k in node.keywords if k.arg == name), None)


def _join(ev: Evaluator, node: ast.Call, args: list[object], depth: int) -> object:
    parts = args[0] if len(args) == 1 and isinstance(args[0], list) else args
    texts = [as_text(p) for p in parts]
    return join_path(texts)


def _command(ev: Evaluator, node: ast.Call, args: list[object], depth: int) -> object:
    return Cmd(as_text(args[0] if args else ev.value(keyword(node, "command"), depth)))


def _python_expression(ev: Evaluator, node: ast.Call, args: list[object], depth: int) -> object:
    result = literal_python_expression(as_text(args[0] if args else UNKNOWN))
    return HOLE if result is None else as_text(result)


def _first(ev: Evaluator, node: ast.Call, args: list[object], depth: int) -> object:
    return args[0] if args else ev.value(keyword(node, "value"), depth)


Simple = Callable[["Evaluator", ast.Call, list[object], int], object]


def _text_kw(key: str) -> Simple:
    """A call whose value is its first argument or keyword `key`."""

    def get(ev: Evaluator, node: ast.Call, args: list[object], depth: int) -> object:
        return args[0] if args else ev.value(keyword(node, key), depth)

    return get


def _dirname(ev: Evaluator, node: ast.Call, args: list[object], depth: int) -> object:
    a = args[0] if args else UNKNOWN
    return os.path.dirname(a) if isinstance(a, str) and HOLE not in a else HOLE


def _normpath(ev: Evaluator, node: ast.Call, args: list[object], depth: int) -> object:
    a = args[0] if args else UNKNOWN
    return os.path.normpath(a) if isinstance(a, str) and HOLE not in a else a


def _process_file(ev: Evaluator, node: ast.Call, args: list[object], depth: int) -> object:
    mappings = ev.value(keyword(node, "mappings"), depth)
    return XacroDoc(args[0] if args else UNKNOWN, mappings)


def _builder(ev: Evaluator, node: ast.Call, args: list[object], depth: int) -> object:
    robot = args[0] if args else ev.value(keyword(node, "robot_name"), depth)
    package = ev.value(keyword(node, "package_name"), depth)
    r = robot if isinstance(robot, str) and HOLE not in robot else None
    p = package if isinstance(package, str) and HOLE not in package else None
    return MoveItBuilder(r, p or (f"{r}_moveit_config" if r else None))


def _dict(ev: Evaluator, node: ast.Call, args: list[object], depth: int) -> object:
    out = dict(args[0]) if args and isinstance(args[0], dict) else {}
    out.update({k.arg: ev.value(k.value, depth) for k in node.keywords if k.arg})
    return out


_SIMPLE: dict[str, Simple] = {
    "PathJoinSubstitution": _join,
    "joinpath": _join,
    "Command": _command,
    "PythonExpression": _python_expression,
    "ParameterValue": _first,
    "TextSubstitution": _text_kw("text"),
    "FindExecutable": _text_kw("name"),
    "str": _first,
    "Path": _join,
    "dirname": _dirname,
    "normpath": _normpath,
    "abspath": _normpath,
    "realpath": _normpath,  # lexical: the filesystem is not asked
    "process_file": _process_file,
    "open": lambda ev, node, args, depth: FileText(args[0] if args else UNKNOWN),
    "ParameterFile": lambda ev, node, args, depth: ParamFile(
        args[0] if args else ev.value(keyword(node, "param_file"), depth)
    ),
    "MoveItConfigsBuilder": _builder,
    "dict": _dict,
}


def _method(ev: Evaluator, obj: object, node: ast.Call, depth: int) -> object:
    """Methods that keep the value: `.perform(context)`, `.toxml()`, `.items()`, ..."""
    name = callee(node)
    if name == "items" and isinstance(obj, dict):
        return [[k, v] for k, v in obj.items()]
    if name == "read" and isinstance(obj, FileText):
        return obj
    if isinstance(obj, MoveItBuilder):
        if name == "robot_description":
            path = keyword(node, "file_path") or (node.args[0] if node.args else None)
            if path is not None:
                obj.urdf = ev.value(path, depth)
        return obj
    if name == "joinpath":
        return join_path([as_text(obj), *(as_text(ev.value(a, depth)) for a in node.args)])
    if name == "join":
        args = [ev.value(a, depth) for a in node.args]
        if isinstance(obj, str):  # "sep".join(items)
            items = args[0] if args and isinstance(args[0], list) else []
            return obj.join(as_text(x) for x in items) if args else HOLE
        return join_path([as_text(a) for a in args])  # os.path.join
    return obj


_METHODS = {
    m: _method
    for m in (
        "perform",
        "toxml",
        "toprettyxml",
        "items",
        "read",
        "to_moveit_configs",
        "to_dict",
        "robot_description",
        "robot_description_semantic",
        "joinpath",
        "trajectory_execution",
        "planning_pipelines",
        "planning_scene_monitor",
        "robot_description_kinematics",
        "joint_limits",
        "moveit_cpp",
        "sensors_3d",
        "pilz_cartesian_limits",
        "join",
    )
}
