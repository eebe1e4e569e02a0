"""URDF `<link>` -> spec link: shapes, materials, and an inertial derived where it can be.

An inertial whose tensor is exactly (to 1e-12) the solid-body formula of one of the
link's primitive shapes at that shape's pose becomes `inertial: {shape, mass}`, so the
spec says where the numbers come from; a link that is the course's one solid (one
visual and one equal collision, inertia from it) becomes the `geometry` shorthand.
Every other inertial is written explicitly.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from lxml import etree

from armcli.importer.compare import LINK_TAGS
from armcli.importer.values import Reader, nums, origin_data, xml_text
from armcli.importer.yamltext import Block, Num

DERIVED_RTOL = 1e-12  # a tensor this close to a shape's formula is that formula
_NAME = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_./-]*$")


@dataclass(frozen=True)
class Geo:
    """One `<geometry>`: a primitive's sizes [m], or a mesh's file name and scale."""

    kind: str
    dims: tuple[float, ...] = ()
    filename: str = ""
    scale: tuple[float, ...] = (1.0, 1.0, 1.0)

    def data(self) -> dict[str, Any]:
        """The spec's `geometry` mapping."""
        if self.kind == "box":
            return {"box": {"size": nums(self.dims)}}
        if self.kind == "cylinder":
            return {"cylinder": {"radius": Num(self.dims[0]), "length": Num(self.dims[1])}}
        if self.kind == "sphere":
            return {"sphere": {"radius": Num(self.dims[0])}}
        mesh: dict[str, Any] = {"filename": self.filename}
        if self.scale != (1.0, 1.0, 1.0):
            mesh["scale"] = nums(self.scale)
        return {"mesh": mesh}

    def moments(self, m: float) -> tuple[float, float, float] | None:
        """(ixx, iyy, izz) of a solid primitive of mass m, as common_properties.xacro computes."""
        if self.kind == "box":
            l_, w, h = self.dims
            return (
                (m / 12) * (w * w + h * h),
                (m / 12) * (l_ * l_ + h * h),
                (m / 12) * (l_ * l_ + w * w),
            )
        if self.kind == "cylinder":
            r, h = self.dims
            i = (m / 12) * (3 * r * r + h * h)
            return (i, i, (m / 2) * (r * r))
        if self.kind == "sphere":
            r = self.dims[0]
            i = (2 / 5) * m * r * r
            return (i, i, i)
        return None


@dataclass
class ShapeIn:
    """A `<visual>` or `<collision>` as read."""

    name: str | None
    xyz: tuple[float, ...]
    rpy: tuple[float, ...]
    geo: Geo
    material: Any = None  # a material name, an inline material mapping, or None

    def data(self) -> dict[str, Any]:
        """The spec's shape mapping."""
        out: dict[str, Any] = {}
        if self.name is not None:
            out["name"] = self.name
        out["geometry"] = self.geo.data()
        origin = origin_data(self.xyz, self.rpy)
        if origin:
            out["origin"] = origin
        if self.material is not None:
            out["material"] = self.material
        return out


@dataclass
class Materials:
    """The document's materials: which can be named entries of `materials`, which stay inline."""

    defs: dict[str, list[tuple[Any, Any]]] = field(default_factory=dict)  # name -> (rgba, tex)

    @staticmethod
    def read(root: etree._Element, reader: Reader) -> Materials:
        """Every colour and texture definition, top-level and inside visuals."""
        out = Materials()
        for m in [*root.findall("material"), *root.findall("link/visual/material")]:
            d = _definition(m, reader)
            if d != (None, None):
                out.defs.setdefault(m.get("name", ""), []).append(d)
        return out

    def named(self) -> dict[str, dict[str, Any]]:
        """Entries for the spec's `materials`: one consistent colour under a usable name."""
        out = {}
        for name, ds in self.defs.items():
            rgba, tex = ds[0]
            if _NAME.match(name) and rgba is not None and all(d == ds[0] for d in ds):
                entry: dict[str, Any] = {"rgba": nums(rgba)}
                if tex is not None:
                    entry["texture"] = tex
                out[name] = entry
        return out

    def ref(self, el: etree._Element | None, reader: Reader, named: dict[str, Any]) -> Any:
        """A visual's material: its name if named, else written in place with its colour."""
        if el is None:
            return None
        name = el.get("name", "")
        rgba, tex = _definition(el, reader)
        if name in named and (rgba, tex) in ((None, None), self.defs[name][0]):
            return name
        if (rgba, tex) == (None, None) and self.defs.get(name):
            rgba, tex = self.defs[name][0]  # a reference to a top-level definition
        inline: dict[str, Any] = {"name": name}
        if rgba is not None:
            inline["rgba"] = nums(rgba)
        if tex is not None:
            inline["texture"] = tex
        return inline


