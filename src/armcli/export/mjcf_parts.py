"""The parts of the MJCF model after the body tree: actuators, keyframes, equalities, notes.

Position actuators carry no `ctrlrange`: their control is armcli's mapped
reference ctrl = q_ref + (Kd / Kp) v_ref, which leaves the joint range whenever
the reference moves near a limit; clipping it there would change the PD law
(5e-2 rad away from `armcli simulate` on a trajectory that returns to the limits).

Keyframes hold qpos in MuJoCo's joint order (the free joint's position and unit
quaternion first, when the base is free) and, for position actuators, a ctrl
equal to the pose so that the key is also a hold command.
"""

from __future__ import annotations

from lxml import etree

from armcli.compiler.xmlfmt import fmt, vec
from armcli.export.mjcf_report import EXTRA_TAGS, Extras, Note
from armcli.robot.joints import rest
from armcli.spec.control import command_interfaces
from armcli.spec.joint_types import position_bounds
from armcli.spec.model import RobotSpec
from armcli.urdf.doc import Joint, Urdf

HOME = "home"
FREE_QPOS = (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)  # origin, identity quaternion (w x y z)


def _range(j: Joint) -> tuple[float, float] | None:
    return position_bounds(j.type, j.limit)


def _command_range(spec: RobotSpec | None, joint: str, name: str) -> tuple[float, float] | None:
    """[min, max] of the spec's ros2_control command interface `name` of `joint`, if given."""
    rc = spec.ros2_control if spec is not None else None
    jc = rc.joints.get(joint) if rc is not None else None
    i = jc.command_interfaces.get(name) if jc is not None else None
    return (i.min, i.max) if i is not None and i.min is not None and i.max is not None else None


def actuators(
    root: etree._Element,
    joints: list[Joint],
    spec: RobotSpec | None,
    extras: Extras,
    notes: list[Note],
) -> list[tuple[str, str]]:
    """One actuator per driven joint, named like it; returns (name, kind) in order.

    The spec's ros2_control interfaces choose it as mujoco_ros2_control maps them: a joint
    with gains and a position or effort command is the PD loop (`position`, force range
    from the effort interface's min/max, else the effort limit); a velocity-only joint a
    `velocity` actuator (kv = Kd, ctrl range from the interface, else the velocity limit);
    an effort command without gains a `motor`; a joint ros2_control only reads, none.
    """
    act = etree.SubElement(root, "actuator")
    gains = spec.control.gains if spec is not None else {}
    rc = spec.ros2_control if spec is not None else None
    out: list[tuple[str, str]] = []
    undriven, state_only = [], []
    for j in joints:
        effort = j.limit.effort if j.limit is not None else None
        if j.name in extras.mimic:
            continue
        commands = command_interfaces(rc, j.name)
        if rc is not None and j.name in rc.joints and not commands:
            state_only.append(j.name)
            continue
        force = _command_range(spec, j.name, "effort")
        force = force or ((-effort, effort) if effort is not None else None)
        attrs = {"name": j.name, "joint": j.name}
        velocity_only = commands and all(c == "velocity" for c in commands)
        if j.name in gains and velocity_only:
            speed = _command_range(spec, j.name, "velocity")
            vmax = j.limit.velocity if j.limit is not None else None
            speed = speed or ((-vmax, vmax) if vmax is not None else None)
            attrs["kv"] = fmt(gains[j.name].kd)
            if speed is not None:
                attrs["ctrlrange"] = vec(speed)
            if force is not None:
                attrs["forcerange"] = vec(force)
            etree.SubElement(act, "velocity", attrs)
            out.append((j.name, "velocity"))
        elif j.name in gains and not velocity_only:
            g = gains[j.name]
            attrs.update(kp=fmt(g.kp), kv=fmt(g.kd))  # no ctrlrange: see the module docstring
            if force is not None:
                attrs["forcerange"] = vec(force)
            etree.SubElement(act, "position", attrs)
            out.append((j.name, "position"))
        elif force is not None and (not commands or "effort" in commands):
            attrs["ctrlrange"] = vec(force)
            etree.SubElement(act, "motor", attrs)
            out.append((j.name, "motor"))
        else:
            undriven.append(j.name)
    if undriven:
        notes.append(
            Note(
                "actuators",
                f"no gains and no effort command or limit for {', '.join(undriven)}",
                "left without an actuator (passive joints)",
            )
        )
    if state_only:
        notes.append(
            Note(
                "actuators",
                f"ros2_control only reads {', '.join(state_only)}",
                "left without an actuator (no command interface)",
            )
        )
    if not len(act):
        root.remove(act)
    return out


