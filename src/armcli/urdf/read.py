"""Strict, safe URDF reading with lxml: a small typed view with line numbers.

URDF files come from anywhere (CI runs `check` on descriptions nobody on the
team wrote), so the reader refuses DOCTYPE/entity declarations, caps size and
nesting depth, and never touches the network. Malformed numbers do not raise:
they are recorded as `NumberProblem`s with their line so that `check` can
report every one of them instead of stopping at the first.
"""

from __future__ import annotations

import math
from pathlib import Path

from lxml import etree

from armcli.defaults import MAX_ROBOT_DOF, MAX_ROBOT_LINKS
from armcli.errors import InputError, XacroRefusedError
from armcli.io.oneline import one_line
from armcli.io.userfile import read_regular
from armcli.io.xml import parse_xml
from armcli.spec.joint_types import total_dof
from armcli.spec.xacro_names import xacro_use
from armcli.urdf import extensions as ext
from armcli.urdf.doc import (
    ZERO3,
    Geometry,
    Inertial,
    Joint,
    Limit,
    Link,
    Material,
    NumberProblem,
    Pose,
    Shape,
    Urdf,
)

MAX_URDF_BYTES = 10_000_000
MAX_URDF_DEPTH = 32
# Bounds on time and memory, measured on a chain robot: yourdfpy's render takes ~5 s at
# 256 links and ~20 s at 500; Pinocchio's Data grows ~cubically with the DoF (19 MB at
# 63, 136 MB at 127, 24 GB RSS for `check` at 1000). The largest robot in
# example-robot-data has 130 links and 101 DoF (tiago_dual).
MAX_URDF_LINKS = MAX_ROBOT_LINKS
MAX_URDF_DOF = MAX_ROBOT_DOF
MAX_URDF_COLLISIONS = 1000  # example-robot-data: at most 113 per robot


def _ln(el: etree._Element) -> int | None:
    """The element's 1-based source line (lxml's stubs type it loosely)."""
    line = el.sourceline
    return line if isinstance(line, int) else None


class _Numbers:
    """Parses numeric attributes, collecting problems instead of raising."""

    def __init__(self) -> None:
        self.problems: list[NumberProblem] = []

    def vec(
        self,
        el: etree._Element | None,
        attr: str,
        n: int,
        where: str,
        default: tuple[float, ...] | None = None,
    ) -> tuple[float, ...] | None:
        text = el.get(attr) if el is not None else None
        line = _ln(el) if el is not None else None
        if text is None:
            if default is None:
                self.problems.append(NumberProblem("missing", f"{where}@{attr}", "", line))
            return default
        try:
            values = tuple(float(t) for t in text.split())
        except ValueError:
            self.problems.append(NumberProblem("not-a-number", f"{where}@{attr}", text, line))
            return None
        if len(values) != n:
            self.problems.append(NumberProblem("length", f"{where}@{attr}", text, line))
            return None
        if not all(math.isfinite(v) for v in values):
            self.problems.append(NumberProblem("non-finite", f"{where}@{attr}", text, line))
        return values

    def one(
        self, el: etree._Element | None, attr: str, where: str, default: float | None = None
    ) -> float | None:
        v = self.vec(el, attr, 1, where, None if default is None else (default,))
        return None if v is None else v[0]

    def pose(self, el: etree._Element | None, where: str) -> Pose:
        if el is None:
            return Pose()
        xyz = self.vec(el, "xyz", 3, f"{where}origin", ZERO3) or ZERO3
        rpy = self.vec(el, "rpy", 3, f"{where}origin", ZERO3) or ZERO3
        return Pose(xyz=xyz, rpy=rpy, line=_ln(el))  # type: ignore[arg-type]


_DIMS = {
    "box": (("size", 3),),
    "cylinder": (("radius", 1), ("length", 1)),
    "sphere": (("radius", 1),),
}


def _geometry(num: _Numbers, el: etree._Element | None, where: str) -> Geometry | None:
    if el is None:
        return None
    shape = next((c for c in el if isinstance(c.tag, str)), None)
    if shape is None:
        return Geometry(kind="", dims=None, line=_ln(el))
    kind = str(shape.tag)
    if kind == "mesh":
        scale = num.vec(shape, "scale", 3, f"{where}mesh", (1.0, 1.0, 1.0)) or (1.0, 1.0, 1.0)
        return Geometry("mesh", None, _ln(shape), shape.get("filename"), scale)  # type: ignore[arg-type]
    if kind not in _DIMS:
        return Geometry(kind=kind, dims=None, line=_ln(shape))
    dims: list[float] = []
    for attr, n in _DIMS[kind]:
        v = num.vec(shape, attr, n, f"{where}{kind}")
        if v is None:
            return Geometry(kind=kind, dims=None, line=_ln(shape))
        dims.extend(v)
    return Geometry(kind=kind, dims=tuple(dims), line=_ln(shape))


