"""ROS 2 parameter YAML files as the rules read them: controllers, their parameters, lines.

A ros2_control controllers file names each controller and its type under
`controller_manager: ros__parameters:` and gives its parameters under `<controller>:
ros__parameters:` (older files nest them under the manager). Node keys may carry a
namespace or the `/**` wildcard; a node's parameters are every block whose key matches it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from armcli.io.yaml import YamlDoc

ROS_PARAMETERS = "ros__parameters"
JTC = "joint_trajectory_controller/JointTrajectoryController"
JSB = "joint_state_broadcaster/JointStateBroadcaster"
DIFF_DRIVE = "diff_drive_controller/DiffDriveController"
KeyPath = tuple[str | int, ...]


@dataclass(frozen=True)
class Controller:
    """One controller of a controllers file: its type and its parameters with their lines."""

    name: str
    type: str | None
    file: str
    params: Mapping[str, object]  # its ros__parameters (or the manager's inline block)
    doc: YamlDoc = field(repr=False)
    at: KeyPath  # where `params` sits in the document
    type_line: int | None = None

    def line(self, *keys: str | int) -> int | None:
        """The line of a parameter (or its closest written ancestor)."""
        return self.doc.line_of((*self.at, *keys))

    @property
    def joints(self) -> list[str]:
        """Joint names the controller's `joints`/`joint` parameters list."""
        return [j for j, _ in self.joint_entries()]

    def joint_entries(self) -> list[tuple[str, KeyPath]]:
        """(joint name, key path relative to `params`) of every joint the parameters name."""
        out: list[tuple[str, KeyPath]] = []
        for key in ("joints", "command_joints", "left_wheel_names", "right_wheel_names"):
            value = self.params.get(key)
            if isinstance(value, list):
                out += [(v, (key, i)) for i, v in enumerate(value) if isinstance(v, str)]
        if isinstance(self.params.get("joint"), str):
            out.append((str(self.params["joint"]), ("joint",)))
        listed = {j for j, _ in out}
        for block in ("gains", "constraints"):
            value = self.params.get(block)
            if isinstance(value, dict):
                for k, v in value.items():
                    if isinstance(v, dict) and k not in listed:
                        out.append((k, (block, k)))
        return out


@dataclass(frozen=True)
class ControllerFile:
    """A controllers YAML: the manager's update rate and every controller declared in it."""

    path: Path
    doc: YamlDoc = field(repr=False)
    controllers: Mapping[str, Controller]
    update_rate: float | None = None


def node_key(key: str) -> str:
    """A parameter file's node key without namespace or wildcard: `/**/cm` -> `cm`."""
    return key.strip().rstrip("/").rsplit("/", 1)[-1]


def node_blocks(doc: YamlDoc) -> list[tuple[str, KeyPath, Mapping[str, object]]]:
    """(node name, key path of its ros__parameters, the parameters) of every node block."""
    out: list[tuple[str, KeyPath, Mapping[str, object]]] = []
    data = doc.data
    if not isinstance(data, dict):
        return out
    for key, body in data.items():
        if isinstance(body, dict) and isinstance(body.get(ROS_PARAMETERS), dict):
            out.append((node_key(str(key)), (key, ROS_PARAMETERS), body[ROS_PARAMETERS]))
        elif isinstance(body, dict) and str(key).startswith("/"):  # `/ns:` then the node
            for sub, inner in body.items():
                if isinstance(inner, dict) and isinstance(inner.get(ROS_PARAMETERS), dict):
                    out.append(
                        (node_key(str(sub)), (key, sub, ROS_PARAMETERS), inner[ROS_PARAMETERS])
                    )
    return out


def node_params(doc: YamlDoc, node: str | None) -> dict[str, object]:
    """The parameters a file gives node `node` (`/**` blocks included)."""
    out: dict[str, object] = {}
    for name, _, params in node_blocks(doc):
        if name == "**" or (node is not None and name == node):
            out.update(params)
    return out


def controller_file(path: Path, doc: YamlDoc) -> ControllerFile | None:
    """The controllers file `doc` is, or None when it declares no controller manager."""
    blocks = node_blocks(doc)
    manager = next(((n, at, p) for n, at, p in blocks if _declares_controllers(p)), None)
    if manager is None:
        return None
    _, at, params = manager
    own = {n: (b_at, p) for n, b_at, p in blocks}
    controllers: dict[str, Controller] = {}
    for name, body in params.items():
        if not isinstance(body, dict) or "type" not in body:
            continue
        kind = body.get("type")
        type_line = doc.line_of((*at, name, "type"))
        if name in own:
            b_at, p = own[name]
        else:  # parameters written inline under the manager
            b_at, p = (*at, name), {k: v for k, v in body.items() if k != "type"}
        controllers[name] = Controller(
            name, kind if isinstance(kind, str) else None, str(path), p, doc, b_at, type_line
        )
    rate = params.get("update_rate")
    return ControllerFile(
        path, doc, controllers, float(rate) if isinstance(rate, int | float) else None
    )


def _declares_controllers(params: Mapping[str, object]) -> bool:
    return any(
        isinstance(v, dict) and isinstance(v.get("type"), str) and "/" in v["type"]
        for v in params.values()
    )
