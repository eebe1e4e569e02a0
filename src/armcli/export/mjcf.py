"""URDF (+ the spec's control data) -> a MuJoCo MJCF model, in mujoco_menagerie style.

Bodies follow the URDF tree (a fixed joint welds a body to its parent, as in
MJCF); each body carries the URDF inertial exactly (`fullinertia` rotated into
the body frame), so MuJoCo's mass matrix equals Pinocchio's. Joints keep range,
damping and friction (`frictionloss`); URDF has no rotor inertia, so `armature`
is 0. Visual geoms (group 2, no contact) and collision geoms (group 3) come from
the primitives; meshes are copied into `meshes/` beside the model.

Actuators: a joint with spec gains gets a `position` actuator with kp = Kp,
kv = Kd and forcerange = the effort limit, i.e. the torque
`Kp (ctrl - q) - Kd v`, clipped. armcli's controller is `Kp (q_ref - q) + Kd (v_ref - v)`;
both agree with ctrl = q_ref + (Kd / Kp) v_ref, which is why the control is not
clipped to the joint range. A joint without gains but with an effort limit gets a
`motor` (ctrl = torque). The integrator is `implicitfast`, which, like `armcli
simulate`, treats damping and Kd implicitly. armcli's joint stops are hard; MuJoCo's
limits are soft constraints, made as stiff as MuJoCo allows (`solreflimit` time
constant = 2 time steps, its stability floor) and overdamped, with no rebound. MuJoCo
acts on a limit once the joint is past it, so a joint hitting its stop at speed v still
goes v dt beyond it for a step (armcli stops it on the stop).

Friction cones are `elliptic`, MuJoCo's recommendation for realistic friction: its
default pyramidal cone degenerates on a frictionless contact (mu 0: the pyramid's edges
coincide) and its solver then lets a robot held by its wheels on a mu-0 caster creep
(9 cm in 3 s, drive.wheelmotor).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from armcli.compiler.xmlfmt import fmt, to_bytes, vec
from armcli.defaults import MJCF_BASES
from armcli.errors import InputError
from armcli.export import mjcf_parts as parts
from armcli.export.mjcf_mass import FromGeometry, Node, Plan, plan_masses, write_inertial
from armcli.export.mjcf_meshes import mesh_assets
from armcli.export.mjcf_report import Extras, Note, scan, text
from armcli.robot.frames import rpy_quaternion
from armcli.spec.joint_types import position_bounds
from armcli.spec.model import RobotSpec
from armcli.urdf.doc import Joint, Link, Pose, Shape, Urdf

BASES = MJCF_BASES
FREE_JOINT = "root"
INTEGRATOR = "implicitfast"
CONE = "elliptic"  # friction cones: see the module docstring
LIMIT_STEPS = 2.0  # solreflimit time constant in time steps: MuJoCo's floor (refsafe)
# solreflimit's damping ratio and solimplimit: overdamped and nearly rigid, as armcli's stop is
# inelastic (MuJoCo's default critical damping let a joint rebound 0.03 rad off a stop hit at
# 5 rad/s). Measured against `armcli simulate` (tests/export/test_mjcf.py): a motion slamming
# into the stops 4.4e-3 -> 1.6e-3 rad, one resting on a stop 1.0e-3 rad.
LIMIT_DAMPRATIO = 2.0
LIMIT_SOLIMP = (0.95, 0.99, 0.001)
CONTACT_FRICTION = ("0.005", "0.0001")  # MuJoCo's default torsional and rolling friction
_HINGE = {"revolute": "hinge", "continuous": "hinge", "prismatic": "slide"}


@dataclass(frozen=True)
class MjcfExport:
    """The model in memory: file name -> bytes, and what the export could not carry over."""

    model: bytes
    meshes: Mapping[str, bytes]  # relative path (meshes/...) -> content
    notes: tuple[Note, ...]
    joints: tuple[str, ...]  # hinge/slide joints in qpos order (after the free joint)
    actuators: tuple[str, ...]
    keyframes: tuple[str, ...]


def _place(attrs: dict[str, str], pose: Pose) -> dict[str, str]:
    """pos/quat attributes of a URDF origin; identity parts are left out."""
    if any(pose.xyz):
        attrs["pos"] = vec(pose.xyz)
    if any(pose.rpy):
        x, y, z, w = rpy_quaternion(pose.rpy)
        attrs["quat"] = vec((w, x, y, z))  # MuJoCo's order
    return attrs


class _Builder:
    """Walks the URDF tree once, emitting bodies, assets, actuators and notes."""

    def __init__(self, urdf: Urdf, spec: RobotSpec | None, extras: Extras) -> None:
        self.urdf, self.spec, self.extras = urdf, spec, extras
        self.links = {lk.name: lk for lk in urdf.links}
        self.children: dict[str, list[Joint]] = {}
        for j in urdf.joints:
            self.children.setdefault(str(j.parent), []).append(j)
        self.rgba = {m.name: m.rgba for m in reversed(urdf.materials) if m.rgba is not None}
        self.joints: list[Joint] = []
        self.mesh_names: dict[str, str] = {}  # URI -> asset name
        self.flat: frozenset[str] = frozenset()  # mesh URIs without volume: display only
        self.notes: list[Note] = []
        self.plan: dict[str, Plan] = {}
        self.infer = False  # some body's inertia comes from its geoms (inertiafromgeom auto)

    def root_link(self) -> str:
        children = {j.child for j in self.urdf.joints}
        roots = [lk.name for lk in self.urdf.links if lk.name not in children]
        if len(roots) != 1:
            raise InputError(
                f"the URDF needs exactly one root link, found {len(roots)}: {', '.join(roots)}",
                file=self.urdf.source,
            )
        return roots[0]

    def body(self, parent: etree._Element, name: str, joint: Joint | None, free: bool) -> None:
        attrs = _place({"name": name}, joint.origin) if joint is not None else {"name": name}
        body = etree.SubElement(parent, "body", attrs)
        link = self.links[name]
        self.inertial(body, link)
        if free:
            etree.SubElement(body, "freejoint", name=FREE_JOINT)
        if joint is not None and joint.type in _HINGE:
            self.joint(body, joint)
        elif joint is not None and joint.type not in ("fixed", "floating"):
            self.notes.append(
                Note(
                    f"{joint.type} joint",
                    f"joint {joint.name!r} is {joint.type}",
                    "not representable as one MJCF joint: the body is welded to its parent",
                )
            )
        for shape in link.visuals:
            self.geom(body, shape, "visual", name)
        for shape in link.collisions:
            self.geom(body, shape, "collision", name)
        for child in self.children.get(name, []):
            self.body(body, str(child.child), child, False)

    def inertial(self, body: etree._Element, link: Link) -> None:
        collisions = self.collisions(link)
        write_inertial(body, self.plan.get(link.name), self.infer and collisions > 0)

    def collisions(self, link: Link) -> int:
        """How many collision geoms the export writes for `link`."""
        return sum(self.geom_attrs(s, True) is not None for s in link.collisions)

    def tree(self, free: bool) -> list[Node]:
        """The bodies as `_worldbody` and `body` emit them, parents first."""
        root = self.root_link()
        out: list[Node] = []
        if self.world_is_worldbody(root):
            for j in self.children.get(root, []):
                self.walk(out, str(j.child), None, j, free and j.type == "floating")
        else:
            self.walk(out, root, None, None, free)
        return out

    def walk(
        self, out: list[Node], name: str, parent: str | None, j: Joint | None, free: bool
    ) -> None:
        pose = j.origin if j is not None else Pose()
        moving = free or (j is not None and j.type in _HINGE)
        jname = j.name if j is not None else None
        link = self.links[name]
        ncol = self.collisions(link)
        lost = tuple(
            str(s.geometry.filename)
            for s in link.collisions
            if s.geometry is not None and self.geom_attrs(s, True) is None
        )
        out.append(Node(name, parent, pose.xyz, pose.rpy, jname, moving, ncol, lost))
        for child in self.children.get(name, []):
            self.walk(out, str(child.child), name, child, False)

    def world_is_worldbody(self, root: str) -> bool:
        """A massless, shapeless root link named `world` is MJCF's worldbody itself."""
        link = self.links[root]
        return root == "world" and link.inertial is None and not (link.visuals or link.collisions)

    def joint(self, body: etree._Element, j: Joint) -> None:
        attrs = {"name": j.name, "type": _HINGE[j.type], "axis": vec(j.axis or (1.0, 0.0, 0.0))}
        bounds = position_bounds(j.type, j.limit)
        if bounds is not None:
            attrs["range"] = vec(bounds)
        attrs.update(damping=fmt(j.damping), frictionloss=fmt(j.friction), armature="0")
        etree.SubElement(body, "joint", attrs)
        self.joints.append(j)

    def geom_attrs(self, shape: Shape, collision: bool) -> dict[str, str] | None:
        """Type, size and pose of the geom for `shape`; None when the export has none.

        A flat mesh has no convex hull, which MuJoCo needs for collision: display only.
        """
        g = shape.geometry
        if g is None or (g.dims is None and g.kind != "mesh"):
            return None
        if collision and g.kind == "mesh" and g.filename in self.flat:
            return None
        attrs: dict[str, str] = {}
        if g.kind == "box":
            attrs.update(type="box", size=vec(d / 2 for d in g.dims or ()))
        elif g.kind == "cylinder":
            r, length = g.dims or (0.0, 0.0)
            attrs.update(type="cylinder", size=vec((r, length / 2)))
        elif g.kind == "sphere":
            attrs.update(type="sphere", size=fmt((g.dims or (0.0,))[0]))
        elif g.kind == "mesh" and g.filename in self.mesh_names:
            attrs.update(type="mesh", mesh=self.mesh_names[g.filename])
        else:
            return None
        return _place(attrs, shape.origin)

    def geom(self, body: etree._Element, shape: Shape, cls: str, link: str) -> None:
        geo = self.geom_attrs(shape, cls == "collision")
        if geo is None:
            return
        attrs = {"class": cls, **geo}
        if cls == "visual" and shape.material in self.rgba:
            attrs["rgba"] = vec(self.rgba[shape.material] or ())
        if cls == "collision" and link in self.extras.mu1:
            attrs["friction"] = " ".join((fmt(self.extras.mu1[link]), *CONTACT_FRICTION))
        plan = self.plan.get(link)
        if cls == "collision" and isinstance(plan, FromGeometry) and plan.geom_mass is not None:
            attrs["mass"] = fmt(plan.geom_mass)
        etree.SubElement(body, "geom", attrs)


