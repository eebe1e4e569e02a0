"""Defaults shared by commands; kept import-free so `armcli --help` stays fast."""

from __future__ import annotations

from pathlib import Path

DEFAULT_SPEC = Path("specs/my_robot.yaml")  # preferred when specs/ holds several
SPEC_FILE = Path("armcli.yaml")  # what `armcli init` writes; found first in the cwd
SPECS_DIR = Path("specs")
TRAJECTORY_DIR = Path("trajectories")  # beside SPEC_FILE after `armcli init`
SPEC_HELP = "Robot spec YAML (default: ./armcli.yaml, else the one in specs/)."
DEFAULT_URDF_DIR = Path("urdf")