def _definition(m: etree._Element, reader: Reader) -> tuple[Any, Any]:
    color, texture = m.find("color"), m.find("texture")
    rgba = reader.floats(color, "rgba", 4) if color is not None else None
    return rgba, (texture.get("filename") if texture is not None else None)


def _geometry(el: etree._Element, reader: Reader) -> Geo | str:
    """The shape's geometry, or why it cannot be a spec shape."""
    geo = el.find("geometry")
    kinds = [c for c in geo if isinstance(c.tag, str)] if geo is not None else []
    if len(kinds) != 1:
        return "no single geometry"
    g = kinds[0]
    try:
        if g.tag == "box":
            dims = reader.floats(g, "size", 3)
        elif g.tag == "cylinder":
            dims = (reader.one(g, "radius"), reader.one(g, "length"))  # type: ignore[assignment]
        elif g.tag == "sphere":
            dims = (reader.one(g, "radius"),)  # type: ignore[assignment]
        elif g.tag == "mesh" and g.get("filename"):
            scale = reader.floats(g, "scale", 3, (1.0, 1.0, 1.0))
            if scale is None or 0.0 in scale:
                return "mesh scale with a zero factor"
            return Geo("mesh", filename=str(g.get("filename")), scale=scale)
        else:
            return f"<{g.tag}> geometry"
    except Exception as exc:
        return str(exc)
    if dims is None or any(d is None or d <= 0 for d in dims):
        return f"<{g.tag}> with a size that is missing or not positive"
    return Geo(str(g.tag), tuple(float(d) for d in dims if d is not None))


@dataclass(frozen=True)
class InertialIn:
    """An `<inertial>` as read: mass [kg], pose, tensor (ixx ixy ixz iyy iyz izz) [kg·m²]."""

    mass: float
    xyz: tuple[float, ...]
    rpy: tuple[float, ...]
    tensor: tuple[float, ...]

    def data(self) -> dict[str, Any]:
        """The explicit `inertial` mapping (zero products of inertia left out)."""
        out: dict[str, Any] = {"mass": Num(self.mass)}
        origin = origin_data(self.xyz, self.rpy)
        if origin:
            out["origin"] = origin
        keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
        out["inertia"] = {
            k: Num(v) for k, v in zip(keys, self.tensor, strict=True) if v != 0 or k[1] == k[2]
        }
        return out

    def derived_from(self, shape: ShapeIn) -> bool:
        """Whether this is the solid-body inertial of `shape` (same pose, formula tensor)."""
        moments = shape.geo.moments(self.mass)
        if moments is None or self.mass <= 0:
            return False
        if (shape.xyz, shape.rpy) != (self.xyz, self.rpy):
            return False
        ixx, ixy, ixz, iyy, iyz, izz = self.tensor
        scale = max(moments)
        close = all(
            abs(a - b) <= DERIVED_RTOL * scale
            for a, b in zip((ixx, iyy, izz), moments, strict=True)
        )
        return close and all(abs(p) <= DERIVED_RTOL * scale for p in (ixy, ixz, iyz))


