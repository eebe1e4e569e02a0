"""The SRDF as MoveIt reads it: planning groups, named joint states, disabled collision pairs.

Read once here (below `plan` and `check`, which both use it): `plan --group` resolves a
group's joints, `check DIR`'s package rules take the named poses and every name the SRDF
uses (`entries`, with its line) to compare with the URDF.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from armcli.errors import InputError
from armcli.io.userfile import read_regular
from armcli.urdf.doc import Urdf
from armcli.urdf.read import parse_root

MAX_SRDF_BYTES = 8 * 1024 * 1024


@dataclass(frozen=True)
class Group:
    """A planning group as the SRDF writes it: joints, links, chains and other groups."""

    name: str
    joints: tuple[str, ...] = ()
    links: tuple[str, ...] = ()  # each stands for the joint above it
    chains: tuple[tuple[str, str], ...] = ()  # (base_link, tip_link)
    groups: tuple[str, ...] = ()  # subgroups by name
    line: int | None = None


@dataclass(frozen=True)
class Entry:
    """A name the SRDF uses: a joint, link or group, its line and the element it is in."""

    kind: str  # "joint", "link" or "group"
    name: str
    line: int | None
    where: str  # e.g. "group arm", "group_state home", "end_effector hand"


@dataclass(frozen=True)
class Srdf:
    """An SRDF's disabled collision pairs, named joint states and planning groups."""

    disabled: tuple[tuple[str, str], ...] = ()
    group_states: dict[str, dict[str, float]] = field(default_factory=dict)
    groups: dict[str, Group] = field(default_factory=dict)
    source: str = "<srdf>"
    robot: str = ""  # <robot name=...>
    entries: tuple[Entry, ...] = ()  # every joint, link and group name it uses
    state_groups: dict[str, str] = field(default_factory=dict)  # group_state -> its group
    virtual_joints: tuple[str, ...] = ()  # joints of MoveIt's model the URDF does not have

    def group_joints(self, name: str, urdf: Urdf) -> tuple[str, ...]:
        """The joints of planning group `name` in `urdf`, in document order.

        As MoveIt resolves them: listed joints, the joint above each listed link, every
        joint of a chain from base to tip, and the subgroups'. InputError naming an
        unknown group or joint, or a chain whose tip is not below its base.
        """
        if name not in self.groups:
            valid = ", ".join(self.groups) or "none"
            raise InputError(f"unknown planning group {name!r}; valid: {valid}", field="group")
        above = {j.child: j for j in urdf.joints if j.child}
        known = {j.name for j in urdf.joints}
        found: set[str] = set()
        todo, seen = [name], set()
        while todo:
            g = self.groups.get(todo.pop())
            if g is None or g.name in seen:
                continue
            seen.add(g.name)
            todo.extend(g.groups)

            def refuse(message: str, g: Group = g) -> InputError:
                return InputError(message, file=self.source, line=g.line, field=f"group {g.name}")

            for j in g.joints:
                if j not in known:
                    raise refuse(f"joint {j!r} is not in {urdf.source}")
                found.add(j)
            found.update(above[lk].name for lk in g.links if lk in above)
            for base, tip in g.chains:
                link: str | None = tip  # walked up to the base
                chain: list[str] = []
                for _ in range(len(above) + 1):  # bounded: a malformed tree may loop
                    if link == base or link not in above:
                        break
                    chain.append(above[link].name)
                    link = above[link].parent
                if link != base:
                    raise refuse(f"chain tip {tip!r} is not below base {base!r}")
                found.update(chain)
        return tuple(j.name for j in urdf.joints if j.name in found)


def _line(el: Any) -> int | None:
    line = el.sourceline
    return line if isinstance(line, int) else None


def read_srdf(path: Path) -> Srdf:
    """Read `disable_collisions` and `group_state` entries; InputError with file and line."""
    return parse_srdf(read_regular(path, max_bytes=MAX_SRDF_BYTES, what="SRDF"), path)


