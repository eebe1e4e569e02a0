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
constant = 2 time steps, its stability floor).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

import numpy as np
from lxml import etree

from armcli.compiler.xmlfmt import fmt, to_bytes, vec
from armcli.errors import InputError
from armcli.export import mjcf_parts as parts
from armcli.export.mjcf_report import Extras, Note, scan, text
from armcli.spec.model import RobotSpec
from armcli.urdf.doc import Joint, Link, Pose, Shape, Urdf, position_bounds
from armcli.urdf.read import parse_root

BASES = ("fixed", "free")
MESH_SUFFIXES = (".stl", ".obj", ".msh")  # what MuJoCo loads
MESH_DIR = "meshes"
FREE_JOINT = "root"
INTEGRATOR = "implicitfast"
LIMIT_STEPS = 2.0  # solreflimit time constant in time steps: MuJoCo's floor (refsafe)
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


def quat(rpy: tuple[float, float, float]) -> tuple[float, float, float, float]:
    """(w, x, y, z) of URDF's fixed-axis roll-pitch-yaw: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    r, p, y = (0.5 * a for a in rpy)
    cr, sr, cp, sp, cy, sy = (
        math.cos(r),
        math.sin(r),
        math.cos(p),
        math.sin(p),
        math.cos(y),
        math.sin(y),
    )
    return (
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    )


def rotation(rpy: tuple[float, float, float]) -> np.ndarray:
    """The 3x3 matrix of URDF's roll-pitch-yaw (to rotate inertias into the body frame)."""
    r, p, y = rpy
    Rx = np.array([[1, 0, 0], [0, math.cos(r), -math.sin(r)], [0, math.sin(r), math.cos(r)]])
    Ry = np.array([[math.cos(p), 0, math.sin(p)], [0, 1, 0], [-math.sin(p), 0, math.cos(p)]])
    Rz = np.array([[math.cos(y), -math.sin(y), 0], [math.sin(y), math.cos(y), 0], [0, 0, 1]])
    out: np.ndarray = Rz @ Ry @ Rx
    return out


def _place(attrs: dict[str, str], pose: Pose) -> dict[str, str]:
    """pos/quat attributes of a URDF origin; identity parts are left out."""
    if any(pose.xyz):
        attrs["pos"] = vec(pose.xyz)
    if any(pose.rpy):
        attrs["quat"] = vec(quat(pose.rpy))
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
        self.meshes: dict[str, bytes] = {}
        self.notes: list[Note] = []
        self.skipped_meshes: list[str] = []

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
        ine = link.inertial
        if ine is None or ine.mass is None or ine.mass <= 0 or ine.inertia is None:
            return
        ixx, ixy, ixz, iyy, iyz, izz = ine.inertia
        inertia = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
        R = rotation(ine.origin.rpy)
        Ib = R @ inertia @ R.T if any(ine.origin.rpy) else inertia  # in the body frame
        attrs = {"pos": vec(ine.origin.xyz), "mass": fmt(ine.mass)}
        if Ib[0, 1] == 0.0 and Ib[0, 2] == 0.0 and Ib[1, 2] == 0.0:
            attrs["diaginertia"] = vec((Ib[0, 0], Ib[1, 1], Ib[2, 2]))
        else:
            full = (Ib[0, 0], Ib[1, 1], Ib[2, 2], Ib[0, 1], Ib[0, 2], Ib[1, 2])
            attrs["fullinertia"] = vec(full)
        etree.SubElement(body, "inertial", attrs)

    def joint(self, body: etree._Element, j: Joint) -> None:
        attrs = {"name": j.name, "type": _HINGE[j.type], "axis": vec(j.axis or (1.0, 0.0, 0.0))}
        bounds = position_bounds(j.type, j.limit)
        if bounds is not None:
            attrs["range"] = vec(bounds)
        attrs.update(damping=fmt(j.damping), frictionloss=fmt(j.friction), armature="0")
        etree.SubElement(body, "joint", attrs)
        self.joints.append(j)

    def geom(self, body: etree._Element, shape: Shape, cls: str, link: str) -> None:
        g = shape.geometry
        if g is None or (g.dims is None and g.kind != "mesh"):
            return
        attrs = {"class": cls}
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
            return
        _place(attrs, shape.origin)
        if cls == "visual" and shape.material in self.rgba:
            attrs["rgba"] = vec(self.rgba[shape.material] or ())
        if cls == "collision" and link in self.extras.mu1:
            attrs["friction"] = " ".join((fmt(self.extras.mu1[link]), *CONTACT_FRICTION))
        etree.SubElement(body, "geom", attrs)

    def assets(self, root: etree._Element, meshes: Mapping[str, Path | None]) -> None:
        """Mesh assets for every resolvable mesh MuJoCo can read, copied under meshes/."""
        asset = etree.SubElement(root, "asset")
        scales = {
            s.geometry.filename: s.geometry.scale
            for lk in self.urdf.links
            for s in (*lk.visuals, *lk.collisions)
            if s.geometry is not None and s.geometry.filename
        }
        for uri in sorted(meshes):
            path = meshes[uri]
            if path is None or not path.is_file() or path.suffix.lower() not in MESH_SUFFIXES:
                self.skipped_meshes.append(uri)
                continue
            stem, k = path.stem, 1
            while stem in self.mesh_names.values():
                k += 1
                stem = f"{path.stem}_{k}"
            self.mesh_names[uri] = stem
            rel = str(PurePosixPath(MESH_DIR) / f"{stem}{path.suffix.lower()}")
            self.meshes[rel] = path.read_bytes()
            attrs = {"name": stem, "file": rel}
            if scales.get(uri, (1.0, 1.0, 1.0)) != (1.0, 1.0, 1.0):
                attrs["scale"] = vec(scales[uri])
            etree.SubElement(asset, "mesh", attrs)
        if not len(asset):
            root.remove(asset)


