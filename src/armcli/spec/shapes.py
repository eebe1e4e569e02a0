"""Links: shapes (primitives and meshes), materials and mass properties.

A link is written either with the course's shorthand, one `geometry` that is visual,
collision and inertia at once, or with lists of `visual` and `collision` shapes and an
`inertial` that is derived from one of them or given explicitly. `Link.visuals()`,
`collisions()` and `mass_properties()` give every link in the general form, so code
after validation never looks at the shorthand.
"""

from __future__ import annotations

import math
import re
from typing import Annotated
from urllib.parse import urlparse

from pydantic import Field, field_validator, model_validator

from armcli.spec.passthrough import PassthroughElement
from armcli.spec.types import NonNeg, Positive, Real, Text, Unit, UrdfName, Vec3, _Model

SHAPE_REF = re.compile(r"^(visual|collision)(?:\.(\d+))?$")


class Origin(_Model):
    """A frame offset: translation `xyz` [m] and roll-pitch-yaw `rpy` [rad], as URDF's <origin>."""

    xyz: Vec3 = Field((0.0, 0.0, 0.0), description="translation [m]")
    rpy: Vec3 = Field(
        (0.0, 0.0, 0.0), description="roll, pitch, yaw [rad], applied about fixed x, y, z"
    )


class Material(_Model):
    """A named colour: `rgba` for RViz and, optionally, its Gazebo classic material name."""

    rgba: tuple[Unit, Unit, Unit, Unit] = Field(
        description="red, green, blue, alpha in [0, 1] (RViz colour)"
    )
    gazebo: str | None = Field(
        None,
        pattern=r"^[A-Za-z0-9_/]+$",
        max_length=64,
        description="Gazebo classic material name, e.g. Gazebo/Orange; none: no Gazebo colour",
    )
    texture: Text | None = Field(None, description="texture image file name (URDF <texture>)")


class InlineMaterial(_Model):
    """A material written inside one visual, as URDFs often do (any name, colour or texture)."""

    name: str = Field(
        "", max_length=128, pattern=r"^[^\x00-\x1f]*$", description="material name, may be empty"
    )
    rgba: tuple[Unit, Unit, Unit, Unit] | None = Field(
        None, description="red, green, blue, alpha in [0, 1]; none: the name refers to a colour"
    )
    texture: Text | None = Field(None, description="texture image file name (URDF <texture>)")


class Box(_Model):
    """A box with edge lengths `size` [m] along x, y and z."""

    size: tuple[Positive, Positive, Positive] = Field(description="edge lengths along x, y, z [m]")


class Cylinder(_Model):
    """A cylinder of `radius` and `length` [m], its axis along z."""

    radius: Positive = Field(description="radius [m]")
    length: Positive = Field(description="length along the z axis [m]")


class Sphere(_Model):
    """A sphere of `radius` [m]."""

    radius: Positive = Field(description="radius [m]")


class Mesh(_Model):
    """A mesh file: `package://pkg/path`, a path relative to the spec file, or an absolute path."""

    filename: Text = Field(
        description="package://NAME/path, file:///abs/path, or a path (relative: to the spec file)"
    )
    scale: Vec3 = Field((1.0, 1.0, 1.0), description="scale along x, y, z (1: metres) [-]")

    @field_validator("filename")
    @classmethod
    def _uri(cls, v: str) -> str:
        parsed = urlparse(v)
        if parsed.scheme == "package" and not (parsed.netloc or parsed.path.strip("/")):
            raise ValueError("package:// needs a package name")
        if parsed.scheme not in ("", "package", "file") and len(parsed.scheme) > 1:
            raise ValueError(f"unsupported URI scheme {parsed.scheme!r}: use package://, file://")
        return v

    @field_validator("scale")
    @classmethod
    def _nonzero(cls, v: tuple[float, float, float]) -> tuple[float, float, float]:
        if any(s == 0 for s in v):
            raise ValueError("a scale factor of 0 flattens the mesh")
        return v


