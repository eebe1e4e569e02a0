"""A robot standing on the ground: its floating model, contacts, support polygon and payload.

What the static balance (`check`) and the dynamic one (`simulate`'s zero-moment point)
share. The model is the whole robot on a free-flyer root held at the identity, so the
root link's own inertia counts (a fixed-base model drops it) and inverse dynamics gives
the wrench the ground must supply. A payload is a point mass added to the body of the
link it hangs on. The joints searched or simulated are the ones that move the centre
of mass without moving a contact (not the wheels, not a caster's swivel).
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from armcli.analysis.ground import Ground, MeshVertices, find_ground, has_wheels
from armcli.analysis.support import SupportPolygon, support_polygon
from armcli.errors import InputError
from armcli.io.names import did_you_mean
from armcli.robot import sampling
from armcli.robot.frames import link_frame
from armcli.robot.joints import Joint
from armcli.robot.model import Robot
from armcli.urdf.doc import Urdf, Vec3

FIXED_BASE = (
    "fixed base: no wheel touches the ground (name the contact links to analyse a robot "
    "standing on feet or skids)"
)


@dataclass(frozen=True)
class Payload:
    """A point mass [kg] at `xyz` [m] in `link`'s frame (the tool point by default)."""

    mass: float
    link: str
    xyz: Vec3 = (0.0, 0.0, 0.0)

    @property
    def label(self) -> str:
        """How reports name it: "2 kg at hand_link + (0, 0, 0.3)"."""
        where = (
            self.link
            if not any(self.xyz)
            else (f"{self.link} + ({', '.join(f'{x:g}' for x in self.xyz)})")
        )
        return f"{self.mass:g} kg at {where}"


@dataclass(frozen=True)
class Stance:
    """A robot on its support polygon: floating model (payload included) and joints."""

    robot: Robot  # on a free-flyer root, without the payload
    ground: Ground
    polygon: SupportPolygon
    payload: Payload | None
    joints: tuple[Joint, ...]  # move the centre of mass, not the contacts

    @property
    def model(self) -> Any:
        """The robot's pinocchio.Model (free-flyer root, no payload)."""
        return self.robot.model

    @property
    def box(self) -> list[tuple[float, float]]:
        """The joints' sampling ranges [rad or m] (`Joint.span`), the search's box."""
        return sampling.bounds(self.joints)

    def q(self, values: Mapping[str, float] | ArrayLike) -> NDArray[np.float64]:
        """Pinocchio configuration: root at the identity, joints set [rad or m].

        `values` by name, or a sequence aligned with `joints`.
        """
        return self.robot.q(values, joints=self.joints)

    @property
    def mass(self) -> float:
        """Mass of the robot [kg], without the payload."""
        return self.robot.mass

    def loaded(self) -> Robot:
        """The robot with the payload's point mass on its link (for inverse dynamics)."""
        p = self.payload
        if p is None or p.mass <= 0:
            return self.robot
        return self.robot.with_point_mass(p.link, p.xyz, p.mass)

    def height(self, com: ArrayLike) -> float:
        """Height [m] of a point above the ground plane."""
        return float(np.asarray(com, dtype=float)[2]) - self.ground.height


@dataclass(frozen=True)
class NoStance:
    """Why a robot has no support polygon to analyse (a note for the report)."""

    reason: str


def stance_of(
    urdf: Urdf,
    *,
    candidates: Collection[str] | None = None,
    declared: Sequence[str] | None = None,
    mesh: MeshVertices | None = None,
    payload: Payload | None = None,
    floating: Callable[[], Robot] | None = None,
) -> Stance | NoStance:
    """The robot standing on its ground contacts, or why it cannot be analysed.

    `candidates`: the links that may touch the ground (a spec's mobile base; None: all).
    `declared`: the contact links, named by the user. Without either, a robot none of
    whose wheels touches the ground has a fixed base (an arm bolted down): no polygon.
    `floating`: gives the URDF's floating, non-strict `Robot` when the caller's robot file
    holds it (`robot.file.robot_of`: built once for `check` and `simulate` alike).
    """
    names = {lk.name for lk in urdf.links}
    if declared is None and candidates is not None and not names & set(candidates):
        return NoStance(FIXED_BASE)  # e.g. a spec's standalone arm: none of its base's links
    robot = floating() if floating is not None else Robot.load(urdf, floating=True, strict=False)
    if declared is not None:
        unknown = [n for n in declared if n not in names]
        if unknown:
            raise InputError(
                f"unknown contact link(s) {', '.join(unknown)}; {did_you_mean(unknown[0], names)}"
                f"links: {', '.join(sorted(names))}",
                file=urdf.source,
                field="contact_links",
            )
    ground = find_ground(urdf, robot, candidates=candidates, declared=declared, mesh=mesh)
    if ground is None or (declared is None and candidates is None and not has_wheels(ground)):
        return NoStance(FIXED_BASE)
    polygon = support_polygon(ground.points())
    if polygon is None:
        links = ", ".join(ground.links)
        return NoStance(f"the ground contacts ({links}) span no area: no support polygon")
    if payload is not None and link_frame(robot.model, payload.link) is None:
        raise InputError(
            f"unknown link {payload.link!r} for the payload; "
            f"{did_you_mean(payload.link, names)}links: {', '.join(sorted(names))}",
            field="payload_link",
        )
    return Stance(robot, ground, polygon, payload, _free_joints(robot, ground.links))


def _free_joints(robot: Robot, contacts: Collection[str]) -> tuple[Joint, ...]:
    """The 1-DoF joints that carry no contact link (those would move the polygon)."""
    model = robot.model
    carrying: set[int] = set()
    for link in contacts:
        jid = model.frames[robot.frame(link)].parentJoint
        while jid > 0:
            carrying.add(jid)
            jid = model.parents[jid]
    return tuple(j for j in robot.joints if model.getJointId(j.name) not in carrying)
