"""Mass properties MuJoCo accepts, taken from the URDF as faithfully as MuJoCo allows.

MuJoCo's compiler refuses, for any body: an inertia given as a full tensor whose
smallest eigenvalue is below mjEPS (1e-14), and principal moments that violate
A + B >= C; for a moving body (one with a joint): a mass or principal moment below
mjMINVAL (1e-15), unless a rigidly attached (static) child carries valid mass.
Robot descriptions break these rules routinely: planning-only industrial models
have no inertials at all, dummy links carry 1e-6 kg with a singular tensor,
CAD exports violate the triangle inequality.

The rules applied, bottom-up so that a body is judged with what its children gave it:
- a static body (fixed joint, or the base welded to the world) with an inertia MuJoCo
  refuses is merged into its parent, as MuJoCo's URDF import fuses static bodies
  (`fusestatic`); the rigid group's mass, centre of mass and inertia are unchanged, so the
  dynamics are exactly the URDF's; merged into the world it plays no role and is dropped;
- a moving body whose principal moments violate the triangle inequality gets the smallest
  isotropic addition that satisfies it (MuJoCo's `balanceinertia` would instead replace
  all three moments by their mean, a larger change);
- a moving body without usable mass or inertia (no inertial, zero mass, a point mass)
  keeps it on a rigidly attached child that has valid mass if there is one, else takes
  its inertia from its collision geometry as MuJoCo's URDF import does
  (`inertiafromgeom`: 1000 kg/m³ when the URDF gives no mass, else the URDF's mass spread
  over the collision geoms); a point mass without geometry becomes a 1 mm solid sphere
  (the URDF's dynamics to within that inertia); a massless one is refused;
- a clearly negative principal moment or a negative mass on a moving body is refused:
  there is no faithful repair.
Every change is a `Note` in the export report. The merging itself (`Mass`, `join`,
`moved`) is `robot.bodies`', the lumping `check` judges the bodies with.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from lxml import etree

from armcli.compiler.xmlfmt import fmt, vec
from armcli.errors import ExportRefusedError
from armcli.export.mjcf_report import Note
from armcli.robot import inertia as inr
from armcli.robot.bodies import Mass, join, link_mass, moved
from armcli.urdf.doc import Link, Vec3

MJ_MINVAL = 1e-15  # mjMINVAL: a moving body's mass and principal moments must reach it
MJ_EPS = 1e-14  # mjEPS: the smallest eigenvalue a `fullinertia` may have
NEGATIVE_RTOL = 1e-9  # a moment below -NEGATIVE_RTOL x the largest is negative, not round-off
TRIANGLE_MARGIN = 1e-9  # relative headroom left by the triangle fix (MuJoCo re-diagonalises)
DENSITY = 1000.0  # [kg/m³] MuJoCo's default geom density, used by its URDF import
POINT_RADIUS = 1e-3  # [m] a point mass without geometry becomes a solid sphere this small


@dataclass(frozen=True)
class FromGeometry:
    """MuJoCo infers the body's inertia from its collision geoms (`inertiafromgeom`)."""

    geom_mass: float | None  # [kg] per collision geom; None: MuJoCo's density


Plan = Mass | FromGeometry | None  # None: massless (allowed for static bodies)


@dataclass(frozen=True)
class Node:
    """One MJCF body as the mass rules see it, listed parents first."""

    link: str
    parent: str | None  # the body it hangs from; None: the world
    xyz: Vec3  # body origin in the parent's frame [m]
    rpy: Vec3  # body orientation in the parent's frame [rad]
    joint: str | None  # the URDF joint that attaches it
    moving: bool  # has a hinge, slide or free joint
    collisions: int  # collision geoms the export writes for it
    lost: tuple[str, ...] = ()  # collision meshes it cannot write (missing or unreadable)


def classify(x: Mass | None) -> str:
    """How MuJoCo sees it: none, negative-mass, point, negative, degenerate, triangle, ok."""
    if x is None:
        return "none"
    if x.mass < 0.0:
        return "negative-mass"
    lam = inr.principal_moments(x.J)
    if lam[2] < MJ_EPS:
        return "point"
    if lam[0] < -NEGATIVE_RTOL * lam[2]:
        return "negative"
    if lam[0] < MJ_EPS:
        return "degenerate"
    return "triangle" if inr.triangle_violation(x.J) > 0.0 else "ok"


