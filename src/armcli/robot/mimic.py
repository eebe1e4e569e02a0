"""Mimic joints: a follower sits at multiplier * leader + offset (URDF `<mimic>`).

One implementation of the coupling for everything that poses a robot from joint values
(simulate, check's samples and poses, the collision matrix), as MoveIt's RobotState
and gazebo_ros2_control apply it: a follower is never set on its own.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from armcli.urdf.doc import Joint


@dataclass(frozen=True)
class Mimic:
    """`follower` = multiplier * `leader` + offset."""

    follower: str
    leader: str
    multiplier: float = 1.0
    offset: float = 0.0

    def position(self, leader: float) -> float:
        """The follower's position for the leader's [rad or m]."""
        return self.multiplier * leader + self.offset


def mimics(joints: Iterable[Joint]) -> list[Mimic]:
    """The mimic couplings among `joints`, leaders before their followers.

    A mimic of a joint not among `joints` (check's `mimic-target`), one on or of a joint
    that does not move (fixed, floating, planar: URDF parsers ignore it), and a cycle are
    left out.
    """
    by_name = {j.name: j for j in joints}
    pending = {
        j.name: Mimic(j.name, j.mimic, j.mimic_multiplier, j.mimic_offset)
        for j in by_name.values()
        if j.mimic is not None
        and j.movable
        and j.mimic != j.name
        and j.mimic in by_name
        and by_name[j.mimic].movable
    }
    out: list[Mimic] = []
    while True:
        ready = [m for m in pending.values() if m.leader not in pending]
        if not ready:
            return out  # what is left (if anything) is a cycle
        for m in ready:
            out.append(m)
            del pending[m.follower]


def follow(couplings: Iterable[Mimic], values: Mapping[str, float]) -> dict[str, float]:
    """`values` with every follower whose leader has a value set from it (leaders first)."""
    out = dict(values)
    for m in couplings:
        if m.leader in out:
            out[m.follower] = m.position(out[m.leader])
    return out
