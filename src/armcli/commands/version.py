"""What `armcli --version` reports: armcli, the simulator engine, pin and xacro, rendering.

A bug report needs to say which installation ran (the path), whether `simulate` uses the
compiled simulator (or why it has none), the versions of the two libraries that shape
every output (Pinocchio for dynamics and checks, xacro for expansion), and whether a
camera sensor can render (the OpenGL backend MuJoCo found: EGL, OSMesa or none, tried
the way the camera tries it). Versions come from the installed metadata.
"""

from __future__ import annotations

import platform
import sys
from importlib import metadata
from pathlib import Path

import armcli
from armcli.sim import native

LIBRARIES = ("pin", "xacro")  # distributions whose versions change armcli's results


def _dist_version(name: str) -> str:
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return "not installed"


def engine() -> str:
    """Where the compiled simulator `simulate` runs is, or why there is none.

    Asks `native.load()`, the same check the simulator makes, so the answer cannot differ
    from what `simulate` does.
    """
    lib = native.load()
    if lib is None:
        return f"unavailable ({native.why_missing()})"
    where = getattr(lib, "__file__", None) or getattr(lib, "_name", "")  # module or CDLL
    return f"compiled ({where})"


def rendering() -> str:
    """The OpenGL backend camera sensors render with (sim.sensors.gl), or why none."""
    from armcli.sim.sensors import gl  # mujoco and OpenGL: loaded only here

    return gl.describe()


def version_lines() -> list[str]:
    """The lines `armcli --version` prints, armcli's own version first."""
    lines = [f"armcli {armcli.__version__} ({Path(armcli.__file__).parent})"]
    lines.append(f"simulator engine: {engine()}")
    lines += [f"{name} {_dist_version(name)}" for name in LIBRARIES]
    lines.append(f"camera rendering: {rendering()}")
    lines.append(f"Python {platform.python_version()} ({sys.executable})")
    return lines
