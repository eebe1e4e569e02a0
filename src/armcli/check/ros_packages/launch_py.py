"""A Python launch file -> `LaunchDoc`, read with `ast` and never imported or run.

Every action constructor in the module counts, wherever it is written (inside
`generate_launch_description`, an `OpaqueFunction`'s function, an event handler), except
a node assigned to a name that is never used again (dead code). A node built in a loop or
list comprehension over a literal list stands for one node per item. Conditions
(`IfCondition`, `UnlessCondition`, `LaunchConfigurationEquals`) are decided from the
launch arguments' literal values; `active` is None when they are not literal.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator, Mapping
from pathlib import Path

from armcli.check.ros_packages.files import Problem
from armcli.check.ros_packages.launch_model import (
    UNKNOWN,
    Description,
    Include,
    LaunchDoc,
    MoveItLaunch,
    Node,
    Process,
    Where,
    truthy,
)
from armcli.check.ros_packages.pyeval import (
    Cmd,
    Evaluator,
    FileText,
    MoveItBuilder,
    ParamFile,
    XacroDoc,
    as_text,
    callee,
    keyword,
)
from armcli.check.ros_packages.substitute import HOLE, Shares, known, xacro_command

NODE_CALLS = ("Node", "LifecycleNode")
MOVEIT_GENERATORS = (
    "generate_demo_launch",
    "generate_move_group_launch",
    "generate_moveit_rviz_launch",
    "generate_rsp_launch",
    "generate_spawn_controllers_launch",
    "generate_static_virtual_joint_tfs_launch",
    "generate_warehouse_db_launch",
    "generate_setup_assistant_launch",
)
MAX_LOOP_ITEMS = 64


def read_python_launch(
    path: Path, source: str, shares: Shares, args: Mapping[str, str | None]
) -> LaunchDoc:
    """The nodes, includes and processes a Python launch file states (see module doc)."""
    try:
        tree = ast.parse(source, filename=str(path))
    except SyntaxError as exc:
        return LaunchDoc(
            path, problems=(Problem(str(path), exc.lineno, f"Python syntax error: {exc.msg}"),)
        )
    except (RecursionError, ValueError, MemoryError):
        return LaunchDoc(
            path,
            problems=(Problem(str(path), None, "Python launch file too deeply nested to read"),),
        )
    try:
        return _Reader(path, tree, Evaluator(tree, path, shares, dict(args)), shares).doc()
    except RecursionError:
        return LaunchDoc(
            path, problems=(Problem(str(path), None, "expressions nested too deeply to read"),)
        )


class _Reader:
    """Collects the actions of one parsed module."""

    def __init__(self, path: Path, tree: ast.Module, ev: Evaluator, shares: Shares) -> None:
        self.path, self.tree, self.ev, self.shares = path, tree, ev, shares
        self.nodes: list[Node] = []
        self.includes: list[Include] = []
        self.processes: list[Process] = []
        self.moveit: list[MoveItLaunch] = []
        self.descriptions: dict[tuple[object, ...], Description] = {}
        self.global_params: dict[str, object] = {}
        loaded = {
            n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)
        }
        self.dead = {
            id(a.value)
            for a in ast.walk(tree)
            if isinstance(a, ast.Assign)
            and isinstance(a.value, ast.Call)
            and all(isinstance(t, ast.Name) and t.id not in loaded for t in a.targets)
        }

    def where(self, node: ast.AST) -> Where:
        return Where(str(self.path), getattr(node, "lineno", None))

    def doc(self) -> LaunchDoc:
        looped: set[int] = set()
        for call, bindings in self._loops():
            looped.add(id(call))
            self.ev.bind(bindings)
            self._action(call)
        self.ev.bind({})
        for node in ast.walk(self.tree):
            if isinstance(node, ast.Call) and id(node) not in looped:
                self._action(node)
        return LaunchDoc(
            self.path,
            tuple(self.nodes),
            tuple(self.includes),
            tuple(self.processes),
            tuple(self.moveit),
            tuple(self.descriptions.values()),
            dict(self.global_params),
            dict(self.shares.uses),
            self._imports(),
        )

    def _loops(self) -> Iterator[tuple[ast.Call, dict[str, object]]]:
        """Calls inside a loop or comprehension over a literal list, with each item bound."""
        for node in ast.walk(self.tree):
            body: list[ast.AST]
            if isinstance(node, ast.For):
                target, items, body = node.target, node.iter, list(node.body)
            elif isinstance(node, ast.ListComp) and len(node.generators) == 1:
                gen = node.generators[0]
                target, items, body = gen.target, gen.iter, [node.elt]
            else:
                continue
            values = self.ev.value(items)
            if not isinstance(target, ast.Name) or not isinstance(values, list):
                continue
            calls = [
                c
                for b in body
                for c in ast.walk(b)
                if isinstance(c, ast.Call) and callee(c) in (*NODE_CALLS, "ExecuteProcess")
            ]
            for value in values[:MAX_LOOP_ITEMS]:
                for c in calls:
                    yield c, {target.id: value}

    def _action(self, call: ast.Call) -> None:
        name = callee(call)
        if name in NODE_CALLS and id(call) not in self.dead:
            self.nodes.append(self._node(call))
        elif name == "IncludeLaunchDescription" and id(call) not in self.dead:
            self.includes.append(self._include(call))
        elif name == "ExecuteProcess" and id(call) not in self.dead:
            cmd = self.ev.value(keyword(call, "cmd") or (call.args[0] if call.args else None))
            tokens = tuple(known(as_text(t)) for t in cmd) if isinstance(cmd, list) else ()
            self.processes.append(Process(self.where(call), tokens, self._condition(call)))
        elif name == "SetParameter":
            key = self.ev.value(keyword(call, "name") or (call.args[0] if call.args else None))
            if isinstance(key, str):
                self.global_params[key] = literal(
                    self.ev.value(
                        keyword(call, "value") or (call.args[1] if len(call.args) > 1 else None)
                    )
                )
        elif name in MOVEIT_GENERATORS and call.args:
            cfg = self.ev.value(call.args[0])
            if isinstance(cfg, MoveItBuilder):
                self.moveit.append(MoveItLaunch(self.where(call), name, cfg.package, cfg.robot))
                self._description(cfg.urdf, call)
        elif name in ("Command", "process_file"):
            self._description(self.ev.value(call), call)

    def _description(self, value: object, at: ast.AST) -> Description | None:
        """The robot description a value loads (a xacro command, a processed or read file)."""
        where = self.where(at)
        found: Description | None = None
        if isinstance(value, Cmd):
            found = xacro_command(value.text, where)
        elif isinstance(value, XacroDoc) and known(as_text(value.file)):
            args, dropped = {}, []
            if isinstance(value.mappings, dict):
                for k, v in value.mappings.items():
                    text = known(as_text(v))
                    if text is None:
                        dropped.append(str(k))
                    else:
                        args[str(k)] = text
            found = Description(as_text(value.file), args, tuple(dropped), where)
        elif isinstance(value, FileText | str) and known(as_text(getattr(value, "file", value))):
            file = as_text(getattr(value, "file", value))
            if file.endswith((".urdf", ".xacro")):
                found = Description(file, {}, (), where)
        if found is not None:
            self.descriptions.setdefault(found.key, found)
        return found

    def _node(self, call: ast.Call) -> Node:
        ev = self.ev

        def text(key: str, old: str) -> str | None:
            return known(ev.text(keyword(call, key) or keyword(call, old)))

        params: dict[str, object] = {}
        lines: dict[str, int] = {}
        files: list[str] = []
        unknown = False
        description = None
        raw = keyword(call, "parameters")
        items = raw.elts if isinstance(raw, ast.List | ast.Tuple) else ([raw] if raw else [])
        for item in items:
            value = ev.value(item)
            for entry in value if isinstance(value, list) else [value]:
                if isinstance(entry, dict):
                    for k, v in entry.items():
                        params[str(k)] = literal(v)
                        lines[str(k)] = _key_line(item, str(k)) or call.lineno
                        if k == "robot_description":
                            description = self._description(v, item) or description
                elif isinstance(entry, ParamFile | str) and known(
                    as_text(getattr(entry, "file", entry))
                ):
                    files.append(as_text(getattr(entry, "file", entry)))
                else:
                    unknown = True
        arguments = ev.value(keyword(call, "arguments"))
        argv = tuple(known(as_text(a)) for a in arguments) if isinstance(arguments, list) else ()
        remaps = ev.value(keyword(call, "remappings"))
        pairs = tuple(
            (known(as_text(p[0])), known(as_text(p[1])))
            for p in (remaps if isinstance(remaps, list) else [])
            if isinstance(p, list) and len(p) == 2
        )
        return Node(
            self.where(call),
            text("package", "package"),
            text("executable", "node_executable"),
            text("name", "node_name"),
            text("namespace", "node_namespace"),
            params,
            lines,
            tuple(files),
            unknown,
            argv,
            pairs,
            self._condition(call),
            description,
        )

    def _include(self, call: ast.Call) -> Include:
        source = call.args[0] if call.args else keyword(call, "launch_description_source")
        target: str | None = None
        if isinstance(source, ast.Call):
            inner = source.args[0] if source.args else keyword(source, "launch_file_path")
            target = known(self.ev.text(inner))
        given = self.ev.value(keyword(call, "launch_arguments"))
        args: dict[str, str | None] = {}
        for pair in given if isinstance(given, list) else []:
            if isinstance(pair, list) and len(pair) == 2 and known(as_text(pair[0])):
                args[as_text(pair[0])] = known(as_text(pair[1]))
        return Include(self.where(call), target, args, self._condition(call))

    def _condition(self, call: ast.Call) -> bool | None:
        cond = keyword(call, "condition")
        if cond is None:
            return True
        if not isinstance(cond, ast.Call):
            return None
        kind = callee(cond)
        values = [self.ev.text(a) for a in cond.args]
        if kind in ("IfCondition", "UnlessCondition") and values:
            verdict = truthy(known(values[0]))
            if verdict is None:
                return None
            return verdict if kind == "IfCondition" else not verdict
        if (
            kind in ("LaunchConfigurationEquals", "LaunchConfigurationNotEquals")
            and len(values) == 2
        ):
            actual = known(self.ev.launch_arg(values[0])) if known(values[0]) else None
            if actual is None or not known(values[1]):
                return None
            return (actual == values[1]) == (kind == "LaunchConfigurationEquals")
        return None

    def _imports(self) -> dict[str, int]:
        out: dict[str, int] = {}
        for node in ast.walk(self.tree):
            if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                out.setdefault(node.module.split(".")[0], node.lineno)
            elif isinstance(node, ast.Import):
                for alias in node.names:
                    out.setdefault(alias.name.split(".")[0], node.lineno)
        return out


def literal(value: object) -> object:
    """A parameter value as the rules see it: literal scalars and lists, else UNKNOWN."""
    if isinstance(value, str):
        return value if HOLE not in value else UNKNOWN
    if isinstance(value, bool | int | float):
        return value
    if isinstance(value, list) and all(isinstance(v, str | bool | int | float) for v in value):
        return value
    return UNKNOWN


def _key_line(item: ast.AST, key: str) -> int | None:
    """The line of `key` in a dict literal (the parameter a fix edits)."""
    if isinstance(item, ast.Dict):
        for k in item.keys:
            if isinstance(k, ast.Constant) and k.value == key:
                return k.lineno
    return None
