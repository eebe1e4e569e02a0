"""The simulator extensions of a URDF, read once into urdf/doc.py's types.

`<gazebo>`, `<ros2_control>`, `<transmission>`, every `<plugin>` and every sensor: what
check (the servo loop, passive joints, the sensors' rules), the MJCF export (friction, the
tags it cannot carry) and the drive model (mu2) read, so none of them parses the XML again.
"""

from __future__ import annotations

from lxml import etree

from armcli.urdf.doc import Gazebo, GazeboSensor, Plugin, Ros2Control, Transmission


def _ln(el: etree._Element) -> int | None:
    line = el.sourceline
    return line if isinstance(line, int) else None


def _first_texts(el: etree._Element, value_attr: bool = False) -> dict[str, str]:
    """Child tag -> stripped text (or its `value` attribute first), the first of each tag."""
    out: dict[str, str] = {}
    for c in el:
        if isinstance(c.tag, str) and c.tag not in out:
            text = c.get("value") if value_attr else None
            out[c.tag] = (text if text is not None else (c.text or "")).strip()
    return out


def _ros2_control(el: etree._Element) -> Ros2Control:
    commands = {
        j.get("name", ""): tuple(c.get("name", "") for c in j.findall("command_interface"))
        for j in el.findall("joint")
    }
    hardware = (el.findtext("hardware/plugin") or "").strip()
    return Ros2Control(el.get("name", ""), hardware, commands, _ln(el))


def gazebo(root: etree._Element) -> tuple[Gazebo, ...]:
    """The top-level <gazebo> blocks."""
    return tuple(
        Gazebo(el.get("reference"), _first_texts(el, value_attr=True), _ln(el))
        for el in root.findall("gazebo")
    )


def ros2_control(root: etree._Element) -> tuple[Ros2Control, ...]:
    """The top-level <ros2_control> blocks."""
    return tuple(_ros2_control(el) for el in root.findall("ros2_control"))


def transmissions(root: etree._Element) -> tuple[Transmission, ...]:
    """The top-level <transmission> blocks."""
    out = []
    for el in root.findall("transmission"):
        joints = tuple(j.get("name", "") for j in el.findall("joint"))
        out.append(Transmission(el.get("name", ""), joints, _ln(el)))
    return tuple(out)


def plugins(root: etree._Element) -> tuple[Plugin, ...]:
    """Every <plugin>, at any depth, in document order."""
    return tuple(
        Plugin(el.get("filename"), el.get("name"), _first_texts(el), _ln(el))
        for el in root.iter("plugin")
    )


def _number(el: etree._Element, path: str) -> float | None:
    text = el.findtext(path)
    try:
        return float(text) if text is not None else None
    except ValueError:
        return None


def _scan(el: etree._Element, axis: str) -> tuple[float | None, float | None, float | None] | None:
    """(samples, min angle, max angle) of a ray sensor's horizontal or vertical scan."""
    for scan in ("ray/scan", "lidar/scan"):
        node = el.find(f"{scan}/{axis}")
        if node is not None:
            return _number(node, "samples"), _number(node, "min_angle"), _number(node, "max_angle")
    return None


def _pair(
    el: etree._Element, path: str, a: str, b: str
) -> tuple[float | None, float | None] | None:
    node = el.find(path)
    return (_number(node, a), _number(node, b)) if node is not None else None


def _sensor(gz: etree._Element, el: etree._Element) -> GazeboSensor:
    pose_text = (el.findtext("pose") or "").split()
    try:
        pose = tuple(float(x) for x in pose_text) if len(pose_text) == 6 else None
    except ValueError:
        pose = None
    frame = el.findtext("gz_frame_id") or el.findtext("plugin/frame_name")
    rng = _pair(el, "ray/range", "min", "max") or _pair(el, "lidar/range", "min", "max")
    return GazeboSensor(
        name=el.get("name", ""),
        type=el.get("type", ""),
        link=gz.get("reference"),
        line=_ln(el),
        pose=pose,
        update_rate=_number(el, "update_rate"),
        frame=frame.strip() if frame else None,
        rays=_scan(el, "horizontal"),
        vertical=_scan(el, "vertical"),
        range=rng,
        horizontal_fov=_number(el, "camera/horizontal_fov"),
        clip=_pair(el, "camera/clip", "near", "far"),
    )


def sensors(root: etree._Element) -> tuple[GazeboSensor, ...]:
    """The <sensor> elements of the top-level <gazebo> blocks."""
    return tuple(_sensor(gz, el) for gz in root.findall("gazebo") for el in gz.findall("sensor"))