def balanced(x: Mass) -> tuple[Mass, float]:
    """The smallest isotropic addition d [kg·m²] that makes A + B >= C, and d."""
    a, b, c = inr.principal_moments(x.J)
    d = (c - a - b) + TRIANGLE_MARGIN * c
    return Mass(x.mass, x.com, x.J + d * np.eye(3)), float(d)


def _moments(x: Mass) -> str:
    return ", ".join(f"{v:.3g}" for v in inr.principal_moments(x.J))


class _Planner:
    """Applies the module's rules to the bodies, children before parents."""

    def __init__(self, nodes: Sequence[Node], links: Mapping[str, Link], source: str) -> None:
        self.nodes, self.source = nodes, source
        self.by_link = {n.link: n for n in nodes}
        self.mass: dict[str, Mass | None] = {n.link: link_mass(links[n.link]) for n in nodes}
        self.plan: dict[str, Plan] = {}
        self.done: dict[str, list[str]] = {}  # note topic -> per-link details

    def log(self, topic: str, detail: str) -> None:
        self.done.setdefault(topic, []).append(detail)

    def run(self) -> dict[str, Plan]:
        for n in reversed(self.nodes):  # a pre-order reversed: every child before its parent
            if n.moving:
                self.moving(n)
            else:
                self.static(n)
        return self.plan

    def static(self, n: Node) -> None:
        x = self.mass[n.link]
        kind = classify(x)
        if x is None or kind in ("ok", "point"):
            self.plan[n.link] = x if kind != "point" or x is None else _point(x)
            return
        why = _why(kind, x)
        self.plan[n.link] = None
        if n.parent is None:
            self.log("welded to the world", f"{n.link} ({why}): dropped, it cannot move")
            return
        self.mass[n.parent] = join(self.mass[n.parent], moved(x, n.xyz, n.rpy))
        self.log("merged into the parent", f"{n.link} ({why}) into {n.parent}")

    def moving(self, n: Node) -> None:
        x = self.mass[n.link]
        kind = classify(x)
        if x is not None and kind == "ok":
            self.plan[n.link] = x
        elif x is not None and kind == "triangle":
            self.plan[n.link], d = balanced(x)
            self.log("triangle inequality", f"{n.link} (moments {_moments(x)}): +{d:.3g}")
        elif x is not None and kind in ("negative", "negative-mass"):
            raise ExportRefusedError(
                self.source,
                f"{_why(kind, x)}; MuJoCo refuses it and no faithful repair exists",
                link=n.link,
            )
        else:
            self.massless(n, x)

    def massless(self, n: Node, x: Mass | None) -> None:
        """A moving body without usable mass properties (none, zero, point, degenerate)."""
        path = self.static_child_with_mass(n)
        if path:
            holder = path[-1].link
            if x is not None:
                held = self.plan[holder]
                assert isinstance(held, Mass)
                for child in path:  # down the fixed joints into the holder's frame
                    x = moved(x, child.xyz, child.rpy, inverse=True)
                self.plan[holder] = join(held, x)
                self.log("merged into a rigid child", f"{n.link} into {holder}")
            self.plan[n.link] = None
            return
        if n.collisions == 0 and x is not None and x.mass >= MJ_MINVAL:
            self.plan[n.link] = Mass(x.mass, x.com, inr.sphere_inertia(x.mass, POINT_RADIUS))
            self.log("point mass", f"{n.link} ({_why(classify(x), x)})")
            return
        if n.collisions == 0:
            raise ExportRefusedError(
                self.source,
                f"moves on joint {n.joint!r} but has {_why(classify(x), x)}, no collision "
                f"geometry to take an inertia from{_lost(n)} and no rigidly attached mass; "
                "MuJoCo needs mass and inertia on every moving body: give the link an "
                "<inertial>",
                link=n.link,
            )
        each = x.mass / n.collisions if x is not None else None
        self.plan[n.link] = FromGeometry(each)
        what = f"{x.mass:.4g} kg kept" if x is not None else f"{DENSITY:g} kg/m³"
        self.log("inertia from geometry", f"{n.link} ({_why(classify(x), x)}; {what})")

    def static_child_with_mass(self, n: Node) -> list[Node]:
        """The fixed-joint path to a rigidly attached body with valid mass; [] if none.

        MuJoCo counts every body welded to a moving one, however deep: the Gen3 lite's
        0.14 kg gripper hangs off its massless wrist link through a massless frame
        (end_effector_link -> dummy_link -> gripper_base_link). Breadth first, so the
        nearest such body holds the moving link's own inertial.
        """
        children: dict[str, list[Node]] = {}
        for c in self.nodes:
            if c.parent is not None and not c.moving:
                children.setdefault(c.parent, []).append(c)
        paths = [[c] for c in children.get(n.link, [])]
        while paths:
            path = paths.pop(0)
            x = self.plan.get(path[-1].link)
            if isinstance(x, Mass) and x.mass >= MJ_MINVAL and classify(x) == "ok":
                return path  # "ok" means moments >= MJ_EPS > MJ_MINVAL
            paths += [[*path, c] for c in children.get(path[-1].link, [])]
        return []

    def notes(self) -> list[Note]:
        for details in self.done.values():
            details.reverse()  # logged children first: back to the tree's order
        return [
            Note(f"mass: {topic}", "; ".join(d), _DONE[topic]) for topic, d in self.done.items()
        ]