class Geometry(_Model):
    """Exactly one shape, as in URDF's <geometry>."""

    box: Box | None = Field(None, description="a box")
    cylinder: Cylinder | None = Field(None, description="a cylinder")
    sphere: Sphere | None = Field(None, description="a sphere")
    mesh: Mesh | None = Field(None, description="a mesh file")

    @model_validator(mode="after")
    def _exactly_one(self) -> Geometry:
        n = sum(s is not None for s in (self.box, self.cylinder, self.sphere, self.mesh))
        if n != 1:
            raise ValueError("give exactly one of box, cylinder, sphere, mesh")
        return self

    @property
    def kind(self) -> str:
        """Which shape is given: "box", "cylinder", "sphere" or "mesh"."""
        if self.box:
            return "box"
        return "cylinder" if self.cylinder else "sphere" if self.sphere else "mesh"

    def volume(self) -> float | None:
        """Volume of a primitive [m³]; None for a mesh (the mesh library computes that)."""
        if self.box is not None:
            return math.prod(self.box.size)
        if self.cylinder is not None:
            return math.pi * self.cylinder.radius**2 * self.cylinder.length
        if self.sphere is not None:
            return 4.0 / 3.0 * math.pi * self.sphere.radius**3
        return None


class Shape(_Model):
    """One visual or collision shape: geometry, its pose in the link frame, a material."""

    name: Annotated[str, Field(max_length=128, pattern=r"^[^\x00-\x1f]*$")] | None = Field(
        None, description="shape name (URDF's name attribute); `inertial.shape` may refer to it"
    )
    geometry: Geometry = Field(description="the shape")
    origin: Origin = Field(Origin(), description="pose of the shape in the link frame")
    material: UrdfName | InlineMaterial | None = Field(
        None, description="visuals: a name from `materials`, or a material written in place"
    )


class Inertia(_Model):
    """The six values of a symmetric inertia tensor [kg·m²], about the centre of mass."""

    ixx: Real = Field(description="moment about x [kg·m²]")
    ixy: Real = Field(0.0, description="product of inertia xy [kg·m²]")
    ixz: Real = Field(0.0, description="product of inertia xz [kg·m²]")
    iyy: Real = Field(description="moment about y [kg·m²]")
    iyz: Real = Field(0.0, description="product of inertia yz [kg·m²]")
    izz: Real = Field(description="moment about z [kg·m²]")

    def values(self) -> tuple[float, float, float, float, float, float]:
        """(ixx, ixy, ixz, iyy, iyz, izz), URDF's order."""
        return (self.ixx, self.ixy, self.ixz, self.iyy, self.iyz, self.izz)


class Inertial(_Model):
    """Mass properties: derived from one of the link's shapes, or given explicitly.

    Derived: `shape` names a visual or collision shape (its `name`, or `visual.i` /
    `collision.i`, where `visual` alone is `visual.0`) and `mass` or `density` says how
    heavy it is; a primitive uses the solid-body formulas, a mesh must be closed and its
    volume, centre of mass and tensor are computed from it. Explicit: `mass`, `inertia`
    and optionally `origin` (centre of mass and the frame of the tensor).
    """

    shape: str | None = Field(
        None,
        max_length=128,
        description="the shape the mass properties come from: a name, visual.i or collision.i",
    )
    mass: NonNeg | None = Field(None, description="mass [kg]")
    density: Positive | None = Field(
        None, description="density [kg/m³], instead of a mass, for a shape"
    )
    origin: Origin | None = Field(
        None, description="explicit only: centre of mass and tensor frame in the link frame"
    )
    inertia: Inertia | None = Field(None, description="explicit only: the tensor [kg·m²]")

    @model_validator(mode="after")
    def _one_source(self) -> Inertial:
        if self.shape is not None:
            if (self.mass is None) == (self.density is None):
                raise ValueError("a shape-derived inertial needs exactly one of mass, density")
            if self.origin is not None or self.inertia is not None:
                raise ValueError("origin and inertia follow from the shape; give them or a shape")
        else:
            if self.density is not None:
                raise ValueError("density needs a shape")
            if self.mass is None or self.inertia is None:
                raise ValueError("give a shape (and mass or density), or mass and inertia")
        return self


