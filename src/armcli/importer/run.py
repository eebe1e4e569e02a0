"""Import a URDF into a spec, then prove it: build the spec and compare with the URDF.

The import reads links, joints, materials and top-level extensions, decides what the
spec can type (derived inertials, named materials, Gazebo colours and friction, the
course's plugins, the arm/base split) and keeps the rest verbatim in `passthrough`.
It then builds the spec it wrote, in memory with the safe xacro evaluator `build` uses,
and lists every way the result differs from the input (`armcli.importer.compare`):
whatever cannot round-trip is reported, never silently lost.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from lxml import etree

from armcli.compiler.meshfiles import is_path
from armcli.compiler.xacro_writer import top_level_files
from armcli.errors import InputError, SpecError
from armcli.importer.compare import Difference, compare_urdf
from armcli.importer.extensions import Extensions, read_extensions
from armcli.importer.joints import read_joint
from armcli.importer.links import LinkIn, Materials, read_link
from armcli.importer.split import JointEdge, Split, split_robot
from armcli.importer.values import Reader, xml_text
from armcli.importer.yamltext import Block, BlockMap, Num, document
from armcli.spec.joint_types import ONE_DOF_TYPES
from armcli.spec.load import loads_spec
from armcli.spec.model import RobotSpec
from armcli.urdf.read import parse_root
from armcli.urdf.source import spec_urdfs

_GAZEBO_NAME = re.compile(r"^[A-Za-z0-9_/]{1,64}$")
_NOT_NAME = re.compile(r"[^A-Za-z0-9_-]")
MOUNT_TAGS = {"parent", "child", "origin"}


GainSource = Callable[[RobotSpec], dict[str, tuple[float, float]]]


@dataclass(frozen=True)
class ImportResult:
    """The spec text, the validated spec, and what did not come back the same."""

    text: str
    spec: RobotSpec
    differences: tuple[Difference, ...]
    notes: tuple[str, ...]  # what the import left out or changed, in words
    passthrough: tuple[str, ...]  # the elements kept verbatim, one line each


def _spec_name(name: str, notes: list[str]) -> str:
    out = (_NOT_NAME.sub("_", name) or "robot")[:64]
    if out.startswith("-"):
        out = "_" + out[1:]
    if out != name:
        notes.append(f"robot name {name!r} written as {out!r} (it also names files)")
    return out


def _rebase(links: list[LinkIn], source_dir: Path, out_dir: Path) -> None:
    """Relative mesh paths of the URDF (from its directory) -> relative to the spec file."""
    for link in links:
        for shape in (*link.visuals, *link.collisions):
            g = shape.geo
            if g.kind == "mesh" and is_path(g.filename) and not os.path.isabs(g.filename):
                target = os.path.abspath(source_dir / g.filename)
                new = Path(os.path.relpath(target, os.path.abspath(out_dir))).as_posix()
                shape.geo = replace(g, filename=new)


def _colours(links: list[LinkIn], ext: Extensions, named: dict[str, Any]) -> None:
    """Gazebo colours onto named materials when every link using the material agrees."""
    users: dict[str, list[LinkIn]] = {}
    for link in links:
        m = link.first_material()
        if m is not None and m in named:
            users.setdefault(m, []).append(link)
    typed: set[str] = set()
    for m, group in users.items():
        colours = {ext.colours.get(link.name) for link in group}
        (colour,) = colours if len(colours) == 1 else (None,)
        if colour is not None and _GAZEBO_NAME.match(colour):
            named[m]["gazebo"] = colour
            typed |= {link.name for link in group}
    for ref, colour in ext.colours.items():
        if ref not in typed:
            block = etree.Element("gazebo", reference=ref)
            etree.SubElement(block, "material").text = colour
            ext.passthrough.append(block)


def _summary(el: etree._Element) -> str:
    tag = str(el.tag)
    attrs = " ".join(f'{k!s}="{v!s}"' for k, v in el.attrib.items())
    inner = ", ".join(str(c.tag) for c in el if isinstance(c.tag, str))[:80]
    return f"<{tag}{' ' + attrs if attrs else ''}>" + (f" ({inner})" if inner else "")


@dataclass
class _Parts:
    links: list[LinkIn]
    joints: dict[str, dict[str, Any]]
    edges: list[JointEdge]
    mount_ok: dict[str, bool]


def _read(root: etree._Element, reader: Reader, notes: list[str]) -> tuple[_Parts, Materials]:
    materials = Materials.read(root, reader)
    named = materials.named()
    links = [
        read_link(el, reader, lambda m: materials.ref(m, reader, named))
        for el in root.findall("link")
    ]
    for link in links:
        notes += link.notes
    joints: dict[str, dict[str, Any]] = {}
    edges, mount_ok = [], {}
    for el in root.findall("joint"):
        name, data = read_joint(el, reader, notes)
        joints[name] = data
        edges.append(JointEdge(name, str(data["type"]), str(data["parent"]), str(data["child"])))
        mount_ok[name] = {c.tag for c in el if isinstance(c.tag, str)} <= MOUNT_TAGS
    for name, data in joints.items():
        lead = data.get("mimic", {}).get("joint")
        if "mimic" not in data:
            continue
        if data["type"] not in ONE_DOF_TYPES:
            notes.append(f"joint {name}: mimic left out (a {data['type']} joint does not move)")
            del data["mimic"]
        elif lead not in joints or joints[lead]["type"] not in ONE_DOF_TYPES:
            notes.append(f"joint {name}: mimic of {lead!r} left out (no such moving joint)")
            del data["mimic"]
    return _Parts(links, joints, edges, mount_ok), materials


def _assemble(
    name: str,
    parts: _Parts,
    named: dict[str, Any],
    ext: Extensions,
    split: Split,
) -> dict[str, Any]:
    def part_links(keep: bool) -> dict[str, Any]:
        out = {}
        for link in parts.links:
            if (link.name in split.arm_links) == keep:
                data = link.data()
                if link.name in ext.contacts:
                    data["contact"] = ext.contacts[link.name]
                out[link.name] = data
        return out

    def part_joints(keep: bool) -> dict[str, Any]:
        return {
            n: j
            for n, j in parts.joints.items()
            if n != split.mount and (j["child"] in split.arm_links) == keep
        }

    data: dict[str, Any] = {"name": name}
    if named:
        data["materials"] = named
    arm: dict[str, Any] = {"links": part_links(True), "joints": part_joints(True)}
    for key in ("joint_state_publisher", "joint_pose_trajectory"):
        if key in ext.plugins:
            arm[key] = ext.plugins[key]
    if split.mount is not None:
        base: dict[str, Any] = {"links": part_links(False), "joints": part_joints(False)}
        if "diff_drive" in ext.plugins:
            base["diff_drive"] = ext.plugins["diff_drive"]
        data["mobile_base"] = base
    data["arm"] = arm
    if split.mount is not None:
        mount = parts.joints[split.mount]
        data["mount"] = {"joint": split.mount, "parent": mount["parent"]}
        if "origin" in mount:
            data["mount"]["origin"] = mount["origin"]
    if ext.ros2_control is not None:
        data["ros2_control"] = ext.ros2_control
    if ext.passthrough:
        data["passthrough"] = [Block(xml_text(el)) for el in ext.passthrough]
    return data


def _choose_split(parts: _Parts, arm_root: str | None, ext: Extensions) -> Split:
    split = split_robot([lk.name for lk in parts.links], parts.edges, arm_root)
    child = {n: j["child"] for n, j in parts.joints.items()}
    crossing = any(
        (child[n] in split.arm_links) != (child[j["mimic"]["joint"]] in split.arm_links)
        for n, j in parts.joints.items()
        if "mimic" in j
    )
    if split.mount is not None and (crossing or not parts.mount_ok[split.mount]):
        split = Split(frozenset(lk.name for lk in parts.links), None)
    if split.mount is None and "diff_drive" in ext.plugins:
        del ext.plugins["diff_drive"]  # only a mobile base holds it: kept verbatim instead
        ext.passthrough.append(ext.plugin_blocks["diff_drive"])
    return split


def _sig(x: float) -> float:
    return float(f"{x:.3g}")


def _load(text: str, out: Path, source: str) -> RobotSpec:
    try:
        return loads_spec(text, str(out)).with_source(out)
    except SpecError as exc:
        raise InputError(
            f"the URDF holds values a spec cannot: {'; '.join(exc.lines()[:5])}", file=source
        ) from None


def import_urdf(
    xml: bytes,
    source: str,
    out: Path,
    *,
    arm_root: str | None = None,
    source_dir: Path | None = None,
    gains: GainSource | None = None,
    packages: Mapping[str, Path] | None = None,
) -> ImportResult:
    """Import URDF bytes (read from `source`) into a spec to be written at `out`.

    `source_dir` is where the URDF's relative mesh paths start (default: `source`'s);
    `gains`, when given, writes start gains for the spec it is shown (`control.gains`);
    `packages`: where the packages its `package://` meshes name were found, recorded in
    the spec relative to `out` (`packages`), so check, view and ros-package find them.

    Raises:
        InputError: the URDF is unusable, or it holds values the spec refuses (listed).
    """
    root = parse_root(xml, source)
    if root.find("link") is None:
        raise InputError("no <link> in this URDF: nothing to import", file=source)
    reader, notes = Reader(source), list[str]()
    parts, materials = _read(root, reader, notes)
    named = materials.named()
    base = source_dir if source_dir is not None else Path(source).parent
    _rebase(parts.links, base, out.parent)
    name = _spec_name(str(root.get("name", "robot")), notes)
    ext = read_extensions(root, name)
    _colours(parts.links, ext, named)
    split = _choose_split(parts, arm_root, ext)
    data = _assemble(name, parts, named, ext, split)
    if packages:
        here = out.parent.absolute()
        data["packages"] = {
            n: Path(os.path.relpath(p, here)).as_posix() for n, p in packages.items()
        }
    header = [
        f"armcli spec imported by `armcli import` from {source}.",
        "`armcli build` turns it back into that URDF; the import listed any difference.",
        "Units: SI (m, kg, s, N, N·m); angles in radians.",
    ]
    comments: dict[str, list[str]] = {
        "passthrough": [f"Kept verbatim from {source}: elements the spec does not type."],
        "packages": ["Where the packages its package:// meshes name are, from this file."],
    }
    text = document(data, header, comments)
    spec = _load(text, out, source)
    start = gains(spec) if gains is not None else {}
    if start:
        per_joint = {j: {"kp": Num(_sig(kp)), "kd": Num(_sig(kd))} for j, (kp, kd) in start.items()}
        # ros2_control holds each effort for 1/update_rate: at controller_manager's default
        # 100 Hz such gains diverge (`check`: ros-controller-unstable); 1000 Hz is Gazebo's
        # physics rate, as the example specs use
        data["control"] = BlockMap(controller_update_rate=1000, gains=BlockMap(per_joint))
        comments["control"] = [
            "Start gains: the model-based start of `armcli tune` (not tuned yet);",
            "`armcli tune --write` improves them. The controllers update at 1000 Hz:",
            "at 100 Hz (ros2_control's default) the arm would diverge between updates.",
        ]
        text = document(data, header, comments)
        spec = _load(text, out, source)
    built = spec_urdfs(spec)
    main = next(n for n in (f"{spec.name}.urdf", *top_level_files(spec)) if n in built)
    got = etree.fromstring(built[main])
    diffs = compare_urdf(root, got, (base, None))
    return ImportResult(
        text=text,
        spec=spec,
        differences=tuple(diffs),
        notes=tuple(notes),
        passthrough=tuple(_summary(el) for el in ext.passthrough),
    )