def _poses(joints: list[Joint], spec: RobotSpec | None) -> dict[str, dict[str, float]]:
    """`home` first (the spec's, else each joint at rest), then the spec's poses.

    A joint a pose leaves out rests (`robot.joints.rest`: 0, else the middle of its range).
    """
    zero = {}
    for j in joints:
        r = _range(j)
        zero[j.name] = rest(*r) if r is not None else 0.0
    out = {HOME: dict(zero)}
    if spec is not None:
        for name in spec.poses:
            out[name] = {**zero, **spec.pose(name)}
    return out


def keyframes(
    root: etree._Element,
    joints: list[Joint],
    acts: list[tuple[str, str]],
    spec: RobotSpec | None,
    free: bool,
) -> tuple[str, ...]:
    """`<keyframe>`: one key per pose (qpos in MuJoCo order, ctrl holding the pose)."""
    key_el = etree.SubElement(root, "keyframe")
    poses = _poses(joints, spec)
    for name, values in poses.items():
        qpos = [*(FREE_QPOS if free else ()), *(values[j.name] for j in joints)]
        attrs = {"name": name, "qpos": vec(qpos)}
        if acts:
            ctrl = [values[a] if kind == "position" else 0.0 for a, kind in acts]
            attrs["ctrl"] = vec(ctrl)
        etree.SubElement(key_el, "key", attrs)
    return tuple(poses)


def excludes(root: etree._Element, urdf: Urdf, bodies: set[str]) -> None:
    """No contact between the two links of a URDF joint, as in Gazebo and MoveIt.

    MuJoCo's own parent/child filter does not apply to a body welded to the world
    (the fixed base), whose children would otherwise touch it by construction.
    """
    pairs = [(str(j.parent), str(j.child)) for j in urdf.joints]
    pairs = [(a, b) for a, b in pairs if a in bodies and b in bodies]
    if not pairs:
        return
    contact = etree.SubElement(root, "contact")
    for a, b in pairs:
        etree.SubElement(contact, "exclude", body1=a, body2=b)


def equalities(root: etree._Element, extras: Extras, joints: set[str]) -> None:
    """Mimic joints as joint equality constraints: q1 = offset + multiplier * q2."""
    pairs = [(f, m) for f, m in sorted(extras.mimic.items()) if f in joints and m.leader in joints]
    if not pairs:
        return
    eq = etree.SubElement(root, "equality")
    for follower, m in pairs:
        poly = vec((m.offset, m.multiplier, 0.0, 0.0, 0.0))
        etree.SubElement(eq, "joint", joint1=follower, joint2=m.leader, polycoef=poly)


def notes(
    urdf: Urdf,
    joints: list[Joint],
    extras: Extras,
    spec: RobotSpec | None,
) -> list[Note]:
    """Everything URDF (or the spec) says that the MJCF model does not carry as such."""
    out = []
    vel = [j.name for j in joints if j.limit is not None and j.limit.velocity is not None]
    if vel:
        out.append(
            Note(
                "velocity limits",
                f"<limit velocity> on {', '.join(vel)}",
                "dropped: MuJoCo has no joint velocity limit (kv damps, nothing clips)",
            )
        )
    if extras.mimic:
        names = ", ".join(
            f"{f} = {m.multiplier:g} {m.leader} + {m.offset:g}"
            for f, m in sorted(extras.mimic.items())
        )
        out.append(
            Note(
                "mimic joints",
                names,
                "MuJoCo has no mimic joint: a soft <equality><joint> constraint, no actuator",
            )
        )
    if extras.tags:
        counts = ", ".join(f"{n} <{t}>" for t, n in extras.tags.items())
        mu = (
            f"; Gazebo mu1 became the sliding friction of {', '.join(sorted(extras.mu1))}"
            if extras.mu1
            else ""
        )
        out.append(
            Note(
                "Gazebo tags",
                f"{counts} ({'/'.join(EXTRA_TAGS)} are simulator-specific)",
                "dropped: plugins, Gazebo materials, transmissions and ros2_control have no "
                f"MJCF meaning; actuators come from the spec's gains{mu}",
            )
        )
    if spec is not None:
        out += _spec_notes(spec)
    return out


def _spec_notes(spec: RobotSpec) -> list[Note]:
    out = []
    with_i = [n for n, g in spec.control.gains.items() if g.ki > 0]
    if with_i:
        out.append(
            Note(
                "integral gains",
                f"ki > 0 on {', '.join(with_i)}",
                "dropped: position actuators are PD",
            )
        )
    if spec.control.gravity_compensation:
        out.append(
            Note(
                "gravity compensation",
                "control.gravity_compensation is on",
                'not exported: add gravcomp="1" to the bodies to reproduce it',
            )
        )
    return out
