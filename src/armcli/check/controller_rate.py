"""Rule `ros-controller-unstable` on a spec: its gains at `control.controller_update_rate`.

`ros-package --target jazzy` writes the spec's gains into an effort JointTrajectoryController
that gz_ros2_control updates every 1/controller_update_rate, holding the effort in between
(analysis.zoh). That loop is judged here, besides the two loops at `control.dt`
(check/dynamics.py: armcli simulate's and an explicit torque loop at the physics step).
The controller adds no gravity compensation, so gravity's stiffness always counts. The
package rule of the same id (check/ros_packages/controller_rate.py) judges a controllers
YAML's `update_rate` and gains.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from armcli.analysis import pdloop
from armcli.analysis.rate import RateVerdict, message, rate_verdict
from armcli.analysis.zoh import Pid
from armcli.check.context import Context
from armcli.check.dynamics import spec_pd
from armcli.check.findings import Value
from armcli.errors import InputError

if TYPE_CHECKING:  # the spec models (pydantic) load only where a spec is read: not for a URDF
    from armcli.spec.model import RobotSpec

RULE = "ros-controller-unstable"
RATE_FIELD = "control.controller_update_rate"


def effort_commanded(spec: RobotSpec) -> bool:
    """Whether the Jazzy target drives the arm by effort (a PID on torque, held between updates)."""
    from armcli.ros.interfaces import JAZZY, trajectory_interface  # they read spec models
    from armcli.ros.srdf import chain_joints

    try:
        return trajectory_interface(spec, chain_joints(spec), JAZZY) == "effort"
    except InputError:  # no common interface: ros-package refuses the spec, check says nothing
        return False


def check(c: Context) -> None:
    """The spec's gains held for 1/controller_update_rate, over the dynamics samples."""
    spec = c.opts.spec
    if spec is None or not spec.control.gains or not effort_commanded(spec):
        return
    if c.servo and set(spec.control.gains) <= c.servo:  # a position servo is not a PD loop
        return
    robot = c.loaded()
    controlled = spec_pd(c.urdf, spec, robot)
    if controlled is None:
        return
    names, pd = controlled
    ki = np.array([spec.control.gains[n].ki for n in names])
    lin = pdloop.linearise(robot, [q for _, q in c.samples])
    v = rate_verdict(lin, Pid.of(pd, ki), spec.control.controller_update_rate)
    c.rate = v
    if v.stable:
        return
    at = c.samples[v.worst][0]
    text = message(
        v,
        names,
        [at[n] for n in names],
        what="the ros2_control controller",
        rate_name=RATE_FIELD,
        gain_names=("kp", "kd", "ki"),
    )
    line = next((j.line for j in c.urdf.joints if j.name == names[0]), None)
    c.out.add(RULE, line, text, fix(v, "controller_update_rate", ("kp", "kd", "ki")), **values(v))


def fix(v: RateVerdict, rate_key: str, gain_keys: tuple[str, str, str]) -> dict[str, Value]:
    """The remedy as `fix` values: the rate, and the gains at the configured rate."""
    out: dict[str, Value] = {}
    r = v.remedy
    if r is None:
        return out
    if r.rate is not None:
        out[rate_key] = r.rate
    if r.kp is not None and r.kd is not None and r.ki is not None:
        for key, gains in zip(gain_keys, (r.kp, r.kd, r.ki), strict=True):
            if key != gain_keys[2] or any(g > 0 for g in gains):  # no integral: no i to write
                out[key] = list(gains)
    return out


def values(v: RateVerdict) -> dict[str, Value]:
    """The verdict's numbers for JSON: the rate, the hold and its edge, the radius."""
    return {
        "update_rate": v.rate,
        "hold": v.hold,
        "hold_max": v.hold_max,
        "spectral_radius": v.radius,
    }
