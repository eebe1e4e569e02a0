"""URDF `<joint>` -> spec joint, with URDF's defaults written out where the spec's differ."""

from __future__ import annotations

from typing import Any

from lxml import etree

from armcli.importer.compare import JOINT_TAGS
from armcli.importer.values import Reader, nums, origin_data, xml_text
from armcli.importer.yamltext import Block, Num
from armcli.spec.joint_types import AXIS_TYPES, LIMITED_TYPES


def _limit(el: etree._Element, jtype: str, reader: Reader) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key in ("lower", "upper"):
        v = reader.one(el, key)
        if v is not None or jtype in LIMITED_TYPES:  # URDF reads a missing bound as 0
            out[key] = Num(v or 0.0)
    for key in ("effort", "velocity"):
        out[key] = Num(reader.one(el, key, 0.0) or 0.0)
    acceleration = reader.one(el, "acceleration")  # URDF 1.2, optional
    if acceleration is not None:
        out["acceleration"] = Num(acceleration)
    return out


def _optional(el: etree._Element, reader: Reader, keys: dict[str, float | None]) -> dict[str, Any]:
    """Attributes that differ from the spec's defaults (`None`: no default, always written)."""
    out: dict[str, Any] = {}
    for key, default in keys.items():
        v = reader.one(el, key)
        if v is not None and v != default:
            out[key] = Num(v)
        elif v is None and default is None and key == "k_velocity":
            out[key] = Num(0.0)  # required by URDF; a file without it reads as 0
    return out


def read_joint(el: etree._Element, reader: Reader, notes: list[str]) -> tuple[str, dict[str, Any]]:
    """(name, spec joint mapping) of `el`; what the spec cannot hold goes to `notes`."""
    name = str(el.get("name"))
    jtype = str(el.get("type"))
    parent, child = el.find("parent"), el.find("child")
    out: dict[str, Any] = {
        "type": jtype,
        "parent": parent.get("link") if parent is not None else None,
        "child": child.get("link") if child is not None else None,
    }
    origin = origin_data(*reader.pose(el))
    if origin:
        out["origin"] = origin
    if jtype in AXIS_TYPES:
        axis_el = el.find("axis")
        axis = reader.floats(axis_el, "xyz", 3, (1.0, 0.0, 0.0)) if axis_el is not None else None
        out["axis"] = nums(axis or (1.0, 0.0, 0.0))  # URDF's default axis is x, the spec's z
    if (lim := el.find("limit")) is not None:
        out["limit"] = _limit(lim, jtype, reader)
    if (dyn := el.find("dynamics")) is not None:
        out["dynamics"] = {
            "friction": Num(reader.one(dyn, "friction", 0.0) or 0.0),
            "damping": Num(reader.one(dyn, "damping", 0.0) or 0.0),
        }
    if (mim := el.find("mimic")) is not None:
        out["mimic"] = {"joint": mim.get("joint")}
        out["mimic"].update(_optional(mim, reader, {"multiplier": 1.0, "offset": 0.0}))
    if (safe := el.find("safety_controller")) is not None:
        keys = {"soft_lower_limit": 0.0, "soft_upper_limit": 0.0, "k_position": 0.0}
        out["safety_controller"] = _optional(safe, reader, {**keys, "k_velocity": None})
    if (cal := el.find("calibration")) is not None:
        out["calibration"] = _optional(cal, reader, {"rising": None, "falling": None})
    extra = [c for c in el if isinstance(c.tag, str) and c.tag not in JOINT_TAGS]
    if extra:
        out["passthrough"] = [Block(xml_text(c)) for c in extra]
    return name, out
