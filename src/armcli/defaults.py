"""Defaults shared across stages, written once; import-free so `armcli --help` stays fast."""

from __future__ import annotations

from pathlib import Path
from typing import Literal

DEFAULT_SPEC = Path("specs/my_robot.yaml")  # preferred when specs/ holds several
SPEC_FILE = Path("armcli.yaml")  # what `armcli init` writes; found first in the cwd
SPECS_DIR = Path("specs")
TRAJECTORY_DIR = Path("trajectories")  # beside SPEC_FILE after `armcli init`
SPEC_HELP = "Robot spec YAML (default: ./armcli.yaml, else the one in specs/)."
DEFAULT_URDF_DIR = Path("urdf")

# Generated file names (build, ros-package, simulate, check all refer to these).
STANDALONE_ARM = "standalone_arm"
STANDALONE_ARM_XACRO = f"{STANDALONE_ARM}.urdf.xacro"
STANDALONE_ARM_URDF = f"{STANDALONE_ARM}.urdf"

# armcli's bound on robot size (URDF reader and spec parts alike): tiago_dual, the largest
# robot in example-robot-data, has 130 links and 101 DoF; a 1000-joint chain made check use 24 GB
MAX_ROBOT_LINKS = 300
MAX_ROBOT_DOF = 128
DEFAULT_DT = 0.001  # [s] control and simulation step when the spec gives none
MAX_DT = 0.1  # [s] the largest time step (spec/types.py's `time_step`, the one rule)
DEFAULT_STATE_RATE_HZ = 10.0  # [Hz] joint-state output without a joint_state_publisher

# Choices and defaults of command options whose `--help` must not import their library.
ROS_TARGETS = ("humble-classic", "jazzy")  # the course's ROS 2 Humble + Gazebo classic; Jazzy + gz
ROS_DISTROS = ("humble", "jazzy", "kilted", "lyrical")  # `check DIR --distro` (ROS packages)
COLLISION_SAMPLES = 10_000  # the MoveIt Setup Assistant's default "sampling density"
MJCF_BASES = ("fixed", "free")  # `export mjcf --base`: root welded to the world, or free
PdLoop = Literal["implicit", "explicit"]  # armcli's simulator, or an explicit torque loop
PD_LOOPS: tuple[PdLoop, ...] = ("implicit", "explicit")  # `tune --loop`
ROBUST_MODES = ("worst", "quantile")  # `tune --robust-mode` over the perturbed models

# [rad/s² or m/s²] a joint's acceleration limit when neither the spec nor the URDF gives one:
# MoveIt's time-optimal parameterisation uses the same 1.0 (DEFAULT_ACCELERATION_LIMIT).
DEFAULT_JOINT_ACCELERATION = 1.0
# `plan --planner`: OMPL geometric planners (RRT-Connect first: MoveIt's default)
PLANNERS = ("rrtconnect", "rrt", "rrtstar", "informedrrtstar", "aorrtc")
