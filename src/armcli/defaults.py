"""Defaults shared by commands; kept import-free so `armcli --help` stays fast."""

from __future__ import annotations

from pathlib import Path

DEFAULT_SPEC = Path("specs/my_robot.yaml")
DEFAULT_URDF_DIR = Path("urdf")
