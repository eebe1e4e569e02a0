"""armcli: typed robot-arm specs compiled to ROS-ready xacro/URDF, checked and simulated."""

from __future__ import annotations

from typing import Any


def __getattr__(name: str) -> Any:
    """`armcli.__version__`, read from the installed metadata (pyproject.toml is the source).

    Lazy, so `import armcli` does not pay for importlib.metadata on every command.
    """
    if name == "__version__":
        from importlib import metadata

        try:
            return metadata.version("armcli")
        except metadata.PackageNotFoundError:  # a bare source tree on sys.path
            return "0+unknown"
    raise AttributeError(f"module 'armcli' has no attribute {name!r}")
