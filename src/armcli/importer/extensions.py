"""Top-level URDF extensions -> typed spec fields where exact, passthrough otherwise.

Typed: a link's Gazebo colour (when every link sharing its first named material has the
same one), `mu1`/`mu2` friction, and the course's three gazebo_ros plugins when the
plugin is exactly what the spec writes back (checked by building it). Everything else
at the top level (other Gazebo tags and plugins, transmissions, ros2_control, vendor
elements) is kept verbatim.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from lxml import etree
from pydantic import BaseModel, ValidationError

from armcli.compiler.gazebo import (
    DIFF_DRIVE,
    JOINT_POSE_TRAJECTORY,
    JOINT_STATE_PUBLISHER,
    diff_drive_element,
    joint_pose_trajectory_element,
    joint_state_publisher_element,
)
from armcli.importer.compare import canon
from armcli.importer.control import read_ros2_control
from armcli.importer.yamltext import Num
from armcli.spec.model import DiffDrive, JointPoseTrajectory, JointStatePublisher

TYPED_TOP = ("link", "joint", "material")
_BOOL = {"true": True, "false": False}


@dataclass
class Extensions:
    """What the top level held beyond links, joints and materials."""

    colours: dict[str, str] = field(default_factory=dict)  # link -> Gazebo material
    contacts: dict[str, dict[str, Num]] = field(default_factory=dict)  # link -> mu1, mu2
    plugins: dict[str, dict[str, Any]] = field(default_factory=dict)  # spec field -> data
    plugin_blocks: dict[str, etree._Element] = field(default_factory=dict)  # as read
    ros2_control: dict[str, Any] | None = None  # the one block, typed
    passthrough: list[etree._Element] = field(default_factory=list)


def _leaf(el: etree._Element) -> str | None:
    """The value of a simple leaf (`<x>v</x>` or `<x value="v"/>`), else None."""
    if len(el) or set(el.attrib) - {"value"}:
        return None
    if "value" in el.attrib:
        return None if (el.text or "").strip() else str(el.get("value"))
    return (el.text or "").strip() or None


def _number(text: str | None) -> float | None:
    try:
        return float(text) if text is not None else None
    except ValueError:
        return None


def _reference_block(ref: str, children: list[etree._Element], ext: Extensions) -> None:
    """Split a link's merged Gazebo children into colour, friction and the rest."""
    rest = list(children)
    colours = [c for c in children if c.tag == "material" and _leaf(c)]
    if len(colours) == 1 and len([c for c in children if c.tag == "material"]) == 1:
        ext.colours[ref] = str(_leaf(colours[0]))
        rest.remove(colours[0])
    mus = {tag: [c for c in children if c.tag == tag] for tag in ("mu1", "mu2")}
    values = {tag: _number(_leaf(els[0])) if len(els) == 1 else None for tag, els in mus.items()}
    if all(v is not None and v >= 0 for v in values.values()):
        ext.contacts[ref] = {tag: Num(float(v or 0.0)) for tag, v in values.items()}
        rest = [c for c in rest if c.tag not in ("mu1", "mu2")]
    if rest:
        block = etree.Element("gazebo", reference=ref)
        block.extend(copy.deepcopy(c) for c in rest)
        ext.passthrough.append(block)


def _params(plugin: etree._Element) -> list[tuple[str, str]] | None:
    out = []
    for c in plugin:
        if not isinstance(c.tag, str):
            continue
        value = _leaf(c)
        if value is None or c.attrib:
            return None
        out.append((str(c.tag), value))
    return out


def _typed(
    block: etree._Element,
    names: tuple[str, str],
    model: type[BaseModel],
    to_data: Callable[[list[tuple[str, str]]], dict[str, Any]],
    element: Callable[[Any], etree._Element],
) -> dict[str, Any] | None:
    """The spec data of a course plugin when building it gives this very block back."""
    plugins = [c for c in block if isinstance(c.tag, str)]
    if len(plugins) != 1 or plugins[0].tag != "plugin" or block.attrib:
        return None
    p = plugins[0]
    if (p.get("name"), p.get("filename")) != names or set(p.attrib) != {"name", "filename"}:
        return None
    params = _params(p)
    if params is None:
        return None
    try:
        value = model.model_validate(to_data(params))
    except (ValidationError, ValueError, KeyError, IndexError):
        return None
    if canon(element(value)) != canon(block):
        return None
    return {k: _yaml(v) for k, v in value.model_dump().items()}


def _yaml(v: Any) -> Any:
    if isinstance(v, float):
        return Num(v)
    return [_yaml(x) for x in v] if isinstance(v, list) else v


def _diff_drive(params: list[tuple[str, str]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in params:
        out[key] = _BOOL[value] if key.startswith("publish_") else value
    return out


def _joint_state_publisher(params: list[tuple[str, str]]) -> dict[str, Any]:
    rate = [v for k, v in params if k == "update_rate"]
    joints = [v for k, v in params if k == "joint_name"]
    return {"update_rate": rate[0], "joints": joints}


def _joint_pose_trajectory(params: list[tuple[str, str]]) -> dict[str, Any]:
    return dict(params)


PLUGINS: dict[str, tuple[Any, ...]] = {  # spec field -> (names, model, params -> data, builder)
    "diff_drive": (DIFF_DRIVE, DiffDrive, _diff_drive, diff_drive_element),
    "joint_state_publisher": (
        JOINT_STATE_PUBLISHER,
        JointStatePublisher,
        _joint_state_publisher,
        joint_state_publisher_element,
    ),
    "joint_pose_trajectory": (
        JOINT_POSE_TRAJECTORY,
        JointPoseTrajectory,
        _joint_pose_trajectory,
        joint_pose_trajectory_element,
    ),
}


def _plugin_block(block: etree._Element, ext: Extensions) -> None:
    for name, (names, model, to_data, element) in PLUGINS.items():
        if name in ext.plugins:
            continue
        data = _typed(block, names, model, to_data, element)
        if data is not None:
            ext.plugins[name] = data
            ext.plugin_blocks[name] = copy.deepcopy(block)
            return
    ext.passthrough.append(copy.deepcopy(block))


def read_extensions(root: etree._Element, robot: str) -> Extensions:
    """Sort the top-level elements other than links, joints and materials.

    Colours and friction are typed for `<gazebo reference=LINK>` only; Gazebo tags of
    joints (or unknown names) are kept verbatim.
    """
    links = {str(el.get("name")) for el in root.findall("link")}
    movable = {str(j.get("name")) for j in root.findall("joint") if j.get("type") != "fixed"}
    blocks = root.findall("ros2_control")
    ext = Extensions()
    by_ref: dict[str, list[etree._Element]] = {}
    for el in root:
        if not isinstance(el.tag, str) or el.tag in TYPED_TOP:
            continue
        if el.tag == "gazebo" and el.get("reference") in links and set(el.attrib) == {"reference"}:
            by_ref.setdefault(str(el.get("reference")), []).extend(
                c for c in el if isinstance(c.tag, str)
            )
        elif el.tag == "gazebo":
            _plugin_block(el, ext)
        elif el.tag == "ros2_control" and len(blocks) == 1:
            ext.ros2_control = read_ros2_control(el, robot, movable)
            if ext.ros2_control is None:
                ext.passthrough.append(copy.deepcopy(el))
        else:
            ext.passthrough.append(copy.deepcopy(el))
    for ref, children in by_ref.items():
        _reference_block(ref, children, ext)
    return ext