_DONE = {
    "welded to the world": "inertials MuJoCo refuses on bodies welded to the world are "
    "dropped (they cannot move, so the dynamics are unchanged)",
    "merged into the parent": "inertials MuJoCo refuses on fixed-joint links are merged "
    "into the parent body (same rigid group: the dynamics are the URDF's), as MuJoCo's "
    "URDF import fuses static bodies",
    "triangle inequality": "principal moments violate A + B >= C, which MuJoCo refuses; the "
    "smallest equal addition to all three was made (its balanceinertia would set all three "
    "to their mean)",
    "merged into a rigid child": "a moving link's unusable inertial was merged into a rigidly "
    "attached child (same rigid group: the dynamics are the URDF's)",
    "point mass": "MuJoCo refuses a moving point mass and the link has no collision "
    f"geometry: mass and centre of mass kept, inertia of a solid sphere of radius "
    f"{POINT_RADIUS * 1e3:g} mm (negligible next to the links it carries)",
    "inertia from geometry": "moving links need mass and inertia in MuJoCo: taken from their "
    f"collision geometry, as MuJoCo's URDF import does (inertiafromgeom; {DENSITY:g} kg/m³ "
    "where the URDF has no mass)",
}


def _lost(n: Node) -> str:
    if not n.lost:
        return ""
    return f" (collision meshes missing or not readable by MuJoCo: {', '.join(n.lost)})"


def _point(x: Mass) -> Mass:
    """A point mass written with an exactly zero tensor (MuJoCo allows it on static bodies)."""
    return Mass(x.mass, x.com, np.zeros((3, 3)))


def _why(kind: str, x: Mass | None) -> str:
    if x is None or kind == "none":
        return "no mass"
    if kind == "negative-mass":
        return f"negative mass {x.mass:.4g} kg"
    if kind == "point":
        return f"mass {x.mass:.4g} kg with no inertia"
    if kind == "negative":
        return f"a negative principal moment (moments {_moments(x)} kg·m²)"
    if kind == "degenerate":
        return f"a singular inertia (moments {_moments(x)} kg·m²)"
    return f"moments {_moments(x)} kg·m² violating A + B >= C"


def plan_masses(
    nodes: Sequence[Node], links: Mapping[str, Link], source: str
) -> tuple[dict[str, Plan], list[Note]]:
    """What each body's mass properties become in MJCF, and the notes saying what changed."""
    p = _Planner(nodes, links, source)
    plan = p.run()
    return plan, p.notes()


def write_inertial(body: etree._Element, plan: Plan, zero: bool) -> None:
    """The body's `<inertial>` (none when MuJoCo takes it from the geoms).

    A massless body gets an explicit zero one when `zero`: its collision geoms would
    otherwise lend it their mass under inertiafromgeom="auto".
    """
    if isinstance(plan, FromGeometry):
        return  # no <inertial>: MuJoCo infers it from the collision geoms
    if plan is None:
        if zero:
            etree.SubElement(body, "inertial", pos="0 0 0", mass="0", diaginertia="0 0 0")
        return
    attrs = {"pos": vec(plan.com), "mass": fmt(plan.mass)}
    J = plan.J
    if J[0, 1] == 0.0 and J[0, 2] == 0.0 and J[1, 2] == 0.0:
        attrs["diaginertia"] = vec((J[0, 0], J[1, 1], J[2, 2]))
    else:
        attrs["fullinertia"] = vec((J[0, 0], J[1, 1], J[2, 2], J[0, 1], J[0, 2], J[1, 2]))
    etree.SubElement(body, "inertial", attrs)
