"""`ros-controller-unstable`: an effort JointTrajectoryController diverges at its update rate.

gz_ros2_control updates the controllers every 1/update_rate of simulated time and holds
their effort in between (analysis.zoh): with gains made for a faster loop the arm
oscillates or flies apart in Gazebo while the same gains look fine at the physics step.
Each effort JTC is judged with its PID gains (p, d, and i while its clamp lets the
integral act), on the robot it drives: its inertia and gravity's stiffness over the
joint-range samples `check` uses (robot.sampling), the joint damping from the URDF.
controller_manager's `update_rate` is 100 Hz where the file does not set it. The finding
sits on the `update_rate` line and gives the rate and the gains that pass.
"""

from __future__ import annotations

from armcli.analysis import pdloop
from armcli.analysis.rate import message, rate_verdict
from armcli.analysis.zoh import Pid
from armcli.check.controller_rate import RULE, fix, values
from armcli.check.ros_packages.context import PackageContext
from armcli.check.ros_packages.params import Controller, ControllerFile
from armcli.check.ros_packages.sag import effort_controllers, joint_gains, number
from armcli.robot import sampling
from armcli.urdf.doc import Urdf

DEFAULT_RATE = 100.0  # [Hz] controller_manager's update_rate when none is given


def check(ctx: PackageContext) -> None:
    """Every effort-commanded JTC of a robot that is not mock hardware."""
    for cf, c, urdf in effort_controllers(ctx):
        _controller(ctx, cf, c, urdf)


def _controller(ctx: PackageContext, cf: ControllerFile, c: Controller, urdf: Urdf) -> None:
    robot = ctx.model(urdf)
    listed = c.params.get("joints")
    names = [j for j in listed if isinstance(j, str)] if isinstance(listed, list) else []
    names = [j for j in names if robot is not None and j in robot.names]
    if robot is None or not names:
        return
    per = joint_gains(c, names)
    kp, kd = [number(g.get("p")) for g in per], [number(g.get("d")) for g in per]
    if not any(kp) and not any(kd):
        return  # no gains: the JTC applies no torque, so nothing can diverge
    ki = [number(g.get("i")) if ctx.distro.integral_cap(g) > 0 else 0.0 for g in per]
    joints = [robot.joint(j) for j in names]
    pd = pdloop.PD.of([j.idx_v for j in joints], kp, kd, [j.damping for j in joints])
    samples = sampling.configurations(robot)
    lin = pdloop.linearise(robot, [q for _, q in samples])
    rate = cf.update_rate if cf.update_rate is not None and cf.update_rate > 0 else DEFAULT_RATE
    v = rate_verdict(lin, Pid.of(pd, ki), rate)
    if v.stable:
        return
    at = samples[v.worst][0]
    text = message(v, names, [at[j] for j in names], what=c.name, rate_name="update_rate")
    if cf.update_rate is None:
        text += f" (update_rate not set: controller_manager's default {DEFAULT_RATE:g} Hz)"
    ctx.add(
        RULE,
        cf.path,
        cf.manager_line,
        text,
        fix(v, "update_rate", ("p", "d", "i")),
        controller=c.name,
        **values(v),
    )