def _header(root: etree._Element, name: str, spec: RobotSpec | None, infer: bool) -> None:
    """compiler, option, defaults; `infer`: some body takes its inertia from its geoms."""
    etree.SubElement(
        root,
        "compiler",
        angle="radian",
        autolimits="true",
        inertiafromgeom="auto" if infer else "false",
    )
    opt = {"integrator": INTEGRATOR, "cone": CONE}
    if spec is not None:
        opt = {"timestep": fmt(spec.control.dt), **opt}
    etree.SubElement(root, "option", opt)
    top = etree.SubElement(etree.SubElement(root, "default"), "default", {"class": name})
    if spec is not None:  # stops as stiff as the time step allows (armcli's are hard)
        etree.SubElement(
            top,
            "joint",
            solreflimit=vec((LIMIT_STEPS * spec.control.dt, LIMIT_DAMPRATIO)),
            solimplimit=vec(LIMIT_SOLIMP),
        )
    vis = etree.SubElement(top, "default", {"class": "visual"})
    visual = {"contype": "0", "conaffinity": "0", "group": "2"}
    if infer:  # as in MuJoCo's URDF import, visual geoms weigh nothing
        visual["density"] = "0"
    etree.SubElement(vis, "geom", visual)
    col = etree.SubElement(top, "default", {"class": "collision"})
    etree.SubElement(col, "geom", group="3")


