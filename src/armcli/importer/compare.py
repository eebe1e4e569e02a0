"""Two URDF documents compared by meaning: what `armcli import` promises to give back.

Compared: the robot name; links (inertial to 1e-12 relative; visuals and collisions in
order: name, origin, geometry, mesh URI and scale, effective material); joints (type,
links, origin, axis, limit, dynamics, mimic, safety controller, calibration, with URDF's
defaults for what is left out); materials by name; Gazebo extensions merged by
reference (as Gazebo merges them); every other top-level element (ros2_control,
transmission, ...) as canonical XML. Element order, whitespace, comments and number
spelling do not count; numbers compare as floats, exactly outside the inertials.
"""

from __future__ import annotations

import math
import os
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from lxml import etree

INERTIAL_RTOL = 1e-12  # the tolerance: derived inertias are recomputed by xacro
TYPED_TOP = ("link", "joint", "material", "gazebo")
LINK_TAGS = ("inertial", "visual", "collision")
JOINT_TAGS = (
    "parent",
    "child",
    "origin",
    "axis",
    "limit",
    "dynamics",
    "mimic",
    "safety_controller",
    "calibration",
)


def _other(el: etree._Element, known: tuple[str, ...]) -> list[str]:
    """Canonical text of the children URDF does not define (vendor extensions), sorted."""
    return sorted(canon(c) for c in el if isinstance(c.tag, str) and c.tag not in known)


@dataclass(frozen=True)
class Difference:
    """One thing that differs: where, and the two values as text."""

    where: str
    expected: str
    got: str

    def __str__(self) -> str:
        return f"{self.where}: {self.expected} -> {self.got}"


def _floats(text: str | None, n: int, default: tuple[float, ...]) -> tuple[float, ...]:
    if text is None:
        return default
    parts = text.split()
    try:
        vals = tuple(float(p) for p in parts)
    except ValueError:
        return (math.nan,) * n
    return vals if len(vals) == n else (math.nan,) * n


def _num(el: etree._Element | None, attr: str, default: float | None) -> float | None:
    if el is None:
        return None
    raw = el.get(attr)
    if raw is None:
        return default
    try:
        return float(raw)
    except ValueError:
        return math.nan


def _pose(el: etree._Element | None) -> tuple[float, ...]:
    origin = el.find("origin") if el is not None else None
    if origin is None:
        return (0.0,) * 6
    return _floats(origin.get("xyz"), 3, (0.0,) * 3) + _floats(origin.get("rpy"), 3, (0.0,) * 3)


def _is_number(text: str) -> bool:
    try:
        return math.isfinite(float(text))
    except ValueError:
        return False


def canon(el: etree._Element) -> str:
    """Canonical text of an element: sorted attributes, stripped text, children in order.

    A leaf with only a `value` attribute reads as a leaf with that text, as Gazebo's
    URDF parser reads `<mu1 value="0.1"/>` and `<mu1>0.1</mu1>` alike.
    """
    children = [c for c in el if isinstance(c.tag, str)]
    attrs = {str(k): str(v).strip() for k, v in el.attrib.items()}
    text = (el.text or "").strip()
    if not children and not text and set(attrs) == {"value"}:
        text, attrs = attrs.pop("value"), {}
    if not children and _is_number(text):
        text = repr(float(text))  # <mu1>100.0</mu1> is <mu1>100</mu1> to every reader
    head = " ".join([str(el.tag), *(f'{k}="{v}"' for k, v in sorted(attrs.items()))])
    return f"<{head}>{text}" + "".join(canon(c) for c in children) + f"</{el.tag}>"


