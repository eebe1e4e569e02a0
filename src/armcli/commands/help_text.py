"""Help texts several commands share, apart from the library: `--help` loads nothing heavy."""

from __future__ import annotations

ROBOT_HELP = (
    "Robot spec YAML, URDF file, or xacro file (expanded in safe mode); "
    "default: ./armcli.yaml, else the spec in specs/."
)