def _inertial(el: etree._Element | None, reader: Reader) -> InertialIn | None:
    if el is None:
        return None
    mass_el, tensor_el = el.find("mass"), el.find("inertia")
    mass = reader.one(mass_el, "value", 0.0) if mass_el is not None else 0.0
    keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
    tensor = tuple(
        (reader.one(tensor_el, k, 0.0) if tensor_el is not None else 0.0) or 0.0 for k in keys
    )
    xyz, rpy = reader.pose(el)
    return InertialIn(float(mass or 0.0), xyz, rpy, tensor)


@dataclass
class LinkIn:
    """One link as read, and what the import could not keep."""

    name: str
    visuals: list[ShapeIn]
    collisions: list[ShapeIn]
    inertial: InertialIn | None
    notes: list[str]
    extra: list[etree._Element] = field(default_factory=list)  # non-URDF children, verbatim

    def first_material(self) -> str | None:
        """The name of the first visual's material when it is a named one (its Gazebo colour)."""
        for v in self.visuals:
            if isinstance(v.material, str):
                return v.material
        return None

    def data(self) -> dict[str, Any]:
        """The spec link: the shorthand when the link is the course's one solid."""
        out: dict[str, Any] = self._shorthand() or {}
        if out:
            return self._with_extra(out)
        if self.visuals:
            out["visual"] = [s.data() for s in self.visuals]
        if self.collisions:
            out["collision"] = [s.data() for s in self.collisions]
        if self.inertial is not None:
            out["inertial"] = self._inertial_data(self.inertial)
        return self._with_extra(out)

    def _with_extra(self, out: dict[str, Any]) -> dict[str, Any]:
        if self.extra:
            out["passthrough"] = [Block(xml_text(el)) for el in self.extra]
        return out

    def _inertial_data(self, ine: InertialIn) -> dict[str, Any]:
        refs: list[tuple[str, ShapeIn]] = [
            *((f"collision.{i}" if i else "collision", s) for i, s in enumerate(self.collisions)),
            *((f"visual.{i}" if i else "visual", s) for i, s in enumerate(self.visuals)),
        ]
        for ref, shape in refs:
            if ine.derived_from(shape):
                return {"shape": ref, "mass": Num(ine.mass)}
        return ine.data()

    def _shorthand(self) -> dict[str, Any] | None:
        if len(self.visuals) != 1 or len(self.collisions) != 1 or self.inertial is None:
            return None
        v, c = self.visuals[0], self.collisions[0]
        same = (v.geo, v.xyz, v.rpy) == (c.geo, c.xyz, c.rpy) and v.geo.kind != "mesh"
        if not same or v.name or c.name or not isinstance(v.material, str | None):
            return None
        if not self.inertial.derived_from(v):
            return None
        out: dict[str, Any] = {"geometry": v.geo.data()}
        origin = origin_data(v.xyz, v.rpy)
        if origin:
            out["origin"] = origin
        if v.material is not None:
            out["material"] = v.material
        out["mass"] = Num(self.inertial.mass)
        return out


def read_link(
    el: etree._Element,
    reader: Reader,
    material: Callable[[etree._Element | None], Any],
) -> LinkIn:
    """The link `el` as a LinkIn; shapes the spec cannot hold are left out with a note."""
    name = str(el.get("name"))
    notes: list[str] = []
    shapes: dict[str, list[ShapeIn]] = {"visual": [], "collision": []}
    for tag in ("visual", "collision"):
        for i, s in enumerate(el.findall(tag)):
            geo = _geometry(s, reader)
            if isinstance(geo, str):
                notes.append(f"link {name} {tag}[{i}]: left out ({geo})")
                continue
            xyz, rpy = reader.pose(s)
            mat = material(s.find("material")) if tag == "visual" else None
            shapes[tag].append(ShapeIn(s.get("name"), xyz, rpy, geo, mat))
    extra = [c for c in el if isinstance(c.tag, str) and c.tag not in LINK_TAGS]
    inertial = _inertial(el.find("inertial"), reader)
    return LinkIn(name, shapes["visual"], shapes["collision"], inertial, notes, extra)