def _shapes(num: _Numbers, link: etree._Element, tag: str, where: str) -> tuple[Shape, ...]:
    out = []
    for el in link.findall(tag):
        mat = el.find("material")
        out.append(
            Shape(
                origin=num.pose(el.find("origin"), f"{where}{tag}/"),
                geometry=_geometry(num, el.find("geometry"), f"{where}{tag}/"),
                line=_ln(el),
                material=mat.get("name") if mat is not None else None,
            )
        )
    return tuple(out)


def _inertial(num: _Numbers, el: etree._Element | None, where: str) -> Inertial | None:
    if el is None:
        return None
    mass_el, inertia_el = el.find("mass"), el.find("inertia")
    mass = num.one(mass_el, "value", f"{where}inertial/mass")
    inertia = None
    if inertia_el is not None:
        values = [
            num.one(inertia_el, a, f"{where}inertial/inertia")
            for a in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
        ]
        if all(v is not None for v in values):
            inertia = tuple(values)
    else:
        num.problems.append(NumberProblem("missing", f"{where}inertial/inertia", "", _ln(el)))
    return Inertial(
        origin=num.pose(el.find("origin"), f"{where}inertial/"),
        mass=mass,
        inertia=inertia,  # type: ignore[arg-type]
        line=_ln(el),
        mass_line=_ln(mass_el) if mass_el is not None else _ln(el),
        inertia_line=_ln(inertia_el) if inertia_el is not None else _ln(el),
    )


def _link(num: _Numbers, el: etree._Element) -> Link:
    name = el.get("name", "")
    where = f"link {name}: "
    return Link(
        name=name,
        line=_ln(el),
        inertial=_inertial(num, el.find("inertial"), where),
        visuals=_shapes(num, el, "visual", where),
        collisions=_shapes(num, el, "collision", where),
    )


def _joint(num: _Numbers, el: etree._Element) -> Joint:
    name = el.get("name", "")
    where = f"joint {name}: "
    jtype = el.get("type", "")
    axis_el, limit_el, dyn_el, mimic_el = (
        el.find(t) for t in ("axis", "limit", "dynamics", "mimic")
    )
    axis = (
        num.vec(axis_el, "xyz", 3, f"{where}axis", (1.0, 0.0, 0.0))
        if axis_el is not None
        else (1.0, 0.0, 0.0)
    )
    limit = None
    if limit_el is not None:
        limit = Limit(
            lower=num.one(limit_el, "lower", f"{where}limit", 0.0),
            upper=num.one(limit_el, "upper", f"{where}limit", 0.0),
            effort=_optional(num, limit_el, "effort", where),
            velocity=_optional(num, limit_el, "velocity", where),
            line=_ln(limit_el),
            missing_bounds=tuple(a for a in ("lower", "upper") if limit_el.get(a) is None),
            acceleration=_optional(num, limit_el, "acceleration", where),
        )
    parent, child = el.find("parent"), el.find("child")
    return Joint(
        name=name,
        type=jtype,
        line=_ln(el),
        parent=parent.get("link") if parent is not None else None,
        child=child.get("link") if child is not None else None,
        origin=num.pose(el.find("origin"), f"{where}"),
        axis=axis,  # type: ignore[arg-type]
        axis_line=_ln(axis_el) if axis_el is not None else _ln(el),
        limit=limit,
        damping=num.one(dyn_el, "damping", f"{where}dynamics", 0.0) or 0.0,
        friction=num.one(dyn_el, "friction", f"{where}dynamics", 0.0) or 0.0,
        mimic=mimic_el.get("joint") if mimic_el is not None else None,
        mimic_line=_ln(mimic_el) if mimic_el is not None else None,
        mimic_multiplier=_or(num.one(mimic_el, "multiplier", f"{where}mimic", 1.0), 1.0),
        mimic_offset=_or(num.one(mimic_el, "offset", f"{where}mimic", 0.0), 0.0),
    )


def _or(value: float | None, default: float) -> float:
    return default if value is None else value


