"""The compiled planner (`armcli.plan._planner`): loading it and handing it a robot and scene.

The collision loop, RRT-Connect, the certification sweep and TOPP-RA's timing are defined in
`_native/` (C++), built at install time with the simulator (CMakeLists.txt) against the
Pinocchio and coal of the `pin` wheel and the toppra library of `cmeel-toppra`; nothing
compiles at run time. Where the extension is missing (no C++ compiler at install, or
ARMCLI_NO_NATIVE set) `load()` returns None and planning runs its Python path (OMPL with a
Python validity callback, TOPP-RA's Python package): the same verdicts, slower. An extension
built from other sources than these (an editable install whose C++ changed without `make
native`) is not used either.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np

from armcli.compiled import Extension

if TYPE_CHECKING:
    from armcli.plan import _planner
    from armcli.plan.robot import PlanRobot

NATIVE = Path(__file__).parent / "_native"
# The sources in CMakeLists.txt's PLANNER_SOURCES order: their hashes make the build's hash.
SOURCES = (
    "core.hpp",
    "checker.cpp",
    "certify.cpp",
    "rrt.cpp",
    "timing.hpp",
    "timing.cpp",
    "module.cpp",
)
PLANNER = Extension("armcli.plan._planner", tuple(NATIVE / name for name in SOURCES))
load = PLANNER.load  # the module, or None: missing, stale or ARMCLI_NO_NATIVE (the Python path)
why_missing = PLANNER.why_missing
source_hash = PLANNER.source_hash


def _serialised(obj: Any) -> bytes:
    """A Pinocchio model or geometry model in Pinocchio's binary format (exactly itself)."""
    import pinocchio as pin

    buf = pin.serialization.StreamBuffer()
    obj.saveToBinary(buf)
    return bytes(buf.tobytes())


def joint_entries(robot: PlanRobot) -> list[tuple[int, int, int, bool, float, np.ndarray]]:
    """(joint id, idx_q, idx_v, continuous, offset, coefficients): angle = offset + c . x.

    One per 1-DoF joint that a planned joint moves: the planned joints themselves and the
    mimic followers of one (through any chain of followers); the others keep the value
    `PlanRobot.q` gives them.
    """
    model, n = robot.model, len(robot.joints)
    affine: dict[str, tuple[float, np.ndarray]] = {
        name: (0.0, np.eye(n)[k]) for k, name in enumerate(robot.joints)
    }
    for m in robot.mimic:  # leaders before their followers
        offset, coeff = affine.get(m.leader, (robot.rest.get(m.leader, 0.0), np.zeros(n)))
        affine[m.follower] = (m.multiplier * offset + m.offset, m.multiplier * coeff)
    out = []
    for jid in range(1, model.njoints):
        name, jm = str(model.names[jid]), model.joints[jid]
        if jm.nv != 1 or name not in affine or not np.any(affine[name][1]):
            continue
        offset, coeff = affine[name]
        out.append((jid, int(jm.idx_q), int(jm.idx_v), jm.nq == 2, float(offset), coeff))
    return out


def compiled_scene(
    mod: ModuleType,
    robot: PlanRobot,
    gmodel: Any,
    pairs: Sequence[tuple[int, int]],
    moving: Sequence[bool],
    bodies: Sequence[str],
) -> _planner.Scene:
    """The extension's copy of the robot, its geometry (obstacles included) and the pairs.

    `bodies`: each geometry's owner (link, scene object), whose geometries are culled together.
    """
    index = {name: k for k, name in enumerate(dict.fromkeys(bodies))}
    entries = joint_entries(robot)
    n = len(robot.joints)
    table = np.array(pairs, dtype=np.int32).reshape(-1, 2)
    scene: _planner.Scene = mod.scene(
        _serialised(robot.model),
        _serialised(gmodel),
        np.asarray(robot.q(np.zeros(n)), dtype=float),
        np.array([e[0] for e in entries], dtype=np.int32),
        np.array([e[1] for e in entries], dtype=np.int32),
        np.array([e[2] for e in entries], dtype=np.int32),
        np.array([e[3] for e in entries], dtype=bool),
        np.array([e[4] for e in entries], dtype=float),
        np.array([e[5] for e in entries], dtype=float).reshape(-1, n),
        np.ascontiguousarray(table[:, 0]),
        np.ascontiguousarray(table[:, 1]),
        np.array(moving, dtype=bool),
        np.array([index[b] for b in bodies], dtype=np.int32),
        np.asarray(robot.lower, dtype=float),
        np.asarray(robot.upper, dtype=float),
    )
    return scene


if __name__ == "__main__":  # `python -m armcli.plan.native`: is the compiled planner installed
    import sys

    if load() is None:
        print(f"armcli: compiled planner unavailable: {why_missing()}", file=sys.stderr)
        raise SystemExit(1)
    print(f"armcli: compiled planner {load()}")
