"""RViz 2 configurations: the description viewer and the MoveIt MotionPlanning view.

RViz stores its configuration as YAML; only the keys that matter are
written, RViz fills in the rest with its defaults when it loads the file.
"""

from __future__ import annotations

from typing import Any

from armcli.ros.srdf import ARM_GROUP

VIEW_DISTANCE = 2.0  # [m] orbit camera distance, frames the 0.6 m base and 0.92 m high arm
VIEW_FOCUS_Z = 0.4  # [m] orbit focal point height


def _grid() -> dict[str, Any]:
    return {"Class": "rviz_default_plugins/Grid", "Enabled": True, "Name": "Grid"}


def _frame(fixed_frame: str, displays: list[dict[str, Any]]) -> dict[str, Any]:
    return {
        "Panels": [
            {"Class": "rviz_common/Displays", "Name": "Displays"},
            {"Class": "rviz_common/Views", "Name": "Views"},
        ],
        "Visualization Manager": {
            "Class": "",
            "Displays": displays,
            "Enabled": True,
            "Global Options": {"Fixed Frame": fixed_frame, "Frame Rate": 30},
            "Name": "root",
            "Tools": [
                {"Class": "rviz_default_plugins/Interact"},
                {"Class": "rviz_default_plugins/MoveCamera"},
                {"Class": "rviz_default_plugins/Select"},
                {"Class": "rviz_default_plugins/FocusCamera"},
                {"Class": "rviz_default_plugins/Measure"},
            ],
            "Value": True,
            "Views": {
                "Current": {
                    "Class": "rviz_default_plugins/Orbit",
                    "Distance": VIEW_DISTANCE,
                    "Focal Point": {"X": 0.0, "Y": 0.0, "Z": VIEW_FOCUS_Z},
                    "Name": "Current View",
                    "Pitch": 0.5,
                    "Target Frame": "<Fixed Frame>",
                    "Yaw": 0.8,
                }
            },
        },
    }


def display_rviz(fixed_frame: str) -> dict[str, Any]:
    """RobotModel (from /robot_description) and TF, in `fixed_frame`."""
    robot_model = {
        "Class": "rviz_default_plugins/RobotModel",
        "Description File": "",
        "Description Source": "Topic",
        "Description Topic": {"Value": "/robot_description"},
        "Enabled": True,
        "Name": "RobotModel",
        "Visual Enabled": True,
        "Collision Enabled": False,
    }
    tf = {"Class": "rviz_default_plugins/TF", "Enabled": True, "Name": "TF", "Show Names": True}
    return _frame(fixed_frame, [_grid(), robot_model, tf])


def moveit_rviz(fixed_frame: str) -> dict[str, Any]:
    """The MoveIt MotionPlanning display for the arm group."""
    planning = {
        "Class": "moveit_rviz_plugin/MotionPlanning",
        "Enabled": True,
        "Name": "MotionPlanning",
        "Move Group Namespace": "",
        "Planning Scene Topic": "/monitored_planning_scene",
        "Robot Description": "robot_description",
        "Planning Request": {
            "Planning Group": ARM_GROUP,
            "Interactive Marker Size": 0.2,
            "Query Goal State": True,
            "Query Start State": False,
        },
        "Scene Robot": {"Show Robot Visual": True, "Show Robot Collision": False},
        "Planned Path": {"Loop Animation": False, "State Display Time": "0.05 s"},
    }
    return _frame(fixed_frame, [_grid(), planning])
