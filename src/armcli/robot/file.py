"""The `Robot`s of a robot file, built once each and kept on the file (`RobotFile.robots`).

A command reads its robot file once (`urdf.source.read_robot`) and hands the `RobotFile`
down; every library call that needs a model asks here, so `simulate` builds the arm it
runs, the whole robot `check` gates and the floating robot its balance stands on once
each, however many stages read them. The cache lives on the file object, not in a module:
it goes when the command's file goes.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import cast

from armcli.robot.model import Robot
from armcli.urdf.doc import Urdf
from armcli.urdf.source import RobotFile

_BUILDING = threading.RLock()  # one model for two threads asking; a gate may ask again


def robot_of(
    file: RobotFile,
    urdf: Urdf | None = None,
    *,
    floating: bool = False,
    strict: bool = True,
    gate: Callable[[Urdf], None] | None = None,
) -> Robot:
    """The `Robot` of one of `file`'s documents (default: the whole robot), built once.

    `floating`, `strict` and `gate` as `Robot.load`'s; the tool point is the file's spec's.
    A `gate` runs when the robot is first built (a refusal raises and keeps nothing).
    """
    doc = urdf if urdf is not None else file.robot
    key = (doc.source, floating, strict)
    with _BUILDING:
        found = file.robots.get(key)
        if found is None:
            found = Robot.load(doc, floating=floating, spec=file.spec, strict=strict, gate=gate)
            file.robots[key] = found
    return cast(Robot, found)


def floating_of(file: RobotFile, urdf: Urdf) -> Callable[[], Robot]:
    """The document's floating robot as a stance asks for it (`analysis.stance.stance_of`).

    Non-strict, as `check` loads: `check`'s static balance, `simulate`'s zero-moment point
    and the drive's stance stand on this one model.
    """
    return lambda: robot_of(file, urdf, floating=True, strict=False)
