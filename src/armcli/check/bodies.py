"""Rules on the rigid bodies the joints move, lumped as simulators lump them.

A body is a movable joint's child link plus everything fixed to it (`robot.bodies`, as
Pinocchio, MuJoCo's fusestatic and Gazebo's fixed-joint reduction lump them).

A zero-mass frame link fixed to a heavy link is fine; what breaks the mass
matrix is a moving *body* with no mass or a singular inertia (a lone point
mass). This is also the condition MuJoCo's compiler enforces ("mass and inertia
of moving bodies must be larger than mjMINVAL"), which the corpus test uses as
an oracle.
"""

from __future__ import annotations

from collections.abc import Sequence

from armcli.check.findings import Collector
from armcli.check.inertia import MIN_MOMENT
from armcli.check.structure import finite
from armcli.robot import inertia as inr
from armcli.robot.bodies import Body, lump
from armcli.urdf.doc import Link, Urdf
from armcli.urdf.tree import KinematicTree

# A moving body lighter than this fraction of the robot makes the dynamics stiff.
TINY_MASS_RATIO = 1e-4
# A link-level finding of these rules already names the problem of the body it belongs to
# (negative mass is not reported again as "the body has no mass").
LINK_ERRORS = ("mass-nonpositive", "inertia-not-pd", "inertia-triangle")


def _massless_consequences(urdf: Urdf, links: Sequence[str]) -> str:
    """What simulators make of a massless moving body, as measured with each.

    MuJoCo's URDF import gives a body whose links have no <inertial> at all a mass from
    its collision geometry (density 1000 kg/m³) and loads it; with an explicit zero mass,
    or nothing to take a mass from, it refuses ("mass and inertia of moving bodies must be
    larger than mjMINVAL").
    """
    found = [urdf.link(n) for n in links]
    parts = [lk for lk in found if lk is not None]
    no_inertial = all(lk.inertial is None for lk in parts)
    if no_inertial and any(lk.collisions for lk in parts):
        return (
            "no <inertial>; MuJoCo's URDF import loads it with a mass made up from its "
            "collision geometry at 1000 kg/m³, Gazebo drops or destabilises it"
        )
    return "MuJoCo refuses it (a moving body needs mass), Gazebo drops or destabilises it"


def moving_bodies(urdf: Urdf, tree: KinematicTree) -> list[Body]:
    """One lumped body (`robot.bodies`) per movable joint whose child link exists, in order."""
    links: dict[str, Link] = {}
    for lk in urdf.links:
        links.setdefault(lk.name, lk)  # a duplicate name is reported; the first one counts
    return [
        lump(links, j, tree.parent_joint.values())
        for j in urdf.joints
        if j.type != "fixed" and j.child in links and tree.parent_joint.get(str(j.child)) is j
    ]


def check(urdf: Urdf, tree: KinematicTree, out: Collector) -> None:
    """Rules on moving bodies: no mass, a singular inertia, or a tiny share of the robot mass.

    Bodies with unusable numbers are skipped: the number rules already reported them.
    """
    total = _robot_mass(urdf)
    lines = {lk.name: lk.line for lk in urdf.links}
    for b in moving_bodies(urdf, tree):
        if b.unknown or any(out.has(LINK_ERRORS, link=name) for name in b.links):
            continue  # one finding per problem: the link's own finding explains the body
        where = f"the body moved by {b.joint!r} ({', '.join(b.links)})"
        if b.mass <= 0.0:
            out.add(
                "mass-nonpositive",
                lines.get(b.link),
                f"{where} has no mass: {_massless_consequences(urdf, b.links)}",
                joint=b.joint,
                link=b.link,
                mass=b.mass,
            )
            continue
        moments = inr.principal_moments(b.inertia)
        if moments[0] <= MIN_MOMENT:
            out.add(
                "inertia-not-pd",
                lines.get(b.link),
                f"{where} has a singular inertia, principal moments "
                f"{[float(f'{x:.4g}') for x in moments]} (e.g. a lone point mass)",
                joint=b.joint,
                link=b.link,
                principal=[float(x) for x in moments],
            )
        if total > 0 and b.mass < TINY_MASS_RATIO * total:
            out.add(
                "tiny-mass",
                lines.get(b.link),
                f"{where}: mass {b.mass:.3g} kg is "
                f"{b.mass / total:.1e} of the robot's {total:.4g} kg",
                joint=b.joint,
                link=b.link,
                mass=b.mass,
                robot_mass=total,
            )


def _robot_mass(urdf: Urdf) -> float:
    total = 0.0
    for lk in urdf.links:
        m = lk.inertial.mass if lk.inertial is not None else None
        if m is not None and finite(m) and m > 0:
            total += m
    return total