def parse_srdf(data: bytes, path: Path | str) -> Srdf:
    """An SRDF document's bytes -> Srdf (the expansion of a `.srdf.xacro` too)."""
    root = parse_root(data, str(path))
    disabled = []
    for el in root.iter("disable_collisions"):
        a, b = el.get("link1"), el.get("link2")
        if not a or not b:
            raise InputError(
                "needs link1 and link2", file=path, line=_line(el), field="disable_collisions"
            )
        disabled.append((a, b))
    states: dict[str, dict[str, float]] = {}
    for el in root.iter("group_state"):
        name = el.get("name")
        if not name:
            raise InputError("needs a name", file=path, line=_line(el), field="group_state")
        values = states.setdefault(name, {})
        for j in el.iter("joint"):
            jname, raw = j.get("name"), j.get("value")
            try:
                value = float(raw or "")
            except ValueError:
                value = math.nan
            if not jname or not math.isfinite(value):
                raise InputError(
                    f"joint needs a name and a finite value, got {raw!r}",
                    file=path,
                    line=_line(j),
                    field=f"group_state {name}",
                )
            values[jname] = value
    groups = {el.get("name", ""): el.get("group", "") for el in root.iter("group_state")}
    virtual = tuple(n for el in root.iter("virtual_joint") if (n := el.get("name")))
    return Srdf(
        tuple(disabled),
        states,
        _groups(root, Path(path)),
        str(path),
        root.get("name", ""),
        tuple(_entries(root)),
        groups,
        virtual,
    )


# element -> (attribute, kind of name) pairs MoveIt resolves against the URDF
_REFERENCES = {
    "chain": (("base_link", "link"), ("tip_link", "link")),
    "end_effector": (("parent_link", "link"), ("group", "group"), ("parent_group", "group")),
    "passive_joint": (("name", "joint"),),
    "disable_collisions": (("link1", "link"), ("link2", "link")),
    "enable_collisions": (("link1", "link"), ("link2", "link")),
    "disable_default_collisions": (("link", "link"),),
    "virtual_joint": (("child_link", "link"),),
    "link_sphere_approximation": (("link", "link"),),
    "group_state": (("group", "group"),),
}


def _entries(root: Any) -> list[Entry]:
    """Every name the SRDF uses, with its line, in document order."""
    out: list[Entry] = []
    for el in root.iter():
        tag = el.tag if isinstance(el.tag, str) else ""
        parent = el.getparent()
        ptag = parent.tag if parent is not None and isinstance(parent.tag, str) else ""
        owner = f"{ptag} {parent.get('name', '')}".strip() if parent is not None else ""
        for attr, kind in _REFERENCES.get(tag, ()):
            if el.get(attr):
                out.append(
                    Entry(kind, el.get(attr), _line(el), f"{tag} {el.get('name', '')}".strip())
                )
        if ptag == "group" and tag in ("joint", "link", "group") and el.get("name"):
            out.append(Entry(tag, el.get("name"), _line(el), owner))
        if ptag == "group_state" and tag == "joint" and el.get("name"):
            out.append(Entry("joint", el.get("name"), _line(el), owner))
    return out


def _groups(root: Any, path: Path) -> dict[str, Group]:
    """The top-level <group> elements by name."""
    out: dict[str, Group] = {}
    for el in root.findall("group"):
        name = el.get("name")
        if not name:
            raise InputError("needs a name", file=path, line=_line(el), field="<group>")
        chains = []
        for c in el.findall("chain"):
            base, tip = c.get("base_link"), c.get("tip_link")
            if not base or not tip:
                raise InputError(
                    "a chain needs base_link and tip_link",
                    file=path,
                    line=_line(c),
                    field=f"group {name}",
                )
            chains.append((base, tip))
        out[name] = Group(
            name,
            tuple(n for j in el.findall("joint") if (n := j.get("name"))),
            tuple(n for lk in el.findall("link") if (n := lk.get("name"))),
            tuple(chains),
            tuple(n for g in el.findall("group") if (n := g.get("name"))),
            _line(el),
        )
    return out
