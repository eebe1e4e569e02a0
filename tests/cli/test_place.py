"""`armcli place` as a user runs it: the JSON keys, the Nav2 goal, bad input, a miss.

The JSON keys are the issue's interface; a target out of reach or inside an object exits
1 with the reason and writes nothing; a malformed scene or --start exits 2 naming the
field.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import yaml

from tests.helpers import DEFAULT_SPEC, FIXTURES, run_cli

KEYS = ["status", "base", "joints", "tool_error_m", "tip_margin_m", "region", "time_s", "reason"]
CLUTTERED = FIXTURES / "plan" / "mobile" / "cluttered_room.yaml"


def test_json_and_the_nav2_goal(tmp_path: Path) -> None:
    goal, plot = tmp_path / "goal.yaml", tmp_path / "floor.png"
    res = run_cli(["place", str(DEFAULT_SPEC), "--target", "1.35,0,0.5", "--scene",
                   str(CLUTTERED), "--start", "-0.5,-0.5,1.0", "--format", "json", "-o",
                   str(goal), "--plot", str(plot)])  # fmt: skip
    assert res.returncode == 0, res.stderr
    doc = json.loads(res.stdout)
    assert list(doc) == KEYS
    assert doc["status"] == "placed" and doc["reason"] is None
    assert set(doc["joints"]) == {"arm_base_forearm_joint", "forearm_hand_joint"}
    for axis in ("x", "y", "yaw"):
        lo, hi = doc["region"][axis]
        assert lo <= doc["base"][axis] <= hi
    nav2 = yaml.safe_load(goal.read_text())
    pose = nav2["pose"]["pose"]
    x, y = pose["position"]["x"], pose["position"]["y"]
    yaw = 2 * math.atan2(pose["orientation"]["z"], pose["orientation"]["w"])
    lo, hi = doc["region"]["x"]  # the goal is inside the region the placed pose bounds
    assert lo <= x <= hi and doc["region"]["y"][0] <= y <= doc["region"]["y"][1]
    assert doc["region"]["yaw"][0] <= yaw <= doc["region"]["yaw"][1]
    assert nav2["xy_goal_tolerance"] > 0 and nav2["yaw_goal_tolerance"] > 0
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_target_too_high_exits_1_and_writes_nothing(tmp_path: Path) -> None:
    goal = tmp_path / "goal.yaml"
    res = run_cli(["place", str(DEFAULT_SPEC), "--target", "1,0,1.5", "-o", str(goal)])
    assert res.returncode == 1
    assert "highest point it reaches is z = 0.920 m" in res.stderr  # 0.32 + 0.3 + 0.3 (spec)
    assert not goal.exists()


def test_a_target_inside_an_object_names_it(tmp_path: Path) -> None:
    res = run_cli(["place", str(DEFAULT_SPEC), "--target", "-1,1.2,0.25", "--scene",
                   str(CLUTTERED), "--format", "json"])  # fmt: skip
    assert res.returncode == 1
    doc = json.loads(res.stdout)
    assert doc["status"] == "failed" and "inside crate" in doc["reason"]


def test_a_malformed_scene_names_file_line_and_field(tmp_path: Path) -> None:
    scene = tmp_path / "scene.yaml"
    scene.write_text("collision_objects:\n  - id: box\n    primitives: [{type: box, "
                     "dimensions: [1, 2]}]\n    primitive_poses: [{}]\n")  # fmt: skip
    res = run_cli(["place", str(DEFAULT_SPEC), "--target", "1,0,0.5", "--scene", str(scene)])
    assert res.returncode == 2
    assert "scene.yaml:3" in res.stderr and "dimensions" in res.stderr


def test_a_malformed_start_names_the_flag() -> None:
    res = run_cli(["place", str(DEFAULT_SPEC), "--target", "1,0,0.5", "--start", "1,2"])
    assert res.returncode == 2
    assert "--start" in res.stderr
