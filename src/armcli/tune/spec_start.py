"""Model-based start gains for a spec that has none (an imported robot), without rollouts.

The same start `armcli tune` begins from (`tune.model_gains.start_gains`, implicit loop,
critically damped, wn a decade under the controller rate), for the arm's moving joints
that have a motor of their own: mimic followers and continuous joints are left out, as
the simulator does not drive them.
"""

from __future__ import annotations

import math

import numpy as np

from armcli.defaults import STANDALONE_ARM_URDF
from armcli.errors import InputError
from armcli.robot.model import Robot
from armcli.sim.simulate import simulated
from armcli.spec.joint_types import LIMITED_TYPES
from armcli.spec.model import RobotSpec
from armcli.tune.model_gains import (
    TARGET_RATIO,
    _largest,
    linearised,
    loop_stable,
    sample_configurations,
    start_gains,
)
from armcli.urdf.read import parse_urdf
from armcli.urdf.source import spec_urdfs

STEP_CAP = math.pi / 2  # [rad or m] the largest step the start gains are sized for
KD_FLOOR = 1e-6  # smallest Kd scale tried for the explicit loop
KD_MARGIN = 0.4  # below the edge on tune's samples: check samples other points (OMX: x0.48)


def spec_start_gains(spec: RobotSpec) -> dict[str, tuple[float, float]]:
    """{joint: (kp, kd)} for the driven arm joints.

    {} when there are none, gravity beats an effort limit, or the mass matrix is singular
    (massless links): the import then writes no gains, and `check` says what is wrong.
    """
    joints = [
        n
        for n in spec.movable_arm_joints()
        if spec.arm.joints[n].mimic is None and spec.arm.joints[n].type in LIMITED_TYPES
    ]
    if not joints:
        return {}
    urdf = parse_urdf(spec_urdfs(spec)[STANDALONE_ARM_URDF], STANDALONE_ARM_URDF)
    robot = simulated(Robot.load(urdf, strict=False), joints)
    span = robot.upper - robot.lower
    steps = np.minimum(np.where(np.isfinite(span), span, STEP_CAP), STEP_CAP)
    wn = 2 * math.pi * spec.control.controller_update_rate / TARGET_RATIO
    try:
        start = start_gains(
            robot, dt=spec.control.dt, loop="implicit", zeta=1.0, wn_target=wn, steps=steps
        )
    except InputError:
        return {}  # an effort limit below gravity: no start gains; tune says why
    except np.linalg.LinAlgError:
        return {}  # a massless chain (singular mass matrix): nothing to size gains on; check says
    kd = _explicit_kd(robot, start.kp, start.kd, spec.control.dt)
    return {
        name: (float(kp), float(kd_j))
        for name, kp, kd_j in zip(robot.names, start.kp, kd, strict=True)
    }


def _explicit_kd(robot: Robot, kp: np.ndarray, kd: np.ndarray, dt: float) -> np.ndarray:
    """kd, lowered until the explicit torque loop (Gazebo's) is stable at dt too.

    `check` judges both loops; the implicit start alone left the imported OpenManipulator-X
    with `pd-explicit-unstable` (Kd too high for its light links at dt = 1 ms). Lower Kd
    only makes that loop more stable, and the simulator's implicit loop stays stable.
    Unchanged when no Kd makes it stable (then `check` says why).
    """
    lin = linearised(robot, sample_configurations(robot), gravity=True)
    if loop_stable(robot, lin, kp, kd, "explicit", dt):
        return kd
    if not loop_stable(robot, lin, kp, 0.0 * kd, "explicit", dt):
        return kd
    s = _largest(lambda s: loop_stable(robot, lin, kp, s * kd, "explicit", dt), KD_FLOOR, 1.0)
    return kd * s * KD_MARGIN
