"""Placements of reusable parts -> ordinary links and joints of the arm or the base.

Run once by `spec.load` after field validation and before the cross-reference rules,
so that everything downstream (semantics, compiler, check, simulate, ROS) sees one
robot with every placed link and joint under its prefixed name. The placements stay in
the spec: the compiler writes them back as xacro macro calls.
"""

from __future__ import annotations

from armcli.defaults import MAX_ROBOT_DOF, MAX_ROBOT_LINKS
from armcli.errors import Problem
from armcli.spec.model import Arm, MobileBase, RobotSpec
from armcli.spec.parts import part_root, placed_joints, placed_links, placed_names


def _expand_part(
    spec: RobotSpec, where: str, holder: Arm | MobileBase, taken: set[str], out: list[Problem]
) -> Arm | MobileBase:
    links, joints = dict(holder.links), dict(holder.joints)
    for i, p in enumerate(holder.parts):
        path = f"{where}.parts[{i}]"
        part = spec.parts.get(p.part)
        if part is None:
            known = ", ".join(sorted(spec.parts)) or "(none)"
            out.append(Problem(f"{path}.part", f"unknown part {p.part!r}; known: {known}"))
            continue
        new_links, new_joints = placed_names(p, part)
        clash = sorted((new_links | new_joints) & (taken | set(links) | set(joints)))
        if clash:
            out.append(Problem(f"{path}.prefix", f"names already used: {', '.join(clash)}"))
            continue
        links.update(placed_links(p, part))
        joints.update(placed_joints(p, part, part_root(part)))
    return holder.model_copy(update={"links": links, "joints": joints})


def _size_problem(spec: RobotSpec) -> Problem | None:
    """The robot's size after expansion, counted before any part is expanded (issue 27).

    100 placements of a 50-link part (a 19 kB spec) kept `build` busy for minutes.
    """
    links, dof = len(spec.all_links()), sum(j.type != "fixed" for j in spec.all_joints().values())
    for p in (*spec.arm.parts, *(spec.mobile_base.parts if spec.mobile_base else [])):
        part = spec.parts.get(p.part)
        if part is not None:
            links += len(part.links)
            dof += (p.type != "fixed") + sum(j.type != "fixed" for j in part.joints.values())
    where = "arm.parts" if spec.arm.parts else "mobile_base.parts"
    if links > MAX_ROBOT_LINKS:
        return Problem(
            where, f"the parts expand to {links} links, more than armcli's {MAX_ROBOT_LINKS}"
        )
    if dof > MAX_ROBOT_DOF:
        return Problem(
            where,
            f"the parts expand to {dof} degrees of freedom, more than armcli's {MAX_ROBOT_DOF}",
        )
    return None


def expand_parts(spec: RobotSpec) -> tuple[RobotSpec, list[Problem]]:
    """The spec with every placement's links and joints added, and the problems found."""
    placements = [*spec.arm.parts, *(spec.mobile_base.parts if spec.mobile_base else [])]
    if not placements:
        return spec, []
    too_big = _size_problem(spec)
    if too_big is not None:
        return spec, [too_big]
    out: list[Problem] = []
    base = spec.mobile_base
    taken = set(spec.all_links()) | set(spec.all_joints())
    update: dict[str, object] = {"arm": _expand_part(spec, "arm", spec.arm, taken, out)}
    if base is not None:
        update["mobile_base"] = _expand_part(spec, "mobile_base", base, taken, out)
    return spec.model_copy(update=update), out