class Contact(_Model):
    """Gazebo surface friction coefficients for a link."""

    mu1: NonNeg = Field(description="Gazebo friction coefficient along the first direction [-]")
    mu2: NonNeg = Field(description="Gazebo friction coefficient along the second direction [-]")


class Link(_Model):
    """A link: the course's one solid (`geometry`), or lists of shapes and an `inertial`.

    Shorthand: `geometry` is visual, collision and inertia at once, placed by `origin`,
    with `material` and `mass`. General form: `visual` and `collision` lists and an
    `inertial`. A link with neither is an empty frame such as `base_footprint`.
    """

    geometry: Geometry | None = Field(
        None,
        description="shorthand: the solid's shape (visual, collision and inertia)",
    )
    origin: Origin = Field(
        Origin(), description="shorthand: pose of the shape and its centre of mass"
    )
    material: UrdfName | None = Field(
        None, description="shorthand: name of an entry of `materials`"
    )
    mass: Positive | None = Field(
        None, description="shorthand: mass [kg]; the inertia tensor follows from the shape"
    )
    visual: list[Shape] = Field([], description="visual shapes, in order")
    collision: list[Shape] = Field([], description="collision shapes, in order")
    inertial: Inertial | None = Field(None, description="mass properties; none: massless frame")
    contact: Contact | None = Field(None, description="Gazebo surface friction")
    passthrough: list[PassthroughElement] = Field(
        [], description="elements inside <link> kept verbatim (non-URDF extensions)"
    )

    @model_validator(mode="after")
    def _solid(self) -> Link:
        general = bool(self.visual or self.collision or self.inertial)
        if self.geometry is not None:
            if general:
                raise ValueError("give either geometry (one solid) or visual/collision/inertial")
            if self.mass is None:
                raise ValueError("a link with geometry needs a mass")
        elif (
            self.mass is not None or self.material is not None or "origin" in self.model_fields_set
        ):
            raise ValueError("mass/material/origin given without geometry")
        for shape in self.collision:
            if shape.material is not None:
                raise ValueError("a collision shape has no material")
        if self.inertial is not None and self.inertial.shape is not None:
            self.shape(self.inertial.shape)  # raises ValueError naming the valid references
        return self

    @property
    def shorthand(self) -> bool:
        """Whether the link is written as the course's one solid."""
        return self.geometry is not None

    def visuals(self) -> list[Shape]:
        """The visual shapes (the shorthand's solid with its material)."""
        if self.geometry is not None:
            return [Shape(geometry=self.geometry, origin=self.origin, material=self.material)]
        return list(self.visual)

    def collisions(self) -> list[Shape]:
        """The collision shapes (the shorthand's solid)."""
        if self.geometry is not None:
            return [Shape(geometry=self.geometry, origin=self.origin)]
        return list(self.collision)

    def inertial_source(self) -> Inertial | None:
        """The inertial in the general form (the shorthand's: its visual solid and mass)."""
        if self.geometry is not None:
            return Inertial(shape="visual", mass=self.mass)
        return self.inertial

    def shape(self, ref: str) -> Shape:
        """The shape `ref` names: `visual.i`, `collision.i` (`.0` may be left out) or a name."""
        m = SHAPE_REF.match(ref)
        if m:
            shapes = self.visuals() if m.group(1) == "visual" else self.collisions()
            i = int(m.group(2) or 0)
            if i < len(shapes):
                return shapes[i]
        else:
            named = [s for s in (*self.visuals(), *self.collisions()) if s.name == ref]
            if named:
                return named[0]
        known = [f"visual.{i}" for i in range(len(self.visuals()))]
        known += [f"collision.{i}" for i in range(len(self.collisions()))]
        known += sorted({s.name for s in (*self.visuals(), *self.collisions()) if s.name})
        raise ValueError(f"no shape {ref!r} in this link; known: {', '.join(known) or '(none)'}")