def _header(root: etree._Element, name: str, spec: RobotSpec | None) -> None:
    etree.SubElement(root, "compiler", angle="radian", autolimits="true", inertiafromgeom="false")
    opt = {"integrator": INTEGRATOR}
    if spec is not None:
        opt = {"timestep": fmt(spec.control.dt), **opt}
    etree.SubElement(root, "option", opt)
    top = etree.SubElement(etree.SubElement(root, "default"), "default", {"class": name})
    if spec is not None:  # stops as stiff as the time step allows (armcli's are hard)
        etree.SubElement(top, "joint", solreflimit=vec((LIMIT_STEPS * spec.control.dt, 1.0)))
    vis = etree.SubElement(top, "default", {"class": "visual"})
    etree.SubElement(vis, "geom", contype="0", conaffinity="0", group="2")
    col = etree.SubElement(top, "default", {"class": "collision"})
    etree.SubElement(col, "geom", group="3")


def _worldbody(world: etree._Element, b: _Builder, name: str, free: bool) -> None:
    """The root link's body; a massless, shapeless `world` root link is MJCF's worldbody."""
    root = b.root_link()
    link = b.links[root]
    if root == "world" and link.inertial is None and not (link.visuals or link.collisions):
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
    b = _Builder(urdf, spec, scan(parse_root(urdf.text, urdf.source)))
    name = urdf.name or "robot"
    root = etree.Element("mujoco", model=name)
    _header(root, name, spec)
    b.assets(root, meshes or {})
    _worldbody(etree.SubElement(root, "worldbody"), b, name, base == "free")
    parts.excludes(root, urdf, {str(el.get("name")) for el in root.iter("body")})
    parts.equalities(root, b.extras, {j.name for j in b.joints})
    actuators = parts.actuators(root, b.joints, spec, b.extras, b.notes)
    keys = parts.keyframes(root, b.joints, actuators, spec, base == "free")
    b.notes[:0] = parts.notes(urdf, b.joints, b.extras, spec, b.skipped_meshes)
    if header is not None:  # the report travels with the model
        header = f"{header}\n\n{text(b.notes)}".replace("--", "- -")
    return MjcfExport(
        model=to_bytes(root, header_comment=header),
        meshes=dict(sorted(b.meshes.items())),
        notes=tuple(b.notes),
        joints=tuple(j.name for j in b.joints),
        actuators=tuple(a for a, _ in actuators),
        keyframes=keys,
    )