class _Doc:
    """The parts of a URDF the comparison looks at, with URDF's defaults filled in."""

    def __init__(self, root: etree._Element, base: Path | None) -> None:
        self.root, self.base = root, base
        self.materials = self._materials()

    def _materials(self) -> dict[str, tuple[Any, Any]]:
        out: dict[str, tuple[Any, Any]] = {}
        top = self.root.findall("material")
        inline = self.root.findall("link/visual/material")
        for m in [*top, *inline]:
            rgba, tex = self._colour(m)
            if (rgba is not None or tex is not None) and m.get("name", "") not in out:
                out[m.get("name", "")] = (rgba, tex)
        return out

    @staticmethod
    def _colour(m: etree._Element) -> tuple[Any, Any]:
        color, texture = m.find("color"), m.find("texture")
        rgba = _floats(color.get("rgba"), 4, (math.nan,) * 4) if color is not None else None
        return rgba, (texture.get("filename") if texture is not None else None)

    def mesh(self, uri: str | None) -> str | None:
        if uri is None or "://" in uri or os.path.isabs(uri) or self.base is None:
            return uri
        return os.path.normpath(self.base / uri)

    def shape(self, el: etree._Element, visual: bool) -> dict[str, Any]:
        geo = el.find("geometry")
        kinds = [c for c in geo if isinstance(c.tag, str)] if geo is not None else []
        kind = kinds[0] if kinds else None
        g: tuple[Any, ...] = ("none",)
        if kind is not None and kind.tag == "box":
            g = ("box", _floats(kind.get("size"), 3, (math.nan,) * 3))
        elif kind is not None and kind.tag in ("cylinder", "capsule"):
            g = (kind.tag, _num(kind, "radius", math.nan), _num(kind, "length", math.nan))
        elif kind is not None and kind.tag == "sphere":
            g = ("sphere", _num(kind, "radius", math.nan))
        elif kind is not None and kind.tag == "mesh":
            scale = _floats(kind.get("scale"), 3, (1.0, 1.0, 1.0))
            g = ("mesh", self.mesh(kind.get("filename")), scale)
        elif kind is not None:
            g = (str(kind.tag), canon(kind))
        out: dict[str, Any] = {"name": el.get("name"), "origin": _pose(el), "geometry": g}
        m = el.find("material")
        if visual and m is not None:
            rgba, tex = self._colour(m)
            known = self.materials.get(m.get("name", ""), (None, None))
            out["material"] = (m.get("name", ""), rgba or known[0], tex or known[1])
        return out

    def link(self, el: etree._Element) -> dict[str, Any]:
        ine = el.find("inertial")
        inertial = None
        if ine is not None:
            i = ine.find("inertia")
            keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
            tensor = tuple(_num(i, k, 0.0) for k in keys) if i is not None else None
            mass = ine.find("mass")
            inertial = (
                _num(mass, "value", math.nan) if mass is not None else None,
                _pose(ine),
                tensor,
            )
        return {
            "inertial": inertial,
            "visual": [self.shape(v, True) for v in el.findall("visual")],
            "collision": [self.shape(c, False) for c in el.findall("collision")],
            "other": _other(el, LINK_TAGS),
        }

    @staticmethod
    def joint(el: etree._Element) -> dict[str, Any]:
        jtype = el.get("type")
        parent, child = el.find("parent"), el.find("child")
        axis = None
        if jtype not in ("fixed", "floating"):
            a = el.find("axis")
            axis = _floats(a.get("xyz") if a is not None else None, 3, (1.0, 0.0, 0.0))
        lim, dyn, mim = el.find("limit"), el.find("dynamics"), el.find("mimic")
        safe, cal = el.find("safety_controller"), el.find("calibration")
        return {
            "type": jtype,
            "parent": parent.get("link") if parent is not None else None,
            "child": child.get("link") if child is not None else None,
            "origin": _pose(el),
            "axis": axis,
            "limit": None
            if lim is None
            else tuple(_num(lim, k, 0.0) for k in ("lower", "upper", "effort", "velocity")),
            "dynamics": (_num(dyn, "damping", 0.0), _num(dyn, "friction", 0.0))
            if dyn is not None
            else (0.0, 0.0),
            "mimic": None
            if mim is None
            else (mim.get("joint"), _num(mim, "multiplier", 1.0), _num(mim, "offset", 0.0)),
            "safety_controller": None
            if safe is None
            else tuple(
                _num(safe, k, 0.0)
                for k in ("soft_lower_limit", "soft_upper_limit", "k_position", "k_velocity")
            ),
            "calibration": None
            if cal is None
            else (_num(cal, "rising", None), _num(cal, "falling", None)),
            "other": _other(el, JOINT_TAGS),
        }

    def gazebo(self) -> dict[str, Counter[str]]:
        out: dict[str, Counter[str]] = {}
        for g in self.root.findall("gazebo"):
            bag = out.setdefault(g.get("reference", ""), Counter())
            bag.update(canon(c) for c in g if isinstance(c.tag, str))
        return {k: v for k, v in out.items() if v}

    def others(self) -> Counter[str]:
        return Counter(
            canon(el) for el in self.root if isinstance(el.tag, str) and el.tag not in TYPED_TOP
        )


def _close(a: Any, b: Any, rtol: float, scale: float) -> bool:
    if a is None or b is None:
        return a is b
    return abs(float(a) - float(b)) <= rtol * max(scale, abs(float(a)), abs(float(b)))


