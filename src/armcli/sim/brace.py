"""The course's brace form `positions: {0.5, 0.3}`: what ROS 2 sends, and armcli with it.

YAML reads `{0.5, 0.3}` as a mapping whose values are null. `ros2 topic pub` loads its
payload with `yaml.safe_load` and fills an array field with
`array.array(typecode, value)` (rosidl_runtime_py's set_message_fields), which iterates
the mapping's keys: ROS 2 sends the distinct keys, in order. So `{0.5, 0.3}` arrives as
[0.5, 0.3], but the course's own `{0.0, 0.0}` arrives as [0.0] (the repeated key
collapses): one position for two joints, which ros2_control's
joint_trajectory_controller rejects and Gazebo classic's joint_pose_trajectory plugin
reads past the end of. armcli takes what ROS sends: when it has one value per joint, it is
used (with a note to write a list); otherwise it is refused with this explanation.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from armcli.io.yaml import FlowKeys


def ros_sends(raw: FlowKeys) -> list[Any]:
    """The array ROS 2 fills from the brace form: its distinct keys, in order."""
    return list(dict.fromkeys(raw))


def as_list(raw: FlowKeys) -> str:
    """The brace form written as the YAML list it was meant to be."""
    return "[" + raw.text.strip()[1:-1].strip() + "]"


@dataclass
class BraceNotes:
    """Reads brace-form vectors of one trajectory and keeps one note for all of them."""

    where: list[str] = field(default_factory=list)
    first: str = ""

    def read(self, raw: FlowKeys, m: int, where: str) -> tuple[list[Any] | None, str]:
        """(what ROS sends, "") when it has `m` values, else (None, the refusal)."""
        sent = ros_sends(raw)
        if len(sent) != m:
            repeated = " (a repeated key counts once)" if len(sent) < len(raw) else ""
            return None, (
                f"{raw.text} is a YAML mapping, not a list: ROS 2 (`ros2 topic pub`) sends its "
                f"keys{repeated}, {len(sent)} value(s) for {m} joint(s), which ros2_control's "
                f"joint_trajectory_controller rejects; write a list: {as_list(raw)}"
            )
        if not self.where:
            self.first = (
                f"{raw.text} is a YAML mapping, not a list; ROS 2 (`ros2 topic pub`) sends its "
                f"keys in order, as armcli reads them; write a list to say so: {as_list(raw)}"
            )
        self.where.append(where)
        return sent, ""

    def warnings(self, source: str) -> list[str]:
        """One warning naming every place the brace form was read."""
        if not self.where:
            return []
        more = f" (and {len(self.where) - 1} more)" if len(self.where) > 1 else ""
        return [f"{source} {self.where[0]}{more}: {self.first}"]
