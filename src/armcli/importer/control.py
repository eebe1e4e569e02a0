"""A URDF's `<ros2_control>` block -> the spec's typed `ros2_control`, when exact.

Typed when it is one block of joints with command/state interfaces and parameters
(hardware plugin, min/max/initial_value, other params as text) and writing it back
gives the same block; anything else (sensors, GPIOs, several blocks) stays verbatim.
"""

from __future__ import annotations

import math
from typing import Any

from lxml import etree
from pydantic import ValidationError

from armcli.compiler.ros2_control import STANDARD_PARAMS, ros2_control_element
from armcli.importer.compare import canon
from armcli.importer.yamltext import Num
from armcli.spec.model import Ros2Control


def _params(el: etree._Element, typed: bool) -> tuple[dict[str, Any], dict[str, str]] | None:
    """(standard numeric params, other params) of an element's `<param>` children."""
    std: dict[str, Any] = {}
    other: dict[str, str] = {}
    for p in el:
        if not isinstance(p.tag, str):
            continue
        if p.tag != "param" or set(p.attrib) != {"name"} or len(p):
            return None
        name, text = str(p.get("name")), (p.text or "").strip()
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if typed and name in STANDARD_PARAMS and math.isfinite(value):
            std[name] = Num(value)
        else:
            other[name] = text
    return std, other


def _joint(el: etree._Element) -> dict[str, Any] | None:
    out: dict[str, Any] = {"command_interfaces": {}, "state_interfaces": {}, "params": {}}
    for child in el:
        if not isinstance(child.tag, str):
            continue
        if child.tag in ("command_interface", "state_interface"):
            got = _params(child, typed=True)
            if got is None or set(child.attrib) != {"name"}:
                return None
            iface: dict[str, Any] = dict(got[0])
            if got[1]:
                iface["params"] = got[1]
            out[f"{child.tag}s"][str(child.get("name"))] = iface
        elif child.tag == "param" and set(child.attrib) == {"name"}:
            out["params"][str(child.get("name"))] = (child.text or "").strip()
        else:
            return None
    return {k: v for k, v in out.items() if v}


def read_ros2_control(el: etree._Element, robot: str, movable: set[str]) -> dict[str, Any] | None:
    """The spec data of a `<ros2_control>` block, or None when it cannot be typed exactly."""
    hw = el.find("hardware")
    if hw is None or set(el.attrib) - {"name", "type"}:
        return None
    plugin = hw.find("plugin")
    got = _params(_without(hw, plugin), typed=False)
    if plugin is None or got is None:
        return None
    data: dict[str, Any] = {"name": el.get("name", ""), "type": el.get("type", "system")}
    data["hardware"] = {"plugin": (plugin.text or "").strip(), "params": got[1]}
    joints: dict[str, Any] = {}
    for child in el:
        if not isinstance(child.tag, str) or child is hw:
            continue
        if child.tag != "joint" or child.get("name") not in movable:
            return None
        joint = _joint(child)
        if joint is None:
            return None
        joints[str(child.get("name"))] = joint
    data["joints"] = joints
    try:
        model = Ros2Control.model_validate(plain(data))
    except ValidationError:
        return None
    if canon(ros2_control_element(robot, model)) != canon(el):
        return None
    if not data["hardware"]["params"]:
        del data["hardware"]["params"]
    return data


def plain(v: Any) -> Any:
    """`v` with every `Num` unwrapped to its float (for validating YAML-bound data)."""
    if isinstance(v, Num):
        return v.value
    if isinstance(v, dict):
        return {k: plain(x) for k, x in v.items()}
    if isinstance(v, list):
        return [plain(x) for x in v]
    return v


def _without(hw: etree._Element, plugin: etree._Element | None) -> etree._Element:
    copy = etree.Element("hardware")
    copy.extend(
        etree.fromstring(etree.tostring(c))
        for c in hw
        if c is not plugin and isinstance(c.tag, str)
    )
    return copy
