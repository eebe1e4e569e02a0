"""Structure and number rules: names, tree shape, joint types, limits, sizes, colours.

Also returns the kinematic tree (urdf/tree.py's `KinematicTree`: root, parent joint of
each link, which links move) that the inertia, joint and model rules build on; the
rules here report what that tree records as malformed.
"""

from __future__ import annotations

import math
from collections import Counter

from armcli.check.findings import Collector
from armcli.spec.joint_types import JOINT_TYPES, LIMITED_TYPES
from armcli.urdf.doc import Joint, Link, Urdf
from armcli.urdf.tree import KinematicTree

NUMBER_RULES = {
    "missing": "number-syntax",
    "not-a-number": "number-syntax",
    "non-finite": "non-finite",
    "length": "vector-length",
}


def check(urdf: Urdf, out: Collector) -> KinematicTree:
    """Run the structure and number rules and return the tree."""
    for p in urdf.problems:
        what = {
            "missing": "missing",
            "not-a-number": "not a number",
            "non-finite": "not finite",
            "length": "wrong number of values",
        }[p.kind]
        out.add(NUMBER_RULES[p.kind], p.line, f"{p.where}: {what}: {p.text!r}", text=p.text)
    if not urdf.name:
        out.add("robot-name", urdf.line, "<robot> has no name attribute (urdfdom refuses it)")
    _names(urdf, out)
    _materials(urdf, out)
    _material_refs(urdf, out)
    for link in urdf.links:
        _geometry_sizes(link, out)
    links = {lk.name for lk in urdf.links}
    for j in urdf.joints:
        _joint_shape(j, links, {jj.name for jj in urdf.joints}, out)
    tree = _tree(urdf, out)
    for link in urdf.links:
        if tree.is_moving(link.name) and link.visuals and not link.collisions:
            out.add(
                "visual-no-collision",
                link.line,
                f"moving link {link.name!r} is visible but has no <collision>: it passes "
                "through everything in simulation",
                link=link.name,
            )
    return tree


def _names(urdf: Urdf, out: Collector) -> None:
    for kind, items in (("link", urdf.links), ("joint", urdf.joints)):
        counts = Counter(it.name for it in items)
        seen: set[str] = set()
        for it in items:
            if not it.name:
                out.add("duplicate-name", it.line, f"{kind} without a name")
            elif counts[it.name] > 1 and it.name in seen:
                out.add(
                    "duplicate-name",
                    it.line,
                    f"{kind} {it.name!r} defined {counts[it.name]}x",
                    name=it.name,
                )
            seen.add(it.name)
    top = Counter(m.name for m in urdf.materials if m.top_level)
    seen = set()
    for m in urdf.materials:
        if m.top_level and top[m.name] > 1 and m.name in seen:
            out.add(
                "duplicate-name",
                m.line,
                f"material {m.name!r} defined {top[m.name]}x at top level",
                name=m.name,
            )
        seen.add(m.name)


def _materials(urdf: Urdf, out: Collector) -> None:
    first: dict[str, tuple[float, ...]] = {}
    for m in urdf.materials:
        if m.rgba is None:
            continue
        bad = [c for c in m.rgba if not 0.0 <= c <= 1.0]
        if bad:
            out.add(
                "rgba-range",
                m.line,
                f"material {m.name!r}: rgba {list(m.rgba)} outside [0, 1]",
                rgba=list(m.rgba),
            )
        if not m.name:  # an unnamed material is a visual's own colour: nothing to conflict
            continue
        prev = first.setdefault(m.name, m.rgba)
        if prev != m.rgba:
            out.add(
                "material-conflict",
                m.line,
                f"material {m.name!r} redefined: rgba {list(m.rgba)} vs {list(prev)}",
                rgba=list(m.rgba),
                first=list(prev),
            )


