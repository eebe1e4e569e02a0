"""The --trust-xacro option: its help text and its value, light enough for `--help`.

`armcli CMD --help` imports this instead of urdf.source (which loads numpy and lxml).
"""

from __future__ import annotations

from typing import Literal

TRUST_XACRO_HELP = (
    "Expand a foreign xacro file with xacro itself, which runs Python from the file, inside "
    "a bubblewrap sandbox (--trust-xacro=unsandboxed: resource limits only). Without it, "
    "xacro files are expanded in safe mode, where no code from the file runs."
)
UNSANDBOXED_HELP = "Same as --trust-xacro=unsandboxed: xacro itself with resource limits only."
Trust = bool | Literal["unsandboxed"]  # --trust-xacro: False, True (sandboxed), "unsandboxed"


def trust_mode(trust_xacro: bool, unsandboxed: bool) -> Trust:
    """The --trust-xacro / --trust-xacro=unsandboxed options as one value."""
    return "unsandboxed" if unsandboxed else trust_xacro
