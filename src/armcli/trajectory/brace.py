"""The course's brace form `positions: {0.5, 0.3}`: what ROS 2 sends, and armcli with it.

YAML reads `{0.5, 0.3}` as a mapping whose values are null. `ros2 topic pub` loads its
payload with `yaml.safe_load` and fills an array field with
`array.array(typecode, value)` (rosidl_runtime_py's set_message_fields), which iterates
the mapping's keys: ROS 2 sends the distinct keys, in order. So `{0.5, 0.3}` arrives as
[0.5, 0.3], but the course's own `{0.0, 0.0}` arrives as [0.0] (the repeated key
collapses): one position for two joints, which ros2_control's
joint_trajectory_controller rejects and Gazebo classic's joint_pose_trajectory plugin
reads past the end of. The student copied it from the course and means (0, 0), so armcli
runs the values as written, one per joint, with one warning saying what ROS 2 would send
and the list to write instead. Only a brace form whose written values do not match the
joint count (nothing to recover) is refused.
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


def _sent_text(sent: list[Any]) -> str:
    return "[" + ", ".join(str(x) for x in sent) + "]"


@dataclass
class BraceNotes:
    """Reads brace-form vectors of one trajectory and keeps one note for all of them."""

    where: list[str] = field(default_factory=list)
    first: str = ""
    collapsed: bool = False  # the note says a repeated key collapses (the stronger one)

    def read(self, raw: FlowKeys, m: int, where: str) -> tuple[list[Any] | None, str]:
        """(the values as written, "") when there are `m` of them, else (None, the refusal)."""
        written, sent = list(raw), ros_sends(raw)
        if len(written) != m:
            return None, (
                f"{raw.text} is a YAML mapping, not a list, with {len(written)} value(s) for "
                f"{m} joint(s) (ROS 2 would send {len(sent)}: {_sent_text(sent)}); "
                f"write a list of {m} number(s), one per joint name"
            )
        if len(sent) != len(written) and not self.collapsed:
            self.collapsed = True
            self.first = (
                f"{raw.text} is a YAML mapping, not a list: ROS 2 (`ros2 topic pub`) would "
                f"send its distinct keys, {len(sent)} value(s) {_sent_text(sent)} for {m} "
                f"joint(s), which ros2_control's joint_trajectory_controller rejects; armcli "
                f"runs the {m} values as written; write a list: {as_list(raw)}"
            )
        elif not self.where:
            self.first = (
                f"{raw.text} is a YAML mapping, not a list; ROS 2 (`ros2 topic pub`) sends its "
                f"keys in order, as armcli reads them; write a list to say so: {as_list(raw)}"
            )
        self.where.append(where)
        return written, ""

    def warnings(self, source: str) -> list[str]:
        """One warning naming every place the brace form was read."""
        if not self.where:
            return []
        more = f" (and {len(self.where) - 1} more)" if len(self.where) > 1 else ""
        return [f"{source} {self.where[0]}{more}: {self.first}"]
