"""armcli: typed robot-arm specs -> ROS-ready URDF, physical checks and simulation, without ROS."""

from __future__ import annotations


def __getattr__(name: str) -> str:
    """`armcli.__version__`, read lazily: importlib.metadata costs ~50 ms at start-up."""
    if name != "__version__":
        raise AttributeError(name)
    from importlib.metadata import PackageNotFoundError, version

    try:  # the one source of the version is pyproject.toml, via the installed metadata
        return version("armcli")
    except PackageNotFoundError:  # a source tree that was never installed
        return "0+unknown"