def _optional(num: _Numbers, el: etree._Element, attr: str, where: str) -> float | None:
    """A limit attribute whose absence is a rule finding (full limits), not a parse problem."""
    return num.one(el, attr, f"{where}limit") if el.get(attr) is not None else None


def _materials(num: _Numbers, root: etree._Element) -> tuple[Material, ...]:
    out = []
    for el in root.iter("material"):
        name = el.get("name", "")
        color = el.find("color")
        rgba = num.vec(color, "rgba", 4, f"material {name}: color") if color is not None else None
        texture = el.find("texture")
        tex = texture.get("filename") if texture is not None else None
        out.append(Material(name, rgba, _ln(el), el.getparent() is root, tex))
    return tuple(out)


def parse_root(data: bytes, source: str) -> etree._Element:
    """Parse XML bytes safely and return the <robot> element (InputError otherwise)."""
    if len(data) > MAX_URDF_BYTES:
        raise InputError(f"file is larger than {MAX_URDF_BYTES} bytes", file=source)
    root = parse_xml(data, source, max_depth=MAX_URDF_DEPTH, kind="URDF")
    if root.tag != "robot":
        raise InputError(
            f"not a URDF: root element is <{root.tag}>, expected <robot>",
            file=source,
            line=_ln(root),
        )
    # by namespace URI *and* the literal `xacro` prefix, elements and attributes: xacro acts
    # on `<xacro:include>` whatever URI the prefix is bound to (issue 27)
    if xacro_use(root) is not None:
        raise XacroRefusedError(
            "this file uses xacro elements; expanding xacro runs code from the file, "
            "so pass --trust-xacro to expand it (in a sandbox)",
            file=source,
        )
    _check_size(root, source)
    _check_names(root, source)
    return root


NAME_ATTRIBUTES = ("name", "link", "joint", "reference")  # names and references to them


def _check_names(root: etree._Element, source: str) -> None:
    """Refuse names holding line breaks or control characters (issue 27).

    Names are printed by every command (tree, check, simulate, view); a robot named
    `r&#10;::add-mask::X` printed a GitHub workflow command line of its own, and a C1
    character (U+009B) is a terminal control sequence.
    """
    for el in root.iter():
        for attr in NAME_ATTRIBUTES:
            value = el.get(attr)
            if value is not None and one_line(value) != value:
                raise InputError(
                    f"<{el.tag}> {attr}={one_line(value)!r} holds line breaks or control "
                    "characters; names must be printable",
                    file=source,
                    line=_ln(el),
                )


def _check_size(root: etree._Element, source: str) -> None:
    links = root.findall("link")
    if len(links) > MAX_URDF_LINKS:
        raise InputError(
            f"more than {MAX_URDF_LINKS} links ({len(links)}); armcli's bound on robot size",
            file=source,
            line=_ln(links[MAX_URDF_LINKS]),
        )
    shapes = root.findall("link/collision")
    if len(shapes) > MAX_URDF_COLLISIONS:  # pairs grow with the square: 10000 shapes hung check
        raise InputError(
            f"more than {MAX_URDF_COLLISIONS} collision shapes ({len(shapes)}); "
            "armcli's bound on robot size",
            file=source,
            line=_ln(shapes[MAX_URDF_COLLISIONS]),
        )
    dof = total_dof(str(j.get("type")) for j in root.findall("joint"))
    if dof > MAX_URDF_DOF:
        raise InputError(
            f"more than {MAX_URDF_DOF} degrees of freedom ({dof}); armcli's bound on robot size",
            file=source,
        )


def parse_urdf(data: bytes, source: str) -> Urdf:
    """The typed view of URDF bytes; raises InputError when the input is unusable."""
    root = parse_root(data, source)
    num = _Numbers()
    links = tuple(_link(num, el) for el in root.findall("link"))
    joints = tuple(_joint(num, el) for el in root.findall("joint"))
    materials = _materials(num, root)
    return Urdf(
        root.get("name", ""),
        source,
        data,
        links,
        joints,
        materials,
        tuple(num.problems),
        _ln(root),
        gazebo=ext.gazebo(root),
        sensors=ext.sensors(root),
        ros2_control=ext.ros2_control(root),
        transmissions=ext.transmissions(root),
        plugins=ext.plugins(root),
    )


def read_urdf(path: str | Path) -> Urdf:
    """Read and parse a URDF file with the size cap applied before reading it all."""
    p = Path(path)
    data = read_regular(p, max_bytes=MAX_URDF_BYTES, what="URDF file")
    return parse_urdf(data, str(p))
