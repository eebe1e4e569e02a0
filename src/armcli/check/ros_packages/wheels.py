"""`ros-wheel-geometry`: a diff-drive's wheel separation or radius against the URDF's wheels.

The diff-drive (Gazebo classic's `libgazebo_ros_diff_drive.so`: `wheel_separation`,
`wheel_diameter`; gz-sim's DiffDrive system: `wheel_separation`, `wheel_radius`;
ros2_control's diff_drive_controller: `wheel_separation` x `wheel_separation_multiplier`,
`wheel_radius` x `left/right_wheel_radius_multiplier`) turns a twist into wheel speeds and
wheel speeds into odometry with these numbers; when they differ from the robot the
simulator moves, odometry drifts and turns come out wrong. The URDF's are: the wheel's
radius (its collision cylinder or sphere, else its visual's) and the separation (the
distance between the two wheels' centres along the wheel axis, at q = 0). More than
`TOLERANCE` apart is an error, with the URDF's number as the fix.

With the diff_drive_controller the distro matters too (distro.py): from Jazzy on its
`~/cmd_vel` is TwistStamped only and `use_stamped_vel` & co. no longer exist, so a file
still setting them (a Humble config moved over) is reported here with what happens.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from armcli.check.ros_packages.context import PackageContext
from armcli.check.ros_packages.params import DIFF_DRIVE, Controller
from armcli.robot.frames import rpy_matrix
from armcli.urdf.doc import Joint, Urdf

RULE = "ros-wheel-geometry"
TOLERANCE = 0.01  # relative difference that makes odometry visibly wrong (1 %)
CLASSIC_FILES = ("libgazebo_ros_diff_drive.so",)
GZ_MARKERS = ("diff-drive-system", "diff_drive-system", "systems::DiffDrive")


@dataclass(frozen=True)
class Wheels:
    """What a diff-drive is configured with [m]."""

    left: str | None
    right: str | None
    separation: float | None
    radius: float | None


def check(ctx: PackageContext) -> None:
    """Plugins of every description, then every diff_drive_controller."""
    seen: set[tuple[str, int | None]] = set()
    for urdf in ctx.robots.values():
        for plug in urdf.plugins:
            wheels = _plugin(plug.filename or "", plug.name or "", plug.params)
            key = (urdf.source, plug.line)
            if wheels is None or key in seen:
                continue
            seen.add(key)
            for what, fix, msg in compare(urdf, wheels):
                ctx.add_in(RULE, urdf, plug.line, msg, {what: fix}, plugin=plug.filename)
    owners = ctx.owners()
    for path in ctx.all_controller_files():
        cf = ctx.controllers(path)
        for c in cf.controllers.values() if cf is not None else ():
            if c.type == DIFF_DRIVE:
                _controller(ctx, c, owners.get(path, []))


def _plugin(filename: str, name: str, p: Mapping[str, str]) -> Wheels | None:
    base = filename.rsplit("/", 1)[-1]
    if base in CLASSIC_FILES:
        diameter = _float(p.get("wheel_diameter"))
        return Wheels(
            p.get("left_joint"),
            p.get("right_joint"),
            _float(p.get("wheel_separation")),
            diameter / 2 if diameter is not None else None,
        )
    if any(m in base or m in name for m in GZ_MARKERS):
        return Wheels(
            p.get("left_joint"),
            p.get("right_joint"),
            _float(p.get("wheel_separation")),
            _float(p.get("wheel_radius")),
        )
    return None


def _float(text: object) -> float | None:
    try:
        x = float(str(text))
    except (TypeError, ValueError):
        return None
    return x if np.isfinite(x) else None


def _controller(ctx: PackageContext, c: Controller, owners: list[Urdf]) -> None:
    """A diff_drive_controller against its robot.

    When nothing says which robot it drives: against every description with its wheel
    joints, reported only when all disagree.
    """
    p = c.params
    left, right = p.get("left_wheel_names"), p.get("right_wheel_names")
    sep, rad = _float(p.get("wheel_separation")), _float(p.get("wheel_radius"))
    if sep is not None:
        sep *= _float(p.get("wheel_separation_multiplier")) or 1.0
    if rad is not None:
        rad *= _float(p.get("left_wheel_radius_multiplier")) or 1.0
    wheels = Wheels(
        left[0] if isinstance(left, list) and left else None,
        right[0] if isinstance(right, list) and right else None,
        sep,
        rad,
    )
    robots = [u for u in owners or ctx.robots.values() if _joint(u, wheels.left) is not None]
    verdicts = [compare(u, wheels) for u in robots]
    for what, fix, msg in verdicts[0] if verdicts and all(verdicts) else ():
        key = "wheel_separation" if what == "wheel_separation" else "wheel_radius"
        ctx.add(
            RULE,
            c.file,
            c.line(key),
            f"controller {c.name!r}: {msg}",
            {what: fix},
            controller=c.name,
        )
    for name in ctx.distro.removed_diff_drive:
        if name in p:
            ctx.add(
                RULE,
                c.file,
                c.line(name),
                f"controller {c.name!r} sets {name}, which diff_drive_controller no longer has "
                f"on {ctx.distro.name}: it is ignored"
                + (
                    "; ~/cmd_vel takes geometry_msgs/msg/TwistStamped only, so a Twist "
                    "publisher (teleop_twist_keyboard without stamped:=true) is not heard"
                    if name == "use_stamped_vel"
                    else ""
                ),
                {},
                controller=c.name,
                parameter=name,
            )


def compare(urdf: Urdf, w: Wheels) -> list[tuple[str, float, str]]:
    """(parameter, the URDF's value, message) for each number more than 1 % off."""
    left, right = _joint(urdf, w.left), _joint(urdf, w.right)
    if left is None or right is None:
        return []
    out = []
    true_radius = _radius(urdf, left.child)
    if w.radius is not None and true_radius is not None and _off(w.radius, true_radius):
        out.append(
            (
                "wheel_radius",
                round(true_radius, 6),
                f"wheel radius {w.radius:g} m, but {left.child!r} is a wheel of radius "
                f"{true_radius:g} m in {urdf.name!r}: odometry is "
                f"{abs(w.radius / true_radius - 1):.0%} off",
            )
        )
    true_sep = _separation(urdf, left, right)
    if w.separation is not None and true_sep is not None and _off(w.separation, true_sep):
        out.append(
            (
                "wheel_separation",
                round(true_sep, 6),
                f"wheel separation {w.separation:g} m, but {w.left!r} and {w.right!r} are "
                f"{true_sep:g} m apart in {urdf.name!r}: turns come out "
                f"{abs(w.separation / true_sep - 1):.0%} off",
            )
        )
    return out


def _off(given: float, true: float) -> bool:
    """More than TOLERANCE (relative) from the URDF's value."""
    return abs(given - true) > TOLERANCE * true


def _joint(urdf: Urdf, name: str | None) -> Joint | None:
    return next((j for j in urdf.joints if j.name == name), None) if name else None


def _radius(urdf: Urdf, link_name: str | None) -> float | None:
    link = urdf.link(link_name) if link_name else None
    if link is None:
        return None
    for shapes in (link.collisions, link.visuals):
        for s in shapes:
            g = s.geometry
            if g is not None and g.dims and g.kind in ("cylinder", "sphere"):
                return float(g.dims[0])
    return None


def _centre(urdf: Urdf, link: str) -> NDArray[np.float64] | None:
    """The wheel's centre in the root frame at q = 0: its link pose and its shape's origin."""
    above = {j.child: j for j in urdf.joints if j.child}
    T = np.eye(4)
    lk = urdf.link(link)
    shape = next(iter((lk.collisions or lk.visuals) if lk else ()), None)
    if shape is not None:
        T = _pose(shape.origin.xyz, shape.origin.rpy)
    name: str | None = link
    for _ in range(len(above) + 1):
        j = above.get(name) if name else None
        if j is None:
            break
        T = _pose(j.origin.xyz, j.origin.rpy) @ T
        name = j.parent
    return T[:3, 3]


def _separation(urdf: Urdf, left: Joint, right: Joint) -> float | None:
    if not left.child or not right.child or left.axis is None:
        return None
    a, b = _centre(urdf, left.child), _centre(urdf, right.child)
    if a is None or b is None:
        return None
    axis = _axis_in_root(urdf, left)
    d = a - b
    return float(abs(d @ axis)) if axis is not None else float(np.linalg.norm(d))


def _axis_in_root(urdf: Urdf, j: Joint) -> NDArray[np.float64] | None:
    above = {x.child: x for x in urdf.joints if x.child}
    R = rpy_matrix(j.origin.rpy)
    name = j.parent
    for _ in range(len(above) + 1):
        up = above.get(name) if name else None
        if up is None:
            break
        R = rpy_matrix(up.origin.rpy) @ R
        name = up.parent
    v = R @ np.asarray(j.axis, dtype=float)
    n = float(np.linalg.norm(v))
    return v / n if n > 0 else None


def _pose(xyz: Sequence[float], rpy: Sequence[float]) -> NDArray[np.float64]:
    T = np.eye(4)
    T[:3, :3] = rpy_matrix(rpy)
    T[:3, 3] = xyz
    return T