def _material_refs(urdf: Urdf, out: Collector) -> None:
    """A visual's material must get a colour or texture somewhere (check_urdf refuses it)."""
    defined = {m.name for m in urdf.materials if m.rgba is not None or m.texture}
    reported: set[str] = set()
    for link in urdf.links:
        for s in link.visuals:
            name = s.material
            if name is None or name in defined or name in reported:
                continue
            reported.add(name)
            out.add(
                "material-undefined",
                s.line,
                f"link {link.name!r}: material {name!r} has no colour or texture anywhere "
                "in the file",
                material=name,
                link=link.name,
            )


def _geometry_sizes(link: Link, out: Collector) -> None:
    for tag, shapes in (("visual", link.visuals), ("collision", link.collisions)):
        for s in shapes:
            g = s.geometry
            if g is None or not g.kind:
                out.add(
                    "geometry-kind", s.line, f"link {link.name!r}: {tag} without a geometry shape"
                )
            elif g.kind not in ("box", "cylinder", "sphere", "mesh"):
                out.add("geometry-kind", g.line, f"link {link.name!r}: unknown geometry <{g.kind}>")
            elif g.dims is not None and not all(d > 0 for d in g.dims):
                out.add(
                    "geometry-size",
                    g.line,
                    f"link {link.name!r}: {tag} {g.kind} sizes {list(g.dims)} must be > 0",
                    dims=list(g.dims),
                )
            elif g.kind == "mesh" and not all(c != 0 for c in g.scale):
                out.add(
                    "geometry-size",
                    g.line,
                    f"link {link.name!r}: mesh scale {list(g.scale)} has a zero",
                    scale=list(g.scale),
                )


def _joint_shape(j: Joint, links: set[str], joints: set[str], out: Collector) -> None:
    for role, name in (("parent", j.parent), ("child", j.child)):
        if name is None:
            out.add("unknown-link", j.line, f"joint {j.name!r}: no <{role} link=...>", link="")
        elif name not in links:
            out.add(
                "unknown-link",
                j.line,
                f"joint {j.name!r}: {role} link {name!r} does not exist",
                link=name,
            )
    if j.type not in JOINT_TYPES:
        out.add("joint-type", j.line, f"joint {j.name!r}: unknown type {j.type!r}", type=j.type)
    if j.type in LIMITED_TYPES:
        lim = j.limit
        missing = (
            ["limit"]
            if lim is None
            else [
                *(lim.missing_bounds if j.type == "revolute" else ()),
                *(a for a in ("effort", "velocity") if getattr(lim, a) is None),
            ]
        )
        if missing:
            out.add(
                "missing-limit",
                (lim.line if lim else j.line),
                f"{j.type} joint {j.name!r} lacks {', '.join(missing)}",
            )
    if j.mimic is not None and j.mimic not in joints:
        out.add(
            "mimic-target",
            j.mimic_line,
            f"joint {j.name!r} mimics unknown joint {j.mimic!r}",
            target=j.mimic,
        )


def _tree(urdf: Urdf, out: Collector) -> KinematicTree:
    """The tree, with a finding for each way it is not one: parents, roots, cycles."""
    tree = KinematicTree.of(urdf)
    for j in tree.extra_parents:
        first = tree.parent_joint[str(j.child)]
        out.add(
            "multiple-parents",
            j.line,
            f"link {j.child!r} is the child of {first.name!r} and {j.name!r}",
            link=j.child,
        )
    roots = sorted(tree.roots)
    if len(roots) != 1:
        line = urdf.links[0].line if urdf.links else None
        out.add("root-count", line, _root_message(roots, bool(tree.links)), roots=", ".join(roots))
    elif tree.orphans:
        orphans = list(tree.orphans)
        line = next((lk.line for lk in urdf.links if lk.name == orphans[0]), None)
        out.add(
            "disconnected",
            line,
            f"links not connected to root {roots[0]!r} (cycle?): {orphans}",
            links=", ".join(orphans),
        )
    return tree


def finite(*values: float | None) -> bool:
    """True when every value is present and finite."""
    return all(v is not None and math.isfinite(v) for v in values)


def _root_message(roots: list[str], has_links: bool) -> str:
    if not has_links:
        return "no <link>"
    if not roots:
        return "no root link: every link has a parent joint, so the joints form a cycle"
    return f"expected one root link, found {len(roots)}: {', '.join(roots)}"
