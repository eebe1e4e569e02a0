"""`ros-srdf-unknown`: an SRDF naming a joint, link or group its robot does not have.

MoveIt's SRDF model drops a group whose joint or link is missing (and with it the named
poses and end effectors built on it: "Group 'arm' not found" at the first plan), and a
`disable_collisions` pair with an unknown link is skipped. The SRDF is compared with the
URDF its MoveIt config loads (`.setup_assistant` or `config/<robot>.urdf.xacro`), its
virtual joints counted as joints; a `.srdf.xacro` is expanded first.
"""

from __future__ import annotations

from armcli.check.ros_packages.context import PackageContext
from armcli.check.ros_packages.descriptions import lookup
from armcli.check.ros_packages.files import Problem
from armcli.check.ros_packages.joint_names import did_you_mean
from armcli.check.ros_packages.moveit import MoveItConfig
from armcli.errors import InputError
from armcli.urdf.source import expand_xacro
from armcli.urdf.srdf import Srdf, parse_srdf
from armcli.xacro.args import XacroInputs
from armcli.xacro.lines import Origin, parse_map

RULE = "ros-srdf-unknown"


def read(ctx: PackageContext, cfg: MoveItConfig) -> tuple[Srdf, dict[int, Origin]] | None:
    """A MoveIt config's SRDF (expanded when xacro), once per check; None when unreadable."""
    path = cfg.srdf
    if path is None:
        return None
    cache = ctx.srdfs
    if path in cache:
        return cache[path]
    found: tuple[Srdf, dict[int, Origin]] | None = None
    try:
        if path.name.endswith(".xacro"):
            xml, used = expand_xacro(path, inputs=XacroInputs(packages=lookup(ctx.ws, {})))
            found = parse_srdf(xml, f"{path}"), dict(parse_map(used.source_map))
        else:
            found = parse_srdf(ctx.ws.jail.read(path, "SRDF"), path), {}
    except InputError as exc:
        ctx.problems.setdefault(str(path), Problem.of(exc, path))
    cache[path] = found
    return found


def check(ctx: PackageContext) -> None:
    """Every name each MoveIt config's SRDF uses, against its URDF."""
    for cfg in ctx.moveit:
        robot = ctx.moveit_urdf(cfg)
        srdf = read(ctx, cfg)
        if robot is None or srdf is None or cfg.srdf is None:
            continue
        doc, origins = srdf
        virtual = set(doc.virtual_joints)
        valid = {
            "joint": {j.name for j in robot.joints} | virtual,
            "link": {lk.name for lk in robot.links},
            "group": set(doc.groups),
        }
        for e in doc.entries:
            if e.name in valid[e.kind]:
                continue
            guess = did_you_mean(e.name, valid[e.kind])
            what = "group" if e.kind == "group" else f"{robot.name!r}"
            msg = (
                f"{e.where or 'the SRDF'} names {e.kind} {e.name!r}, which "
                f"{'the SRDF does not define' if e.kind == 'group' else what + ' does not have'}"
                f"{f'; did you mean {guess!r}?' if guess else ''}"
            )
            origin = origins.get(e.line) if e.line else None
            file, line = (origin.file, origin.line) if origin else (str(cfg.srdf), e.line)
            ctx.add(RULE, file, line, msg, {e.kind: guess} if guess else {}, name=e.name)