def _worldbody(world: etree._Element, b: _Builder, name: str, free: bool) -> None:
    """The root link's body; a massless, shapeless `world` root link is MJCF's worldbody."""
    root = b.root_link()
    if b.world_is_worldbody(root):
        for j in b.children.get(root, []):
            b.body(world, str(j.child), j, free and j.type == "floating")
        if free:
            b.notes.append(
                Note("free base", "the URDF is attached to a `world` link", "kept as in the URDF")
            )
    else:
        b.body(world, root, None, free)
    for body in world:
        body.set("childclass", name)


def build_mjcf(
    urdf: Urdf,
    spec: RobotSpec | None = None,
    *,
    base: str = "fixed",
    meshes: Mapping[str, Path | None] | None = None,
    header: str | None = None,
) -> MjcfExport:
    """The MJCF model of `urdf`; `spec` adds gains (actuators), dt and named poses."""
    if base not in BASES:
        raise InputError(f"unknown base {base!r}; known: {', '.join(BASES)}")
    if urdf.problems:
        p = urdf.problems[0]
        raise InputError(f"{p.where}: bad number {p.text!r}", file=urdf.source, line=p.line)
    b = _Builder(urdf, spec, scan(urdf))
    name = urdf.name or "robot"
    root = etree.Element("mujoco", model=name)
    assets = mesh_assets(urdf, meshes or {})  # first: the mesh geoms decide the masses
    b.mesh_names, b.flat = assets.names, assets.flat
    b.plan, mass_notes = plan_masses(b.tree(base == "free"), b.links, urdf.source)
    b.infer = any(isinstance(p, FromGeometry) for p in b.plan.values())
    _header(root, name, spec, b.infer)
    if len(assets.element):
        root.append(assets.element)
    _worldbody(etree.SubElement(root, "worldbody"), b, name, base == "free")
    parts.excludes(root, urdf, {str(el.get("name")) for el in root.iter("body")})
    parts.equalities(root, b.extras, {j.name for j in b.joints})
    actuators = parts.actuators(root, b.joints, spec, b.extras, b.notes)
    free = root.find(".//freejoint") is not None  # not under a `world` link: kept fixed
    keys = parts.keyframes(root, b.joints, actuators, spec, free)
    b.notes[:0] = [*mass_notes, *assets.notes, *parts.notes(urdf, b.joints, b.extras, spec)]
    if header is not None:  # the report travels with the model
        header = f"{header}\n\n{text(b.notes)}".replace("--", "- -")
    return MjcfExport(
        model=to_bytes(root, header_comment=header),
        meshes=dict(sorted(assets.files.items())),
        notes=tuple(b.notes),
        joints=tuple(j.name for j in b.joints),
        actuators=tuple(a for a, _ in actuators),
        keyframes=keys,
    )