def _same_inertial(a: Any, b: Any) -> bool:
    if a is None or b is None:
        return a is b
    (ma, pa, ta), (mb, pb, tb) = a, b
    if not _close(ma, mb, INERTIAL_RTOL, 0.0) or (ta is None) != (tb is None):
        return False
    if not all(_close(x, y, INERTIAL_RTOL, 1.0) for x, y in zip(pa, pb, strict=True)):
        return False
    if ta is None:
        return True
    scale = max(abs(float(x)) for x in (*ta, *tb)) if ta else 0.0
    return all(_close(x, y, INERTIAL_RTOL, scale) for x, y in zip(ta, tb, strict=True))


def _text(v: Any) -> str:
    return "(none)" if v is None else str(v)


def _diff_dicts(where: str, a: dict[str, Any], b: dict[str, Any], out: list[Difference]) -> None:
    for key in a:
        if a[key] != b.get(key):
            out.append(Difference(f"{where} {key}", _text(a[key]), _text(b.get(key))))


def _by_name(root: etree._Element, tag: str) -> dict[str, etree._Element]:
    return {str(el.get("name")): el for el in root.findall(tag)}


def _links(a: _Doc, b: _Doc, out: list[Difference]) -> None:
    la, lb = _by_name(a.root, "link"), _by_name(b.root, "link")
    for name in la.keys() - lb.keys():
        out.append(Difference(f"link {name}", "present", "missing"))
    for name in lb.keys() - la.keys():
        out.append(Difference(f"link {name}", "missing", "present"))
    for name in [n for n in la if n in lb]:
        x, y = a.link(la[name]), b.link(lb[name])
        if not _same_inertial(x["inertial"], y["inertial"]):
            out.append(
                Difference(f"link {name} inertial", _text(x["inertial"]), _text(y["inertial"]))
            )
        for tag in ("visual", "collision"):
            if len(x[tag]) != len(y[tag]):
                out.append(Difference(f"link {name} {tag}s", str(len(x[tag])), str(len(y[tag]))))
                continue
            for i, (sx, sy) in enumerate(zip(x[tag], y[tag], strict=True)):
                _diff_dicts(f"link {name} {tag}[{i}]", sx, sy, out)
        if x["other"] != y["other"]:
            out.append(Difference(f"link {name} other", _text(x["other"]), _text(y["other"])))


def _joints(a: _Doc, b: _Doc, out: list[Difference]) -> None:
    ja, jb = _by_name(a.root, "joint"), _by_name(b.root, "joint")
    for name in ja.keys() - jb.keys():
        out.append(Difference(f"joint {name}", "present", "missing"))
    for name in jb.keys() - ja.keys():
        out.append(Difference(f"joint {name}", "missing", "present"))
    for name in [n for n in ja if n in jb]:
        _diff_dicts(f"joint {name}", a.joint(ja[name]), b.joint(jb[name]), out)


def _bags(where: str, x: Counter[str], y: Counter[str], out: list[Difference]) -> None:
    for item in sorted((x - y).elements()):
        out.append(Difference(where, item, "(missing)"))
    for item in sorted((y - x).elements()):
        out.append(Difference(where, "(missing)", item))


def compare_urdf(
    expected: etree._Element,
    got: etree._Element,
    bases: tuple[Path | None, Path | None] = (None, None),
) -> list[Difference]:
    """Every difference in meaning between two URDF `<robot>` elements; [] if equal.

    `bases` are the documents' directories, so that relative mesh paths compare as the
    files they name.
    """
    a, b = _Doc(expected, bases[0]), _Doc(got, bases[1])
    out: list[Difference] = []
    if expected.get("name") != got.get("name"):
        out.append(Difference("robot name", _text(expected.get("name")), _text(got.get("name"))))
    _links(a, b, out)
    _joints(a, b, out)
    for name in sorted(a.materials.keys() | b.materials.keys()):
        if a.materials.get(name) != b.materials.get(name):
            where = f"material {name!r}"
            out.append(
                Difference(where, _text(a.materials.get(name)), _text(b.materials.get(name)))
            )
    ga, gb = a.gazebo(), b.gazebo()
    for ref in sorted(ga.keys() | gb.keys()):
        _bags(f"gazebo {ref or '(robot)'}", ga.get(ref, Counter()), gb.get(ref, Counter()), out)
    _bags("element", a.others(), b.others(), out)
    return out


def differences(items: Iterable[Difference]) -> list[str]:
    """The differences as text lines."""
    return [str(d) for d in items]
