"""Findings in a spec's generated URDF, pointed back at the spec: file, line and field path.

A spec is compiled to URDFs in memory and checked there, so a finding's line is in text
the user never sees. This module maps the URDF element at that line back to the spec
field it came from, by the spec's structure rather than by the compiler's internals:
`<joint name="J">` came from `arm.joints.J` (or `mobile_base.joints.J`, or `mount`),
`<link name="L">` from `*.links.L`, `<material name="M">` from `materials.M`, a child
element from the field of the same name below it (`<limit>` -> `.limit`, `<inertial>` ->
`.inertial` or `.mass`, `<visual>` -> `.visual[i]` or `.geometry`, ...), and the number a
finding is about from its values (`upper` -> `.limit.upper`). Among the candidate paths the
deepest one that the spec file really has wins, with the line armcli's YAML reader recorded
for it; PD findings point at `control.gains.<joint>` (or `control.dt`), the controller's
rate finding at `control.controller_update_rate`. The URDF location
stays on the finding as secondary information.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import replace
from itertools import product
from typing import Any

from lxml import etree

from armcli.check.findings import Finding, SpecPlace
from armcli.io.yaml import YamlDoc, dotted

Path_ = tuple[str | int, ...]

# URDF child element -> the spec keys it may have come from, most specific first
_CHILD_KEYS: dict[str, tuple[str, ...]] = {
    "inertial": ("inertial", "mass"),
    "mass": ("mass",),
    "inertia": ("inertia",),
    "origin": ("origin",),
    "visual": ("visual", "visuals", "geometry"),
    "collision": ("collision", "collisions", "geometry"),
    "geometry": ("geometry",),
    "limit": ("limit",),
    "dynamics": ("dynamics",),
    "axis": ("axis",),
    "mimic": ("mimic",),
    "parent": ("parent",),
    "child": ("child",),
    "material": ("material",),
    "safety_controller": ("safety_controller",),
    "calibration": ("calibration",),
}
_PD_RULE_PREFIX = "pd-"
_SENSOR_RULE_PREFIX = "sensor-"  # check/sensors.py: about the spec's sensor named
_RATE_RULE = "ros-controller-unstable"  # check/controller_rate.py: the spec's controller rate
# check/tipover.py and check/zmp.py: about a pose or the base's drive, not a URDF element
_BALANCE_RULES = frozenset(
    {"com-outside-support", "support-margin", "zmp-outside-support", "zmp-margin"}
)


def _element_at(root: Any, line: int) -> Any:
    """The first element that starts on `line` (lxml's sourceline), or None."""
    for el in root.iter():
        if isinstance(el.tag, str) and el.sourceline == line:
            return el
    return None


def _bases(top: Any, doc: YamlDoc) -> list[Path_]:
    """Spec paths a top-level URDF element (joint, link, material, gazebo) came from."""
    name = top.get("name")
    data = doc.data if isinstance(doc.data, dict) else {}
    if top.tag == "joint":
        mount = data.get("mount")
        out: list[Path_] = [("arm", "joints", name), ("mobile_base", "joints", name)]
        if isinstance(mount, dict) and mount.get("joint") == name:
            out.append(("mount",))
        return out
    if top.tag == "link":
        return [("arm", "links", name), ("mobile_base", "links", name)]
    if top.tag == "gazebo" and top.get("reference"):
        ref = top.get("reference")
        return [("arm", "links", ref), ("mobile_base", "links", ref)]
    if top.tag == "material":
        return [("materials", name)]
    return []


def _index(el: Any) -> int:
    """Position of `el` among its parent's children of the same tag (visual[1], ...)."""
    parent = el.getparent()
    same = [c for c in parent if c.tag == el.tag] if parent is not None else [el]
    return same.index(el)


def _candidates(el: Any, doc: YamlDoc) -> Iterator[Path_]:
    """Spec paths the element may have come from, deepest first."""
    chain = [el, *el.iterancestors()][::-1][1:]  # below <robot>: top element first
    if not chain:
        return
    top, below = chain[0], chain[1:]
    for base in _bases(top, doc):
        for depth in range(len(below), -1, -1):
            options = [
                [(key, _index(e)) for key in _CHILD_KEYS.get(e.tag, (e.tag,))]
                for e in below[:depth]
            ]
            for combo in product(*options):
                path: list[str | int] = list(base)
                for key, i in combo:
                    path.append(key)
                    if (*path, i) in doc.lines:  # a list in the spec: visual[i]
                        path.append(i)
                yield tuple(path)


def _refine(path: Path_, f: Finding, doc: YamlDoc) -> Path_:
    """The field below `path` the finding's numbers are about, when the spec has it."""
    for key in f.values:
        if (*path, key) in doc.lines:
            return (*path, key)
    return path


def _balance_path(f: Finding, doc: YamlDoc) -> Path_ | None:
    """Balance findings are about the pose named, or the diff drive's acceleration limit."""
    pose = f.values.get("pose")
    paths: list[Path_] = [("poses", str(pose))] if pose is not None else []
    drive = ("mobile_base", "diff_drive")
    if "max_wheel_acceleration" in f.fix:
        paths += [(*drive, "max_wheel_acceleration"), drive]
    return next((p for p in paths if p in doc.lines), None)


def _pd_path(f: Finding, doc: YamlDoc) -> Path_ | None:
    """PD findings are about the gains (of the joint named, if one is) or the time step."""
    joint = f.values.get("joint")
    paths: list[Path_] = [("control", "gains", str(joint))] if joint is not None else []
    paths += [("control", "gains"), ("control", "dt"), ("control",)]
    return next((p for p in paths if p in doc.lines), None)


def _sensor_path(f: Finding, doc: YamlDoc) -> Path_ | None:
    """Sensor findings are about the spec's sensor named, the number they name in it."""
    base = ("sensors", str(f.values.get("sensor")))
    for part in ("lidar", "camera", None):
        path = (*base, part) if part else base
        if path in doc.lines:
            refined = _refine(path, f, doc)
            if refined != path or part is None:
                return refined
    return None


def _rate_path(doc: YamlDoc) -> Path_ | None:
    """The controller's rate (where the spec writes it), else its gains."""
    paths: list[Path_] = [("control", "controller_update_rate"), ("control", "gains"), ("control",)]
    return next((p for p in paths if p in doc.lines), None)


def spec_path(f: Finding, root: Any, doc: YamlDoc) -> Path_ | None:
    """The spec field a finding in the URDF `root` (lxml tree of the generated text) is about."""
    if f.rule == _RATE_RULE:
        return _rate_path(doc)
    if f.rule.startswith(_PD_RULE_PREFIX):
        return _pd_path(f, doc)
    if f.rule.startswith(_SENSOR_RULE_PREFIX) and "sensor" in f.values:
        return _sensor_path(f, doc)
    if f.rule in _BALANCE_RULES:
        return _balance_path(f, doc)
    el = _element_at(root, f.line) if f.line else None
    if el is None:
        return None
    for path in _candidates(el, doc):
        if path in doc.lines:
            return _refine(path, f, doc)
    return None


def key_lines(text: str) -> dict[Path_, int]:
    """The line of each mapping key (1-based) by field path: where `gains:` is written.

    armcli's reader records where a value starts, which for a block mapping is its first
    key's line; a finding about `control.gains` belongs on the `gains:` line.
    """
    import yaml

    out: dict[Path_, int] = {}

    def walk(node: Any, path: Path_) -> None:
        if isinstance(node, yaml.MappingNode):
            for key, value in node.value:
                if isinstance(key, yaml.ScalarNode):
                    out.setdefault((*path, key.value), key.start_mark.line + 1)
                    walk(value, (*path, key.value))
        elif isinstance(node, yaml.SequenceNode):
            for i, item in enumerate(node.value):
                out.setdefault((*path, i), item.start_mark.line + 1)
                walk(item, (*path, i))

    walk(yaml.compose(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader)), ())
    return out


def locate(
    findings: Sequence[Finding], urdf_text: bytes, doc: YamlDoc, keys: dict[Path_, int]
) -> list[Finding]:
    """`findings` of one generated URDF, each with its spec place where one is found.

    `keys` are the spec's `key_lines`, preferred to the value lines of `doc`.
    """
    parser = etree.XMLParser(resolve_entities=False, no_network=True, huge_tree=False)
    root = etree.fromstring(urdf_text, parser)
    out = []
    for f in findings:
        path = spec_path(f, root, doc)
        if path is None:
            out.append(f)
            continue
        line = keys.get(path, doc.line_of(path))
        out.append(replace(f, spec=SpecPlace(file=doc.source, line=line, field=dotted(path))))
    return out
